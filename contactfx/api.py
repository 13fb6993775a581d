"""The Python API: solve(scene, method) -> Solution; run_scene and run_case add the summary.

The CLI, the demos, the benchmarks and the tests are thin layers over these calls. The
options given by name become one SolveRequest (request.py), validated when it is made;
below this module only the request travels.
"""

from __future__ import annotations

import resource
import time
from typing import Unpack

from mpi4py import MPI

from .errors import InputError
from .methods.active_set import ActiveSetOptions
from .methods.autosolve import prepare_solver, warn_if_stretched
from .methods.friction import frictional_pairs, refuse_friction
from .methods.multipliers import solve_contact
from .methods.predictor import coarse_initial_set, coarse_margin, predict
from .methods.solution import Solution
from .options import Enforcement, Method, SolverKind
from .request import RequestOptions, SolveRequest
from .results.records import RunSummary
from .results.summary import summary
from .scenes import BlockParams, HertzParams, Scene, build_scene
from .scenes.steps import step_scenes
from .timers import Timers

TIME_KEYS = ("mesh", "assemble", "search", "contact", "solve")


def as_request(
    request: SolveRequest | Method | str = Method.MORTAR, **options: Unpack[RequestOptions]
) -> SolveRequest:
    """`request` itself if it is a SolveRequest (no option beside it), else the parsed one."""
    if not isinstance(request, SolveRequest):
        return SolveRequest.parse(request, **options)
    if options:
        raise InputError(f"option {next(iter(options))} given beside a SolveRequest: set it in it")
    return request


def solve(
    scene: Scene,
    request: SolveRequest | Method | str = Method.MORTAR,
    *,
    timers: Timers | None = None,
    initial: Solution | None = None,
    **options: Unpack[RequestOptions],
) -> Solution:
    """Solve the frictionless contact problem of `scene` as `request` asks.

    Args:
        scene: The scene (a built-in scene, a scene file, or `scene_from_gmsh`).
        request: A SolveRequest, or a method's name: nts, sts, mortar (multipliers), penalty
            or schwarz (mortar with that enforcement).
        timers: Where the labelled times go (a new Timers if None).
        initial: A solution of the same scene on another mesh (an adaptive loop's previous
            level): its active set is the first guess of a multiplier method, in place of
            the predictor's (penalty and schwarz have no active-set guess to take).
        options: With a method's name, the request's options (`RequestOptions`, the
            defaults of `SolveRequest.parse`): enforcement (multipliers, penalty or schwarz
            on the discretization named), solver (a preset of `SOLVERS` or a SolverSpec;
            default auto: mumps unless its memory estimate does not fit, then condensed),
            basis (standard or dual), predictor (auto, coarse or none; the converged
            solution does not depend on it), max_iterations (default 50), penalty (default
            1e3 E_max / h), schwarz (its controls), reference_timing (also time one fresh
            solve of the final system) and available_mb.

    Returns:
        The Solution: displacement, multipliers per pair, history and costs.
    """
    return solve_request(scene, as_request(request, **options), timers, initial)


def solve_request(
    scene: Scene,
    request: SolveRequest,
    timers: Timers | None = None,
    initial: Solution | None = None,
) -> Solution:
    """Run the method of `request` on `scene` (see `solve`)."""
    refuse_friction(scene, request)
    timers = timers or Timers()
    aso = ActiveSetOptions(request.max_iterations)
    if scene.steps and not frictional_pairs(scene):
        # Frictionless, each step's answer is its loads' alone: one solve per step.
        sols = [solve_request(s, request, timers, initial) for s in step_scenes(scene)]
        sols[-1].steps = sols
        return sols[-1]
    # The penalty and Schwarz modules are imported when they run (first-answer time of a
    # plain solve: docs/scale.md).
    if request.enforcement is Enforcement.PENALTY and frictional_pairs(scene):
        from .methods.penalty_friction import solve_penalty_friction

        return solve_penalty_friction(scene, request, timers, aso)
    if request.enforcement is Enforcement.PENALTY:
        from .methods.penalty import solve_penalty

        return solve_penalty(scene, request, timers, aso=aso)
    if request.enforcement is Enforcement.SCHWARZ:
        from .methods.schwarz import solve_schwarz

        return solve_schwarz(scene, request, timers)
    if frictional_pairs(scene):
        from .methods.friction import solve_friction

        return solve_friction(scene, request, timers, aso)
    # `auto` chooses on the fine system before the predictor, whose mesh follows the choice.
    prepared = None
    if request.solver.kind is SolverKind.AUTO:
        prepared = prepare_solver(scene, request, aso.penetration_tol, timers)
        request = prepared.request
    else:
        warn_if_stretched(scene.mesh, request)  # `auto` logs its own choice
    try:
        init = (
            coarse_initial_set(initial, margin=coarse_margin(request.solver))
            if initial is not None
            else predict(scene, request, aso, timers)
        )
    except BaseException:
        if prepared is not None:
            prepared.destroy()
        raise
    return solve_contact(scene, request, timers, aso=aso, initial_active=init, prepared=prepared)


def run_scene(
    scene: Scene,
    request: SolveRequest,
    *,
    t_start: float | None = None,
    timers: Timers | None = None,
    paper_interface: bool = False,
    initial: Solution | None = None,
) -> tuple[Solution, RunSummary]:
    """Solve `scene` as `request` asks; return the solution with its summary.

    `request` is one SolveRequest (`SolveRequest.parse("mortar", basis="dual")` names one);
    `t_start` is where the summary's total time starts; `timers`, `initial` are `solve`'s;
    `paper_interface` adds the x-sorted `interface` block of pair 0 (the paper's scenes: one
    horizontal contact line). The summary's `to_json()` is the JSON of `contactfx solve --json`.
    """
    _require_request(request)
    t_start = time.perf_counter() if t_start is None else t_start
    timers = timers or Timers()
    sol = solve_request(scene, request, timers, initial)
    times = {k: timers.seconds.get(k, 0.0) for k in TIME_KEYS}
    for key in ("predictor", "reference_solve", "reference_lu", "reference_ldlt"):
        if key in timers.seconds:
            times[key] = timers.seconds[key]
    times["total"] = time.perf_counter() - t_start
    return sol, summary(
        sol, times, request=request, memory=peak_memory(scene.comm), paper_interface=paper_interface
    )


def _require_request(request: object) -> None:
    """Refuse a method's name where a SolveRequest is due (it would fail deep in the solve)."""
    if not isinstance(request, SolveRequest):
        raise InputError(
            f"expected a SolveRequest, not {request!r}: name one with SolveRequest.parse"
            f"({request!r}, ...), or call contactfx.solve"
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
    request: SolveRequest,
    active: int = 2,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> tuple[Solution, RunSummary]:
    """Mesh, assemble and solve a built-in scene; return the solution and its summary.

    `request` is `run_scene`'s; the summary carries the paper's `interface` block.
    """
    _require_request(request)  # refused before the mesh is made
    t_start = time.perf_counter()
    timers = Timers()
    with timers("mesh"):
        scene = build_scene(kind, params, active=active, comm=comm)
    return run_scene(scene, request, t_start=t_start, timers=timers, paper_interface=True)
