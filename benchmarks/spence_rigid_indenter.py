"""Spence against a frictional solve: the rigid cylinder of rigid_indenter.toml pressed with mu.

demos/scenes/rigid_indenter.toml (a rigid cylinder R = 20 moved 0.05 into a block, E = 7000,
nu = 0.3, plane strain, half model) with mu on the obstacle, the indenter's motion applied in
equal load steps (the obstacle's name in the steps). Per step: the contact half-width a (the
last contact node), the stick half-width c (the last stick node), c/a against
contactfx.results.friction_references.spence_stick_ratio, and c - (c/a)_ref a in cells:

    OPENBLAS_NUM_THREADS=1 python benchmarks/spence_rigid_indenter.py nts 20
    OPENBLAS_NUM_THREADS=1 python benchmarks/spence_rigid_indenter.py mortar 4

(arguments: method, number of steps; mu = 0.3).
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from contactfx import load_scene_file, solve
from contactfx.contact.friction import Status
from contactfx.results.friction_references import spence_stick_ratio

MU, NU = 0.3, 0.3
SCENE = Path(__file__).resolve().parents[1] / "demos" / "scenes" / "rigid_indenter.toml"


def main(method: str, n_steps: int) -> None:
    """Print each step's a, c, c/a and the stick edge's offset from Spence's, in cells."""
    scene = load_scene_file(SCENE)
    obstacle = replace(scene.obstacles[0], mu=MU)
    factors = [(k + 1) / n_steps for k in range(n_steps)]
    scene = replace(scene, obstacles=(obstacle,), steps=tuple({"indenter": f} for f in factors))
    sol = solve(scene, method)
    ref = spence_stick_ratio(MU, NU)
    for f, step in zip(factors, sol.steps, strict=True):
        assert step.friction is not None
        x = step.layout.x[:, 0]
        stick = step.friction.status == Status.STICK
        a = float(x[step.active].max())
        h = float(np.median(np.diff(np.sort(x[step.active]))))
        c = float(x[stick].max()) if stick.any() else 0.0
        print(
            f"step {f:.3f}: a = {a:.4f}, c = {c:.4f}, c/a = {c / a:.4f} (Spence {ref:.4f}), "
            f"c - ref a = {(c - ref * a) / h:+.2f} cells, {step.iterations} iterations"
        )


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]))
