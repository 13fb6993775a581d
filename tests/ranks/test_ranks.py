"""mpirun -n 2 gives the serial answer: every case of tests/ranks/rank_cases.py, one launch for all.

The serial side runs here, in this process, through the same case function; the 2-rank
side comes from the one session-wide mpirun (conftest.two_rank_results).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from mpi4py import MPI
from rank_cases import CASES, run
from rank_checks import compare


@pytest.mark.mpi
@pytest.mark.parametrize("case", sorted(CASES))
def test_two_ranks_equal_serial(
    case: str, two_rank_results: Callable[[str], dict[str, np.ndarray]]
) -> None:
    """Same mesh, same answer: the rank count changes only the round-off."""
    two = two_rank_results(case)
    # It really ran on 2 ranks, each owning part of the mesh.
    assert int(two.pop("_ranks")) == 2
    owned = two.pop("_owned_cells")
    assert len(owned) == 2 and owned.min() > 0, owned
    assert MPI.COMM_WORLD.size == 1
    one, owned_serial = run(case)
    assert owned_serial.sum() == owned.sum()  # the same mesh, all of it on one rank
    compare(CASES[case].checks, one, two)
