"""The damped semismooth Newton step and the round-off margin of contact/friction.py."""

from __future__ import annotations

import numpy as np

from contactfx.contact.friction import (
    STICK_MARGIN,
    Epochs,
    RowState,
    Status,
    classify,
    damped_length,
    merit,
)

MU, C = 0.5, 1.0
W = np.ones(1)


def row(lam_n: float, lam_t: float, g_n: float, u_t: float) -> RowState:
    """One row's state."""
    return RowState(*(np.array([v]) for v in (lam_n, lam_t, g_n, u_t)))


def test_merit_is_zero_exactly_where_coulomb_holds() -> None:
    """Stick with |lambda_t| < mu lambda_n and no slip, slip at the bound along the slip,
    open with no traction: zero; a shear beyond the cone or against the slip: positive."""
    for lam_n, lam_t, g_n, u_t in ((1, 0.2, 0, 0), (1, 0.5, 0, 0.3), (0, 0, 0.1, 2.0)):
        assert merit(row(lam_n, lam_t, g_n, u_t), MU, C, C, W) == 0.0
    for lam_n, lam_t, g_n, u_t in ((1, 0.7, 0, 0), (1, -0.5, 0, 0.3), (1, 0.2, 0, 0.1)):
        assert merit(row(lam_n, lam_t, g_n, u_t), MU, C, C, W) > 0.0


def test_an_overshooting_step_is_halved_until_the_merit_falls() -> None:
    """From a slip row 0.1 beyond its bound, a step that turns the slip around (merit 6.25)
    is halved to 1/16, where the row lands on the bound (merit 0): the lengths 1/2 .. 1/8
    leave it above 0.01 (tau turns back inside the cone first)."""
    start, target = row(1.0, 0.4, 0.0, 0.3), row(1.0, 2.0, 0.0, -3.0)
    assert np.isclose(merit(start, MU, C, C, W), 0.01)
    assert merit(target, MU, C, C, W) == 6.25
    alpha, before, after = damped_length(start, target, MU, C, C, W)
    assert alpha == 1 / 16 and np.isclose(before, 0.01) and after < 1e-30
    assert merit(start.toward(target, alpha), MU, C, C, W) == after


def test_a_step_to_the_root_is_taken_in_full() -> None:
    """The set's solution satisfying Coulomb: the full step, to merit 0."""
    alpha, before, after = damped_length(
        row(1.0, 0.7, 0.0, 0.0), row(1.0, 0.5, 0.0, 0.3), MU, C, C, W
    )
    assert (alpha, after) == (1.0, 0.0) and before > 0.0


def test_from_a_root_no_step_lowers_the_merit() -> None:
    """Already at a root: no length lowers the merit, the full step is taken (a kink's)."""
    alpha, before, after = damped_length(
        row(1.0, 0.2, 0.0, 0.0), row(1.0, 2.0, 0.0, -3.0), MU, C, C, W
    )
    assert (alpha, before, after) == (1.0, 0.0, 6.25)


def test_an_iterate_that_comes_round_sets_no_new_epoch() -> None:
    """Epochs count record lows: a merit falling 4, 2, 1 makes three; rising back to 4 and
    falling to 2 and 1 again (a cycle of iterates) none, so the loop sees its sets repeat."""
    epochs = Epochs()
    for before, after in ((8, 4), (4, 2), (2, 1)):
        epochs.update(before, after)
    assert epochs.epoch == 3
    for before, after in ((1, 4), (4, 2), (2, 1), (1, 4)):
        epochs.update(before, after)
    assert epochs.epoch == 3


def test_a_slip_row_with_round_off_slip_sticks() -> None:
    """|tau| at the bound to round-off is stick; a slip beyond the margin is slip; with mu = 0
    every contact row is slip (the frictionless rows), a zero trial included."""
    lam_n = np.array([1.0, 1.0])
    lam_t = MU * np.array([1.0 + 1e-14, 1.0 + 100 * STICK_MARGIN])
    zero = np.zeros(2)
    status = classify(lam_n, lam_t, zero, zero, MU, C, C)
    np.testing.assert_array_equal(status, [Status.STICK, Status.SLIP])
    frictionless = classify(lam_n, zero, zero, zero, 0.0, C, C)
    np.testing.assert_array_equal(frictionless, [Status.SLIP, Status.SLIP])
