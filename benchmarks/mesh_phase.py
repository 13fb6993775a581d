"""The structured Hertz grid's mesh phase in parts, seconds per rank: each rank's part of the
grid (`hertz_grid_part`), DOLFINx's create_mesh (which calls the partitioner, `stay_on_rank`),
its own timers (the topology, the dual graph, the reordering) and the facet tags (which
create the facets).

    [mpirun -n 2] python benchmarks/mesh_phase.py H

meshes the accurate family (`--refine H --h-far 10H`) through `build_scene` with those
wrapped, and prints each rank's peak memory (VmHWM). docs/scale.md ("Setup") cites it.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import Any

import dolfinx_solver  # noqa: F401  (before dolfinx)
from dolfinx.common import list_timings
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
    structured.hertz_grid_part = timed("grid", structured.hertz_grid_part)
    structured.stay_on_rank = timed("partition", structured.stay_on_rank)
    structured.dmesh.create_mesh = timed("create_mesh", structured.dmesh.create_mesh)
    structured.tag_hertz_facets = timed("tags", structured.tag_hertz_facets)
    comm = MPI.COMM_WORLD
    t0 = time.perf_counter()
    scene = build_scene("hertz", HertzParams(refine=h, h_far=10 * h, mesh="structured"), comm=comm)
    T["total"] = time.perf_counter() - t0
    dofs = 2 * scene.mesh.topology.index_map(0).size_global
    print(comm.rank, dofs, {k: round(v, 2) for k, v in T.items()}, flush=True)
    with open("/proc/self/status") as f:
        peak = next(line.split()[1] for line in f if line.startswith("VmHWM"))
    print(comm.rank, f"VmHWM {int(peak) // 1024} MB", flush=True)
    comm.barrier()
    list_timings(comm)  # DOLFINx's timers (create_mesh's parts, the facets), max over ranks


if __name__ == "__main__":
    main()
