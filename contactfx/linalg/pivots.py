"""The pivots of the condensation: which displacement each active constraint row gives.

Each active row j picks the component of its own node with the largest coefficient (for a
contact row: the node's normal direction), the pivot p(j). The pivot block B_AP (rows x
pivots) is diagonal for NTS and for dual mortar on a flat passive surface; on a curved one
the passive normal turns within an active segment and row j also touches its neighbours'
pivots (measured on two cylinders: up to 0.3 % of the pivot). Then

    u_P = -B_AP^-1 (g_A + B_AF u_F),    mu = B_AP^-T (f - K u)_P,

with B_AP factorized once per set (sparse LU of a rows x rows matrix, replicated: the active
rows are a few thousand at most). The rows of B_AP^-1 B_AF decay geometrically away from the
diagonal; entries below DROP of a row's largest are round-off and are dropped.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from mpi4py import MPI

if TYPE_CHECKING:
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

from ..errors import EliminationError
from .elimination import LocalRows, PivotRows

# Off-diagonal entries of B_AP up to this (relative to the row's pivot) are round-off of a
# diagonal D (dual mortar on a flat surface: 1e-17): the rows decouple exactly.
DIAGONAL_TOL = 1e-10
# Entries of B_AP^-1 B_AF below this fraction of their row's largest are dropped.
DROP = 1e-16


def _own_pivots(B: LocalRows, rows: np.ndarray, comm: MPI.Comm) -> tuple[np.ndarray, np.ndarray]:
    """Each row's pivot dof (its own node's component of largest |coefficient|) and value.

    EliminationError on every rank if a row's node has no free dof (it carries that node's
    dofs: the linear algebra knows no pairs, the caller names the pair).
    """
    piv = np.zeros(len(rows), dtype=np.int64)
    coef = np.zeros(len(rows))
    bad: tuple[int, int] | None = None
    for i, j in enumerate(rows):
        cols, vals = B.row(j)
        own = np.isin(cols, B.node_dofs[j])
        if not own.any() or np.abs(vals[own]).max() == 0.0:
            bad = bad or (int(B.node_dofs[j, 0]), int(B.node_dofs[j, 1]))
            continue
        k = np.flatnonzero(own)[int(np.argmax(np.abs(vals[own])))]
        piv[i], coef[i] = cols[k], vals[k]
    found = [b for b in comm.allgather(bad) if b is not None]
    if found:
        raise EliminationError(
            "the condensed solver cannot eliminate a contact row whose active node is fully "
            "prescribed: use --solver mumps",
            min(found),
            "prescribed",
        )
    return piv, coef


def _gathered_rows(B: LocalRows, rows: np.ndarray, comm: MPI.Comm, n: int) -> sp.csr_matrix:
    """The active rows of every rank (rank order), as one replicated CSR matrix (m x n)."""
    parts = [B.row(j) for j in rows]
    counts = np.array([len(c) for c, _ in parts], dtype=np.int64)
    cols = np.concatenate([c for c, _ in parts]) if parts else np.zeros(0, dtype=np.int64)
    vals = np.concatenate([v for _, v in parts]) if parts else np.zeros(0)
    counts_all, cols_all, vals_all = (
        np.concatenate(comm.allgather(a)) for a in (counts, cols.astype(np.int64), vals)
    )
    indptr = np.concatenate([[0], np.cumsum(counts_all)])
    import scipy.sparse as sp  # only the condensed solver: not on a plain solve (docs/scale.md)

    return sp.csr_matrix((vals_all, cols_all, indptr), shape=(len(counts_all), n))


@dataclass(frozen=True)
class Coupled:
    """The factorized pivot block of a non-diagonal D, replicated on every rank."""

    lu: spla.SuperLU
    mine: slice  # this rank's rows in the rank-ordered global list of active rows
    comm: MPI.Comm

    def solve(self, local: np.ndarray, transposed: bool = False) -> np.ndarray:
        """This rank's part of B_AP^-1 b (or B_AP^-T b) for the local rows' part b."""
        rhs = np.concatenate(self.comm.allgather(np.asarray(local, dtype=float)))
        return self.lu.solve(rhs, trans="T" if transposed else "N")[self.mine]


@dataclass(frozen=True)
class Pivots:
    """The pivots of a set: owned active rows, their pivot dofs and coefficients, E's rows."""

    rows: np.ndarray  # owned active rows (local indices)
    dofs: np.ndarray  # their pivot dofs (global)
    coef: np.ndarray  # B[row, pivot]
    e_rows: PivotRows  # row p(j) of E = T - I, by local row of the pivot dof
    coupled: Coupled | None  # None: D is diagonal, the rows decouple

    def shift(self, g: np.ndarray) -> np.ndarray:
        """The shift t at the owned pivots (u_P where u_F = 0), from every local row's gap."""
        if self.coupled is None:
            return -np.asarray(g)[self.rows] / self.coef
        return -self.coupled.solve(np.asarray(g)[self.rows])

    def multipliers(self, residual: np.ndarray) -> np.ndarray:
        """The multipliers of the owned active rows from (f - K u) at their pivots."""
        if self.coupled is None:
            return residual / self.coef
        return self.coupled.solve(residual, transposed=True)


