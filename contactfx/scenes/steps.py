"""Load steps: factors on named loads, in order (friction depends on the load path).

Any pressure, traction or Dirichlet condition may carry a `name`; an obstacle's `name` names
its prescribed rigid motion (`displacement`). Each step is a mapping of
load names to factors; a load without a name acts in full in every step, a named load that a
step does not mention keeps its factor from the step before (0 before the first step). A
scene without steps is one step with every load in full (the model unchanged).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

from ..errors import InputError
from .model import Dirichlet, Load, Pressure, Scene, Traction


def load_names(scene: Scene) -> set[str]:
    """The names the scene's loads, Dirichlet conditions and obstacles (their motion) carry."""
    named = {x.name for x in (*scene.loads, *scene.dirichlet) if x.name is not None}
    return named | {ob.name for ob in scene.obstacles}


def check_steps(steps: Sequence[Any], names: set[str]) -> tuple[Mapping[str, float], ...]:
    """The steps as stored, each a table of numbers on known load names (InputError else)."""
    out = []
    for k, step in enumerate(steps):
        if not isinstance(step, Mapping):
            raise InputError(f"step {k}: expected a table of load names and factors (got {step!r})")
        factors = {}
        for name, value in step.items():
            if name not in names:
                known = ", ".join(sorted(names)) or "none: give a load a name"
                raise InputError(f"step {k}: no load is named '{name}' (named loads: {known})")
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise InputError(f"step {k}.{name}: expected a number (a factor), got {value!r}")
            if not math.isfinite(value):
                raise InputError(f"step {k}.{name}: expected a finite number, got {value!r}")
            factors[str(name)] = float(value)
        out.append(factors)
    return tuple(out)


def step_factors(scene: Scene) -> list[dict[str, float]]:
    """Every named load's factor in every step (a named load keeps its last factor)."""
    current = dict.fromkeys(load_names(scene), 0.0)
    out = []
    for step in scene.steps:
        current.update(step)
        out.append(dict(current))
    return out


def _scaled(x: Pressure | Traction | Dirichlet, f: float) -> Pressure | Traction | Dirichlet:
    if isinstance(x, Pressure):
        return replace(x, p=f * x.p)
    if isinstance(x, Traction):
        return replace(x, t=(f * x.t[0], f * x.t[1]))
    ux = None if x.ux is None else f * x.ux
    uy = None if x.uy is None else f * x.uy
    return replace(x, ux=ux, uy=uy)


def step_scenes(scene: Scene) -> list[Scene]:
    """The scene of each load step (its loads scaled); [scene] itself without steps."""
    if not scene.steps:
        return [scene]
    out = []
    for factors in step_factors(scene):

        def scale(x: Any, factors: dict[str, float] = factors) -> Any:
            return x if x.name is None else _scaled(x, factors[x.name])

        loads: tuple[Load, ...] = tuple(scale(x) for x in scene.loads)
        dirichlet = tuple(scale(x) for x in scene.dirichlet)
        obstacles = tuple(
            replace(ob, displacement=(f * ob.displacement[0], f * ob.displacement[1]))
            for ob, f in ((ob, factors[ob.name]) for ob in scene.obstacles)
        )
        out.append(replace(scene, loads=loads, dirichlet=dirichlet, obstacles=obstacles, steps=()))
    return out
