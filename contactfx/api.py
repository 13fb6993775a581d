"""One call from parameters to a solved scene and its summary, shared by the CLI, demos, tests."""

from __future__ import annotations

import time
from dataclasses import replace
from typing import Any

from mpi4py import MPI

from .methods import Method
from .postprocess import summary
from .problem import ActiveSetOptions, InitialSet, Solution, coarse_initial_set, solve_contact
from .saddle import SOLVERS
from .scenes import BlockParams, HertzParams, Scene, build_scene
from .schwarz import SchwarzOptions, solve_schwarz
from .timers import Timers

# Above this many dofs, "auto" starts the active set from a coarser solve of the same scene:
# one factorization then suffices (measured in docs/scale.md, "Coarse predictor").
COARSE_PREDICTOR_DOFS = 200_000
# Mesh sizes of the coarse solve relative to the fine one (1/40 of the dofs on the graded
# Hertz meshes): its zone edge is then good to a coarse element, which the band probes cover.
COARSE_FACTOR = 8.0


def scene_dofs(scene: Scene) -> int:
    """Displacement dofs of `scene` (P1 vector: two per vertex)."""
    return 2 * scene.mesh.topology.index_map(0).size_global


def coarse_params(params: BlockParams | HertzParams, factor: float = COARSE_FACTOR
                  ) -> HertzParams | None:
    """The same Hertz scene with mesh sizes times `factor`; None for scenes without one."""
    if not isinstance(params, HertzParams):
        return None  # block scenes are in contact everywhere: the gap already says it all
    return replace(params, refine=params.refine * factor,
                   refine_edge=params.refine_edge * factor)


def use_coarse(predictor: str, scene: Scene, options: dict[str, object]) -> bool:
    """Whether `predictor` ("auto", "coarse" or "none") asks for a coarse solve here."""
    if predictor not in ("auto", "coarse", "none"):
        raise ValueError(f"predictor must be auto, coarse or none (got {predictor!r})")
    if predictor == "auto":
        # Small meshes gain nothing. Direct solvers then factorize once (release path); the
        # GAMG fieldsplit path halves its active-set steps (115k DOFs: 17 -> 9, 29 s -> 13 s).
        return scene_dofs(scene) >= COARSE_PREDICTOR_DOFS
    return predictor == "coarse"


def coarse_prediction(coarse: Scene, method: Method, options: dict[str, object],
                      max_iterations: int = 50) -> InitialSet:
    """Solve `coarse` (the same scene, coarser) and turn its contact zone into an InitialSet."""
    sol = solve_contact(coarse, method, options, ActiveSetOptions(max_iterations))
    return coarse_initial_set(sol)


def run_case(kind: str, params: BlockParams | HertzParams, method: Method | str,
             active: int = 2, solver: str | dict[str, object] = "mumps",
             max_iterations: int = 50, comm: MPI.Comm = MPI.COMM_WORLD,
             penalty: float | None = None, schwarz: SchwarzOptions | None = None,
             reference_timing: bool = False, predictor: str = "auto"
             ) -> tuple[Solution, dict[str, Any]]:
    """Mesh, assemble and solve one scene; return the solution and its JSON summary.

    `predictor` "coarse" starts the active-set loop from a solve of the same scene with
    coarser meshes (Hertz only), "auto" does so above COARSE_PREDICTOR_DOFS; the converged
    solution does not depend on it.
    """
    t_start = time.perf_counter()
    method = Method(method)
    options = SOLVERS[solver] if isinstance(solver, str) else solver
    timers = Timers()
    with timers("mesh"):
        scene = build_scene(kind, params, active=active, comm=comm)
    if method == Method.PENALTY:
        from .penalty import penetration, solve_penalty

        sol = solve_penalty(scene, penalty, options, ActiveSetOptions(max_iterations), timers)
    elif method == Method.SCHWARZ:
        sol = solve_schwarz(scene, schwarz or SchwarzOptions(max_iterations=max_iterations),
                            timers)
    else:
        init = None
        cparams = coarse_params(params)
        if cparams is not None and use_coarse(predictor, scene, options):
            with timers("predictor"):
                coarse = build_scene(kind, cparams, active=active, comm=comm)
                init = coarse_prediction(coarse, method, options, max_iterations)
        sol = solve_contact(scene, method, options, ActiveSetOptions(max_iterations), timers,
                            reference_timing=reference_timing, initial_active=init)
    times = {k: timers.seconds.get(k, 0.0)
             for k in ("mesh", "assemble", "search", "contact", "solve")}
    if "predictor" in timers.seconds:
        times["predictor"] = timers.seconds["predictor"]
    times["total"] = time.perf_counter() - t_start
    if "reference_solve" in timers.seconds:
        times["reference_solve"] = timers.seconds["reference_solve"]
    extra: dict[str, Any] = {"solver": solver if isinstance(solver, str) else "custom"}
    if method == Method.PENALTY:
        extra["penalty"] = sol.history[-1]["penalty"]
        extra["penetration"] = penetration(sol)
    if kind == "hertz":
        from .hertz import hertz_summary

        extra["hertz"] = hertz_summary(sol)
    return sol, summary(sol, times, extra)
