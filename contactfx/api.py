"""One call from parameters to a solved scene and its summary, shared by the CLI, demos, tests."""

from __future__ import annotations

import time
from typing import Any

from mpi4py import MPI

from .methods import Method
from .postprocess import summary
from .problem import ActiveSetOptions, Solution, solve_contact
from .saddle import SOLVERS
from .scenes import BlockParams, HertzParams, build_scene
from .schwarz import SchwarzOptions, solve_schwarz
from .timers import Timers


def run_case(kind: str, params: BlockParams | HertzParams, method: Method | str,
             active: int = 2, solver: str | dict[str, object] = "mumps",
             max_iterations: int = 50, comm: MPI.Comm = MPI.COMM_WORLD,
             penalty: float | None = None, schwarz: SchwarzOptions | None = None,
             reference_timing: bool = False) -> tuple[Solution, dict[str, Any]]:
    """Mesh, assemble and solve one scene; return the solution and its JSON summary."""
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
        sol = solve_contact(scene, method, options, ActiveSetOptions(max_iterations), timers,
                            reference_timing=reference_timing)
    times = {k: timers.seconds.get(k, 0.0)
             for k in ("mesh", "assemble", "search", "contact", "solve")}
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
