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

from contactfx.api import COARSE_FACTOR, coarse_prediction, use_coarse
from contactfx.methods import Method
from contactfx.problem import ActiveSetOptions, solve_contact
from contactfx.scenes import HertzParams, hertz
from contactfx.solvers import SOLVERS
from contactfx.timers import Timers


def peak_rss_mb() -> float:
    """This process's peak resident memory (MB) since its exec.

    getrusage's ru_maxrss would also count the parent's image copied by fork before exec.
    """
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main() -> None:
    """Parse, run, print the JSON record on rank 0."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--method", default="mortar")
    ap.add_argument("--solver", default="mumps")
    ap.add_argument("--refine", type=float, required=True, help="h at the contact (cm)")
    ap.add_argument("--h-far", type=float, required=True, help="largest element size (cm)")
    ap.add_argument("--option", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--no-reference", action="store_true")
    ap.add_argument("--predictor", default="auto", choices=("auto", "coarse", "none"),
                    help="first active set from a solve with 8x coarser sizes (timed as "
                    "'predictor', part of the contact solve); auto: above 200k dofs")
    ap.add_argument("--fixed-set", action="store_true",
                    help="no active-set loop: one fresh solve with the Hertz zone x < a active "
                    "(the iterative path's scaling of linear iterations)")
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
        scene = hertz(HertzParams(refine=args.refine, h_far=args.h_far, mesh="structured"),
                      comm=comm)
    if args.fixed_set:
        record = fixed_set_solve(scene, Method(args.method), options, timers)
        comm.Barrier()
        record.update(method=args.method, solver=args.solver, ranks=comm.size,
                      refine=args.refine, h_far=args.h_far, total=time.perf_counter() - t0,
                      peak_rss_mb=comm.allreduce(peak_rss_mb()),
                      times={k: comm.allreduce(v, op=MPI.MAX)
                             for k, v in timers.seconds.items()})
        if comm.rank == 0:
            print("RESULT " + json.dumps(record), flush=True)
        return
    init = None
    if use_coarse(args.predictor, scene, options):
        with timers("predictor"):
            coarse = scene.resize(COARSE_FACTOR)
            init = coarse_prediction(coarse, Method(args.method), options)
    sol = solve_contact(scene, Method(args.method), options, ActiveSetOptions(), timers,
                        reference_timing=not args.no_reference, initial_active=init)
    comm.Barrier()
    total = time.perf_counter() - t0
    V = sol.elasticity.V
    rss = comm.allreduce(peak_rss_mb())
    times = {k: comm.allreduce(v, op=MPI.MAX) for k, v in timers.seconds.items()}
    times["total"] = total
    record = {
        "method": args.method, "solver": args.solver, "ranks": comm.size,
        "refine": args.refine, "h_far": args.h_far, "predictor": "predictor" in times,
        "dofs": V.dofmap.index_map.size_global * V.dofmap.index_map_bs,
        "multipliers": int(sol.layout.size), "active_nodes": int(sol.active.sum()),
        "iterations": sol.iterations, "times": times, "peak_rss_mb": rss,
        "history": [{k: (float(v) if not isinstance(v, int) else v) for k, v in h.items()}
                    for h in sol.history],
        "contact_force_error": abs(float((sol.pressure * sol.layout.weights).sum())
                                   - scene.params["P"] / 2) / (scene.params["P"] / 2),
    }
    if comm.rank == 0:
        print("RESULT " + json.dumps(record), flush=True)


def fixed_set_solve(scene, method: Method, options: dict, timers: Timers) -> dict:
    """Assemble, search, build B, then one fresh solve with x < a (Hertz) active."""
    from contactfx.nullspace import near_nullspace
    from contactfx.prepare import prepare_contact
    from contactfx.problem import ActiveSetOptions
    from contactfx.saddle import reference_solve
    from contactfx.solvers import uses_augmentation

    comm = scene.mesh.comm
    setup = prepare_contact(scene, method.operator, ActiveSetOptions().penetration_tol, timers)
    el, layout = setup.elasticity, setup.layout
    V = el.V
    gamma = (max(b.material.E for b in scene.bodies) / setup.h**2 if uses_augmentation(options)
             else 0.0)
    active = layout.x[layout.mine, 0] < scene.params["hertz_exact"]["a"]
    nsp = near_nullspace(V, scene) if uses_augmentation(options) else None
    res, seconds = reference_solve(el.K, setup.B, el.f, setup.g, active, options, gamma, nsp)
    setup.B.destroy()
    timers.seconds["reference_solve"] = seconds
    return {"dofs": V.dofmap.index_map.size_global * V.dofmap.index_map_bs,
            "multipliers": int(layout.size),
            "active_nodes": comm.allreduce(int(active.sum())), "iterations": 1,
            "linear_iterations": res.iterations}


if __name__ == "__main__":
    main()
