"""A structured mesh's coarser grids as PETSc prolongations on the displacement space.

`meshes.grid_levels` gives the prolongations between the grid's levels in the grid's node
numbering; here the finest one is mapped to DOLFINx's owned dofs (the mesh's input node
numbers are the grid's), every level takes the two displacement components, and the coarser
levels are split over the ranks in contiguous blocks of nodes. Rows of Dirichlet dofs are
zero: the coarse grids do not correct what the boundary fixes.
"""

from __future__ import annotations

from typing import Any, cast

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..meshes import GridLines, Level, grid_levels

# The coarsest grid's nodes: it is factorized (MUMPS), a few thousand unknowns.
COARSEST_NODES = 1500


def grid_interpolations(
    V: fem.FunctionSpace, bcs: list[fem.DirichletBC], lines: GridLines
) -> list[PETSc.Mat]:
    """Prolongations of the vector P1 space V on `lines`' grid, finest first (PETSc AIJ).

    V's mesh must be the grid's (`hertz_grid` / `hertz_grid_part`, input node numbers kept).
    """
    comm = V.mesh.comm
    levels = grid_levels(lines, COARSEST_NODES)
    imap = V.dofmap.index_map
    n_owned = imap.size_local
    msh = V.mesh
    # The grid node of each owned dof block (P1: a block per mesh node).
    node_block = np.empty(msh.geometry.x.shape[0], dtype=np.int64)
    node_block[msh.geometry.dofmaps[0].ravel()] = V.dofmap.list.ravel()
    grid_of_block = np.empty(imap.size_local + imap.num_ghosts, dtype=np.int64)
    grid_of_block[node_block] = np.asarray(msh.geometry.input_global_indices)
    if levels and comm.allreduce(n_owned) != levels[0].n_fine:
        raise ValueError("the mesh is not the grid of these lines")
    fixed = _owned_fixed(bcs, n_owned)
    mats = []
    rows_of = grid_of_block[:n_owned]  # fine rows: the owned blocks' grid nodes
    owner = _owners(rows_of, levels[0].n_fine if levels else 0, comm)
    for k, level in enumerate(levels):
        # Each coarser node stays on the rank of the finer node it is, numbered in rank
        # blocks: the products and transfers then stay on their rank (a split of the grid's
        # own numbering sent most of the fine rows' columns to the other rank).
        owner = owner[level.fine_of]
        order = np.argsort(owner, kind="stable")  # the new numbering's coarse nodes
        number = np.empty_like(order)
        number[order] = np.arange(len(order))
        lo, hi = np.searchsorted(owner[order], [comm.rank, comm.rank + 1])
        count, cols, vals = _level_rows(level, rows_of)
        mats.append(
            node_prolongation(comm, count, number[cols], vals, hi - lo, fixed if k == 0 else None)
        )
        rows_of = order[lo:hi]
    return mats


def _owners(rows_of: np.ndarray, n: int, comm: MPI.Comm) -> np.ndarray:
    """(n,) the rank owning each grid node, from every rank's owned nodes `rows_of`."""
    owner = np.zeros(n, dtype=np.int32)
    owner[rows_of] = comm.rank
    if comm.size > 1:
        comm.Allreduce(MPI.IN_PLACE, owner, op=MPI.MAX)
    return owner


def _owned_fixed(bcs: list[fem.DirichletBC], n_owned: int) -> np.ndarray:
    """(2 n_owned,) whether each owned dof of a 2-component P1 space is fixed by `bcs`."""
    fixed = np.zeros(2 * n_owned, dtype=bool)
    for bc in bcs:
        dofs = bc.dof_indices()[0]
        fixed[dofs[dofs < 2 * n_owned]] = True
    return fixed


def split_nodes(n: int, rank: int, size: int) -> tuple[int, int]:
    """This rank's contiguous block of n coarse nodes (the first n % size blocks one larger)."""
    q, r = divmod(n, size)
    lo = rank * q + min(rank, r)
    return lo, lo + q + (rank < r)


def _level_rows(level: Level, rows_of: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows of fine nodes `rows_of` (in that order) as counts, columns and weights."""
    order = np.argsort(level.rows, kind="stable")
    rows, cols, vals = level.rows[order], level.cols[order], level.vals[order]
    starts = np.searchsorted(rows, np.arange(level.n_fine + 1))
    count = starts[rows_of + 1] - starts[rows_of]
    local_ptr = np.concatenate([[0], np.cumsum(count)])
    take = np.repeat(starts[rows_of] - local_ptr[:-1], count) + np.arange(local_ptr[-1])
    return count, cols[take], vals[take]


def node_prolongation(
    comm: MPI.Comm,
    count: np.ndarray,
    c: np.ndarray,
    v: np.ndarray,
    n_cols: int,
    fixed: np.ndarray | None = None,
) -> PETSc.Mat:
    """The owned rows of a level, both components, from its node rows in CSR form.

    Node row i has `count[i]` entries of `c` (global coarse nodes) and `v`; `n_cols`: the
    owned coarse nodes; the rows of `fixed` dofs are zero.
    """
    local_ptr = np.concatenate([[0], np.cumsum(count)])
    n_rows = len(count)
    # Node rows -> dof rows 2i, 2i + 1 with the same weights on columns 2j, 2j + 1.
    indptr = np.zeros(2 * n_rows + 1, dtype=np.int64)
    indptr[1:] = np.cumsum(np.repeat(count, 2))
    ci = np.empty(2 * len(c), dtype=np.int64)
    vi = np.empty(2 * len(c))
    for comp in (0, 1):
        # Row 2i + comp holds entries local_ptr[i] .. local_ptr[i + 1] of comp's columns.
        pos = indptr[2 * np.arange(n_rows) + comp]
        dest = np.repeat(pos - local_ptr[:-1], count) + np.arange(len(c))
        ci[dest] = 2 * c + comp
        vi[dest] = v
    if fixed is not None:
        vi[np.repeat(fixed, np.diff(indptr))] = 0.0
    csr: Any = (indptr.astype(PETSc.IntType), ci.astype(PETSc.IntType), vi)
    sizes = ((2 * n_rows, PETSc.DECIDE), (2 * n_cols, PETSc.DECIDE))
    P = PETSc.Mat().createAIJ(size=sizes, csr=csr, comm=cast(Any, comm))
    P.assemble()
    return P
