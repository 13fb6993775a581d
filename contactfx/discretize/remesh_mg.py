"""Coarser meshes of the same scene as a multigrid's levels (gmsh meshes: non-nested grids).

A gmsh mesh has no nested coarser grid, but its recipe remeshes the same geometry with every
size x8, x16, ... (FIRST_FACTOR, then doubling). The prolongation from a coarse mesh to a
finer one evaluates the coarse cell's linear basis at each finer node (`meshes.cell_weights`):
the cell of the same body that contains it (DOLFINx's bounding-box tree, then an edge-sign
test), else the nearest cell of that body (finer nodes on a curved boundary, outside the
coarser polygon: extrapolated). Measured against GAMG on the gmsh Hertz family in
docs/scale.md ("A geometric multigrid on gmsh meshes").

Every rank meshes every coarser level whole (on its own communicator: the ranks' meshes are
identical, checked) and numbers its nodes as that serial mesh does; the levels are split over
the ranks in contiguous blocks of nodes as the structured grid's are (`grid_mg`).
"""

from __future__ import annotations

import logging
import time

import numpy as np
from dolfinx import fem, geometry
from dolfinx.mesh import Mesh
from mpi4py import MPI
from petsc4py import PETSc

from ..errors import InputError, MeshError
from ..meshes.cell_weights import contains, p1_weights
from ..scenes import Scene
from .grid_mg import COARSEST_NODES, node_prolongation, split_nodes

log = logging.getLogger(__name__)

# A coarser mesh that keeps more than this share of the finer one's nodes ends the levels:
# the scene's smallest features fix the sizes there, and the level would cost its
# factorization without coarsening.
MAX_KEPT = 0.6
MAX_LEVELS = 8
# The first coarser mesh is x8 (then x16, x32, ...): on the gmsh Hertz family x2, x4 and x8
# gave the same 5 CG iterations from 100k to 2M DOFs, x16 6-7; x8 costs gmsh 1/64 of the
# fine mesh and the cycle least (docs/scale.md, "A geometric multigrid on gmsh meshes").
FIRST_FACTOR = 8.0


def remesh_interpolations(
    V: fem.FunctionSpace, bcs: list[fem.DirichletBC], scene: Scene
) -> list[PETSc.Mat]:
    """Prolongations of the vector P1 space V from remeshes of `scene`, finest first.

    Empty if the scene's first remesh fails or does not coarsen (the caller keeps GAMG).
    """
    comm = V.mesh.comm
    t0 = time.perf_counter()
    n_owned = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:n_owned, :2]
    body = _block_bodies(V, scene)[:n_owned]
    fixed = np.zeros(2 * n_owned, dtype=bool)
    for bc in bcs:
        dofs = bc.dof_indices()[0]
        fixed[dofs[dofs < 2 * n_owned]] = True
    n_nodes = comm.allreduce(n_owned)
    mats: list[PETSc.Mat] = []
    sizes = []
    for k in range(MAX_LEVELS):
        if n_nodes <= COARSEST_NODES:
            break
        coarse = _coarser(scene, FIRST_FACTOR * 2.0**k, comm)
        if coarse is None:
            break
        cx = coarse.mesh.geometry.x[:, :2]
        if len(cx) > MAX_KEPT * n_nodes:
            break
        count, cols, vals = _rows(x, body, coarse)
        lo, hi = split_nodes(len(cx), comm.rank, comm.size)
        mats.append(node_prolongation(comm, count, cols, vals, hi - lo, fixed if k == 0 else None))
        sizes.append(len(cx))
        node_body = _node_bodies(coarse)
        x, body, n_nodes = cx[lo:hi], node_body[lo:hi], len(cx)
    log.info(
        "multigrid: %d coarser meshes of %s nodes (remeshed x%g to x%g), %.2f s",
        len(mats),
        " / ".join(f"{n:,}" for n in sizes),
        FIRST_FACTOR,
        FIRST_FACTOR * 2 ** max(len(mats) - 1, 0),
        time.perf_counter() - t0,
    )
    return mats


