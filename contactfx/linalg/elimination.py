"""The elimination of the active multipliers: T, E = T - I, and T^T K T.

Each active row j of B gives one displacement of its own node, the pivot p(j)
(linalg/pivots.py): with a diagonal pivot block u_p = -(g_j + sum_{k != p} B_jk u_k) / c_j.
Writing u = T v + t (T the identity except on pivot rows) turns the saddle point into the
symmetric positive definite displacement system

    (T^T K T + P) v = T^T (f - K t),    P = diag(K_pp) on the pivots (v_p is free: set 0),

and the multipliers follow from the pivot rows of equilibrium. Every function here takes
what it needs explicitly (B's local CSR rows, E's pivot rows).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from petsc4py import PETSc

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


def condensed_matrix(
    K: PETSc.Mat, prows: PivotRows, r0: int, piv: np.ndarray, k_diag: PETSc.Vec
) -> PETSc.Mat:
    """T^T K T + P = K + C, C = E^T K + K E + E^T K E (E = T - I: this rank's `prows`).

    E is nonzero on the pivot rows only, so C touches the pivots' neighbourhoods: it is
    summed here from the pivots' rows of K as coordinates (`coupling`) and added to K in
    one pass, into a new matrix (K itself is kept; the union pattern is allocated once).
    PETSc's products E^T K and their transposes cost passes over all rows, which grew
    faster than the DOFs (docs/scale.md, "The condensed matrix").
    """
    comm = K.getComm()
    i, j, v = coupling(K, prows, r0, comm.tompi4py())
    A = PETSc.Mat().create(comm)
    A.setSizes(cast(Any, K.getSizes()))
    A.setType(PETSc.Mat.Type.AIJ)
    A.setPreallocationCOO(cast(Any, i.astype(PETSc.IntType)), cast(Any, j.astype(PETSc.IntType)))
    A.setValuesCOO(cast(Any, v.astype(PETSc.ScalarType)), cast(Any, PETSc.InsertMode.ADD_VALUES))
    A.assemble()
    A.axpy(1.0, K, structure=cast(Any, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN))
    # Round-off leaves ~1e-16 on the pivot rows and columns: zero them, with K_pp on the
    # diagonal (the decoupled v_p = 0).
    ip: Any = piv.astype(PETSc.IntType)
    A.zeroRowsColumns(ip, diag=1.0)
    diag = A.getDiagonal()
    diag.setValues(ip, cast(Any, k_diag.getValues(ip)))
    diag.assemble()
    A.setDiagonal(diag)
    diag.destroy()
    A.setBlockSize(2)
    # Symmetric positive definite: what a Cholesky factorization (MUMPS SYM=1) needs to know.
    A.setOption(cast(PETSc.Mat.Option, PETSc.Mat.Option.SPD), True)
    return A


def coupling(
    K: PETSc.Mat, prows: PivotRows, r0: int, comm: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """C = E^T K + K E + E^T K E as global coordinates (duplicates to be summed).

    With K symmetric, (E^T K)[c, :] sums E[p, c] K[p, :] over the pivots p and K E is its
    transpose; E^T K E needs, for each pivot column of a pivot's row of K, that pivot's row
    of E, which may live on another rank: the pivot rows of E are gathered (a few per
    contact node).
    """
    every = [
        e for part in comm.allgather([(r0 + r, c, v) for r, (c, v) in prows.items()]) for e in part
    ]
    e_rows = {int(p): (c, v) for p, c, v in every}
    pivot_ids = np.fromiter(e_rows, dtype=np.int64, count=len(e_rows))
    ii: list[np.ndarray] = []
    jj: list[np.ndarray] = []
    vv: list[np.ndarray] = []
    for r, (c, v) in prows.items():
        kc, kv = K.getRow(r0 + r)
        kc = np.asarray(kc, dtype=np.int64)
        kv = np.asarray(kv, dtype=float)
        etk = np.outer(v, kv).ravel()  # row c, column kc: (E^T K)
        rows, cols = np.repeat(c, len(kc)), np.tile(kc, len(c))
        ii += [rows, cols]
        jj += [cols, rows]
        vv += [etk, etk]
        # K[p, q] couples two pivots (a few of a row's columns): (E^T K E)[c, c_q].
        hit = np.isin(kc, pivot_ids)
        for q, kq in zip(kc[hit], kv[hit], strict=True):
            cq, vq = e_rows[int(q)]
            ii.append(np.repeat(c, len(cq)))
            jj.append(np.tile(cq, len(c)))
            vv.append(np.outer(v, kq * vq).ravel())
    if not ii:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    return np.concatenate(ii), np.concatenate(jj), np.concatenate(vv)


def t_mult(E: PETSc.Mat, x: PETSc.Vec, y: PETSc.Vec) -> None:
    """Set y = T x = x + E x, without an assembled T (its identity part costs a row per dof)."""
    E.mult(x, y)
    y.axpy(1.0, x)


def t_mult_transpose(E: PETSc.Mat, x: PETSc.Vec, y: PETSc.Vec) -> None:
    """Set y = T^T x = x + E^T x."""
    E.multTranspose(x, y)
    y.axpy(1.0, x)


class CondensedOperator:
    """y = (T^T K T + P) x applied matrix-free, T = I + E (a petsc4py Python matrix context)."""

    def __init__(self, K: PETSc.Mat, E: PETSc.Mat, d: PETSc.Vec) -> None:
        self._K, self._E, self._d = K, E, d
        self._w1, self._w2 = K.createVecRight(), K.createVecLeft()

    def mult(self, mat: PETSc.Mat, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """The product with x (the pivots' own diagonal added: they are decoupled)."""
        t_mult(self._E, x, self._w1)
        self._K.mult(self._w1, self._w2)
        t_mult_transpose(self._E, self._w2, y)
        self._w1.pointwiseMult(self._d, x)
        y.axpy(1.0, self._w1)

    def destroy(self, mat: PETSc.Mat) -> None:
        """Free the work vectors with the shell matrix."""
        self._w1.destroy()
        self._w2.destroy()
