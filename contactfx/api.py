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
from .timers import Timers


def run_case(kind: str, params: BlockParams | HertzParams, method: Method | str,
             active: int = 2, solver: str | dict[str, object] = "mumps",
             max_iterations: int = 50, comm: MPI.Comm = MPI.COMM_WORLD
             ) -> tuple[Solution, dict[str, Any]]:
    """Mesh, assemble and solve one scene; return the solution and its JSON summary."""
    t_start = time.perf_counter()
    method = Method(method)
    options = SOLVERS[solver] if isinstance(solver, str) else solver
    timers = Timers()
    with timers("mesh"):
        scene = build_scene(kind, params, active=active, comm=comm)
    sol = solve_contact(scene, method, options, ActiveSetOptions(max_iterations), timers)
    times = {k: timers.seconds.get(k, 0.0)
             for k in ("mesh", "assemble", "search", "contact", "solve")}
    times["total"] = time.perf_counter() - t_start
    extra: dict[str, Any] = {"solver": solver if isinstance(solver, str) else "custom"}
    if kind == "hertz":
        from .hertz import hertz_summary

        extra["hertz"] = hertz_summary(sol)
    return sol, summary(sol, times, extra)
