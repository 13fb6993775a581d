"""The active-set loop's bookkeeping (methods/active_set.py)."""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from contactfx.errors import ActiveSetError
from contactfx.methods.active_set import SetHistory


def test_only_final_answers_settle_a_set() -> None:
    """SetHistory: a set met again after a loose answer is no cycle; after a final one it is."""
    state = SetHistory(MPI.COMM_SELF, np.arange(4), 4)
    a, b = np.array([1, 1, 0, 0], dtype=bool), np.array([1, 0, 0, 0], dtype=bool)
    state.visit(a, 1, 2, False)  # a loose answer: not settled
    state.visit(b, 2, 1, False)
    state.settle()
    state.visit(a, 3, 2, False)  # met again: allowed
    state.settle()
    with pytest.raises(ActiveSetError, match="cycles at iteration 4"):
        state.visit(b, 4, 1, False)
