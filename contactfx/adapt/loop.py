"""The adaptive loop: solve, estimate, mark (size the next mesh), remesh with gmsh; repeat.

DOLFINx cannot refine quadrilaterals, so every level remeshes the scene's geometry (a
built-in scene's gmsh model or a .geo) from a background size field built from the
indicators (adapt/sizing.py). The loop stops when the relative estimate is at most `tol`,
after `max_levels` levels, or when the next mesh would exceed `max_dofs`. `uniform_levels`
refines the same starting scene uniformly, for the comparison charts.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..api import run_scene
from ..errors import InputError
from ..methods.predictor import scene_dofs
from ..methods.solution import Solution
from ..request import SolveRequest
from ..results.records import RunSummary
from ..scenes import Scene
from ..timers import Timers
from .estimate import Estimate, estimate
from .goal import Goal, GoalRecord
from .sizing import Plan, SizingRule, plan_mesh

# On a full budget, the pressure sizing goes on while its estimate falls below this fraction
# of the previous level's.
PRESSURE_PROGRESS = 0.8


@dataclass(frozen=True)
class AdaptOptions:
    """When the loop stops and how it sizes meshes."""

    tol: float = 0.05  # relative estimate to reach
    max_dofs: int = 200_000
    max_levels: int = 8
    rule: SizingRule = field(default_factory=SizingRule)
    pressure_tol: float | None = None  # relative L2 pressure estimate to reach too
    # The quantity `tol` bounds (adapt/planned.py: the goal loop); None: the residual
    # estimate's loop below (the expert flags' loop, `--goal residual`).
    goal: Goal | None = None

    def pressure_met(self, est: Estimate) -> bool:
        """Whether the pressure estimate needs nothing more (always, without pressure_tol)."""
        if self.pressure_tol is None or est.pressure is None:
            return True
        return est.pressure.relative <= self.pressure_tol

    def pressure_settled(self, est: Estimate, before: Estimate | None) -> bool:
        """Whether the pressure sizing has nothing left to gain on a full budget.

        Met, or fallen by less than PRESSURE_PROGRESS on the last level: past that the
        pressure error is the bulk's (a three-body scene's discrete half-width settles
        0.09 % short of Hertz's while the estimate creeps down, docs/adapt.md).
        """
        if self.pressure_met(est):
            return True
        if before is None or before.pressure is None or est.pressure is None:
            return False
        return est.pressure.relative > PRESSURE_PROGRESS * before.pressure.relative

    def met(self, est: Estimate) -> str | None:
        """Why the loop may stop at this estimate, or None."""
        if est.relative > self.tol:
            return None
        if not self.pressure_met(est):
            return None
        # Percent, as the level lines print the estimates.
        reached = f"estimate {100 * est.relative:.2g} % <= tol {100 * self.tol:g} %"
        if self.pressure_tol is None or est.pressure is None:
            return reached
        return (
            f"{reached}, pressure estimate {100 * est.pressure.relative:.2g} % "
            f"<= {100 * self.pressure_tol:g} %"
        )

    def check(self) -> None:
        """InputError for a value out of range."""
        if not (self.tol > 0):
            raise InputError(f"--tol must be > 0 (got {self.tol})")
        if not (self.rule.growth > 1.0):
            raise InputError(
                f"--growth must be > 1: the most cells of a level relative to the previous "
                f"one (got {self.rule.growth:g})"
            )
        if self.max_dofs < 10:
            raise InputError(f"--max-dofs must be at least 10 (got {self.max_dofs})")
        if not (self.rule.contact_weight >= 1.0):
            raise InputError(f"--weight-contact must be >= 1 (got {self.rule.contact_weight})")
        if self.max_levels < 1:
            raise InputError(f"--max-levels must be at least 1 (got {self.max_levels})")
        if self.pressure_tol is not None and not (self.pressure_tol > 0):
            raise InputError(f"--pressure-tol must be > 0 (got {self.pressure_tol})")


@dataclass(frozen=True)
class AdaptLevel:
    """One solved level: its summary (with the estimate), the solution and the estimate."""

    index: int
    summary: RunSummary
    solution: Solution
    est: Estimate
    time: float  # seconds: meshing (remesh) + solve + estimate (+ the goal's refined solve)
    goal: GoalRecord | None = None  # the goal estimate (the goal loop, adapt/planned.py)

    @property
    def dofs(self) -> int:
        """Displacement DOFs of the level."""
        return self.summary.dofs

    def to_json(self) -> dict[str, Any]:
        """The level's entry of adapt.json: the run's JSON, `estimate` the relative total."""
        out = self.summary.to_json()
        out["estimate"] = self.est.relative
        out["estimate_parts"] = self.est.summary().to_json()
        out["level"] = self.index
        out["time"] = self.time
        if self.goal is not None:
            out.update(self.goal.to_json())
            out["estimate"] = self.goal.relative
            exact = self.exact_error
            if exact is not None:
                out["exact_error"] = exact
                out["effectivity"] = self.goal.relative / exact if exact > 0 else None
        return out

    @property
    def exact_error(self) -> float | None:
        """The goal's exact relative error where the scene has one (pressure on Hertz)."""
        if self.goal is None or self.goal.goal is not Goal.PRESSURE or not self.summary.hertz:
            return None
        return max(h.l2_error for h in self.summary.hertz)