def _block_bodies(V: fem.FunctionSpace, scene: Scene) -> np.ndarray:
    """The body index of every dof block (P1: a block per mesh node)."""
    msh = V.mesh
    node_block = np.empty(msh.geometry.x.shape[0], dtype=np.int64)
    node_block[msh.geometry.dofmaps[0].ravel()] = V.dofmap.list.ravel()
    out = np.full(len(node_block), -1, dtype=np.int64)
    out[node_block] = _node_bodies(scene)
    return out


def _node_bodies(scene: Scene) -> np.ndarray:
    """The body index of every geometry node (the first body's where bodies share a node)."""
    nodes = scene.mesh.geometry.dofmaps[0]
    out = np.full(scene.mesh.geometry.x.shape[0], -1, dtype=np.int64)
    for i, b in reversed(list(enumerate(scene.bodies))):
        out[nodes[scene.body_cells(b)].ravel()] = i
    return out


def _coarser(scene: Scene, factor: float, comm: MPI.Comm) -> Scene | None:
    """The scene remeshed x`factor` on this rank alone; None where gmsh cannot mesh it."""
    try:
        coarse = scene.remeshed(factor, comm=None if comm.size == 1 else MPI.COMM_SELF)
    except (InputError, MeshError) as exc:
        log.info("multigrid: no mesh x%g (%s)", factor, exc)
        return None
    # The ranks meshed alone: their numberings must agree (gmsh and DOLFINx are deterministic).
    cx = coarse.mesh.geometry.x
    stamp = float(np.dot(cx[:, 0], np.arange(len(cx)) % 7919)) + len(cx)
    if comm.size > 1 and len(set(comm.allgather(stamp))) > 1:
        raise MeshError(f"the ranks' meshes x{factor:g} differ: cannot build a multigrid on them")
    return coarse


def _rows(x: np.ndarray, body: np.ndarray, coarse: Scene) -> tuple[np.ndarray, ...]:
    """Each point's prolongation row in the coarse mesh: counts, columns and weights (CSR)."""
    msh = coarse.mesh
    cells = msh.geometry.dofmaps[0].astype(np.int64)
    cx = msh.geometry.x[:, :2]
    cell = np.full(len(x), -1, dtype=np.int64)
    for b in np.unique(body):
        mine = np.flatnonzero(body == b)
        cell[mine] = _locate(msh, coarse.body_cells(coarse.bodies[b]), x[mine])
    w, ok = p1_weights(x, cx[cells[cell]])
    # Far out of its cell's reference square (a concave corner): the cell's nearest vertex.
    for i in np.flatnonzero(~ok):
        w[i] = 0.0
        w[i, np.argmin(((cx[cells[cell[i]]] - x[i]) ** 2).sum(axis=1))] = 1.0
    w[np.abs(w) < 1e-13] = 0.0
    keep = w != 0.0
    return keep.sum(axis=1), cells[cell][keep], w[keep]


def _locate(msh: Mesh, entities: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The cell among `entities` that holds each point, else the nearest one of them."""
    pts = np.zeros((len(points), 3))
    pts[:, :2] = points
    entities = entities.astype(np.int32)
    tree = geometry.bb_tree(msh, 2, entities=entities)
    candidates = geometry.compute_collisions_points(tree, pts)
    point = np.repeat(np.arange(len(points)), np.diff(candidates.offsets))
    cell = candidates.array.astype(np.int64)
    corners = msh.geometry.x[msh.geometry.dofmaps[0][cell], :2]
    holds = contains(points[point], corners)
    found = np.full(len(points), -1, dtype=np.int64)
    # The first candidate that holds the point (reversed: the first write is the last).
    found[point[holds][::-1]] = cell[holds][::-1]
    missing = found < 0
    if missing.any():
        mid = geometry.create_midpoint_tree(msh, 2, entities)
        found[missing] = geometry.compute_closest_entity(tree, mid, msh, pts[missing])
    return found
