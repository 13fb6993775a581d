"""The geometric multigrid on gmsh meshes (remeshes x2, x4, ...) against GAMG, by size.

The gmsh Hertz family (`--refine H --h-far 10H --refine-edge H/4`, dual mortar) has no nested
coarser grids; `condensed` builds its levels from the scene remeshed coarser
(`discretize/remesh_mg.py`), `condensed-gamg` aggregates. Per size, in one process: the
levels' build (remeshing and point location; run with an empty XDG_CACHE_HOME for a first
run's gmsh time), then one fresh solve of the fixed Hertz zone to 1e-9 by each solver
(`--mumps`: and MUMPS' LDL^T of the saddle point; serial only, see below):

    python benchmarks/nonnested_mg.py 100e3 400e3 1e6 2e6 [--mumps]
    mpirun -n 2 python benchmarks/nonnested_mg.py 400e3

docs/scale.md, "A geometric multigrid on gmsh meshes", cites its output.
"""

from __future__ import annotations

import sys
import time
from typing import Any

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)
from mpi4py import MPI

# benchmarks/run.py, next to this script: on sys.path as its folder.
from run import EDGE_RATIO, refine_for

from contactfx.contact import Kernel
from contactfx.discretize.remesh_mg import remesh_interpolations
from contactfx.discretize.setup import prepare_contact
from contactfx.methods.solvers import setup_solver
from contactfx.options import SOLVERS, Basis
from contactfx.scenes import HertzParams, hertz
from contactfx.timers import Timers


def run(target: float, mumps: bool = False) -> dict[str, Any]:
    """One size: the levels, then both multigrids (and MUMPS) on the same fixed set."""
    comm = MPI.COMM_WORLD
    h = refine_for(target, "gmsh")
    params = HertzParams(refine=h, h_far=10 * h, mesh="gmsh", refine_edge=h / EDGE_RATIO)
    t0 = time.perf_counter()
    scene = hertz(params, comm=comm)
    mesh_s = time.perf_counter() - t0
    setup = prepare_contact(scene, Kernel.MORTAR, 1e-8, Timers(), Basis.DUAL)
    el = setup.elasticity
    comm.barrier()
    t0 = time.perf_counter()
    mats = remesh_interpolations(el.V, scene)
    comm.barrier()
    out: dict[str, Any] = {
        "ranks": comm.size,
        "dofs": el.K.getSize()[0],
        "mesh_s": round(mesh_s, 2),
        "levels_s": round(time.perf_counter() - t0, 2),
        "levels": [m.getSize()[1] for m in mats],
    }
    zone = setup.layout.x[setup.layout.mine, 0] < scene.params["hertz_exact"]["a"]
    for name in ("condensed", "condensed-gamg", *(["mumps"] if mumps else [])):
        # The levels built above, copied: the solve is timed without them.
        levels = (lambda: [m.copy() for m in mats]) if name == "condensed" else None
        solver = setup_solver(setup, SOLVERS[name], scene, reuse=False, grid=levels)
        comm.barrier()
        t = time.perf_counter()
        res = solver.solve(setup.g, zone)
        comm.barrier()
        out[name] = {"its": res.iterations, "seconds": round(time.perf_counter() - t, 2)}
        solver.destroy()
    for m in mats:
        m.destroy()
    return out


if __name__ == "__main__":
    if "--mumps" in sys.argv and MPI.COMM_WORLD.size > 1:
        # Under mpirun its fixed-set MUMPS solve hung, not investigated (docs/scale.md, "A
        # geometric multigrid on gmsh meshes"): the comparison is serial.
        sys.exit("nonnested_mg.py: --mumps is serial only (run it without mpirun)")
    for arg in sys.argv[1:]:
        if arg == "--mumps":
            continue
        result = run(float(arg), mumps="--mumps" in sys.argv)
        if MPI.COMM_WORLD.rank == 0:
            print(result, flush=True)
