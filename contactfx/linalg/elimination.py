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
    summed here from the pivots' rows of K as coordinates (`coupling`), sent to the rows'
    owners and inserted into a copy of K's local rows (`add_entries`, the union pattern); the
    pivot rows and columns are decoupled there (`decouple`), and the diagonal and
    off-diagonal blocks are handed to PETSc as they are (`split_blocks`). PETSc's products
    E^T K cost passes over all rows that grew faster than the DOFs, and its MatAXPY with a
    different pattern rebuilds the matrix entry by entry: several times slower at millions
    of DOFs (benchmarks/README.md, "Building the condensed matrix").
    """
    mpi = K.getComm().tompi4py()
    i, j, v = coupling(K, prows, r0, mpi)
    # Zero entries on the pivots' rows and columns of K: every row a pivot touches is then
    # one of the rows handed over (the pivots of `piv` without an E row included).
    zi, zj = _pivot_pattern(K, piv)
    i, j = np.concatenate([i, zi, zj]), np.concatenate([j, zj, zi])
    v = np.concatenate([v, np.zeros(2 * len(zi))])
    i, j, v = _to_owners(i, j, v, K.getOwnershipRanges(), mpi)
    ptr, cols, vals = (np.asarray(a) for a in K.getValuesCSR())
    n_global = K.getSize()[1]
    ptr, cols, vals = add_entries(ptr, cols, vals, i - r0, j, v, n_global)
    every = np.concatenate(mpi.allgather(np.asarray(piv, dtype=np.int64)))
    ip: Any = np.asarray(piv, dtype=PETSc.IntType)
    decouple(ptr, cols, vals, np.unique(i - r0), r0, every, ip - r0, k_diag.getValues(ip))
    c0, c1 = K.getOwnershipRangeColumn()
    A = PETSc.Mat().createAIJWithArrays(
        cast(Any, K.getSizes()), cast(Any, split_blocks(ptr, cols, vals, c0, c1)), comm=K.getComm()
    )
    A.setBlockSize(2)
    # Symmetric positive definite: what a Cholesky factorization (MUMPS SYM=1) needs to know.
    A.setOption(cast(PETSc.Mat.Option, PETSc.Mat.Option.SPD), True)
    return A


Csr = tuple[np.ndarray, np.ndarray, np.ndarray]


def _pivot_pattern(K: PETSc.Mat, piv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(p, c) for each pivot p of this rank and each column c of K's row p."""
    rows = [K.getRow(int(p))[0] for p in piv]
    if not rows:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    lengths = [len(r) for r in rows]
    return np.repeat(np.asarray(piv, np.int64), lengths), np.concatenate(rows).astype(np.int64)


