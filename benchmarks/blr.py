"""MUMPS' block low-rank (BLR) LDL^T against the full-rank default on one Hertz mesh.

`[mpirun -n 2] python benchmarks/blr.py --mesh structured --refine H [--h-far F]
[--variants full,blr:1e-8:2,...] [--repeats R]` meshes once, then solves the scene (mortar,
`--reference-timing`: the fresh LDL^T and LU stay full rank) with each variant in turn, R
rounds, so old and new alternate in one process. A variant is `full` (the `mumps` preset) or
`blr:CNTL7:ICNTL35[:ICNTL36]` (`mumps-blr` with that threshold and variants). Prints per solve the
contact solve time, the fresh LDL^T / LU, the steps and linear iterations, and against the
first `full` solve: the largest pressure and displacement differences relative to their
maxima, whether the active set is the same, the force and Hertz a / p0 / L2 errors.
docs/scale.md, "Block low-rank factorization", cites it.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np
from mpi4py import MPI

from contactfx.api import run_scene
from contactfx.options import LowRank, SolverSpec, solver_spec
from contactfx.scenes import HertzParams
from contactfx.scenes.builtin import build_scene


def variant(name: str) -> SolverSpec:
    """The spec of a variant name: `full` or `blr:CNTL7:ICNTL35`."""
    if name == "full":
        return solver_spec("mumps")
    _, tol, icntl, *ufcs = name.split(":")
    spec = replace(solver_spec("mumps-blr"), low_rank=LowRank(0, float(tol), int(icntl)))
    # ICNTL(36): 0 UFSC (MUMPS' default), 1 UCFS (compress before the solve, cheaper).
    return spec.with_petsc([f"mat_mumps_icntl_36={u}" for u in ufcs])


def largest(comm: MPI.Comm, a: np.ndarray) -> float:
    """The largest |entry| over every rank."""
    return comm.allreduce(float(np.max(np.abs(a))) if a.size else 0.0, op=MPI.MAX)


def main() -> None:
    """Run the variants in turn and print one line per solve."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="structured")
    ap.add_argument("--refine", type=float, required=True)
    ap.add_argument("--h-far", type=float, default=None)
    ap.add_argument("--variants", default="full,blr:1e-8:2")
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    kw = {} if args.h_far is None else {"h_far": args.h_far}
    edge = args.refine / 4 if args.mesh == "gmsh" else 0.0
    p = HertzParams(mesh=args.mesh, refine=args.refine, refine_edge=edge, **kw)
    scene = build_scene("hertz", p, comm=comm)
    names = args.variants.split(",")
    ref: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    for r in range(args.repeats):
        for name in names[r % len(names) :] + names[: r % len(names)]:
            t0 = time.perf_counter()
            sol, summary = run_scene(scene, "mortar", solver=variant(name), reference_timing=True)
            wall = time.perf_counter() - t0
            d = summary.to_json()
            u, pr = sol.u.x.array.copy(), np.asarray(sol.pressure)
            if ref is None and name == "full":
                ref = (u, pr, sol.active.copy())
            du = dp = float("nan")
            same = None
            if ref is not None:
                du = largest(comm, u - ref[0]) / largest(comm, ref[0])
                dp = largest(comm, pr - ref[1]) / largest(comm, ref[1])
                same = bool(np.array_equal(sol.active, ref[2]))
            t, h = d["times"], d.get("hertz", {})
            its = [s["linear_iterations"] for s in d["active_set"]]
            steps = [round(s["solve_time"], 2) for s in d["active_set"]]
            if comm.rank == 0:
                print(
                    f"{name:>14} dofs {d['dofs']} solve {t['solve']:.2f} "
                    f"fresh {t['reference_solve']:.2f} ldlt {t['reference_ldlt']:.2f} "
                    f"lu {t['reference_lu']:.2f} step times {steps} "
                    f"wall {wall:.1f} steps {len(its)} its {its} "
                    f"dp {dp:.2e} du {du:.2e} same_set {same} "
                    f"force {d['contact_force']:.10g} hertz {h}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
