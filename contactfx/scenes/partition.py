"""Cell partitions that spread every body over all ranks: equal-count strips per body."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from dolfinx.cpp.mesh import cell_num_vertices
from dolfinx.graph import adjacencylist
from mpi4py import MPI


def body_strips(dest: np.ndarray, cell_label: np.ndarray, mid: np.ndarray, nparts: int) -> None:
    """Within each body (`cell_label`), equal-count strips by midpoint x (then y), into `dest`.

    The contact line of each body is spread over all ranks, and the strips of the bodies
    overlap.
    """
    for label in np.unique(cell_label):
        ids = np.flatnonzero(cell_label == label)
        order = ids[np.lexsort((mid[ids, 1], mid[ids, 0]))]
        dest[order] = (np.arange(len(order)) * nparts) // len(order)


def cell_arrays(cell_types: list[Any], cells: list[Any]) -> list[np.ndarray]:
    """A partitioner's flat cell lists as (cells, vertices) int64 arrays, one per cell type."""
    return [
        np.asarray(c, dtype=np.int64).reshape(-1, cell_num_vertices(ct))
        for ct, c in zip(cell_types, cells, strict=True)
    ]


def known_bodies_partitioner(
    coordinates: np.ndarray, cell_bodies: np.ndarray
) -> Callable[..., Any]:
    """The strips partition for cells whose bodies the caller knows (the structured grid).

    The same partition as `gmsh_io.balanced_partitioner`, which finds the bodies as the node
    graph's connected components, a large share of create_mesh on big grids (measured:
    docs/scale.md, "Setup"). `coordinates` (n, 2+) and `cell_bodies` on the rank holding the
    cells.
    """

    def partition(comm: MPI.Comm, nparts: int, cell_types: list[Any], cells: list[Any]) -> Any:
        conn = cell_arrays(cell_types, cells)
        num_cells = sum(len(c) for c in conn)
        dest = np.zeros(num_cells, dtype=np.int32)
        if num_cells and nparts > 1:
            x = np.asarray(coordinates)
            mid = np.vstack([x[c, :2].mean(axis=1) for c in conn])
            body_strips(dest, np.asarray(cell_bodies), mid, nparts)
        return adjacencylist(dest)._cpp_object

    return partition
