"""When a persistent saddle-point solver refactors, and when it reuses its factorization.

The active set switches rows of the multiplier block on and off; every matrix keeps its
pattern. A set that differs from the factorized one in `c` rows is a rank-2c change:
- a subset of the factorized set (rows only released) is solved exactly by a capacitance
  system on the released rows (`linalg/capacitance.py`), two back-substitutions;
- otherwise GMRES preconditioned by the old factorization converges in about 2c + 1
  iterations (a lagged factorization), which pays while those applications cost less than a
  new numeric factorization.
`FactorizationPolicy` makes that choice from the measured costs; tests drive it directly.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from mpi4py import MPI


class Decision(StrEnum):
    """How the next solve uses the factorization."""

    REFACTOR = "refactor"  # a new numeric factorization of this set
    LAGGED = "lagged"  # GMRES preconditioned by the factorization of an earlier set
    RELEASED = "released"  # a capacitance system on the rows released since it


class ReuseMode(StrEnum):
    """`auto` weighs a lagged factorization against a new one; the others force one side."""

    AUTO = "auto"
    REUSE = "reuse"
    REFACTOR = "refactor"


@dataclass
class FactorizationPolicy:
    """The reuse decision, from the costs of the last factorization and back-substitution.

    `reuse` False: every solve factorizes (a throwaway solver). `max_released` bounds the
    capacitance system (dense, rows x rows); `max_lagged` the GMRES iterations a lagged
    factorization may need (2 per changed row and one).
    """

    reuse: bool = True
    mode: ReuseMode = ReuseMode.AUTO
    max_released: int = 2000
    max_lagged: int = 100
    t_numeric: float = float("inf")  # seconds of the last numeric factorization
    t_apply: float = 0.0  # seconds of one application (back-substitution) of it

    def decide(
        self, changed: int, subset: bool, fresh: bool = False, release: bool = True
    ) -> Decision:
        """The decision for a set that differs from the factorized one in `changed` rows.

        `changed` < 0: nothing is factorized yet. `subset`: the set only releases rows of the
        factorized one. `fresh`: the caller needs this very set factorized (probes).
        `release` False: the capacitance path is not available (augmented A00, or it failed).
        """
        if not self.reuse or changed < 0 or fresh:
            return Decision.REFACTOR
        if (
            release
            and subset
            and self.mode is not ReuseMode.REFACTOR
            and 0 < changed <= self.max_released
        ):
            return Decision.RELEASED
        lagged = 2 * changed + 1
        if (
            self.mode is ReuseMode.REFACTOR
            or (self.mode is ReuseMode.AUTO and lagged * self.t_apply > self.t_numeric)
            or lagged > self.max_lagged
        ):
            return Decision.REFACTOR
        return Decision.LAGGED

    def factorized(self, seconds: float, numeric_only: bool) -> None:
        """Record a factorization's cost (the first one includes the analysis: a bound)."""
        if numeric_only or self.t_numeric == float("inf"):
            self.t_numeric = seconds

    def applied(self, seconds: float, applications: int) -> None:
        """Record the cost of the solve after a factorization (one application per iteration)."""
        self.t_apply = seconds / max(applications, 1)


@dataclass
class Factored:
    """Which set the current factorization is of, and what is kept about it.

    `solution`: the factorized set's own solution (for these gaps), which a capacitance solve
    starts from; `own_residual`: the relative residual of the factorization's own
    back-substitution, the floor of any solve on it.
    """

    active: np.ndarray | None = None
    count: int = 0  # factorizations so far
    own_residual: float = 0.0
    solution: tuple[int, np.ndarray, np.ndarray] | None = None  # (count, g, x)

    def changed(self, active: np.ndarray, comm: MPI.Comm) -> tuple[int, bool]:
        """(rows whose flag differs from the factorized set, whether `active` is a subset)."""
        if self.active is None:
            return -1, False
        changed = comm.allreduce(int(np.count_nonzero(active != self.active)))
        grown = comm.allreduce(bool(np.any(active & ~self.active)), op=MPI.LOR)
        return changed, not grown

    def factorized(self, active: np.ndarray) -> None:
        """A new factorization of `active`."""
        self.active, self.count, self.own_residual = active.copy(), self.count + 1, 0.0

    def keep(self, active: np.ndarray, g: np.ndarray, x: np.ndarray) -> None:
        """Keep x if it solves the factorized set itself."""
        if self.active is not None and np.array_equal(active, self.active):
            self.solution = (self.count, np.array(g, copy=True), x.copy())

    def solution_for(self, g: np.ndarray) -> np.ndarray | None:
        """The kept solution of the factorized set for these gaps, if any."""
        kept = self.solution
        if kept is None or kept[0] != self.count or not np.array_equal(kept[1], g):
            return None
        return kept[2]