def _to_owners(
    i: np.ndarray, j: np.ndarray, v: np.ndarray, ranges: np.ndarray, comm: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each (row, column, value) sent to the rank owning its row; this rank's received."""
    owner = np.searchsorted(ranges, i, side="right") - 1
    order = np.argsort(owner, kind="stable")
    cuts = np.searchsorted(owner[order], np.arange(comm.size + 1))
    parts = [
        (i[order[a:b]], j[order[a:b]], v[order[a:b]]) for a, b in zip(cuts, cuts[1:], strict=False)
    ]
    got = comm.alltoall(parts)
    return tuple(np.concatenate([g[k] for g in got]) for k in range(3))  # type: ignore[return-value]


def add_entries(
    ptr: np.ndarray,
    cols: np.ndarray,
    vals: np.ndarray,
    rows: np.ndarray,
    new_cols: np.ndarray,
    new_vals: np.ndarray,
    n_cols: int,
) -> Csr:
    """The CSR rows (ptr, cols, vals) plus the coordinates (rows, new_cols, new_vals).

    Columns sorted in each row (as given and as returned); repeated coordinates are summed;
    the pattern is the union. Coordinates already in the pattern are added into the values;
    the others are inserted in one pass over the arrays (`np.insert`), so the cost is a copy
    of the arrays however few rows the coordinates touch.
    """
    if len(rows) == 0:
        return ptr.copy(), cols.copy(), vals.copy()
    keys, where = np.unique(
        rows.astype(np.int64) * n_cols + new_cols.astype(np.int64), return_inverse=True
    )
    sums = np.bincount(where.ravel(), weights=new_vals, minlength=len(keys))
    key_rows = keys // n_cols
    # The touched rows' entries as keys (ascending: rows ascending, columns sorted).
    touched = np.unique(key_rows)
    lengths = (ptr[touched + 1] - ptr[touched]).astype(np.int64)
    at = _segments(ptr[touched].astype(np.int64), lengths)
    old_keys = np.repeat(touched, lengths) * n_cols + cols[at]
    pos = np.searchsorted(old_keys, keys)
    found = pos < len(old_keys)
    found[found] = old_keys[pos[found]] == keys[found]
    new = ~found
    # An absent key goes before the first larger column of its row (or at the row's end).
    row_start = np.searchsorted(old_keys, key_rows[new] * n_cols)
    put = ptr[key_rows[new]] + (pos[new] - row_start)
    out_cols = np.insert(cols, put, (keys[new] % n_cols).astype(cols.dtype))
    out_vals = np.insert(vals, put, sums[new])
    old_at = at[pos[found]]
    out_vals[old_at + np.searchsorted(put, old_at, side="right")] += sums[found]
    counts = np.bincount(key_rows[new], minlength=len(ptr) - 1)
    out_ptr = ptr + np.concatenate([[0], np.cumsum(counts)]).astype(ptr.dtype)
    return out_ptr, out_cols, out_vals


def _segments(starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """The positions start, start + 1, ..., start + length - 1 of each segment, in order."""
    offsets = np.cumsum(lengths) - lengths
    return np.repeat(starts - offsets, lengths) + np.arange(int(lengths.sum()))


def decouple(
    ptr: np.ndarray,
    cols: np.ndarray,
    vals: np.ndarray,
    rows: np.ndarray,
    r0: int,
    pivots: np.ndarray,
    mine: np.ndarray,
    diag: np.ndarray,
) -> None:
    """Zero the pivots' rows and columns in place; diag on the diagonal of the local rows
    `mine` (this rank's pivots, each with its diagonal in the pattern).

    Only the local `rows` (and `mine`) are looked at: they must hold every entry of a
    pivot's row or column (all of C's rows do, with the pivots' own rows of K).
    """
    rows = np.union1d(rows, mine).astype(np.int64)
    lengths = (ptr[rows + 1] - ptr[rows]).astype(np.int64)
    at = _segments(ptr[rows].astype(np.int64), lengths)
    row_of = np.repeat(rows, lengths)
    own = np.isin(row_of, mine)
    vals[at[own | np.isin(cols[at], pivots)]] = 0.0
    on_diag = own & (cols[at] == row_of + r0)
    order = np.argsort(mine)
    vals[at[on_diag]] = diag[order][np.searchsorted(mine[order], row_of[on_diag])]


def split_blocks(
    ptr: np.ndarray, cols: np.ndarray, vals: np.ndarray, c0: int, c1: int
) -> tuple[Csr, Csr]:
    """The diagonal block (columns c0 <= c < c1, made local) and the rest (global columns)."""
    it = PETSc.IntType
    off = np.flatnonzero((cols < c0) | (cols >= c1))
    off_rows = np.searchsorted(ptr, off, side="right") - 1
    n_off = np.concatenate([[0], np.cumsum(np.bincount(off_rows, minlength=len(ptr) - 1))])
    diag = (
        (ptr - n_off).astype(it),
        np.subtract(np.delete(cols, off), c0, dtype=it),
        np.delete(vals, off),
    )
    return diag, (n_off.astype(it), cols[off].astype(it), vals[off])


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
