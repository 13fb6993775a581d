"""The elimination of the active multipliers with a diagonal D: pivots, T, and T^T K T.

With a diagonal D (NTS, or mortar with the dual basis) each active row j of B touches one
active node's own dofs only, so one of them, the pivot p(j) (the component with the largest
coefficient c_j), is given by the constraint: u_p = -(g_j + sum_{k != p} B_jk u_k) / c_j.
Writing u = T v + t (T the identity except on pivot rows, t = -g_j / c_j there) turns the
saddle point into the symmetric positive definite displacement system

    (T^T K T + P) v = T^T (f - K t),    P = diag(K_pp) on the pivots (v_p is free: set 0),

and the multipliers follow from the pivot rows of equilibrium, mu_j = (f - K u)_p / c_j.
Every function here takes what it needs explicitly (B's local CSR rows, the node dofs).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..errors import EliminationError

# Entries of B on another active node's dofs larger than this (relative to the row's pivot)
# mean D is not diagonal: the elimination would couple the pivots.
DIAGONAL_TOL = 1e-10

PivotRows = dict[int, tuple[np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class LocalRows:
    """This rank's rows of B in CSR form, and the two dofs of each row's active node."""

    indptr: np.ndarray
    cols: np.ndarray
    vals: np.ndarray
    node_dofs: np.ndarray  # (m, 2) global dofs of each row's active node

    @classmethod
    def of(cls, B: PETSc.Mat, node_dofs: np.ndarray) -> LocalRows:
        """B's local rows and the node dofs (m, 2)."""
        indptr, cols, vals = B.getValuesCSR()
        return cls(indptr, cols, vals, np.asarray(node_dofs, dtype=np.int64).reshape(-1, 2))

    def row(self, j: int | np.integer) -> tuple[np.ndarray, np.ndarray]:
        """(columns, values) of local row j."""
        lo, hi = self.indptr[j], self.indptr[j + 1]
        return self.cols[lo:hi], self.vals[lo:hi]


def pivots(
    B: LocalRows, active: np.ndarray, comm: MPI.Comm
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(owned active rows, their pivot dofs, the pivot coefficients).

    EliminationError on every rank if a row has no free dof of its own node or D is not
    diagonal (it carries that row's node dofs; the linear algebra knows no pairs).
    """
    rows = np.flatnonzero(active)
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
    _raise_first(
        comm,
        bad,
        "prescribed",
        "the condensed solver cannot eliminate a contact row whose active node is fully "
        "prescribed: use --solver mumps",
    )
    # Every active node's dofs, from all ranks: a row touching another one means that D is
    # not diagonal.
    others = np.concatenate(comm.allgather(B.node_dofs[rows].ravel()))
    for i, j in enumerate(rows):
        cols, vals = B.row(j)
        foreign = np.isin(cols, others) & ~np.isin(cols, B.node_dofs[j])
        if foreign.any() and np.abs(vals[foreign]).max() > DIAGONAL_TOL * abs(coef[i]):
            bad = bad or (int(B.node_dofs[j, 0]), int(B.node_dofs[j, 1]))
    _raise_first(
        comm,
        bad,
        "not_diagonal",
        "the condensed solver needs a diagonal D (one active node per constraint row): use "
        "--method nts, or mortar with --basis dual (on a flat passive surface), or --solver mumps",
    )
    return rows, piv, coef


def _raise_first(comm: MPI.Comm, bad: tuple[int, int] | None, reason: str, text: str) -> None:
    """Raise EliminationError on every rank if any rank found a bad row (the smallest dofs)."""
    found = [b for b in comm.allgather(bad) if b is not None]
    if found:
        raise EliminationError(text, min(found), reason)


def pivot_rows(
    B: LocalRows, rows: np.ndarray, piv: np.ndarray, coef: np.ndarray, r0: int
) -> PivotRows:
    """Row p(j) of E = T - I per pivot (by local row): -B_j / c_j, -1 on the pivot, sorted."""
    out: PivotRows = {}
    for i, j in enumerate(rows):
        cols, vals = B.row(j)
        keep = (cols != piv[i]) & (vals != 0.0)
        c = np.append(cols[keep], piv[i])
        v = np.append(-vals[keep] / coef[i], -1.0)
        order = np.argsort(c)
        out[int(piv[i] - r0)] = (c[order], v[order])
    return out


def elimination_matrix(
    prows: PivotRows, r0: int, r1: int, n_global: int, comm: PETSc.Comm, identity: bool
) -> PETSc.Mat:
    """T (identity=True: I off the pivot rows, 0 on the pivot itself) or E = T - I."""
    n = r1 - r0
    counts = np.full(n, 1 if identity else 0, dtype=np.int64)
    for r, (c, _) in prows.items():
        counts[r] = len(c)
    indptr = np.concatenate([[0], np.cumsum(counts)])
    cols = np.arange(r0, r1, dtype=np.int64).repeat(counts)
    vals = np.ones(indptr[-1])
    for r, (c, v) in prows.items():
        seg = slice(indptr[r], indptr[r + 1])
        cols[seg] = c
        vals[seg] = v + (c == r0 + r) if identity else v
    csr: Any = (
        indptr.astype(PETSc.IntType),
        cols.astype(PETSc.IntType),
        vals.astype(PETSc.ScalarType),
    )
    M = PETSc.Mat().createAIJ(size=((n, n_global), (n, n_global)), csr=csr, comm=comm)
    M.assemble()
    return M


def condensed_matrix(K: PETSc.Mat, E: PETSc.Mat, piv: np.ndarray, k_diag: PETSc.Vec) -> PETSc.Mat:
    """T^T K T + P = K + E^T K + K E + E^T K E (E = T - I, nonzero on pivot rows only).

    A general PtAP costs several passes over K and leaves the pivot rows without a diagonal
    (inserting one reallocates the matrix, once per row). Here E^T K is a few rows of K (the
    pivots' neighbourhoods); only the final sum passes over K once.
    """
    ip: Any = piv.astype(PETSc.IntType)
    diff = cast(Any, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    Et = E.transpose(PETSc.Mat())  # without `out` petsc4py transposes in place
    EtK = Et.matMult(K)
    C = EtK.transpose(PETSc.Mat())  # K E (K is symmetric)
    C.axpy(1.0, EtK, structure=diff)
    EtKE = EtK.matMult(E)
    C.axpy(1.0, EtKE, structure=diff)
    A = K.copy()
    A.axpy(1.0, C, structure=diff)
    # Round-off leaves ~1e-16 on the pivot rows and columns: zero them, with K_pp on the
    # diagonal (the decoupled v_p = 0).
    A.zeroRowsColumns(ip, diag=1.0)
    diag = A.getDiagonal()
    diag.setValues(ip, cast(Any, k_diag.getValues(ip)))
    diag.assemble()
    A.setDiagonal(diag)
    A.setBlockSize(2)
    for obj in (Et, EtK, C, EtKE, diag):
        obj.destroy()
    return A


class CondensedOperator:
    """y = (T^T K T + P) x applied matrix-free (a petsc4py Python matrix context)."""

    def __init__(self, K: PETSc.Mat, T: PETSc.Mat, d: PETSc.Vec) -> None:
        self._K, self._T, self._d = K, T, d
        self._w1, self._w2 = K.createVecRight(), K.createVecLeft()

    def mult(self, mat: PETSc.Mat, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """The product with x (the pivots' own diagonal added: they are decoupled)."""
        self._T.mult(x, self._w1)
        self._K.mult(self._w1, self._w2)
        self._T.multTranspose(self._w2, y)
        self._w1.pointwiseMult(self._d, x)
        y.axpy(1.0, self._w1)
