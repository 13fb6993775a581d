"""Distribute a gathered ContactOperator as a PETSc matrix: rows by the active node's owner."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..contact import ContactOperator
from .surfaces import GatheredSurface


@dataclass(frozen=True)
class Multipliers:
    """The multiplier (active-surface node) layout: global order, and the rows this rank owns."""

    x: np.ndarray  # (n, 2) coordinates of every multiplier node, global order
    weights: np.ndarray  # (n,) int N_j dGamma over the overlap
    mine: np.ndarray  # indices (into the global order) of the rows owned here
    offset: int  # global index of this rank's first row
    gblock: np.ndarray  # (n,) global dof block of each node
    pair: np.ndarray  # (n,) contact pair of each multiplier

    @property
    def size(self) -> int:
        """Total number of multipliers."""
        return self.x.shape[0]


def global_unrolled(V: fem.FunctionSpace, local: np.ndarray) -> np.ndarray:
    """Global unrolled dof numbers of owned local unrolled dofs."""
    bs = V.dofmap.index_map_bs
    return V.dofmap.index_map.local_to_global(local // bs) * bs + local % bs


def global_dirichlet_dofs(V: fem.FunctionSpace, bc_dofs: np.ndarray) -> np.ndarray:
    """All ranks' Dirichlet dofs as global unrolled numbers (small: boundary only)."""
    nloc = V.dofmap.index_map.size_local * V.dofmap.index_map_bs
    mine = global_unrolled(V, bc_dofs[bc_dofs < nloc].astype(np.int64))
    return np.unique(np.concatenate(V.mesh.comm.allgather(mine)))


def constrained_rows(op: ContactOperator, dirichlet: np.ndarray, rtol: float = 1e-10) -> np.ndarray:
    """Rows of `op` that constrain a free dof.

    A row on prescribed dofs only is data, not a constraint: its multiplier would make the
    saddle point singular. "Only" is up to round-off: with the dual basis a pinned node
    facing a locally matching mesh keeps free entries of 1e-17 (biorthogonality).
    """
    free = op.B.without_columns(column_mask(dirichlet, op.B.shape[1])).row_max_abs()
    return free > rtol * op.B.row_max_abs()


def column_mask(dofs: np.ndarray, n: int) -> np.ndarray:
    """A bool mask of n columns, True on `dofs` (those beyond n, other ranks' columns, left)."""
    mask = np.zeros(n, dtype=bool)
    mask[dofs[dofs < n]] = True
    return mask


def multiplier_layout(
    comm: MPI.Comm,
    active: GatheredSurface,
    op: ContactOperator,
    pair: np.ndarray | None = None,
    usable: np.ndarray | None = None,
) -> tuple[Multipliers, np.ndarray]:
    """Order constrained nodes by (owner rank, pair, global node): each rank's rows contiguous.

    `pair` (one entry per row of `op`) tells which contact pair a row belongs to when the
    operator stacks several pairs; weights below round-off of the largest mark no overlap;
    rows outside `usable` (if given) are left out.
    """
    pair = np.zeros(len(op.weights), dtype=np.int64) if pair is None else pair
    ok = op.overlapping
    keep = np.flatnonzero(ok if usable is None else ok & usable)
    order = keep[np.lexsort((active.gblock[keep], pair[keep], active.owner[keep]))]
    owner = active.owner[order]
    mine = np.flatnonzero(owner == comm.rank)
    offset = int(np.count_nonzero(owner < comm.rank))
    x = active.surface.x[order]
    return Multipliers(x, op.weights[order], mine, offset, active.gblock[order], pair[order]), order


def petsc_constraint(
    V: fem.FunctionSpace,
    op: ContactOperator,
    order: np.ndarray,
    layout: Multipliers,
    dirichlet: np.ndarray,
) -> PETSc.Mat:
    """Build this rank's rows of B (global columns), with Dirichlet columns removed."""
    imap = V.dofmap.index_map
    bs = V.dofmap.index_map_bs
    n_local, n_global = imap.size_local * bs, imap.size_global * bs
    drop = column_mask(dirichlet, op.B.shape[1])
    rows = op.B.rows(order[layout.mine]).without_columns(drop)  # column indices sorted
    m = rows.shape[0]
    B = PETSc.Mat().createAIJ(
        size=((m, layout.size), (n_local, n_global)),
        csr=(
            rows.indptr.astype(PETSc.IntType),
            rows.indices.astype(PETSc.IntType),
            rows.data.astype(PETSc.ScalarType),
        ),  # type: ignore[arg-type]  # the stub wants Sequences; PETSc takes the arrays
        comm=V.mesh.comm,
    )
    B.assemble()
    return B
