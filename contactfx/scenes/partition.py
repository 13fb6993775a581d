"""Cell partitions: equal-count strips per body, or every cell kept where it was made.

The strips spread every body over all ranks (gmsh scenes); the structured Hertz grid is
generated on every rank already cut so (`meshes.hertz_grid_part`) and stays.
"""

from __future__ import annotations

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


def stay_on_rank(comm: MPI.Comm, nparts: int, cell_types: list[Any], cells: list[Any]) -> Any:
    """Every cell stays on the rank that passed it to create_mesh (input made distributed)."""
    num_cells = sum(len(c) for c in cell_arrays(cell_types, cells))
    return adjacencylist(np.full(num_cells, comm.rank, dtype=np.int32))._cpp_object
