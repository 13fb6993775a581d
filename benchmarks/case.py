"""One benchmark run: the Hertz scene on the structured mesh, solved once, timings as JSON.

Run serially or under mpirun; rank 0 prints one JSON line. Used by benchmarks/run.py, which
runs every case in a fresh process so that peak memory (max RSS) belongs to that case.
"""

from __future__ import annotations

import argparse
import json
import resource
import time

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)
from mpi4py import MPI

from contactfx.methods import Method
from contactfx.problem import ActiveSetOptions, solve_contact
from contactfx.saddle import SOLVERS
from contactfx.scenes import HertzParams
from contactfx.timers import Timers
from meshes.hertz_structured import hertz_structured_scene


def main() -> None:
    """Parse, run, print the JSON record on rank 0."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--method", default="mortar")
    ap.add_argument("--solver", default="mumps")
    ap.add_argument("--refine", type=float, required=True, help="h at the contact (cm)")
    ap.add_argument("--h-far", type=float, required=True, help="largest element size (cm)")
    ap.add_argument("--option", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--no-reference", action="store_true")
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    options = dict(SOLVERS[args.solver])
    for item in args.option:
        key, _, value = item.partition("=")
        options[key] = value
    timers = Timers()
    comm.Barrier()
    t0 = time.perf_counter()
    with timers("mesh"):
        scene = hertz_structured_scene(HertzParams(refine=args.refine), comm, h_far=args.h_far)
    sol = solve_contact(scene, Method(args.method), options, ActiveSetOptions(), timers,
                        reference_timing=not args.no_reference)
    comm.Barrier()
    total = time.perf_counter() - t0
    V = sol.elasticity.V
    rss = comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
    times = {k: comm.allreduce(v, op=MPI.MAX) for k, v in timers.seconds.items()}
    times["total"] = total
    record = {
        "method": args.method, "solver": args.solver, "ranks": comm.size,
        "refine": args.refine, "h_far": args.h_far,
        "dofs": V.dofmap.index_map.size_global * V.dofmap.index_map_bs,
        "multipliers": int(sol.layout.size), "active_nodes": int(sol.active.sum()),
        "iterations": sol.iterations, "times": times, "peak_rss_mb": rss,
        "history": [{k: (float(v) if not isinstance(v, int) else v) for k, v in h.items()}
                    for h in sol.history],
        "contact_force_error": abs(float((sol.pressure * sol.layout.weights).sum())
                                   - scene.params.P / 2) / (scene.params.P / 2),
    }
    if comm.rank == 0:
        print("RESULT " + json.dumps(record), flush=True)


if __name__ == "__main__":
    main()
