"""Solves on a kept factorization for a matrix changed in a few rows (linalg/row_update.py).

A random diagonally dominant sparse matrix P is factored (MUMPS LU); A equals it but in a few
rows (one zeroed to a unit row, as an opened contact row; others rescaled). The Woodbury
solve on P's factorization must give numpy's dense solve of A to round-off, and a second
solve with more changed rows reuses the kept columns (only the new ones are solved for).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from petsc4py import PETSc

from contactfx.linalg.row_update import KeptFactorization

N = 60


def aij(dense: np.ndarray) -> PETSc.Mat:
    """A serial AIJ matrix with the full pattern of `dense` (zeros stored: one pattern)."""
    rows, cols = np.nonzero(np.ones_like(dense))
    M = PETSc.Mat().createAIJ(size=dense.shape, comm=PETSc.COMM_SELF)
    M.setPreallocationCOO(
        cast_any(rows.astype(PETSc.IntType)), cast_any(cols.astype(PETSc.IntType))
    )
    M.setValuesCOO(cast_any(dense.ravel()), cast_any(PETSc.InsertMode.INSERT_VALUES))
    M.assemble()
    return M


def cast_any(x: object) -> Any:
    return x


def test_woodbury_on_the_kept_factorization_solves_the_changed_matrix() -> None:
    rng = np.random.default_rng(7)
    dense = rng.normal(size=(N, N)) * (rng.random((N, N)) < 0.1)
    dense += np.diag(10.0 + rng.random(N))
    changed = dense.copy()
    changed[5] = 0.0
    changed[5, 5] = 1.0  # an opened row: its unknown is set to the right-hand side
    changed[17] *= 3.0
    changed[17, 3] = -4.0
    P, A = aij(dense), aij(changed)
    ksp = PETSc.KSP().create(PETSc.COMM_SELF)
    ksp.setOperators(P)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.setUp()
    kept = KeptFactorization(ksp.getPC().getFactorMatrix())
    b = P.createVecRight()
    b.array[:] = rng.normal(size=N)
    x = b.duplicate()
    assert kept.solve(A, P, np.array([5, 17]), b, x, 1e-12)
    expected = np.linalg.solve(changed, b.array_r)
    np.testing.assert_allclose(x.array_r, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    assert kept.columns_solved == 2
    # One more row changes: only its column is solved for.
    changed[40] *= 0.5
    A2 = aij(changed)
    assert kept.solve(A2, P, np.array([5, 17, 40]), b, x, 1e-12)
    expected = np.linalg.solve(changed, b.array_r)
    np.testing.assert_allclose(x.array_r, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    assert kept.columns_solved == 3
    for obj in (P, A, A2, ksp, b, x):
        obj.destroy()