def pivots(B: LocalRows, active: np.ndarray, comm: MPI.Comm, r0: int, n: int) -> Pivots:
    """The pivots of the active rows, and E's rows (diagonal or coupled pivot block).

    `r0`: this rank's first displacement dof; `n`: the number of displacement dofs.
    """
    rows = np.flatnonzero(active)
    piv, coef = _own_pivots(B, rows, comm)
    all_piv = np.concatenate(comm.allgather(piv))
    counts = comm.allgather(len(rows))
    mine = slice(sum(counts[: comm.rank]), sum(counts[: comm.rank + 1]))
    A = _gathered_rows(B, rows, comm, n)
    import scipy.sparse as sp  # imported by _gathered_rows already: a dict look-up

    block = A[:, all_piv].tocsr()
    off = (block - sp.diags(block.diagonal())).tocsr()
    off.eliminate_zeros()
    scale = np.abs(np.concatenate(comm.allgather(coef)))
    row_off = np.abs(off).max(axis=1).toarray().ravel() if off.nnz else np.zeros(len(scale))
    if not np.any(row_off > DIAGONAL_TOL * scale):
        return Pivots(rows, piv, coef, _diagonal_rows(B, rows, piv, coef, r0), None)
    import scipy.sparse.linalg as spla  # only where used (first-answer time: docs/scale.md)

    lu = spla.splu(block.tocsc())
    keep = np.ones(n)
    keep[all_piv] = 0.0
    free = (A @ sp.diags(keep)).tocsr()
    free.eliminate_zeros()
    return Pivots(rows, piv, coef, _coupled_rows(lu, free, piv, mine, r0), Coupled(lu, mine, comm))


def _diagonal_rows(
    B: LocalRows, rows: np.ndarray, piv: np.ndarray, coef: np.ndarray, r0: int
) -> PivotRows:
    """Row p(j) of E per pivot (diagonal D): -B_j / c_j, -1 on the pivot, sorted."""
    out: PivotRows = {}
    for i, j in enumerate(rows):
        cols, vals = B.row(j)
        keep = (cols != piv[i]) & (vals != 0.0)
        c = np.append(cols[keep], piv[i])
        v = np.append(-vals[keep] / coef[i], -1.0)
        order = np.argsort(c)
        out[int(piv[i] - r0)] = (c[order], v[order])
    return out


def _coupled_rows(
    lu: spla.SuperLU, free: sp.csr_matrix, piv: np.ndarray, mine: slice, r0: int
) -> PivotRows:
    """Rows p(j) of E for this rank's pivots: -(B_AP^-1 B_AF)_j, -1 on the pivot."""
    used = np.unique(free.indices)
    m = free.shape[0]
    # Rows `mine` of B_AP^-1 are the columns `mine` of B_AP^-T.
    unit = np.zeros((m, len(piv)))
    unit[np.arange(mine.start, mine.stop), np.arange(len(piv))] = 1.0
    inv_rows = lu.solve(unit, trans="T").T if len(piv) else np.zeros((0, m))
    X = inv_rows @ free[:, used].toarray()
    out: PivotRows = {}
    for i in range(len(piv)):
        x = X[i]
        keep = np.abs(x) > DROP * max(float(np.abs(x).max(initial=0.0)), 1e-300)
        c = np.append(used[keep], piv[i])
        v = np.append(-x[keep], -1.0)
        order = np.argsort(c)
        out[int(piv[i] - r0)] = (c[order], v[order])
    return out
