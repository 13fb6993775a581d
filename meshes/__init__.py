"""gmsh scene definitions (blocks S1-S4, Hertz S5) and their conversion to DOLFINx meshes."""

import threading
from collections.abc import Callable
from typing import Any

import dolfinx_solver  # noqa: F401 - orders MPI ahead of the dolfinx bindings
import gmsh
import numpy as np
from dolfinx.cpp.mesh import cell_num_vertices
from dolfinx.graph import adjacencylist
from dolfinx.io.gmsh import MeshData, model_to_mesh
from mpi4py import MPI
from scipy.sparse import coo_array
from scipy.sparse.csgraph import connected_components

from contactfx.errors import MeshError
from meshes.blocks import build_blocks
from meshes.hertz import build_hertz

__all__ = ["balanced_partitioner", "build_blocks", "build_hertz", "to_dolfinx"]


def _gmsh_node_coordinates() -> np.ndarray:
    """Return the current gmsh model's node coordinates, row i = node tag i + 1."""
    if not gmsh.isInitialized():
        raise MeshError("balanced_partitioner needs node coordinates: no gmsh session is open")
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    x = np.zeros((int(tags.max()) if len(tags) else 0, 3))
    x[tags.astype(np.int64) - 1] = xyz.reshape(-1, 3)
    return x


def balanced_partitioner(coordinates: np.ndarray | None = None) -> Callable[..., Any]:
    """Return a cell partitioner that splits every body (connected component) over all ranks."""

    def partition(comm: MPI.Comm, nparts: int, cell_types: list, cells: list) -> Any:
        # Cells of one type per list entry, flattened; node index = gmsh node tag - 1.
        conn = [
            np.asarray(c, dtype=np.int64).reshape(-1, cell_num_vertices(ct))
            for ct, c in zip(cell_types, cells, strict=True)
        ]
        num_cells = sum(len(c) for c in conn)
        dest = np.zeros(num_cells, dtype=np.int32)
        if num_cells == 0 or nparts == 1:
            return adjacencylist(dest)._cpp_object
        x = _gmsh_node_coordinates() if coordinates is None else np.asarray(coordinates)
        mid = np.vstack([x[c, :2].mean(axis=1) for c in conn])
        # Bodies share no node, so the connected components of the node graph are the
        # bodies: linking each cell's first vertex to its others is enough to find them.
        first = np.concatenate([np.repeat(c[:, 0], c.shape[1]) for c in conn])
        other = np.concatenate([c.ravel() for c in conn])
        n = int(max(first.max(), other.max())) + 1
        graph = coo_array((np.ones(len(first)), (first, other)), shape=(n, n))
        _, node_label = connected_components(graph, directed=False)
        cell_label = node_label[np.concatenate([c[:, 0] for c in conn])]
        # Within each body, equal-count strips by midpoint x (then y): the contact line of
        # each body is spread over all ranks, and the strips of the two bodies overlap.
        for label in np.unique(cell_label):
            ids = np.flatnonzero(cell_label == label)
            order = ids[np.lexsort((mid[ids, 1], mid[ids, 0]))]
            dest[order] = (np.arange(len(order)) * nparts) // len(order)
        return adjacencylist(dest)._cpp_object

    return partition


def to_dolfinx(
    comm: MPI.Comm, build: Callable[[], None], partitioner: Callable[..., Any] | None = None
) -> MeshData:
    """Build a scene on rank 0 in a fresh gmsh session; return the distributed MeshData (gdim 2)."""
    root = 0
    on_root = comm.rank == root
    fresh = previous = failure = None
    error = ""
    if on_root:
        fresh = not gmsh.isInitialized()
        if fresh:
            # gmsh's SIGINT handler can only be installed from the main thread.
            gmsh.initialize(interruptible=threading.current_thread() is threading.main_thread())
            gmsh.option.setNumber("General.Terminal", 0)
        else:
            previous = gmsh.model.getCurrent()
        gmsh.model.add(f"contactfx-{id(build)}")
        try:
            build()
        except Exception as exc:  # told to every rank below, else the others hang in bcast
            failure = exc
            error = f"{type(exc).__name__}: {exc}"
    try:
        error = comm.bcast(error, root=root)
        if failure is not None:
            raise failure
        if error:
            raise MeshError(f"gmsh scene build failed on rank {root}: {error}")
        return model_to_mesh(
            gmsh.model if on_root else None, comm, root, gdim=2, partitioner=partitioner
        )
    finally:
        if on_root:
            if fresh:
                gmsh.finalize()
            else:
                gmsh.model.remove()
                if previous:
                    gmsh.model.setCurrent(previous)
