"""The structured Hertz grid's mesh phase in parts: the grid on rank 0, the partitioner, and
DOLFINx's create_mesh (which calls the partitioner), seconds per rank.

    [mpirun -n 2] python benchmarks/mesh_phase.py H

meshes the accurate family (`--refine H --h-far 10H`) through `build_scene` with those three
wrapped. docs/scale.md ("Setup") cites it.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import Any

from mpi4py import MPI

import contactfx.scenes.structured as structured
from contactfx.scenes import HertzParams, build_scene

T: dict[str, float] = {}


def timed(name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
    """`fn` with its seconds kept in T[name]."""

    def run(*args: Any, **kwargs: Any) -> Any:
        t0 = time.perf_counter()
        out = fn(*args, **kwargs)
        T[name] = T.get(name, 0.0) + time.perf_counter() - t0
        return out

    return run


def main() -> None:
    """Mesh once and print each rank's parts."""
    h = float(sys.argv[1])
    partitioner = structured.known_bodies_partitioner
    structured.hertz_grid = timed("grid", structured.hertz_grid)
    structured.known_bodies_partitioner = lambda *a: timed("partition", partitioner(*a))
    structured.dmesh.create_mesh = timed("create_mesh", structured.dmesh.create_mesh)
    comm = MPI.COMM_WORLD
    t0 = time.perf_counter()
    scene = build_scene("hertz", HertzParams(refine=h, h_far=10 * h, mesh="structured"), comm=comm)
    T["total"] = time.perf_counter() - t0
    dofs = 2 * scene.mesh.topology.index_map(0).size_global
    print(comm.rank, dofs, {k: round(v, 2) for k, v in T.items()}, flush=True)


if __name__ == "__main__":
    main()
