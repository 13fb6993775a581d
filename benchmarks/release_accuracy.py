"""How accurate is the release step's capacitance answer? (docs/scale.md, "The release step's
refinement").

`[mpirun -n R] python benchmarks/release_accuracy.py REFINE [MESH]`: the Hertz scene (mortar,
`mumps`, default grading) solved three times in one process with `--reference-timing`:
the loop as it is; the loop with every release step refined as before 0.9.0 (to the
factorization's own residual, ROUNDOFF = 1); and once more with the reference solve by
GMRES to 1e-15 around the fresh LDL^T (the accurate answer of the final set). Prints the
largest difference of u and mu from the accurate answer, relative to its largest entry, for
the last release step of each loop and for the fresh LDL^T's single back-substitution.
"""

from __future__ import annotations

import sys

import numpy as np
from mpi4py import MPI

import contactfx.linalg.capacitance as cap
import contactfx.linalg.saddle as sad
import contactfx.methods.multipliers as mult
from contactfx.api import solve
from contactfx.options import SOLVERS, SolverSpec
from contactfx.scenes import HertzParams, hertz

COMM = MPI.COMM_WORLD
ACCURATE = [
    "ksp_type=gmres",
    "ksp_rtol=1e-15",
    "ksp_atol=0",
    "ksp_gmres_modifiedgramschmidt=1",
    "ksp_pc_side=right",
    "ksp_max_it=30",
]


def _capture() -> dict[str, tuple]:
    """Wrap the release step and the reference solve to keep copies of their answers."""
    got: dict[str, tuple] = {}
    released, fresh = sad.SaddleSolver._solve_released, mult._timed_fresh_solve

    def on_release(self, g, active, changed):  # type: ignore[no-untyped-def]
        res = released(self, g, active, changed)
        if res is not None:
            got["released"] = (res.u.copy(), res.mu.copy(), res.iterations, res.residual)
        return res

    def on_fresh(setup, spec, scene, active):  # type: ignore[no-untyped-def]
        res, seconds = fresh(setup, spec, scene, active)
        got.setdefault("fresh", (res.u.copy(), res.mu.copy(), res.iterations, None))
        return res, seconds

    sad.SaddleSolver._solve_released = on_release  # type: ignore[method-assign]
    mult._timed_fresh_solve = on_fresh
    return got


def _diff(a: np.ndarray, b: np.ndarray) -> float:
    num = COMM.allreduce(float(np.abs(a - b).max()) if a.size else 0.0, op=MPI.MAX)
    return num / COMM.allreduce(float(np.abs(b).max()) if b.size else 0.0, op=MPI.MAX)


def main() -> None:
    refine = float(sys.argv[1])
    mesh = sys.argv[2] if len(sys.argv) > 2 else "structured"
    got = _capture()

    def run(spec: SolverSpec) -> dict[str, tuple]:
        got.clear()
        solve(hertz(HertzParams(refine=refine, mesh=mesh)), "mortar", solver=spec,
              reference_timing=True)  # fmt: skip
        return dict(got)

    now = run(SOLVERS["mumps"])
    roundoff, cap.ROUNDOFF = cap.ROUNDOFF, 1.0
    before = run(SOLVERS["mumps"])
    cap.ROUNDOFF = roundoff
    accurate = run(SOLVERS["mumps"].with_petsc(ACCURATE))["fresh"]
    rows = [
        ("release step, this rule", now.get("released")),
        ("release step, refined (ROUNDOFF 1)", before.get("released")),
        ("fresh LDL^T, one back-substitution", now["fresh"]),
    ]
    for name, d in rows:
        if d is None:
            text = f"{name}: no release step"
        else:
            du, dmu = _diff(d[0], accurate[0]), _diff(d[1], accurate[1])
            res = "" if d[3] is None else f", residual {d[3]:.2e}"
            text = f"{name}: u {du:.2e}, mu {dmu:.2e} ({d[2]} back-substitutions{res})"
        if COMM.rank == 0:
            print(text)


if __name__ == "__main__":
    main()
