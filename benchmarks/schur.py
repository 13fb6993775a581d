"""The Schur-complement route against the default: contact solves and their floor in one process.

`python benchmarks/schur.py gmsh:0.005 structured:0.0025 ... [--method mortar] [--repeats 2]`
meshes each Hertz case once (default grading: `--refine H`, gmsh also `--refine-edge H/4`),
then solves it by `mumps` (probes by selected inverse, coarse start above 500 rows) and by
`mumps-schur` (MUMPS' Schur complement of every multiplier row: linalg/schur.py) in turn,
each with `--reference-timing` (a fresh plain LDL^T of the final system after the solve),
and writes benchmarks/schur.json: per case and solver the contact solve (search + B +
predictor + active-set solves), the fresh LDL^T, their ratio, and the largest differences
of u and of the pressure between the two solvers (relative to their maxima). Ratios are
taken within one process (the machine is shared).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)
import numpy as np
from mpi4py import MPI

from contactfx.api import solve
from contactfx.scenes import HertzParams, hertz
from contactfx.timers import Timers

HERE = Path(__file__).resolve().parent
SOLVERS = ("mumps", "mumps-schur")


def contact_solve(seconds: dict[str, float]) -> float:
    """Search + B assembly + the coarse predictor (if any) + the active-set solves."""
    return sum(seconds.get(k, 0.0) for k in ("search", "contact", "predictor", "solve"))


def run_case(mesh: str, refine: float, method: str, repeats: int) -> dict[str, object]:
    """One mesh, both solvers `repeats` times (taking turns); ratios and differences."""
    extra = {"refine_edge": refine / 4} if mesh == "gmsh" else {}
    scene = hertz(HertzParams(refine=refine, mesh=mesh, **extra), comm=MPI.COMM_WORLD)
    runs: dict[str, list[dict[str, float]]] = {s: [] for s in SOLVERS}
    fields = {}
    for k in range(repeats):
        order = SOLVERS if k % 2 == 0 else SOLVERS[::-1]
        for solver in order:
            timers = Timers()
            sol = solve(scene, method, solver=solver, timers=timers, reference_timing=True)
            cs = contact_solve(timers.seconds)
            ldlt = timers.seconds["reference_ldlt"]
            runs[solver].append(
                {
                    "contact_solve": cs,
                    "fresh_ldlt": ldlt,
                    "ratio": cs / ldlt,
                    "steps": sol.iterations,
                    "predictor": timers.seconds.get("predictor", 0.0),
                }
            )
            fields[solver] = (sol.u.x.array.copy(), np.asarray(sol.pressure), sol)
            print(f"{mesh} {refine} {solver}: {runs[solver][-1]}", flush=True)
    (ua, pa, a), (ub, pb, b) = fields["mumps"], fields["mumps-schur"]
    return {
        "mesh": mesh,
        "refine": refine,
        "method": method,
        "dofs": a.dofs,
        "rows": int(a.layout.size),
        "same_set": bool(np.array_equal(a.active, b.active)),
        "du": float(np.abs(ua - ub).max() / np.abs(ua).max()),
        "dp": float(np.abs(pa - pb).max() / np.abs(pa).max()),
        "runs": runs,
        "median_ratio": {s: float(np.median([r["ratio"] for r in runs[s]])) for s in SOLVERS},
    }


def main() -> None:
    """Run the cases given as MESH:REFINE, merge them into benchmarks/schur.json."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("cases", nargs="+", metavar="MESH:REFINE")
    ap.add_argument("--method", default="mortar")
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    out = HERE / "schur.json"
    data = json.loads(out.read_text()) if out.exists() else {"cases": []}
    for case in args.cases:
        mesh, refine = case.split(":")
        rec = run_case(mesh, float(refine), args.method, args.repeats)
        rec["date"] = time.strftime("%Y-%m-%d %H:%M")
        rec["load"] = os.getloadavg()[0]
        key = (rec["mesh"], rec["refine"], rec["method"])
        data["cases"] = [
            c for c in data["cases"] if (c["mesh"], c["refine"], c["method"]) != key
        ] + [rec]
        out.write_text(json.dumps(data, indent=1) + "\n")
        print(
            f"{mesh} {refine}: {rec['dofs']:,} dofs, {rec['rows']} rows, ratios "
            f"{rec['median_ratio']}, du {rec['du']:.1e}, dp {rec['dp']:.1e}",
            flush=True,
        )


if __name__ == "__main__":
    main()
