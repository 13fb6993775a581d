"""In-process A/Bs behind docs/scale.md "Two ranks at 2.29M DOFs" ("This round").

`mpirun -n 2 python benchmarks/two_rank_overheads.py probes REFINE EDGE`: the structured
Hertz mesh (mortar), one MUMPS factorization of a set of every node within a + 0.05, then
the probe responses of its 20 and 40 outermost rows, asked on every active row and on the
probed rows only, alternating, twice; prints the seconds and the largest difference
(relative to the largest entry).

`mpirun -n 2 python benchmarks/two_rank_overheads.py predictor REFINE [REPEATS]`: the coarse
predictor of that mesh at x8 and x16, alternating (default 3 repeats); prints the seconds.
The issue's case: REFINE 0.00035, EDGE 0.005 (2.29M DOFs).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from functools import partial

import numpy as np
from mpi4py import MPI

from contactfx.contact import Kernel
from contactfx.discretize.setup import prepare_contact
from contactfx.methods import predictor
from contactfx.methods.active_set import ActiveSetOptions
from contactfx.methods.solvers import setup_solver
from contactfx.options import SOLVERS, Method
from contactfx.request import SolveRequest
from contactfx.scenes import HertzParams, Scene, hertz
from contactfx.timers import Timers

COMM = MPI.COMM_WORLD


def _timed(run: Callable[[], object]) -> tuple[float, object]:
    """Seconds of `run()` between two barriers, and its result."""
    COMM.Barrier()
    t0 = time.perf_counter()
    out = run()
    COMM.Barrier()
    return time.perf_counter() - t0, out


def probes(refine: float, edge: float) -> None:
    """Probe responses on every active row against the probed rows only."""
    scene = hertz(HertzParams(refine=refine, refine_edge=edge, mesh="structured"))
    setup = prepare_contact(scene, Kernel.MORTAR, ActiveSetOptions().penetration_tol, Timers())
    solver = setup_solver(setup, SOLVERS["mumps"], scene, reuse=True)
    x = setup.layout.x[setup.layout.mine, 0]
    active = np.abs(x) < scene.params["hertz_exact"]["a"] + 0.05
    solver.solve(setup.g, active, fresh=True)
    rows = np.concatenate(COMM.allgather(setup.layout.mine[active]))
    xs = np.concatenate(COMM.allgather(x[active]))
    seconds: dict[str, list[float]] = {}
    worst = 0.0
    for _ in range(2):
        for k in (20, 40):
            outer = np.sort(rows[np.argsort(-np.abs(xs))[:k]])
            rhs = (setup.layout.mine[:, None] == outer[None, :]).astype(float)
            wanted = rhs.any(axis=1)
            t_all, full = _timed(partial(solver.responses, rhs, active))
            t_probed, part = _timed(partial(solver.responses, rhs, active, wanted))
            seconds.setdefault(f"{k} all rows", []).append(t_all)
            seconds.setdefault(f"{k} probed rows", []).append(t_probed)
            diff = np.abs(np.asarray(part)[wanted] - np.asarray(full)[wanted]).max(initial=0.0)
            scale = COMM.allreduce(float(np.abs(np.asarray(full)).max(initial=0.0)), op=MPI.MAX)
            worst = max(worst, COMM.allreduce(float(diff), op=MPI.MAX) / scale)
    solver.destroy()
    if COMM.rank == 0:
        n = setup.elasticity.V.dofmap.index_map.size_global * 2
        print(f"{n} DOFs, {len(rows)} active rows; largest difference {worst:.1e} (relative)")
        for key, vals in seconds.items():
            print(f"{key}: " + " / ".join(f"{v:.3f}" for v in vals) + " s", flush=True)


def _predict(scene: Scene, factor: float) -> float:
    """Seconds of the coarse predictor of `scene` at this coarse factor."""
    predictor.coarse_factor = lambda spec, fine: factor  # type: ignore[assignment]
    request = SolveRequest.parse(Method.MORTAR, solver="mumps", predictor="coarse")
    return _timed(lambda: predictor.predict(scene, request, ActiveSetOptions(), Timers()))[0]


def predictors(refine: float, repeats: int) -> None:
    """The coarse predictor at x8 and x16, alternating."""
    scene = hertz(HertzParams(refine=refine, mesh="structured"))
    seconds: dict[float, list[float]] = {8.0: [], 16.0: []}
    for _ in range(repeats):
        for factor in seconds:
            seconds[factor].append(_predict(scene, factor))
    if COMM.rank == 0:
        for factor, vals in seconds.items():
            print(f"x{factor:g}: " + " / ".join(f"{v:.2f}" for v in vals) + " s", flush=True)


def main() -> None:
    """Dispatch on the first argument (probes or predictor)."""
    if sys.argv[1] == "probes":
        probes(float(sys.argv[2]), float(sys.argv[3]))
    else:
        predictors(float(sys.argv[2]), int(sys.argv[3]) if len(sys.argv) > 3 else 3)


if __name__ == "__main__":
    main()
