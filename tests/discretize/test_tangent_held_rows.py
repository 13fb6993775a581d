"""Which tangential rows are held by the supports (discretize/tangents.py, held_rows)."""

from __future__ import annotations

import numpy as np

from contactfx.contact.sparse import CSR
from contactfx.discretize.tangents import HELD_FRACTION, held_rows


def test_a_row_whose_own_node_is_held_along_it() -> None:
    """Row 0: its own node's y is prescribed and its x enters by a chord's tilt (2 %): held,
    though it touches its neighbour's free dofs (the standard basis). Row 1: its own node
    moves along it: free. Row 2: its own x enters at just over HELD_FRACTION: free."""
    node_dofs = np.array([[0, 1], [2, 3], [4, 5]])
    fixed = np.zeros(6, dtype=bool)
    fixed[[1, 5]] = True
    entries = [
        (0, 0, 0.02), (0, 1, 1.0), (0, 2, 0.5), (0, 3, 0.5),
        (1, 2, 0.3), (1, 3, 1.0), (1, 1, 0.5),
        (2, 4, 1.01 * HELD_FRACTION), (2, 5, -1.0),
    ]  # fmt: skip
    r, c, v = (np.array(a) for a in zip(*entries, strict=True))
    B = CSR.from_coo(r, c, v, (3, 6))
    np.testing.assert_array_equal(held_rows(B, node_dofs, fixed), [True, False, False])
