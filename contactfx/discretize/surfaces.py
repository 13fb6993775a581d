"""Gather a body's contact facets into a small 1D Surface known on every rank."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import fem

from ..contact import ContactOperator, Surface
from ..contact.geometry import nodal_normals, segment_lengths
from ..contact.search import project
from ..errors import GeometryError, MeshError
from ..scenes import Model, Scene
from .mesh_utils import facet_ends, owned_facets


@dataclass(frozen=True)
class GatheredSurface:
    """A Surface plus, per node, its owning rank and its global block (node) number."""

    surface: Surface
    owner: np.ndarray
    gblock: np.ndarray


def gather_surface(scene: Scene, V: fem.FunctionSpace, name: str) -> GatheredSurface:
    """Allgather the facets of curve group `name` with coordinates, outward normals and dofs."""
    msh = V.mesh
    comm = msh.comm
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, 0)
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets = owned_facets(scene, name)
    f2v = msh.topology.connectivity(tdim - 1, 0)
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    imap = V.dofmap.index_map
    nloc = imap.size_local
    owners_ghost = imap.owners

    fv = f2v.array.reshape(-1, 2)[facets]
    cells = f2c.array[f2c.offsets[facets]]
    cx, _, ends, blocks = facet_ends(V, cells, fv)
    cell_mid = cx.mean(axis=1)
    x0, x1 = ends[:, 0], ends[:, 1]
    t = x1 - x0
    normal = np.column_stack([t[:, 1], -t[:, 0]]) / np.linalg.norm(t, axis=1)[:, None]
    flip = np.einsum("ij,ij->i", normal, 0.5 * (x0 + x1) - cell_mid) < 0
    normal[flip] *= -1
    gblocks = imap.local_to_global(blocks.ravel()).reshape(-1, 2)
    owner = np.concatenate([np.full(nloc, comm.rank, dtype=np.int64), owners_ghost])[blocks]

    local = np.column_stack([x0, x1, normal, gblocks, owner]).astype(np.float64)
    rows = comm.allgather(local)
    allrows = np.concatenate(rows) if rows else np.zeros((0, 10))
    if allrows.shape[0] == 0:
        raise MeshError(f"the contact surface '{name}' has no facets")
    coords = allrows[:, 0:4].reshape(-1, 2)
    gb = allrows[:, 6:8].astype(np.int64).ravel()
    own = allrows[:, 8:10].astype(np.int64).ravel()
    uniq, first, inverse = np.unique(gb, return_index=True, return_inverse=True)
    segments = inverse.reshape(-1, 2)
    x = coords[first]
    surface = Surface(
        x=x,
        segments=segments.astype(np.int64),
        normals=allrows[:, 4:6].copy(),
        dofs=np.column_stack([2 * uniq, 2 * uniq + 1]).astype(np.int64),
        axisymmetric=scene.model is Model.AXISYMMETRIC,
    )
    return GatheredSurface(surface, own[first], uniq)


def check_facing(active: Surface, passive: Surface, op: ContactOperator, label: str = "") -> None:
    """Raise GeometryError if the active nodes nearest the passive surface do not face it."""
    nodes = np.flatnonzero(op.overlapping)
    if nodes.size == 0:
        return
    gap = op.gap[nodes] / op.weights[nodes]
    h = float(np.median(segment_lengths(active)))
    # Only the nodes that can come into contact matter: a curved body turns away elsewhere.
    near = nodes[gap <= gap.min() + h]
    seg, _, _ = project(active.x[near], passive)
    dot = np.einsum("ij,ij->i", nodal_normals(active)[near], passive.normals[seg])
    if np.any(dot >= 0.0):
        j = int(np.argmax(dot))
        xa = active.x[near[j]]
        angle = np.degrees(np.arccos(min(dot[j], 1.0)))
        raise GeometryError(
            f"the contact surfaces{label} do not face each other: at ({xa[0]:.4g}, "
            f"{xa[1]:.4g}) the outward normals of the active and passive "
            f"surfaces make an angle of {angle:.0f} degrees (180 expected)"
        )
