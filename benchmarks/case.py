"""One benchmark run: the Hertz scene (structured or gmsh mesh) solved by each method, as JSON.

Run serially or under mpirun; rank 0 prints one `RESULT {json}` line per method. The mesh is
built once and every method of `--method nts,sts,mortar` is solved on it in turn (with its own
reference solve), as a user's `python -m contactfx solve hertz ... --reference-timing` with
the default options would: `contactfx.api.solve` picks the predictor. Used by
benchmarks/run.py, which runs every case in a fresh process (peak memory, max RSS, is that
process's: the largest over its methods).
"""

from __future__ import annotations

import argparse
import gc
import json
import resource
import time

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)
from mpi4py import MPI

from contactfx.api import solve
from contactfx.discretize.setup import prepare_contact
from contactfx.methods.active_set import ActiveSetOptions
from contactfx.methods.multipliers import reference_solve
from contactfx.options import Method, SolverSpec, solver_spec
from contactfx.results.references import hertz_summary
from contactfx.scenes import HertzParams, hertz
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
    """Parse, mesh once, solve each method, print one JSON record per method on rank 0."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--method", default="mortar", help="one method or a comma list")
    ap.add_argument("--solver", default="mumps")
    ap.add_argument("--mesh", default="structured", choices=("structured", "gmsh"))
    ap.add_argument("--basis", default="standard", help="mortar's multiplier basis")
    ap.add_argument("--refine", type=float, required=True, help="h at the contact (cm)")
    ap.add_argument(
        "--refine-edge", type=float, default=None, help="gmsh: h at x = a (cm); default refine / 4"
    )
    ap.add_argument("--h-far", type=float, required=True, help="largest element size (cm)")
    ap.add_argument("--option", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--no-reference", action="store_true")
    ap.add_argument(
        "--predictor",
        default="auto",
        choices=("auto", "coarse", "none"),
        help="first active set from a solve with 8x coarser sizes (timed as "
        "'predictor', part of the contact solve); auto: the library's default",
    )
    ap.add_argument(
        "--fixed-set",
        action="store_true",
        help="no active-set loop: one fresh solve with the Hertz zone x < a active "
        "(the iterative path's scaling of linear iterations)",
    )
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    solver = solver_spec(args.solver).with_petsc(args.option)
    edge = args.refine / 4 if args.refine_edge is None else args.refine_edge
    params = HertzParams(
        refine=args.refine,
        h_far=args.h_far or None,  # 0: the default grading (R / 6)
        mesh=args.mesh,
        **({"refine_edge": edge} if args.mesh == "gmsh" else {}),
    )
    comm.Barrier()
    t0 = time.perf_counter()
    mesh_timers = Timers()
    with mesh_timers("mesh"):
        scene = hertz(params, comm=comm)
    common = {
        "solver": args.solver,
        "ranks": comm.size,
        "mesh": args.mesh,
        "basis": args.basis,
        "refine": args.refine,
        "h_far": args.h_far,
        "refine_edge": edge if args.mesh == "gmsh" else None,
    }
    for method in args.method.split(","):
        gc.collect()  # the previous method's PETSc objects
        timers = Timers()
        timers.seconds["mesh"] = mesh_timers.seconds["mesh"]
        t_run = time.perf_counter()
        if args.fixed_set:
            record = fixed_set_solve(scene, Method(method), solver, timers)
        else:
            try:
                basis = args.basis if method == "mortar" else "standard"
                sol = solve(
                    scene,
                    method,
                    solver=solver,
                    timers=timers,
                    basis=basis,
                    reference_timing=not args.no_reference,
                    predictor=args.predictor,
                )
            except Exception as err:  # one method's failure must not hide the others
                if comm.rank == 0:
                    print(
                        "RESULT "
                        + json.dumps(
                            {**common, "method": method, "error": f"{type(err).__name__}: {err}"}
                        ),
                        flush=True,
                    )
                continue
            record = {
                "predictor": "predictor" in timers.seconds,
                "dofs": sol.dofs,
                "multipliers": int(sol.layout.size),
                "active_nodes": int(sol.active.sum()),
                "iterations": sol.iterations,
                "history": [
                    {k: (float(v) if not isinstance(v, int) else v) for k, v in h.items()}
                    for h in sol.history
                ],
                "reference_linear_iterations": sol.reference_linear_iterations,
                "hertz": {
                    k: v
                    for k, v in hertz_summary(sol).to_json().items()
                    if k in ("a", "a_exact", "p0", "p0_exact", "l2_error")
                },
                "contact_force_error": abs(
                    float((sol.pressure * sol.layout.weights).sum()) - scene.params["P"] / 2
                )
                / (scene.params["P"] / 2),
            }
        comm.Barrier()
        times = {k: comm.allreduce(v, op=MPI.MAX) for k, v in timers.seconds.items()}
        times["total"] = time.perf_counter() - t_run + times["mesh"]
        record.update(
            common,
            method=method,
            times=times,
            since_start=time.perf_counter() - t0,
            peak_rss_mb=comm.allreduce(peak_rss_mb()),
        )
        if comm.rank == 0:
            print("RESULT " + json.dumps(record), flush=True)


def fixed_set_solve(scene, method: Method, spec: SolverSpec, timers: Timers) -> dict:
    """Assemble, search, build B, then one fresh solve with x < a (Hertz) active."""
    comm = scene.mesh.comm
    setup = prepare_contact(scene, method.kernel, ActiveSetOptions().penetration_tol, timers)
    layout = setup.layout
    active = layout.x[layout.mine, 0] < scene.params["hertz_exact"]["a"]
    res = reference_solve(setup, spec, scene, active, timers)
    setup.destroy()
    return {
        "dofs": sol_dofs(setup.elasticity.V),
        "multipliers": int(layout.size),
        "active_nodes": comm.allreduce(int(active.sum())),
        "iterations": 1,
        "linear_iterations": res.iterations,
    }


def sol_dofs(V) -> int:
    """Displacement dofs of the space V."""
    return V.dofmap.index_map.size_global * V.dofmap.index_map_bs


if __name__ == "__main__":
    main()
