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
from itertools import pairwise
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
    owners and added to K's rows there (`add_entries`, the union pattern), where the pivot
    rows and columns are decoupled (`decouple`); K's local rows (one copy) get these rows
    in place, as the diagonal and off-diagonal blocks PETSc takes as they are
    (`assemble_blocks`, MatCreateMPIAIJWithSplitArrays). PETSc's products E^T K cost passes
    over all rows that grew faster than the DOFs, and its MatAXPY with a different pattern
    rebuilds the matrix entry by entry (the two ways timed: benchmarks/README.md, "Building
    the condensed matrix").
    """
    mpi = K.getComm().tompi4py()
    i, j, v = coupling(K, prows, r0, mpi)
    ptr, cols, vals = (np.asarray(a) for a in K.getValuesCSR())
    # Zero entries on the pivots' rows and columns of K: every row a pivot touches is then
    # one of the rows handed over (the pivots of `piv` without an E row included).
    zi, zj = _pivot_pattern(ptr, cols, np.asarray(piv, np.int64), r0)
    i, j = np.concatenate([i, zi, zj]), np.concatenate([j, zj, zi])
    v = np.concatenate([v, np.zeros(2 * len(zi))])
    i, j, v = _to_owners(i, j, v, K.getOwnershipRanges(), mpi)
    # The few rows C touches: summed with K's there and decoupled, as a small CSR.
    rows = np.unique(i - r0)
    sub = _rows_of(ptr, cols, vals, rows)
    sub = add_entries(*sub, np.searchsorted(rows, i - r0), j, v, K.getSize()[1])
    ip: Any = np.asarray(piv, dtype=PETSc.IntType)
    every = np.concatenate(mpi.allgather(np.asarray(piv, dtype=np.int64)))
    decouple(*sub, rows + r0, every, ip, k_diag.getValues(ip))
    c0, c1 = K.getOwnershipRangeColumn()
    blocks = assemble_blocks(ptr, cols, vals, rows, sub, c0, c1)  # in cols' and vals' memory
    del ptr, cols, vals
    sizes: Any = K.getSizes()
    A = PETSc.Mat().createAIJWithArrays(sizes, cast(Any, blocks), comm=K.getComm())
    A.setBlockSize(2)
    # Symmetric positive definite: what a Cholesky factorization (MUMPS SYM=1) needs to know.
    A.setOption(cast(PETSc.Mat.Option, PETSc.Mat.Option.SPD), True)
    return A


Csr = tuple[np.ndarray, np.ndarray, np.ndarray]


def _pivot_pattern(
    ptr: np.ndarray, cols: np.ndarray, piv: np.ndarray, r0: int
) -> tuple[np.ndarray, np.ndarray]:
    """(p, c) for each pivot p of this rank and each column c of its row in K's local CSR."""
    local = piv - r0
    lengths = (ptr[local + 1] - ptr[local]).astype(np.int64)
    at = _segments(ptr[local].astype(np.int64), lengths)
    return np.repeat(piv, lengths), cols[at].astype(np.int64)


def _to_owners(
    i: np.ndarray, j: np.ndarray, v: np.ndarray, ranges: np.ndarray, comm: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each (row, column, value) sent to the rank owning its row; this rank's received."""
    owner = np.searchsorted(ranges, i, side="right") - 1
    order = np.argsort(owner, kind="stable")
    cuts = np.searchsorted(owner[order], np.arange(comm.size + 1))
    parts = [(i[order[a:b]], j[order[a:b]], v[order[a:b]]) for a, b in pairwise(cuts)]
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


def _rows_of(ptr: np.ndarray, cols: np.ndarray, vals: np.ndarray, rows: np.ndarray) -> Csr:
    """The CSR rows `rows` (sorted) of (ptr, cols, vals), copied."""
    lengths = (ptr[rows + 1] - ptr[rows]).astype(np.int64)
    at = _segments(ptr[rows].astype(np.int64), lengths)
    sub_ptr = np.concatenate([[0], np.cumsum(lengths)]).astype(ptr.dtype)
    return sub_ptr, cols[at], vals[at]


def decouple(
    ptr: np.ndarray,
    cols: np.ndarray,
    vals: np.ndarray,
    row_ids: np.ndarray,
    pivots: np.ndarray,
    own: np.ndarray,
    diag: np.ndarray,
) -> None:
    """Zero the pivots' rows and columns in place, diag on the diagonal of the rows `own`.

    row_ids: the global row of each CSR row; own: pivots among them, each with its diagonal
    in the pattern (diag: their values); pivots: every rank's. The rows given must hold
    every entry of these rows and columns (what C touches does, with the pivots' own rows).
    """
    lengths = np.diff(ptr).astype(np.int64)
    row_of = np.repeat(np.asarray(row_ids, np.int64), lengths)
    mine = np.isin(row_of, own)
    vals[mine | np.isin(cols, pivots)] = 0.0
    on_diag = np.flatnonzero(mine & (cols == row_of))
    order = np.argsort(own)
    sorted_own = np.asarray(own)[order]
    vals[on_diag] = np.asarray(diag)[order][np.searchsorted(sorted_own, row_of[on_diag])]


def assemble_blocks(
    ptr: np.ndarray,
    cols: np.ndarray,
    vals: np.ndarray,
    rows: np.ndarray,
    sub: Csr,
    c0: int,
    c1: int,
) -> tuple[Csr, Csr]:
    """The local CSR rows, rows `rows` replaced by `sub`'s, as diagonal and off-diagonal blocks.

    The diagonal block has the columns c0 <= c < c1 (made local), the other the rest (global
    columns), both PetscInt; `rows` is sorted. cols and vals (PetscInt, PetscScalar) are
    consumed: the diagonal block is built in their memory (resized, the runs of entries
    between the replaced rows and the off-diagonal ones moved in place), which maps no new
    pages but the growth: on fresh pages the faults cost as much as the copy
    (benchmarks/README.md, "Building the condensed matrix").
    """
    it = PETSc.IntType
    n, nnz = len(ptr) - 1, len(cols)
    rows = np.asarray(rows, np.int64)
    sp_, sc, sv = sub
    sub_len = np.diff(sp_).astype(np.int64)
    # Off-diagonal entries: K's outside the replaced rows, and the replacements'.
    off = np.flatnonzero((cols < c0) | (cols >= c1))
    off_row = np.searchsorted(ptr, off, side="right") - 1
    keep = ~_member(off_row, rows)
    off, off_row = off[keep], off_row[keep]
    sub_row = np.repeat(rows, sub_len)
    sub_off = (sc < c0) | (sc >= c1)
    o_row = np.concatenate([off_row, sub_row[sub_off]])
    order = np.argsort(o_row, kind="stable")  # each row from one source, columns sorted
    o_cols = np.concatenate([cols[off], sc[sub_off]])[order].astype(it)
    o_vals = np.concatenate([vals[off], sv[sub_off]])[order]
    o_count = np.bincount(o_row, minlength=n)
    counts = np.diff(ptr).astype(np.int64)
    counts[rows] = sub_len
    d_ptr = np.concatenate([[0], np.cumsum(counts - o_count)])
    # The runs of K's entries kept: between the replaced rows and the off-diagonal entries.
    starts = np.concatenate([ptr[rows].astype(np.int64), off])
    ends = np.concatenate([ptr[rows + 1].astype(np.int64), off + 1])
    order = np.argsort(starts, kind="stable")
    run_a = np.concatenate([[0], ends[order]])
    run_b = np.concatenate([starts[order], [nnz]])
    nonempty = run_b > run_a
    run_a, run_b = run_a[nonempty], run_b[nonempty]
    run_row = np.searchsorted(ptr, run_a, side="right") - 1
    before = np.searchsorted(off, run_a) - np.searchsorted(off, ptr[run_row])
    shift = d_ptr[run_row] - ptr[run_row] - before
    size = int(d_ptr[-1])
    d_cols = _resized(cols, max(size, nnz))
    d_vals = _resized(vals, max(size, nnz))
    for arr in (d_cols, d_vals):
        _move_runs(arr, run_a, run_b, shift)
    d_cols, d_vals = _resized(d_cols, size), _resized(d_vals, size)
    d_cols -= c0
    at = _segments(d_ptr[rows], sub_len - np.bincount(sub_row[sub_off], minlength=n)[rows])
    d_cols[at] = sc[~sub_off] - c0
    d_vals[at] = sv[~sub_off]
    o_ptr = np.concatenate([[0], np.cumsum(o_count)])
    return (d_ptr.astype(it), d_cols, d_vals), (o_ptr.astype(it), o_cols, o_vals)


# Entries moved at a time through one buffer (numpy's own, one per move: new pages).
_CHUNK = 1 << 18


def _resized(a: np.ndarray, size: int) -> np.ndarray:
    """The array with `size` entries, in place where numpy can (realloc), else copied."""
    try:
        a.resize(size, refcheck=False)
        return a
    except ValueError:  # a view or not its own memory
        out = np.empty(size, dtype=a.dtype)
        m = min(size, len(a))
        out[:m] = a[:m]
        return out


def _move_runs(a: np.ndarray, run_a: np.ndarray, run_b: np.ndarray, shift: np.ndarray) -> None:
    """a[x + s] = a[x] for each run [x0, x1) and its shift s, in place.

    The destinations keep the runs' order and do not overlap: runs moving right are moved
    from the last, the ones moving left from the first, each in chunks from its leading
    end (through a buffer), so no source is overwritten before it is read.
    """
    right = np.flatnonzero(shift > 0)[::-1]
    left = np.flatnonzero(shift < 0)
    buf = np.empty(min(_CHUNK, len(a)), dtype=a.dtype)
    for k in right.tolist():
        x0, x1, d = int(run_a[k]), int(run_b[k]), int(shift[k])
        for y in range(x1, x0, -_CHUNK):
            x = max(x0, y - _CHUNK)
            buf[: y - x] = a[x:y]
            a[x + d : y + d] = buf[: y - x]
    for k in left.tolist():
        x0, x1, d = int(run_a[k]), int(run_b[k]), int(shift[k])
        for x in range(x0, x1, _CHUNK):
            y = min(x1, x + _CHUNK)
            buf[: y - x] = a[x:y]
            a[x + d : y + d] = buf[: y - x]


def _member(x: np.ndarray, sorted_set: np.ndarray) -> np.ndarray:
    """Which entries of x are in sorted_set (sorted, unique)."""
    at = np.minimum(np.searchsorted(sorted_set, x), max(len(sorted_set) - 1, 0))
    return sorted_set[at] == x if len(sorted_set) else np.zeros(len(x), dtype=bool)


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
    """y = (W^T K T + P) x applied matrix-free (a petsc4py Python matrix context).

    T = I + E, W = I + G (G None: W = T); friction's slipping rows make W differ from T.
    """

    def __init__(
        self, K: PETSc.Mat, E: PETSc.Mat, d: PETSc.Vec, G: PETSc.Mat | None = None
    ) -> None:
        self._K, self._E, self._G, self._d = K, E, E if G is None else G, d
        self._w1, self._w2 = K.createVecRight(), K.createVecLeft()

    def mult(self, mat: PETSc.Mat, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """The product with x (the pivots' own diagonal added: they are decoupled)."""
        t_mult(self._E, x, self._w1)
        self._K.mult(self._w1, self._w2)
        t_mult_transpose(self._G, self._w2, y)
        self._w1.pointwiseMult(self._d, x)
        y.axpy(1.0, self._w1)

    def destroy(self, mat: PETSc.Mat) -> None:
        """Free the work vectors with the shell matrix."""
        self._w1.destroy()
        self._w2.destroy()