@dataclass
class AdaptResult:
    """The levels, why the loop stopped, and the uniform levels if asked for."""

    levels: list[AdaptLevel]
    stop: str
    uniform: list[AdaptLevel] = field(default_factory=list)

    def to_json(self, scene: str, method: str, opts: AdaptOptions, solver: str) -> dict[str, Any]:
        """adapt.json: the settings, every level (estimate a number), why the loop stopped.

        `scene`, `method` and `solver` as the user named them.
        """
        return {
            "scene": scene,
            "method": method,
            "settings": {
                "tol": opts.tol,
                "max_dofs": opts.max_dofs,
                "max_levels": opts.max_levels,
                "rate": opts.rule.rate,
                "growth": opts.rule.growth,
                "weight_contact": opts.rule.contact_weight,
                "pressure_tol": opts.pressure_tol,
                "goal": opts.goal.value if opts.goal is not None else "residual",
                "solver": solver,
            },
            "stop": self.stop,
            "levels": [lv.to_json() for lv in self.levels],
            **({"uniform": [lv.to_json() for lv in self.uniform]} if self.uniform else {}),
        }


def solve_level(
    scene: Scene,
    index: int,
    mesh_time: float,
    request: SolveRequest,
    paper_interface: bool,
    previous: Solution | None = None,
) -> AdaptLevel:
    """Solve one mesh and estimate its error; the summary carries the estimate.

    `previous` (the level before) gives the first active set: remeshing a coarser copy of
    an adapted mesh for the predictor costs more than it saves, and gmsh may fail to
    recombine it.
    """
    t0 = time.perf_counter()
    sol, run = run_scene(
        scene, request, timers=Timers(), paper_interface=paper_interface, initial=previous
    )
    est = estimate(sol)
    run = run.with_estimate(est.summary()).with_times(mesh=mesh_time)
    elapsed = mesh_time + time.perf_counter() - t0
    return AdaptLevel(index, run, sol, est, elapsed)


# Remeshings with a smaller budget when gmsh's mesh exceeds --max-dofs.
REPLANS = 2


