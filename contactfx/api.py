"""The Python API: solve(scene, method) -> Solution, and run_case for the built-in scenes.

The CLI, the demos, the benchmarks and the tests are thin layers over these calls.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any

from mpi4py import MPI

from .condensed import is_condensed
from .errors import InputError
from .methods import Method
from .problem import ActiveSetOptions, InitialSet, coarse_initial_set, solve_contact
from .report import summary
from .saddle import selected_inverse_available
from .scenes import BlockParams, HertzParams, Scene, build_scene
from .schwarz import SchwarzOptions, solve_schwarz
from .solution import Solution
from .solvers import SOLVERS
from .timers import Timers

# Above this many dofs, "auto" starts the active set from a coarser solve of the same scene:
# one factorization then suffices (measured in docs/scale.md, "Coarse predictor").
COARSE_PREDICTOR_DOFS = 200_000
# Mesh sizes of the coarse solve relative to the fine one (1/40 of the dofs on the graded
# Hertz meshes): its zone edge is then good to a coarse element, which the band probes cover.
COARSE_FACTOR = 8.0
CONDENSED_COARSE_FACTOR = 4.0


def scene_dofs(scene: Scene) -> int:
    """Displacement dofs of `scene` (P1 vector: two per vertex)."""
    return 2 * scene.mesh.topology.index_map(0).size_global


def use_coarse(predictor: str, scene: Scene, options: Mapping[str, object]) -> bool:
    """Whether `predictor` ("auto", "coarse" or "none") asks for a coarse solve here."""
    if predictor not in ("auto", "coarse", "none"):
        raise ValueError(f"predictor must be auto, coarse or none (got {predictor!r})")
    if predictor == "auto":
        # Small meshes gain nothing. Direct solvers then factorize once (release path); the
        # GAMG fieldsplit path halves its active-set steps (115k DOFs: 17 -> 9, 29 s -> 13 s).
        # Serial MUMPS needs none at any size: its probe responses are selected entries of
        # the inverse, so the loop starts from every row (ActiveSetOptions.start_all).
        if selected_inverse_available(options, scene.comm.size):
            return False
        if is_condensed(options):
            # No probes without a factorization: a coarse solve (1/64 of the DOFs) saves the
            # condensed path most of its active-set steps at every size.
            return True
        return scene_dofs(scene) >= COARSE_PREDICTOR_DOFS
    return predictor == "coarse"


def coarse_prediction(
    coarse: Scene,
    method: Method,
    options: Mapping[str, object],
    max_iterations: int = 50,
    basis: str = "standard",
) -> InitialSet:
    """Solve `coarse` (the same scene, coarser) and turn its contact zone into an InitialSet."""
    sol = solve_contact(coarse, method, options, ActiveSetOptions(max_iterations), basis=basis)
    # A direct solver probes the uncertain band, so a generous superset costs it nothing;
    # every ring of nodes the condensed loop must release costs a whole solve, so it starts
    # from half a coarse element around the coarse zone (463k DOFs: 6 -> 4 steps).
    return coarse_initial_set(sol, margin=0.5 if is_condensed(options) else 1.5)


def solve(
    scene: Scene,
    method: Method | str = Method.MORTAR,
    *,
    solver: str | Mapping[str, object] = "mumps",
    max_iterations: int = 50,
    penalty: float | None = None,
    schwarz: SchwarzOptions | None = None,
    reference_timing: bool = False,
    predictor: str = "auto",
    timers: Timers | None = None,
    basis: str = "standard",
) -> Solution:
    """Solve the frictionless contact problem of `scene` with `method`.

    `predictor` "coarse" starts the active-set loop from a solve of the same scene with mesh
    sizes times COARSE_FACTOR (scenes that can be remeshed), "auto" does so above
    COARSE_PREDICTOR_DOFS; the converged solution does not depend on it. `basis` "dual"
    takes mortar's biorthogonal multiplier basis.
    """
    method = Method(method)
    if basis != "standard" and method != Method.MORTAR:
        raise InputError(f"the {basis} multiplier basis applies to the mortar method only")
    if method == Method.SCHWARZ and (solver if isinstance(solver, str) else dict(solver)) not in (
        "mumps",
        dict(SOLVERS["mumps"]),
    ):
        raise InputError(
            "schwarz factorizes each body with MUMPS: the solver option does not apply to it"
        )
    if isinstance(solver, str) and solver not in SOLVERS:
        raise InputError(f"unknown solver '{solver}' (choose {', '.join(SOLVERS)})")
    options = SOLVERS[solver] if isinstance(solver, str) else solver
    timers = timers or Timers()
    aso = ActiveSetOptions(max_iterations)
    if method == Method.PENALTY:
        from .penalty import penetration, solve_penalty

        sol = solve_penalty(scene, penalty, options, aso, timers)
        sol.info.update({"penalty": sol.history[-1]["penalty"], "penetration": penetration(sol)})
        return sol
    if method == Method.SCHWARZ:
        return solve_schwarz(
            scene, schwarz or SchwarzOptions(max_iterations=max_iterations), timers
        )
    init = None
    if scene.resize is not None and use_coarse(predictor, scene, options):
        with timers("predictor"):
            # The condensed loop pays a whole solve per ring of nodes it adds or releases, so
            # a sharper prediction (1/16 of the DOFs, not 1/64) pays for itself
            # (1.85M DOFs: 4 fine steps -> 2, 27.6 s -> 21.9 s with the predictor).
            factor = CONDENSED_COARSE_FACTOR if is_condensed(options) else COARSE_FACTOR
            coarse = scene.resize(factor)
            init = coarse_prediction(coarse, method, options, max_iterations, basis)
    return solve_contact(
        scene,
        method,
        options,
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
    solver: str | Mapping[str, object] = "mumps",
    t_start: float | None = None,
    timers: Timers | None = None,
    **options: Any,
) -> tuple[Solution, dict[str, Any]]:
    """Solve `scene` and return the solution with its JSON summary (times from `t_start`)."""
    t_start = time.perf_counter() if t_start is None else t_start
    timers = timers or Timers()
    sol = solve(scene, method, solver=solver, timers=timers, **options)
    times = {
        k: timers.seconds.get(k, 0.0) for k in ("mesh", "assemble", "search", "contact", "solve")
    }
    for key in ("predictor", "reference_solve"):
        if key in timers.seconds:
            times[key] = timers.seconds[key]
    times["total"] = time.perf_counter() - t_start
    return sol, summary(
        sol,
        times,
        {
            "solver": solver if isinstance(solver, str) else "custom",
            "memory": peak_memory(scene.comm),
        },
    )


def peak_memory(comm: MPI.Comm) -> dict[str, float]:
    """Peak resident memory so far (MB): summed over the ranks, and the largest rank's."""
    import resource

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
    solver: str | Mapping[str, object] = "mumps",
    max_iterations: int = 50,
    comm: MPI.Comm = MPI.COMM_WORLD,
    penalty: float | None = None,
    schwarz: SchwarzOptions | None = None,
    reference_timing: bool = False,
    predictor: str = "auto",
) -> tuple[Solution, dict[str, Any]]:
    """Mesh, assemble and solve a built-in scene; return the solution and its JSON summary."""
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
        max_iterations=max_iterations,
        penalty=penalty,
        schwarz=schwarz,
        reference_timing=reference_timing,
        predictor=predictor,
    )
