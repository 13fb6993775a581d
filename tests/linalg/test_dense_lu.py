"""linalg.capacitance.DenseLU: numpy's solve for small capacitance systems, scipy's kept LU above.

Reference: a constructed solution x (b = A x) and scipy.linalg's lu_factor/lu_solve, the
previous implementation of the capacitance solve.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from contactfx.linalg import capacitance
from contactfx.linalg.capacitance import DenseLU


def system(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A nonsymmetric, well-conditioned (n, n) matrix, a solution and its right-hand side."""
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((n, n)) + n * np.eye(n)
    x = rng.standard_normal(n)
    return a, x, a @ x


@pytest.mark.parametrize("numpy_rows", [1000, 0])  # numpy's solve, then scipy's kept LU
def test_solves_equal_scipys_lu(monkeypatch: pytest.MonkeyPatch, numpy_rows: int) -> None:
    monkeypatch.setattr(capacitance, "NUMPY_ROWS", numpy_rows)
    a, x, b = system(40)
    lu = DenseLU(a)
    assert (lu._lu is None) == (numpy_rows >= 40)
    ref = scipy.linalg.lu_solve(scipy.linalg.lu_factor(a), b)
    for _ in range(2):  # a refinement step solves with the same matrix again
        np.testing.assert_allclose(lu.solve(b), ref, rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(lu.solve(b), x, rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("numpy_rows", [1000, 0])  # both paths refuse alike
def test_non_finite_and_singular_matrices_raise(
    monkeypatch: pytest.MonkeyPatch, numpy_rows: int
) -> None:
    monkeypatch.setattr(capacitance, "NUMPY_ROWS", numpy_rows)
    a = system(5)[0]
    a[2, 3] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        DenseLU(a)
    with pytest.raises(np.linalg.LinAlgError):
        DenseLU(np.zeros((3, 3))).solve(np.ones(3))
    # An exact zero pivot in column 2 (zero column): refused on both paths, not inf / nan.
    a = system(3)[0]
    a[:, 1] = 0.0
    with pytest.raises(np.linalg.LinAlgError):
        DenseLU(a).solve(np.ones(3))
