"""The contact solve against a warm LU of the same saddle point, per solver, in one process.

Issue 32 asks for a contact solve of at most 0.85x a plain warm MUMPS LU at 1.2M DOFs. Per
mesh (the Hertz scene of the 10H family, `--refine H --h-far 10H`, gmsh also
`--refine-edge H/4`, dual mortar), in one process: the scene meshed once, then `--pairs`
rounds of each solver's whole contact solve (search, B, predictor, every active-set step),
the solvers taking turns; every `mumps` solve also times a fresh LU and a fresh LDL^T of the
final saddle point (`--reference-timing`), the warm floors. Serial only (the floors of two
ranks need the memory the condensed path saves):

    python benchmarks/warm_lu.py --mesh structured,gmsh --dofs 1.2e6 --pairs 3

docs/scale.md, "A warm LU at 1.2M", cites its output (benchmarks/warm_lu.json).
"""

from __future__ import annotations

import argparse
import gc
import json
import statistics
import time
from pathlib import Path
from typing import Any

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)
from mpi4py import MPI

# benchmarks/run.py, next to this script: on sys.path as its folder.
from run import EDGE_RATIO, H_RATIO, refine_for
from sweep_report import contact_solve

from contactfx.api import solve
from contactfx.scenes import HertzParams, hertz
from contactfx.timers import Timers

HERE = Path(__file__).resolve().parent
SOLVERS = ("condensed", "mumps")


def one_mesh(mesh: str, dofs: float, pairs: int) -> list[dict[str, Any]]:
    """Mesh once; `pairs` rounds of each solver's contact solve; one record per solve."""
    h = refine_for(dofs, mesh)
    edge = {"refine_edge": h / EDGE_RATIO} if mesh == "gmsh" else {}
    t0 = time.perf_counter()
    scene = hertz(HertzParams(refine=h, h_far=H_RATIO * h, mesh=mesh, **edge), comm=MPI.COMM_SELF)
    mesh_s = time.perf_counter() - t0
    out = []
    for k in range(pairs):
        for solver in SOLVERS:
            gc.collect()  # the previous solve's PETSc objects
            timers = Timers()
            sol = solve(
                scene,
                "mortar",
                solver=solver,
                basis="dual",
                timers=timers,
                reference_timing=solver == "mumps",
            )
            s = timers.seconds
            rec = {
                "mesh": mesh,
                "dofs": sol.dofs,
                "round": k,
                "solver": solver,
                "mesh_s": round(mesh_s, 2),
                "steps": sol.iterations,
                "active": int(sol.active.sum()),
                "linear_iterations": [h.get("linear_iterations") for h in sol.history],
                "contact_solve": round(contact_solve({"times": s}), 3),
                "times": {key: round(v, 3) for key, v in s.items()},
            }
            out.append(rec)
            print(json.dumps(rec), flush=True)
    return out


def summary(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per mesh: the medians of each solver's contact solve and of the warm floors."""
    rows = []
    for mesh in dict.fromkeys(r["mesh"] for r in runs):
        mine = [r for r in runs if r["mesh"] == mesh]
        direct = [r for r in mine if r["solver"] == "mumps"]
        lu = statistics.median(r["times"]["reference_lu"] for r in direct)
        ldlt = statistics.median(r["times"]["reference_ldlt"] for r in direct)
        row: dict[str, Any] = {"mesh": mesh, "dofs": mine[0]["dofs"], "lu": lu, "ldlt": ldlt}
        for solver in SOLVERS:
            cs = [r["contact_solve"] for r in mine if r["solver"] == solver]
            row[solver] = statistics.median(cs)
            row[f"{solver}_range"] = (min(cs), max(cs))
            row[f"{solver}_over_lu"] = row[solver] / lu
        rows.append(row)
    return rows


def table(rows: list[dict[str, Any]]) -> str:
    """The markdown table of `summary`."""
    lines = [
        "| mesh | DOFs | warm LU (s) | warm LDL^T (s) | `condensed` (s) | / LU | `mumps` (s) "
        "| / LU |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        c, m = r["condensed_range"], r["mumps_range"]
        lines.append(
            f"| {r['mesh']} | {r['dofs']:,} | {r['lu']:.2f} | {r['ldlt']:.2f} | "
            f"{r['condensed']:.2f} ({c[0]:.2f}-{c[1]:.2f}) | {r['condensed_over_lu']:.2f} | "
            f"{r['mumps']:.2f} ({m[0]:.2f}-{m[1]:.2f}) | {r['mumps_over_lu']:.2f} |"
        )
    return "\n".join(lines)


def main() -> None:
    """Parse, run every mesh, write warm_lu.json and print the table."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mesh", default="structured,gmsh", help="comma list: structured, gmsh")
    ap.add_argument("--dofs", type=float, default=1.2e6, help="target DOFs (the 10H family)")
    ap.add_argument("--pairs", type=int, default=3, help="rounds of the solvers per mesh")
    args = ap.parse_args()
    if MPI.COMM_WORLD.size > 1:
        ap.error("serial only (the warm floors of several ranks would need the memory)")
    t0 = time.strftime("%Y-%m-%d %H:%M")
    runs = [r for mesh in args.mesh.split(",") for r in one_mesh(mesh, args.dofs, args.pairs)]
    rows = summary(runs)
    (HERE / "warm_lu.json").write_text(
        json.dumps({"date": t0, "runs": runs, "summary": rows}, indent=1) + "\n"
    )
    print(table(rows))


if __name__ == "__main__":
    main()
