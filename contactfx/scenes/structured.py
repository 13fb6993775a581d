"""The structured Hertz grid of meshes/ as a distributed DOLFINx mesh with named groups."""

from __future__ import annotations

import basix.ufl
import numpy as np
import ufl
from dolfinx import mesh as dmesh
from dolfinx.io.gmsh import MeshData, PhysicalGroup
from mpi4py import MPI

from ..errors import InputError
from ..meshes import GridLines, grid_geometry, hertz_grid_part
from .gmsh_io import stay_on_rank

# Physical groups, named like the gmsh scene's (the numbers themselves are free).
TAGS = {
    "body1": PhysicalGroup(2, 1),
    "body2": PhysicalGroup(2, 2),
    "contact1": PhysicalGroup(1, 3),
    "contact2": PhysicalGroup(1, 4),
    "symmetry": PhysicalGroup(1, 5),
    "support": PhysicalGroup(1, 6),
    "load": PhysicalGroup(1, 7),
}


def build_hertz_structured(
    comm: MPI.Comm,
    R: float,
    width: float,
    height: float,
    h_contact: float,
    r_refine: float,
    h_far: float | None = None,
    slope: float = 0.1,
    contact_extent: float | None = None,
) -> tuple[MeshData, GridLines]:
    """The Hertz half model (quarter disc on a block) as a distributed structured quad mesh.

    Returned as gmsh's MeshData (no ridge or peak tags), so that both meshers feed the same
    scene construction, with the grid's lines (its coarser grids: `Scene.grid`).
    """
    h_far = R / 6.0 if h_far is None else h_far
    extent = min(width, R / 4.0) if contact_extent is None else contact_extent
    if min(R, width, height, h_contact, h_far, slope) <= 0.0 or r_refine < 0.0:
        raise InputError("radius, block size, mesh sizes and slope must be positive")
    if not 0.0 < extent < min(width, R):
        raise InputError(f"contact_extent={extent} must lie in (0, min(width, R))")
    part = hertz_grid_part(
        R, width, height, h_contact, r_refine, h_far, slope, comm.rank, comm.size
    )
    element = ufl.Mesh(basix.ufl.element("Lagrange", "quadrilateral", 1, shape=(2,)))
    msh = dmesh.create_mesh(comm, part.cells, element, part.x, partitioner=stay_on_rank)
    body = cell_bodies(msh, comm.allgather((len(part.cells), part.n_block)))
    tdim = msh.topology.dim
    cell_tags = dmesh.meshtags(msh, tdim, np.arange(len(body), dtype=np.int32), body)
    facet_tags = tag_hertz_facets(msh, body, R, height, extent)
    lines = grid_geometry(R, width, height, h_contact, r_refine, h_far, slope).lines()
    return MeshData(msh, cell_tags, facet_tags, None, None, dict(TAGS)), lines


def cell_bodies(msh: dmesh.Mesh, parts: list[tuple[int, int]]) -> np.ndarray:
    """Body 1 or 2 of each local cell, from its input index (`original_cell_index`).

    `parts`: (cells, block cells) that each rank passed to create_mesh, in rank order; a
    rank's input cells are numbered after the lower ranks' and its block cells come first.
    """
    tdim = msh.topology.dim
    ncells = msh.topology.index_map(tdim).size_local + msh.topology.index_map(tdim).num_ghosts
    counts = np.array(parts, dtype=np.int64).reshape(-1, 2)
    starts = np.concatenate([[0], np.cumsum(counts[:, 0])])
    index = np.asarray(msh.topology.original_cell_index, dtype=np.int64)[:ncells]
    rank = np.searchsorted(starts, index, side="right") - 1
    return np.where(index - starts[rank] < counts[rank, 1], 1, 2).astype(np.int32)


def tag_hertz_facets(
    msh: dmesh.Mesh, body: np.ndarray, R: float, height: float, extent: float
) -> dmesh.MeshTags:
    """The facet groups of TAGS on the exterior facets, by position and body."""
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets = dmesh.exterior_facet_indices(msh.topology)
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    fbody = body[f2c.array[f2c.offsets[facets]]]
    xf = msh.geometry.x[dmesh.entities_to_geometry(msh, tdim - 1, facets)][:, :, :2]
    yc = height + R
    mid_x = xf[:, :, 0].mean(axis=1)
    on_arc = np.abs(np.hypot(xf[:, :, 0], xf[:, :, 1] - yc) - R) <= 1e-10 * R
    values = np.zeros(len(facets), dtype=np.int32)
    rules = [
        (fbody == 1, (xf[:, :, 1] == height).all(axis=1) & (mid_x <= extent), "contact1"),
        (fbody == 2, on_arc.all(axis=1) & (mid_x <= extent), "contact2"),
        (fbody > 0, (xf[:, :, 0] == 0.0).all(axis=1), "symmetry"),
        (fbody == 1, (xf[:, :, 1] == 0.0).all(axis=1), "support"),
        (fbody == 2, (xf[:, :, 1] == yc).all(axis=1), "load"),
    ]
    for in_body, cond, name in rules:
        values[(values == 0) & in_body & cond] = TAGS[name].tag
    keep = values > 0
    order = np.argsort(facets[keep])
    return dmesh.meshtags(msh, tdim - 1, facets[keep][order].astype(np.int32), values[keep][order])
