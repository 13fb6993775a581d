"""MUMPS' memory estimate (its analysis) against what its factorization then takes.

`[mpirun -n R] python benchmarks/mumps_memory.py [--analysis-only] H [H ...]` meshes the
accurate Hertz family (structured, `--refine H --h-far 10H`, dual mortar) and, per size,
runs the loop's direct solver as `--solver auto` does: the analysis alone (linalg/saddle.py
`SaddleSolver.mumps_estimate`), then the first factorization and solve. One JSON line per size: the
estimate (INFO(15) summed over the ranks, INFOG(16), INFOG(17)), the analysis seconds,
MUMPS' allocated (INFOG(18/19)) and effectively used (INFOG(21/22)) memory after the
factorization, and the growth of the resident memory (VmHWM after minus VmRSS before the
analysis, and after it: where `auto` reads the memory available; summed over the ranks). One
size per process keeps VmHWM that size's; docs/scale.md ("The default solver") cites it.
`--analysis-only` stops after the analysis (what `auto` pays where MUMPS does not fit).
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np
from mpi4py import MPI

from contactfx.discretize.setup import prepare_contact
from contactfx.linalg.saddle import SaddleSolver
from contactfx.methods.solvers import setup_solver
from contactfx.options import SOLVERS, Basis, Method
from contactfx.scenes import HertzParams, build_scene
from contactfx.timers import Timers


def status_mb(key: str) -> float:
    """A /proc/self/status entry (VmRSS, VmHWM) in MB (1e6 bytes, MUMPS' unit)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return float(line.split()[1]) * 1024 / 1e6
    raise KeyError(key)


def measure(h: float, comm: MPI.Comm, analysis_only: bool = False) -> dict[str, float]:
    """The estimate and the actual memory of one size (collective)."""
    params = HertzParams(mesh="structured", refine=h, h_far=10 * h)
    scene = build_scene("hertz", params, comm=comm)
    setup = prepare_contact(scene, Method.MORTAR.kernel, 1e-8, Timers(), Basis.DUAL)
    solver = setup_solver(setup, SOLVERS["mumps"], scene, reuse=True)
    assert isinstance(solver, SaddleSolver)
    rss0 = status_mb("VmRSS")
    estimate = solver.mumps_estimate()
    assert estimate is not None
    rss1 = status_mb("VmRSS")  # `auto` reads MemAvailable here, after the analysis
    dofs = setup.elasticity.K.getSize()[0]
    if analysis_only:
        total = comm.allreduce(estimate.rank_mb)
        solver.destroy()
        setup.destroy()
        return {
            "h": h,
            "ranks": comm.size,
            "dofs": dofs,
            "analysis_s": estimate.seconds,
            "estimate_sum_info15_mb": total,
            "rss_before_total_mb": comm.allreduce(rss0),
            "rss_analysis_total_mb": comm.allreduce(status_mb("VmHWM") - rss0),
        }
    t0 = time.perf_counter()
    solver.solve(setup.g, np.zeros(len(setup.g), dtype=bool))
    seconds = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    F = solver._ksp.getPC().getFactorMatrix()  # the benchmark reads MUMPS' own counters
    out = {
        "h": h,
        "ranks": comm.size,
        "dofs": dofs,
        "estimate_sum_info15_mb": comm.allreduce(estimate.rank_mb),
        "estimate_max_infog16_mb": estimate.max_mb,
        "estimate_total_infog17_mb": estimate.total_mb,
        "analysis_s": estimate.seconds,
        "factor_and_solve_s": seconds,
        "allocated_max_infog18_mb": F.getMumpsInfog(18),
        "allocated_total_infog19_mb": F.getMumpsInfog(19),
        "used_max_infog21_mb": F.getMumpsInfog(21),
        "used_total_infog22_mb": F.getMumpsInfog(22),
        "rss_growth_total_mb": comm.allreduce(status_mb("VmHWM") - rss0),
        "rss_growth_after_analysis_total_mb": comm.allreduce(status_mb("VmHWM") - rss1),
        "rss_before_total_mb": comm.allreduce(rss0),
    }
    solver.destroy()
    setup.destroy()
    return out


if __name__ == "__main__":
    only = "--analysis-only" in sys.argv
    for arg in (a for a in sys.argv[1:] if a != "--analysis-only"):
        row = measure(float(arg), MPI.COMM_WORLD, only)
        if MPI.COMM_WORLD.rank == 0:
            print(json.dumps(row), flush=True)
