"""DOLFINx mesh helpers the surface, stress and support code share (Q1 quadrilaterals)."""

from __future__ import annotations

import numpy as np
from dolfinx import fem, mesh

from ..scenes import Scene


def scene_dofs(scene: Scene) -> int:
    """Displacement dofs of `scene` (P1 vector: two per vertex)."""
    return 2 * scene.mesh.topology.index_map(0).size_global


def max_cell_aspect(msh: mesh.Mesh) -> float:
    """The largest longest-to-shortest edge ratio of the local cells (Q1 quadrilaterals)."""
    x, cells = msh.geometry.x[:, :2], msh.geometry.dofmaps[0]  # tensor-product order
    if len(cells) == 0:
        return 1.0
    # The edges of a DOLFINx quadrilateral: 0-1, 1-3, 3-2, 2-0; squared lengths, one edge
    # at a time (`auto` asks this of its largest meshes: no (cells, 4, 2) temporary).
    sq = []
    for i, j in ((1, 0), (3, 1), (2, 3), (0, 2)):
        v = x[cells[:, i]] - x[cells[:, j]]
        sq.append(np.einsum("ij,ij->i", v, v))
    longest = np.maximum(np.maximum(sq[0], sq[1]), np.maximum(sq[2], sq[3]))
    shortest = np.minimum(np.minimum(sq[0], sq[1]), np.minimum(sq[2], sq[3]))
    return float(np.sqrt(np.max(longest / shortest)))


def vertex_to_block(V: fem.FunctionSpace) -> np.ndarray:
    """Local dof block of every local vertex (Q1: one block per vertex)."""
    msh = V.mesh
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim, 0)
    c2v = msh.topology.connectivity(tdim, 0).array.reshape(-1, 4)
    ncells = c2v.shape[0]
    v2b = np.full(
        msh.topology.index_map(0).size_local + msh.topology.index_map(0).num_ghosts,
        -1,
        dtype=np.int32,
    )
    # For Q1 the dofs of a cell are listed in the order of its vertices.
    v2b[c2v.ravel()] = V.dofmap.list[:ncells].ravel()
    return v2b


def owned_facets(scene: Scene, name: str) -> np.ndarray:
    """Owned facets of the curve group `name`."""
    msh = scene.mesh
    tdim = msh.topology.dim
    tag = scene.curve_tag(name, "contact")
    assert scene.facet_tags is not None  # curve_tag found the group
    facets = scene.facet_tags.find(tag)
    return facets[facets < msh.topology.index_map(tdim - 1).size_local]


def facet_ends(
    V: fem.FunctionSpace, cells: np.ndarray, f2v: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Boundary facets' two ends, read from their cells only (Q1 quadrilaterals).

    `cells` (n,): each facet's cell; `f2v` (n, 2): its vertices. Returns the cells' vertex
    coordinates (n, 4, 2), each end's column in its cell (n, 2), the ends' coordinates
    (n, 2, 2) and local dof blocks (n, 2). Only these cells are read, not every vertex of
    the mesh (docs/scale.md, "One CG run per stationary set").
    """
    msh = V.mesh
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim, 0)
    c2v = msh.topology.connectivity(tdim, 0).array.reshape(-1, 4)[cells]
    # Q1: the cell's geometry nodes and its dofs are listed in the order of its vertices.
    cx = msh.geometry.x[msh.geometry.dofmaps[0][cells], :2]
    cols = np.column_stack([np.argmax(c2v == f2v[:, [k]], axis=1) for k in range(2)])
    at = np.arange(len(cells))[:, None]
    return cx, cols, cx[at, cols], V.dofmap.list[cells][at, cols]