def adapt(
    scene: Scene,
    request: SolveRequest,
    opts: AdaptOptions,
    *,
    paper_interface: bool = False,
    say: Callable[[str], None] | None = None,
    mesh_time: float = 0.0,
    count_dofs: Callable[[Scene], int] = scene_dofs,
    plan: Callable[..., Plan] = plan_mesh,
) -> AdaptResult:
    """Run the adaptive loop from `scene` (collective); `say` prints progress (rank 0).

    `count_dofs` counts a remeshed scene's DOFs against the budget and `plan` sizes the next
    mesh (`plan_mesh`'s arguments); tests pass their own to steer the loop.
    """
    opts.check()
    scene.require_recipe()
    comm = scene.comm
    say = say or (lambda line: print(line, flush=True) if comm.rank == 0 else None)
    levels: list[AdaptLevel] = []
    stop = f"max levels ({opts.max_levels})"
    for k in range(opts.max_levels):
        previous = levels[-1].solution if levels else None
        level = solve_level(scene, k, mesh_time, request, paper_interface, previous)
        levels.append(level)
        say(level_line(level))
        reached = opts.met(level.est)
        if reached is not None:
            stop = reached
            break
        if k + 1 == opts.max_levels:
            break
        ratio = level.dofs / max(level.summary.elements, 1)
        # 10 % margin: gmsh meets a size field only approximately.
        budget = 0.9 * opts.max_dofs / ratio
        sizes = plan(level.solution, level.est, opts.tol, budget, opts.rule, opts.pressure_tol)
        if (
            sizes.predicted > opts.tol
            and sizes.cells < 1.1 * level.summary.elements
            and opts.pressure_settled(level.est, levels[-2].est if k else None)
        ):
            stop = f"the next mesh would exceed --max-dofs {opts.max_dofs}"
            break
        t0 = time.perf_counter()
        nxt = scene.remeshed_to(sizes.field)
        dofs = count_dofs(nxt)
        for _ in range(REPLANS):
            if dofs <= opts.max_dofs:
                break
            # gmsh overshot the budget: plan again for what fits, rather than stop a level
            # early (on Hertz the last level is the one the pressure target needs).
            budget *= 0.95 * opts.max_dofs / dofs
            sizes = plan(level.solution, level.est, opts.tol, budget, opts.rule, opts.pressure_tol)
            nxt = scene.remeshed_to(sizes.field)
            dofs = count_dofs(nxt)
        mesh_time = time.perf_counter() - t0
        if dofs > opts.max_dofs:
            stop = f"the next mesh would have {dofs} DOFs > --max-dofs {opts.max_dofs}"
            break
        say(
            f"  remeshed: {dofs} DOFs planned for an estimate of "
            f"{100 * sizes.predicted:.3g} % ({mesh_time:.2f} s)"
        )
        scene = nxt
    say(f"stopped: {stop}")
    return AdaptResult(levels, stop)


def uniform_levels(
    scene: Scene,
    request: SolveRequest,
    max_dofs: int,
    *,
    ratio: float = 2.0,
    max_levels: int = 8,
    paper_interface: bool = False,
    say: Callable[[str], None] | None = None,
) -> list[AdaptLevel]:
    """The same scene refined uniformly (every size / ratio per level) up to max_dofs.

    The last level is the first at or beyond max_dofs (so that the uniform curve spans the
    adaptive one), unless it would exceed ratio^2 max_dofs.
    """
    comm = scene.comm
    say = say or (lambda line: print(line, flush=True) if comm.rank == 0 else None)
    out: list[AdaptLevel] = []
    current, mesh_time = scene, 0.0
    for k in range(max_levels):
        if scene_dofs(current) > ratio**2 * max_dofs:
            break
        level = solve_level(current, k, mesh_time, request, paper_interface)
        out.append(level)
        say("uniform " + level_line(level))
        if level.dofs >= max_dofs:
            break
        t0 = time.perf_counter()
        current = scene.remeshed(ratio ** -(k + 1))
        mesh_time = time.perf_counter() - t0
    return out


def level_line(level: AdaptLevel) -> str:
    """One progress line: DOFs, estimate (contact and bulk), the reference error, time."""
    run = level.summary
    e = level.est.summary()
    ref = ""
    if len(run.hertz) == 1:
        ref = f", Hertz L2 {100 * run.hertz[0].l2_error:.3f} %"
    elif run.hertz:
        # Every pair: the first alone hid a pair ten times worse.
        ref = ", Hertz L2 " + ", ".join(
            f"pair {h.pair} {100 * h.l2_error:.3f} %" for h in run.hertz
        )
    elif run.patch is not None:
        ref = f", patch max {run.patch.max:.2e}"
    pressure = f", pressure {100 * e.pressure:.3g} %" if e.pressure else ""
    if level.goal is not None:
        g = level.goal
        eff = level.exact_error
        eff_s = f", effectivity {g.relative / eff:.2f}" if eff else ""
        return (
            f"level {level.index}: {run.dofs} DOFs, {g.goal.value} estimate "
            f"{100 * g.relative:.3g} %{ref}{eff_s} (residual {100 * e.total:.3g} %), "
            f"{level.time:.2f} s"
        )
    return (
        f"level {level.index}: {run.dofs} DOFs, estimate {100 * e.total:.3g} % "
        f"(contact {100 * e.contact:.3g} %, bulk {100 * e.bulk:.3g} %{pressure}){ref}, "
        f"{level.time:.2f} s"
    )
