"""What every linear solver of the saddle points offers the active-set loop, and what it returns.

The loop never asks which solver it has: it asks the solver. `exact` says whether the
answers are exact solves of the set's system (a factorization) or stop at a loose
tolerance (then they ask the loop's `stationary` test and go on to the final one on a
stationary set); `can_probe` whether
`responses` (multiplier responses to unit gap openings, the probe step's data) is
available, and `cheap_responses` whether they cost a few selected entries of the inverse
rather than one back-substitution per column.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np


@dataclass
class SaddleResult:
    """One solve: the owned blocks of u and mu, and what it cost."""

    u: np.ndarray
    mu: np.ndarray
    iterations: int  # Krylov iterations (or back-substitutions of a capacitance solve)
    reason: int  # PETSc's converged reason (> 0)
    refactored: bool = True  # a new factorization (or multigrid) was set up for this solve
    changed_rows: int = -1  # rows that differ from the factorized set (-1: none factorized)
    released: int = 0  # rows released by a capacitance system instead of refactoring
    setup: float = 0.0  # seconds of numeric setup (factorization, multigrid)
    solve: float = 0.0  # seconds of the solve proper
    residual: float | None = None  # relative residual, where the solver measured it
    final: bool = True  # solved to the final tolerance (False: a loose solve of the loop)


# The loop's test of a loose answer (True: the set is stationary, solve on to the end), or None.
LoopTest = Callable[[SaddleResult], bool] | None


class LinearSolver(Protocol):
    """A persistent solver for one (K, B, f): `solve(g, active)` for each set of the loop."""

    @property
    def exact(self) -> bool:
        """Whether `solve` answers exactly (else it asks `stationary` at its loose tolerance)."""
        ...

    @property
    def can_probe(self) -> bool:
        """Whether `responses` is available (the solver holds an exact inverse)."""
        ...

    @property
    def cheap_responses(self) -> bool:
        """Whether `responses` come from selected entries of the inverse (serial MUMPS)."""
        ...

    def solve(
        self, g: np.ndarray, active: np.ndarray, *, fresh: bool = False, stationary: LoopTest = None
    ) -> SaddleResult:
        """Solve with the rows of `active` enforced as equalities and mu = 0 elsewhere.

        `fresh`: factorize this very set (what `responses` needs afterwards). `stationary`:
        an inexact solver asks it at its loose tolerance and, where it says True, goes on
        in the same Krylov run to the final one (`final`); exact solvers never call it.
        """
        ...

    def responses(
        self, rhs: np.ndarray, active: np.ndarray, rows: np.ndarray | None = None
    ) -> np.ndarray:
        """Multiplier responses (local rows x k) to multiplier-block right-hand sides.

        Column j of `rhs` (local rows x k) opens weighted gaps; the set solved last (with
        `fresh`) is the operator. `rows` (a local mask): only these rows are needed, a
        solver may leave the others zero (None: every active row). Only where `can_probe`.
        """
        ...

    def destroy(self) -> None:
        """Free the PETSc objects."""
        ...
