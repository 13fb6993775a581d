"""A small compressed-row matrix for the contact operators, without scipy.sparse.

The contact operators, the pair views and the load-path check need a handful of operations
(build from point contributions with duplicates summed, row selection, column slices and
masks, products with vectors and with a narrow sparse matrix, transposed products, stacking);
holding them in numpy arrays keeps `import scipy.sparse` (most of it scipy's own import-time
work) off a plain solve (docs/scale.md, "Time to the first answer"). `to_scipy()` gives the
same matrix to scipy (the tests' reference). The sums run in the order scipy's kernels use
(entries of a row in column order, rows in order), so products equal scipy's up to its
kernels' rounding (bit for bit where they keep separate multiplies and adds); duplicates of
one entry may be summed in another order.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import scipy.sparse as sp


@dataclass(frozen=True, eq=False)
class CSR:
    """Compressed sparse rows: row i holds indices[indptr[i]:indptr[i+1]] (sorted, unique)."""

    indptr: np.ndarray  # (m + 1,) int64
    indices: np.ndarray  # (nnz,) int64, increasing within each row
    data: np.ndarray  # (nnz,) float64
    shape: tuple[int, int]

    @classmethod
    def from_coo(
        cls,
        rows: np.ndarray,
        cols: np.ndarray,
        vals: np.ndarray,
        shape: tuple[int, int],
        drop_zeros: bool = False,
    ) -> CSR:
        """Entries (rows, cols, vals), duplicates summed; exact zeros dropped if asked."""
        r = np.asarray(rows, dtype=np.int64).ravel()
        c = np.asarray(cols, dtype=np.int64).ravel()
        v = np.asarray(vals, dtype=np.float64).ravel()
        m, n = int(shape[0]), int(shape[1])
        if r.size and (r.min() < 0 or r.max() >= m or c.min() < 0 or c.max() >= n):
            raise ValueError(f"an entry lies outside the shape {(m, n)}")
        key = r * n + c  # row-major position: m n < 2^63 for any mesh that fits in memory
        order = np.argsort(key, kind="stable")  # duplicates keep their input order
        key, v = key[order], v[order]
        if key.size:
            new = np.empty(key.size, dtype=bool)
            new[0] = True
            np.not_equal(key[1:], key[:-1], out=new[1:])
            starts = np.flatnonzero(new)
            if starts.size < key.size:
                v = np.add.reduceat(v, starts)
                key = key[starts]
        r, c = np.divmod(key, n)
        if drop_zeros:
            nz = v != 0.0
            r, c, v = r[nz], c[nz], v[nz]
        indptr = np.zeros(m + 1, dtype=np.int64)
        np.cumsum(np.bincount(r, minlength=m), out=indptr[1:])
        return cls(indptr, c, v, (m, n))

    @classmethod
    def vstack(cls, blocks: list[CSR]) -> CSR:
        """The blocks one below the other (all with the same number of columns)."""
        n = blocks[0].shape[1]
        if any(b.shape[1] != n for b in blocks):
            raise ValueError("vstack: blocks with different numbers of columns")
        offsets = np.cumsum([0] + [b.nnz for b in blocks[:-1]])
        indptr = np.concatenate(
            [np.zeros(1, dtype=np.int64)]
            + [b.indptr[1:] + o for b, o in zip(blocks, offsets, strict=True)]
        )
        return cls(
            indptr,
            np.concatenate([b.indices for b in blocks]),
            np.concatenate([b.data for b in blocks]),
            (sum(b.shape[0] for b in blocks), n),
        )

    @property
    def nnz(self) -> int:
        """Number of stored entries."""
        return int(self.indices.size)

    @cached_property
    def entry_rows(self) -> np.ndarray:
        """The row of each stored entry (computed once; do not modify)."""
        return np.repeat(np.arange(self.shape[0], dtype=np.int64), np.diff(self.indptr))

    def _select(self, keep: np.ndarray) -> CSR:
        """The matrix with the stored entries where `keep` (one bool per entry)."""
        indptr = np.zeros_like(self.indptr)
        np.cumsum(np.bincount(self.entry_rows[keep], minlength=self.shape[0]), out=indptr[1:])
        return CSR(indptr, self.indices[keep], self.data[keep], self.shape)

    def rows(self, idx: np.ndarray) -> CSR:
        """The rows `idx` (any order, repeats allowed), as a new matrix."""
        idx = np.asarray(idx, dtype=np.int64).ravel()
        start, count = self.indptr[idx], np.diff(self.indptr)[idx]
        indptr = np.zeros(idx.size + 1, dtype=np.int64)
        np.cumsum(count, out=indptr[1:])
        take = np.repeat(start - indptr[:-1], count) + np.arange(indptr[-1], dtype=np.int64)
        return CSR(indptr, self.indices[take], self.data[take], (idx.size, self.shape[1]))

    def columns(self, lo: int, hi: int) -> CSR:
        """The columns lo..hi-1, renumbered from 0."""
        keep = (self.indices >= lo) & (self.indices < hi)
        out = self._select(keep)
        return CSR(out.indptr, out.indices - lo, out.data, (self.shape[0], hi - lo))

    def without_columns(self, drop: np.ndarray) -> CSR:
        """Entries in the columns where `drop` (bool, one per column) and exact zeros left out."""
        return self._select(~drop[self.indices] & (self.data != 0.0))

    def transpose_matmul(self, y: np.ndarray) -> np.ndarray:
        """A^T @ y for a dense vector (m,), each column's sum in row order (as scipy's)."""
        y = np.asarray(y)
        if y.shape != (self.shape[0],):
            raise ValueError(f"transpose_matmul: shape {self.shape} against {y.shape}")
        w = self.data * y[self.entry_rows]
        return np.bincount(self.indices, weights=w, minlength=self.shape[1])

    def row_max_abs(self) -> np.ndarray:
        """max_j |A_ij| of every row (0 for an empty row)."""
        out = np.zeros(self.shape[0])
        np.maximum.at(out, self.entry_rows, np.abs(self.data))
        return out

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        """A @ x for a dense vector (n,) or dense block (n, k)."""
        x = np.asarray(x)
        if x.shape[0] != self.shape[1]:
            raise ValueError(f"matmul: shape {self.shape} against {x.shape}")
        r = self.entry_rows
        if x.ndim == 1:
            return np.bincount(r, weights=self.data * x[self.indices], minlength=self.shape[0])
        out = np.zeros((self.shape[0], *x.shape[1:]), dtype=np.result_type(self.data, x))
        np.add.at(out, r, self.data[:, None] * x[self.indices])
        return out

    def dense_product(self, other: CSR) -> np.ndarray:
        """A @ B as a dense (m, k) array, for a B with few columns."""
        if other.shape[0] != self.shape[1]:
            raise ValueError(f"product: shape {self.shape} against {other.shape}")
        count = np.diff(other.indptr)[self.indices]  # B's entries met by each entry of A
        left = np.repeat(np.arange(self.nnz, dtype=np.int64), count)
        first = np.cumsum(count) - count
        right = np.repeat(other.indptr[self.indices] - first, count) + np.arange(
            left.size, dtype=np.int64
        )
        out = np.zeros((self.shape[0], other.shape[1]))
        np.add.at(
            out,
            (self.entry_rows[left], other.indices[right]),
            self.data[left] * other.data[right],
        )
        return out

    def toarray(self) -> np.ndarray:
        """The dense (m, n) array."""
        out = np.zeros(self.shape)
        out[self.entry_rows, self.indices] = self.data
        return out

    def to_scipy(self) -> sp.csr_matrix:
        """The same matrix as scipy.sparse (imported here: only the paths that need it)."""
        import scipy.sparse as sp

        return sp.csr_matrix((self.data, self.indices, self.indptr), shape=self.shape)
