"""The Python API: solve(scene, method) -> Solution, run_scene with its summary, run_case.

The CLI, the demos, the benchmarks and the tests are thin layers over these calls. Every
option is validated here, once, into its typed value (options.py).
"""

from __future__ import annotations

import resource
import time
from typing import Any

from mpi4py import MPI

from .errors import InputError
from .methods.active_set import ActiveSetOptions
from .methods.multipliers import solve_contact
from .methods.penalty import solve_penalty
from .methods.predictor import coarse_initial_set, coarse_margin, predict
from .methods.schwarz import SchwarzOptions, solve_schwarz
from .methods.solution import Solution
from .options import SOLVERS, Basis, Method, Predictor, SolverSpec, solver_spec
from .results.records import RunSummary
from .results.summary import solver_label, summary
from .scenes import BlockParams, HertzParams, Scene, build_scene
from .timers import Timers

TIME_KEYS = ("mesh", "assemble", "search", "contact", "solve")


def solve(
    scene: Scene,
    method: Method | str = Method.MORTAR,
    *,
    solver: SolverSpec | str = "mumps",
    max_iterations: int = 50,
    penalty: float | None = None,
    schwarz: SchwarzOptions | None = None,
    reference_timing: bool = False,
    predictor: Predictor | str = Predictor.AUTO,
    timers: Timers | None = None,
    basis: Basis | str = Basis.STANDARD,
    initial: Solution | None = None,
) -> Solution:
    """Solve the frictionless contact problem of `scene` with `method`.

    Args:
        scene: The scene (a built-in scene, a scene file, or `scene_from_gmsh`).
        method: nts, sts, mortar (multipliers), penalty, or schwarz.
        solver: A preset name of `SOLVERS` or a SolverSpec.
        max_iterations: Limit of the active-set (or Schwarz) iterations.
        penalty: The penalty method's normal stiffness (default 1e3 E_max / h).
        schwarz: The Schwarz method's controls.
        reference_timing: Also time one fresh solve of the final system (the cost floor).
        predictor: auto, coarse (a first active set from a coarser solve of the same scene)
            or none; the converged solution does not depend on it.
        timers: Where the labelled times go (a new Timers if None).
        basis: Mortar's multiplier basis: standard or dual (biorthogonal, D diagonal).
        initial: A solution of the same scene on another mesh (an adaptive loop's previous
            level): its active set is the first guess of a multiplier method, in place of
            the predictor's (penalty and schwarz have no active-set guess to take).

    Returns:
        The Solution: displacement, multipliers per pair, history and costs.
    """
    method = Method.parse(method)
    basis = Basis.parse(basis)
    predictor = Predictor.parse(predictor)
    spec = solver_spec(solver)
    if basis is not Basis.STANDARD and method is not Method.MORTAR:
        raise InputError(f"the {basis.value} multiplier basis applies to the mortar method only")
    if method is Method.SCHWARZ and spec != SOLVERS["mumps"]:
        raise InputError(
            "schwarz factorizes each body with MUMPS: the solver option does not apply to it"
        )
    timers = timers or Timers()
    aso = ActiveSetOptions(max_iterations)
    if method is Method.PENALTY:
        return solve_penalty(scene, penalty, spec, aso, timers)
    if method is Method.SCHWARZ:
        return solve_schwarz(
            scene, schwarz or SchwarzOptions(max_iterations=max_iterations), timers
        )
    init = (
        coarse_initial_set(initial, margin=coarse_margin(spec))
        if initial is not None
        else predict(scene, method, spec, predictor, aso, basis, timers)
    )
    return solve_contact(
        scene,
        method,
        spec,
        aso,
        timers,
        reference_timing=reference_timing,
        initial_active=init,
        basis=basis,
    )


def run_scene(
    scene: Scene,
    method: Method | str = Method.MORTAR,
    *,
    solver: SolverSpec | str = "mumps",
    t_start: float | None = None,
    timers: Timers | None = None,
    paper_interface: bool = False,
    **options: Any,
) -> tuple[Solution, RunSummary]:
    """Solve `scene` and return the solution with its summary (times from `t_start`).

    `options` go to `solve`; `paper_interface` adds the x-sorted `interface` block of pair
    0 (the paper's scenes: one horizontal contact line). The summary's `to_json()` is the
    JSON of `contactfx solve --json`.
    """
    t_start = time.perf_counter() if t_start is None else t_start
    timers = timers or Timers()
    spec = solver_spec(solver)
    sol = solve(scene, method, solver=spec, timers=timers, **options)
    times = {k: timers.seconds.get(k, 0.0) for k in TIME_KEYS}
    for key in ("predictor", "reference_solve", "reference_lu", "reference_ldlt"):
        if key in timers.seconds:
            times[key] = timers.seconds[key]
    times["total"] = time.perf_counter() - t_start
    return sol, summary(
        sol,
        times,
        solver=solver_label(sol.method, spec),
        memory=peak_memory(scene.comm),
        paper_interface=paper_interface,
    )


def peak_memory(comm: MPI.Comm) -> dict[str, float]:
    """Peak resident memory so far (MB): summed over the ranks, and the largest rank's."""
    # ru_maxrss is in kilobytes on Linux.
    mine = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return {
        "peak_mb": float(comm.allreduce(mine)),
        "peak_mb_max_rank": float(comm.allreduce(mine, op=MPI.MAX)),
    }


def run_case(
    kind: str,
    params: BlockParams | HertzParams,
    method: Method | str,
    active: int = 2,
    solver: SolverSpec | str = "mumps",
    comm: MPI.Comm = MPI.COMM_WORLD,
    **options: Any,
) -> tuple[Solution, RunSummary]:
    """Mesh, assemble and solve a built-in scene; return the solution and its summary.

    `options` go to `solve`; the summary carries the paper's `interface` block.
    """
    t_start = time.perf_counter()
    timers = Timers()
    with timers("mesh"):
        scene = build_scene(kind, params, active=active, comm=comm)
    return run_scene(
        scene,
        method,
        solver=solver,
        t_start=t_start,
        timers=timers,
        paper_interface=True,
        **options,
    )
