"""contact.sparse.CSR against scipy.sparse (the container it replaces on the solve path).

Reference: scipy.sparse on the same entries. Products sum in scipy's order: equal up to the
rounding of one sum (bit for bit unless scipy's kernels fuse multiply-adds), checked against a
bound of a few ulps of the sum of |terms|; duplicates of one entry may be summed in another
order than scipy's (its per-row sort is not stable), so the values built from duplicates are
compared to a few ulps too.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from contactfx.contact.sparse import CSR


def random_coo(
    seed: int, m: int = 23, n: int = 41, k: int = 400
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """k entries with many duplicates and a few exact zeros, rows and columns unordered."""
    rng = np.random.default_rng(seed)
    r = rng.integers(0, m, k)
    c = rng.integers(0, n, k)
    v = rng.standard_normal(k)
    v[rng.random(k) < 0.05] = 0.0
    return r, c, v


def reference(r: np.ndarray, c: np.ndarray, v: np.ndarray, shape: tuple[int, int]) -> sp.csr_matrix:
    """scipy's canonical CSR of the entries (duplicates summed, zeros dropped)."""
    out = sp.coo_matrix((v, (r, c)), shape=shape).tocsr()
    out.sum_duplicates()
    out.eliminate_zeros()
    return out


@pytest.mark.parametrize("seed", range(5))
def test_from_coo_is_scipys_canonical_matrix(seed: int) -> None:
    r, c, v = random_coo(seed)
    a = CSR.from_coo(r, c, v, (23, 41), drop_zeros=True)
    ref = reference(r, c, v, (23, 41))
    np.testing.assert_array_equal(a.indptr, ref.indptr)
    np.testing.assert_array_equal(a.indices, ref.indices)
    np.testing.assert_allclose(a.data, ref.data, rtol=1e-14, atol=1e-15)
    kept = CSR.from_coo(r, c, v, (23, 41))  # zeros kept: every distinct position stored
    assert kept.nnz == len(np.unique(r * 41 + c))


def test_entries_in_input_order_without_duplicates_are_exact() -> None:
    r, c, v = random_coo(7)
    _, first = np.unique(r * 41 + c, return_index=True)
    r, c, v = r[first], c[first], v[first]
    a = CSR.from_coo(r, c, v, (23, 41), drop_zeros=True)
    np.testing.assert_array_equal(a.data, reference(r, c, v, (23, 41)).data)


def assert_same_sums(got: np.ndarray, want: np.ndarray, magnitude: np.ndarray) -> None:
    """Equal up to the rounding of either sum: a few ulps of the sum of |terms|.

    Bit for bit where scipy's compiled kernels keep separate multiplies and adds; a kernel
    built with fused multiply-adds rounds each term once less, which this bound allows.
    """
    assert np.all(np.abs(got - want) <= 4 * np.finfo(float).eps * magnitude)


@pytest.mark.parametrize("seed", range(3))
def test_products_equal_scipys(seed: int) -> None:
    r, c, v = random_coo(seed)
    a = CSR.from_coo(r, c, v, (23, 41), drop_zeros=True)
    s = a.to_scipy()
    size = abs(s)
    rng = np.random.default_rng(100 + seed)
    x, y, X = rng.standard_normal(41), rng.standard_normal(23), rng.standard_normal((41, 3))
    assert_same_sums(a @ x, s @ x, size @ np.abs(x))
    assert_same_sums(a.transpose_matmul(y), s.T @ y, size.T @ np.abs(y))
    assert_same_sums(a @ X, s @ X, size @ np.abs(X))
    r2, c2, v2 = random_coo(seed + 50, m=41, n=4, k=60)
    b = CSR.from_coo(r2, c2, v2, (41, 4), drop_zeros=True)
    want = (s @ b.to_scipy()).toarray()
    assert_same_sums(a.dense_product(b), want, (size @ abs(b.to_scipy())).toarray())
    with pytest.raises(ValueError, match="transpose_matmul"):
        a.transpose_matmul(x)


def test_selections_are_scipys() -> None:
    r, c, v = random_coo(3)
    a = CSR.from_coo(r, c, v, (23, 41), drop_zeros=True)
    s = a.to_scipy()
    idx = np.array([5, 0, 22, 5, 11])
    np.testing.assert_array_equal(a.rows(idx).toarray(), s[idx].toarray())
    assert a.rows(np.zeros(0, dtype=np.int64)).shape == (0, 41)
    np.testing.assert_array_equal(a.columns(10, 30).toarray(), s[:, 10:30].toarray())
    drop = np.zeros(41, dtype=bool)
    drop[::3] = True
    masked = a.without_columns(drop)
    expect = s.toarray()
    expect[:, drop] = 0.0
    np.testing.assert_array_equal(masked.toarray(), expect)
    assert not np.any(drop[masked.indices]) and np.all(masked.data != 0.0)
    np.testing.assert_array_equal(a.row_max_abs(), np.abs(s.toarray()).max(axis=1))
    both = CSR.vstack([a, a.rows(idx)])
    np.testing.assert_array_equal(both.toarray(), sp.vstack([s, s[idx]]).toarray())


def test_bad_shapes_are_refused() -> None:
    with pytest.raises(ValueError, match="outside the shape"):
        CSR.from_coo(np.array([3]), np.array([0]), np.array([1.0]), (3, 2))
    a = CSR.from_coo(np.array([0]), np.array([1]), np.array([1.0]), (1, 2))
    with pytest.raises(ValueError, match="matmul"):
        a @ np.ones(3)
    with pytest.raises(ValueError, match="vstack"):
        CSR.vstack([a, CSR.from_coo(np.array([0]), np.array([0]), np.array([1.0]), (1, 3))])
