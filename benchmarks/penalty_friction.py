"""The penalty friction baseline against the multipliers on one Cattaneo-Mindlin scene.

tests/scenes/cattaneo_cylinders.geo as in tests/methods/test_friction.py (R = 1, h = 0.004
at the contact, E = 1000, nu = 0.3, mu = 0.3): the lower flat face held, the upper one
pressed down by 0.03 (a = 0.1) and then pushed sideways by 0.01 (Q about 0.6 mu P), mortar
with multipliers and the penalty on the same mortar rows at 0.1, 1 and 10 times its default
eps_n = eps_t = 1e3 E / h. Per run: Q / mu P, the stick half-width against Cattaneo's c (in
cells), the shear's L2 error against the closed form, the largest and the L2 difference of
pressure and shear from the multipliers' (relative to the largest pressure), the largest
penetration, the iterations per step and the wall time (median of `repeats`; the machine may
be shared: compare within one run). Writes benchmarks/penalty_friction.json:

    OPENBLAS_NUM_THREADS=1 python benchmarks/penalty_friction.py [repeats]
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from contactfx import ContactPair, SolveRequest, scene_from_gmsh, solve
from contactfx.methods.solution import Solution
from contactfx.results.friction_references import cattaneo_errors, cattaneo_mindlin
from contactfx.scenes import Dirichlet, Material, Scene

HERE = Path(__file__).resolve().parent
GEO = HERE.parent / "tests" / "scenes" / "cattaneo_cylinders.geo"
E, NU, MU, R, PRESS, PUSH = 1000.0, 0.3, 0.3, 1.0, 0.03, 0.01


def scene() -> Scene:
    """The mirrored half-cylinders, pressed then pushed (two load steps)."""
    return scene_from_gmsh(
        GEO,
        bodies={"upper": Material(E, NU), "lower": Material(E, NU)},
        contacts=[ContactPair("upper_arc", "lower_arc", mu=MU)],
        dirichlet=[
            Dirichlet("lower_flat", ux=0.0, uy=0.0),
            Dirichlet("upper_flat", uy=-PRESS, name="press"),
            Dirichlet("upper_flat", ux=PUSH, name="push"),
        ],
        steps=[{"press": 1.0}, {"push": 1.0}],
    )


def timed(request: SolveRequest, repeats: int) -> tuple[Solution, float]:
    """The solution and the median wall time of `repeats` solves."""
    times, sol = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        sol = solve(scene(), request)
        times.append(time.perf_counter() - t0)
    assert sol is not None
    return sol, float(np.median(times))


def row(sol: Solution, ref: Solution | None, seconds: float) -> dict[str, object]:
    """One run's measures (module docstring)."""
    fr = sol.friction
    assert fr is not None
    w, x = sol.layout.weights, sol.layout.x[:, 0]
    p_total, q_total = float(w @ sol.pressure), float(w @ fr.shear)
    cm = cattaneo_mindlin(p_total, q_total, MU, R / 2, E / (2 * (1 - NU**2)))
    err = cattaneo_errors(cm, x, fr.shear, sol.pressure, fr.status == 1)
    cell = float(np.median(np.diff(np.sort(x[sol.active]))))
    out: dict[str, object] = {
        "eps": None if sol.penalty is None else sol.penalty.eps,
        "penetration": None if sol.penalty is None else sol.penalty.penetration,
        "q_over_mu_p": q_total / (MU * p_total),
        "stick_minus_c_cells": (err.c - cm.c) / cell,
        "shear_l2_vs_cattaneo": err.shear_l2,
        "iterations": [s.iterations for s in sol.steps],
        "seconds": seconds,
    }
    if ref is not None:
        assert ref.friction is not None
        scale = float(ref.pressure.max())
        for name, a, b in (
            ("p", sol.pressure, ref.pressure),
            ("shear", fr.shear, ref.friction.shear),
        ):
            out[f"{name}_max_diff"] = float(np.abs(a - b).max()) / scale
            out[f"{name}_l2_diff"] = float(np.sqrt(w @ (a - b) ** 2 / (w @ ref.pressure**2)))
    return out


def main(repeats: int) -> None:
    """Solve by multipliers, then by penalty at three sizes; print and write the rows."""
    ref, t_ref = timed(SolveRequest.parse("mortar"), repeats)
    rows = {"multipliers": row(ref, None, t_ref)}
    default = solve(scene(), SolveRequest.parse("penalty"))
    assert default.penalty is not None
    for factor in (0.1, 1.0, 10.0):
        request = SolveRequest.parse("penalty", penalty=factor * default.penalty.eps)
        sol, t = timed(request, repeats)
        rows[f"penalty x{factor:g}"] = row(sol, ref, t)
    for name, r in rows.items():
        print(name, json.dumps(r))
    (HERE / "penalty_friction.json").write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
