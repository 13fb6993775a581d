"""Coarser meshes of the same scene as a multigrid's levels (gmsh meshes: non-nested grids).

A gmsh mesh has no nested coarser grid, but its recipe remeshes the same geometry with every
size x8, x16, ... (FIRST_FACTOR, then doubling). The prolongation from a coarse mesh to a
finer one evaluates the coarse cell's bilinear basis at each finer node (`meshes.cell_weights`):
the cell of the same body that contains it (DOLFINx's bounding-box tree, then an edge-sign
test), else the nearest cell of that body (finer nodes on a curved boundary, outside the
coarser polygon: extrapolated). Unlike the structured grid's, the Dirichlet rows keep their
weights: zeroed, they left the columns of coarse nodes near a support empty (a singular
Galerkin coarse operator on the default Hertz mesh); coarse nodes no finer node interpolates
from are dropped for the same reason. Measured against GAMG on the gmsh Hertz family in
docs/scale.md ("A geometric multigrid on gmsh meshes").

Every rank meshes every coarser level whole (on its own communicator: the ranks' meshes are
identical, checked) and numbers its nodes as that serial mesh does; the levels are split over
the ranks in contiguous blocks of nodes as the structured grid's are (`grid_mg`).
"""

from __future__ import annotations

import logging
import time
from typing import NamedTuple

import numpy as np
from dolfinx import fem, geometry
from dolfinx.mesh import Mesh
from mpi4py import MPI
from petsc4py import PETSc

from ..errors import InputError, MeshError
from ..meshes.cell_weights import contains, q1_weights
from ..scenes import Scene
from .grid_mg import COARSEST_NODES, node_prolongation, split_nodes
from .supports import body_blocks

log = logging.getLogger(__name__)

# A coarser mesh that keeps more than this share of the finer one's nodes ends the levels:
# the scene's smallest features fix the sizes there, and the level would cost its
# factorization without coarsening.
MAX_KEPT = 0.6
MAX_LEVELS = 8
# The first coarser mesh is x8 (then x16, x32, ...): the coarsest first step whose CG
# iterations match x2's, so gmsh and the cycle cost least (measured by first factor:
# docs/scale.md, "A geometric multigrid on gmsh meshes").
FIRST_FACTOR = 8.0


class CoarseLevel(NamedTuple):
    """A coarser level: the prolongation onto the finer one, its nodes' coordinates and bodies."""

    P: PETSc.Mat
    x: np.ndarray  # (n, 2): every node of the level (all ranks), in its column order
    body: np.ndarray  # (n,): each node's body index


def remesh_interpolations(V: fem.FunctionSpace, scene: Scene) -> list[PETSc.Mat]:
    """Prolongations of the vector P1 space V from remeshes of `scene`, finest first.

    Empty if the scene's first remesh fails or does not coarsen (the caller keeps GAMG).
    """
    return [level.P for level in remesh_levels(V, scene)]


def remesh_levels(V: fem.FunctionSpace, scene: Scene) -> list[CoarseLevel]:
    """The coarser levels of V from remeshes of `scene`, finest first (remesh_interpolations)."""
    comm = V.mesh.comm
    t0 = time.perf_counter()
    n_owned = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:n_owned, :2]
    body = _block_bodies(V, scene)[:n_owned]
    n_nodes = comm.allreduce(n_owned)
    levels: list[CoarseLevel] = []
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
        used = _used_nodes(comm, len(cx), count, cols)
        count, cols, vals = _only_used(used, count, cols, vals)
        n_used = int(used.sum())
        lo, hi = split_nodes(n_used, comm.rank, comm.size)
        P = node_prolongation(comm, count, cols, vals, hi - lo)
        levels.append(CoarseLevel(P, cx[used], _node_bodies(coarse)[used]))
        x, body, n_nodes = levels[-1].x[lo:hi], levels[-1].body[lo:hi], n_used
    log.info(
        "multigrid: %d coarser meshes of %s nodes (remeshed x%g to x%g), %.2f s",
        len(levels),
        " / ".join(f"{len(level.x):,}" for level in levels),
        FIRST_FACTOR,
        FIRST_FACTOR * 2 ** max(len(levels) - 1, 0),
        time.perf_counter() - t0,
    )
    return levels


def _used_nodes(comm: MPI.Comm, n: int, count: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """(n,) the coarse nodes some finer row (on any rank) interpolates from.

    A non-nested coarse node can have no finer node in its cells: its column would be empty
    and the Galerkin coarse operator singular, so it is dropped.
    """
    used = np.zeros(n, dtype=bool)
    used[cols] = True
    comm.Allreduce(MPI.IN_PLACE, used, op=MPI.LOR)
    return used


def _only_used(
    used: np.ndarray, count: np.ndarray, cols: np.ndarray, vals: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows (CSR) without the entries of unused nodes, columns renumbered among the used."""
    keep = used[cols]
    row = np.repeat(np.arange(len(count)), count)
    count = np.bincount(row[keep], minlength=len(count))
    return count, (np.cumsum(used) - 1)[cols[keep]], vals[keep]


def _block_bodies(V: fem.FunctionSpace, scene: Scene) -> np.ndarray:
    """The body index of every local dof block (the first body's where bodies share one)."""
    im = V.dofmap.index_map
    out = np.full(im.size_local + im.num_ghosts, -1, dtype=np.int64)
    for i, b in reversed(list(enumerate(scene.bodies))):
        out[body_blocks(V, scene.body_cells(b))] = i
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
        coarse = scene.remeshed(factor, comm=MPI.COMM_SELF)
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
    corners = cx[cells[cell]]
    w, ok = q1_weights(x, corners)
    # Far out of its cell's reference square (a concave corner): the cell's nearest vertex.
    far = np.flatnonzero(~ok)
    nearest = np.argmin(((corners[far] - x[far, None, :]) ** 2).sum(axis=2), axis=1)
    w[far] = 0.0
    w[far, nearest] = 1.0
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
