"""The CSR kernels that build the condensed matrix (contactfx/linalg/elimination.py),
against scipy.sparse: the sum with coordinates, the pivots decoupled, the two blocks with
rows replaced."""

from __future__ import annotations

import gc

import numpy as np
import pytest
import scipy.sparse as sp
from mpi4py import MPI
from petsc4py import PETSc

from contactfx.linalg import elimination
from contactfx.linalg.elimination import (
    add_entries,
    assemble_blocks,
    condensed_matrix,
    decouple,
)


def _random_csr(
    rng: np.random.Generator, n: int, m: int, density: float, diagonal: bool = True
) -> sp.csr_matrix:
    """A random n x m CSR matrix, sorted columns, a fifth of its rows empty (but for the
    diagonal, with `diagonal`)."""
    a = sp.random(n, m, density=density, format="csr", random_state=rng)
    keep = np.ones(n)
    keep[rng.choice(n, n // 5, replace=False)] = 0.0
    a = (sp.diags(keep) @ a).tocsr()
    a.eliminate_zeros()
    if diagonal:
        a = (a + sp.eye(n, m, format="csr")).tocsr()
    a.sort_indices()
    return a


def _arrays(a: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return a.indptr.astype(np.int32), a.indices.astype(np.int32), a.data.copy()


def _dense(ptr: np.ndarray, cols: np.ndarray, vals: np.ndarray, m: int) -> np.ndarray:
    return sp.csr_matrix((vals, cols, ptr), shape=(len(ptr) - 1, m)).toarray()


def _pattern(ptr: np.ndarray, cols: np.ndarray, m: int) -> np.ndarray:
    return _dense(ptr, cols, np.ones(len(cols)), m) != 0


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("n_new", [0, 1, 40, 400])
def test_add_entries_is_the_sum(seed: int, n_new: int) -> None:
    """CSR + coordinates (repeats summed, rows and columns anywhere: inside the pattern,
    outside it, in empty rows) is scipy's sum; the pattern is the union, columns sorted."""
    rng = np.random.default_rng(seed)
    n, m = 60, 75
    a = _random_csr(rng, n, m, 0.08, diagonal=False)
    rows = rng.integers(0, n // 3, n_new)  # a few rows, many coordinates each
    cols = rng.integers(0, m, n_new)
    if n_new:
        rows[: n_new // 4] = rows[0]  # repeated coordinates
        cols[: n_new // 4] = cols[0]
    vals = rng.standard_normal(n_new)
    ptr, cj, cv = _arrays(a)
    before = (ptr.copy(), cj.copy(), cv.copy())
    p2, j2, v2 = add_entries(ptr, cj, cv, rows, cols, vals, m)
    for x, y in zip(before, (ptr, cj, cv), strict=True):
        assert np.array_equal(x, y)  # the inputs are left alone
    c = sp.coo_matrix((vals, (rows, cols)), shape=(n, m)).toarray()
    assert np.allclose(_dense(p2, j2, v2, m), a.toarray() + c, rtol=0, atol=1e-14)
    structural = a.toarray() != 0
    structural |= sp.coo_matrix((np.ones(n_new), (rows, cols)), shape=(n, m)).toarray() != 0
    assert np.array_equal(_pattern(p2, j2, m), structural)
    assert len(j2) == structural.sum()  # each entry once
    for r in range(n):
        assert np.all(np.diff(j2[p2[r] : p2[r + 1]]) > 0)
    assert p2.dtype == ptr.dtype and j2.dtype == cj.dtype


@pytest.mark.parametrize("seed", range(4))
def test_decouple_zeroes_pivot_rows_and_columns(seed: int) -> None:
    """The pivots' rows and columns zero, their own diagonal given; the rest unchanged
    (some rows of a symmetric matrix: the ones holding a pivot's column; pivots elsewhere
    too)."""
    rng = np.random.default_rng(seed)
    m = 80
    a = _random_csr(rng, m, m, 0.1)
    a = (a + a.T).tocsr()
    a.sort_indices()
    pivots = np.sort(rng.choice(m, 12, replace=False))
    dense = a.toarray()
    rows = np.flatnonzero((dense[:, pivots] != 0).any(axis=1))  # what the caller hands over
    local = a[rows].tocsr()
    own = rng.permutation(pivots[np.isin(pivots, rows[::2])])  # this rank's, in any order
    diag = rng.uniform(1.0, 2.0, len(own))
    ptr, cols, vals = _arrays(local)
    decouple(ptr, cols, vals, rows, pivots, own, diag)
    want = dense.copy()
    want[:, pivots] = 0.0
    want[own, :] = 0.0
    want[own, own] = diag
    assert np.array_equal(_dense(ptr, cols, vals, m), want[rows])
    assert len(own) > 0


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize(("c0", "c1"), [(0, 75), (20, 50), (0, 30), (40, 75)])
@pytest.mark.parametrize("n_rows", [0, 1, 9, 30])
@pytest.mark.parametrize("views", [False, True])
def test_assemble_blocks_rebuild_the_rows(
    seed: int, c0: int, c1: int, n_rows: int, views: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The diagonal block (columns made local) and the off-diagonal block (global columns)
    put back together are the rows given, with the rows `rows` replaced by `sub`'s
    (longer, shorter, empty, both blocks): the runs moved in place both ways, in chunks of
    3 entries (overlapping moves), or copied where the arrays are views."""
    monkeypatch.setattr(elimination, "_CHUNK", 3)
    rng = np.random.default_rng(seed + 10 * c0 + c1)
    n, m = 40, 75
    a = _random_csr(rng, n, m, 0.15, diagonal=False)
    rows = np.sort(rng.choice(n, n_rows, replace=False))
    sub = _random_csr(rng, n_rows, m, 0.3, diagonal=False)
    ptr, cols, vals = _arrays(a)
    if views:
        cols, vals = np.concatenate([cols, cols])[: len(cols)], np.tile(vals, 2)[: len(vals)]
    (dp, dj, dv), (op, oj, ov) = assemble_blocks(ptr, cols, vals, rows, _arrays(sub), c0, c1)
    for x in (dp, dj, op, oj):
        assert x.dtype == PETSc.IntType
    for p, j in ((dp, dj), (op, oj)):
        assert all(np.all(np.diff(j[p[r] : p[r + 1]]) > 0) for r in range(n))
    want = a.toarray()
    want[rows] = sub.toarray()
    diag = _dense(dp, dj, dv, c1 - c0)
    off = _dense(op, oj, ov, m)
    assert not off[:, c0:c1].any()
    off[:, c0:c1] = diag
    assert np.array_equal(off, want)
    assert len(dj) + len(oj) == (want != 0).sum()


def test_condensed_matrix_outlives_its_python_object() -> None:
    """PETSc holds the matrix's arrays (they are not copied): a KSP's operator stays valid
    after the Python object that built it is gone; with no pivots it is K."""
    n = 40
    k = sp.diags([-1.0, 4.0, -1.0], [-1, 0, 1], shape=(n, n), format="csr")
    K = PETSc.Mat().createAIJ(size=(n, n), csr=_arrays(k), comm=MPI.COMM_SELF)
    K.assemble()
    ksp = PETSc.KSP().create(MPI.COMM_SELF)
    A = condensed_matrix(K, {}, 0, np.zeros(0, np.int64), K.getDiagonal())
    ksp.setOperators(A)
    del A
    gc.collect()
    for _ in range(3):  # reuse the freed memory
        np.ones(10 * n).sum()
    x, y = K.createVecs()
    x.setRandom()
    ksp.getOperators()[0].mult(x, y)
    z = K.createVecLeft()
    K.mult(x, z)
    z.axpy(-1.0, y)
    assert z.norm() == 0.0
    ksp.destroy()
