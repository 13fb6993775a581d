"""Exact solves for a subset of the factorized active set, by a capacitance system (no refactor).

The factorized system with its gap right-hand sides shifted by s on the released rows R has
the same u as the new one as soon as mu_R = 0, and mu_R = mu_R(0) + M s with M the
multiplier responses of R to unit shifts (kept from the probe step, else one multi-RHS
solve). The answer is accepted where its relative residual is within ROUNDOFF times that of
the factorized set's own back-substitution (or below RELEASED_RTOL): as accurate as a fresh
factorization of the new set, solved once. Starting from every row, mu_R(0) is large (far
rows pulled shut) and the shift that cancels it can leave more: up to two steps of iterative
refinement, each the same capacitance solve (two back-substitutions) on the residual; if
that is not enough, the caller refactors.
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Callable

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from .responses import local_slice

log = logging.getLogger("contactfx")

# A capacitance solve is refined while its relative residual exceeds this or, if larger,
# ROUNDOFF times that of the factorization's own back-substitution (MUMPS' accuracy on these
# saddle points). Within it the answer is as far from the exact one as a fresh factorization's
# single back-substitution of the same set: docs/scale.md, "The release step's refinement".
RELEASED_RTOL = 1e-8
ROUNDOFF = 2.0
# Refinement steps before giving up (each costs two back-substitutions).
REFINEMENTS = 2
# Up to this many released rows numpy's gesv refactors the capacitance matrix for each solve
# instead of keeping scipy.linalg's LU: a plain solve then never imports scipy.linalg, and a
# refactorization costs less than the import up to here (docs/scale.md, "Time to the first
# answer").
NUMPY_ROWS = 1000

Apply = Callable[[PETSc.Vec, PETSc.Vec], None]
Residual = Callable[[PETSc.Vec], tuple[PETSc.Vec, float]]
Responses = Callable[[np.ndarray, np.ndarray], np.ndarray]


class DenseLU:
    """Solves with one dense matrix: LAPACK's LU, by numpy (small) or scipy.linalg (kept)."""

    def __init__(self, a: np.ndarray) -> None:
        """Factorize `a` (square); ValueError if it holds a non-finite entry."""
        if not np.all(np.isfinite(a)):
            raise ValueError("the capacitance matrix has non-finite entries")
        self._a = a
        self._lu: tuple[np.ndarray, np.ndarray] | None = None
        if len(a) > NUMPY_ROWS:
            import scipy.linalg  # only for a large released set (docs/scale.md)

            with warnings.catch_warnings():  # a zero pivot is refused in solve, as numpy's
                warnings.simplefilter("ignore", scipy.linalg.LinAlgWarning)
                self._lu = scipy.linalg.lu_factor(a, check_finite=False)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """a^-1 b; np.linalg.LinAlgError if `a` is singular (an exact zero pivot), as numpy's."""
        if self._lu is None:
            return np.linalg.solve(self._a, b)
        if not np.all(np.diagonal(self._lu[0])):  # scipy only warns and returns inf / nan
            raise np.linalg.LinAlgError("Singular matrix")
        import scipy.linalg  # imported by __init__ already: a dict look-up

        return scipy.linalg.lu_solve(self._lu, b)


def _gathered(comm: MPI.Comm, local: np.ndarray) -> np.ndarray:
    return np.concatenate(comm.allgather(local))


def released_solve(
    apply: Apply,
    residual: Residual,
    b_new: PETSc.Vec,
    x: PETSc.Vec,
    rows_l: np.ndarray,
    factored: np.ndarray,
    active: np.ndarray,
    g: np.ndarray,
    responses: Responses,
    comm: MPI.Comm,
    first: np.ndarray | None,
    floor: float = 0.0,
) -> tuple[int, float, int] | None:
    """Solve the new system (right-hand side `b_new`, set `active`) into x, or None.

    `apply(b, x)` applies the factorization of the `factored` set; `residual(x)` is the new
    system's residual and its relative norm; `responses(rows, local_mask)` the multiplier
    responses to unit shifts of the global `rows`; `first`, if given, the factorized set's
    own solution for these gaps (saves a back-substitution); `floor` the relative residual of
    the factorization's own back-substitution. Returns
    (back-substitutions, relative residual, released rows), or None where the caller must
    refactor (a log line says why).
    """
    released = factored & ~active
    rel_global = np.flatnonzero(_gathered(comm, released))
    rows_r = rows_l[released]
    mine = local_slice(comm, released)
    b = b_new.duplicate()
    b_new.copy(b)
    b.array[rows_l] = np.where(factored, -g, 0.0)
    applies = 1
    target = max(RELEASED_RTOL, ROUNDOFF * floor)
    try:
        if first is not None:
            x.array[:] = first
        else:
            apply(b, x)
            applies += 1
        mu0 = _gathered(comm, x.array_r[rows_r])
        resp = responses(rel_global, released)
        lu = DenseLU(_gathered(comm, resp[released]))
        b.array[rows_r] += lu.solve(-mu0)[mine]
        apply(b, x)
        x.array[rows_r] = 0.0
        r, res = residual(x)
        for _ in range(REFINEMENTS):
            if res <= target:
                break
            # The correction solves the new system with the residual as right-hand side: the
            # factorized one with mu_R = 0 imposed by the same capacitance matrix.
            r.array[rows_r] = 0.0
            dx = r.duplicate()
            apply(r, dx)
            d0 = _gathered(comm, dx.array_r[rows_r])
            r.array[rows_r] = lu.solve(-d0)[mine]
            apply(r, dx)
            dx.array[rows_r] = 0.0
            x.axpy(1.0, dx)
            dx.destroy()
            r.destroy()
            applies += 2
            r, res = residual(x)
        r.destroy()
    except (PETSc.Error, np.linalg.LinAlgError, ValueError) as err:
        _say(comm, f"released-rows solve failed ({type(err).__name__}): refactoring")
        return None
    finally:
        b.destroy()
    if res > target:
        _say(comm, f"released-rows solve left residual {res:.1e} > {target:.1e}: refactoring")
        return None
    return applies, res, len(rel_global)


def _say(comm: MPI.Comm, text: str) -> None:
    if comm.rank == 0:
        log.info("saddle solver: %s", text)
