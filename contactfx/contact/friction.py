"""Coulomb friction as a nonlinear complementarity function, per contact row (numpy only).

A building block of the frictional method under construction (docs/friction.md): no solver
calls it yet. Each contact row j (an active-surface node with a normal row of the contact
operator and a tangential row of the same kernel, `direction="tangent"`) carries

    lambda_n  the normal multiplier (a pressure, >= 0 in contact),
    lambda_t  the tangential multiplier, positive along +t (t = (n_y, -n_x), n the passive
              surface's outward normal): the traction on the active body is -lambda_t t, so in
              slip it opposes the slip increment,
    g_n       the weighted gap (>= 0: open or touching),
    u_t       the weighted slip increment of the load step: the tangential row applied to the
              displacement increment since the previous converged step (quasi-static).

Coulomb's law (|lambda_t| <= mu lambda_n; stick: u_t = 0; slip: lambda_t = mu lambda_n u_t/|u_t|)
with the normal complementarity (g_n >= 0, lambda_n >= 0, g_n lambda_n = 0) is, for any
c_n, c_t > 0, the root of (Hueber, Stadler and Wohlmuth 2008, in the projection form that
Popp et al. use for dual mortar in 2D)

    xi  = lambda_n - c_n g_n,      tau = lambda_t + c_t u_t,      r = mu max(xi, 0),
    C_n = lambda_n - max(xi, 0),   C_t = lambda_t - clip(tau, -r, r).

Its three sets: open (xi <= 0: C_n = lambda_n, C_t = lambda_t), stick (xi > 0, |tau| < r:
C_n = c_n g_n, C_t = -c_t u_t) and slip (xi > 0, |tau| >= r: C_n = c_n g_n,
C_t = lambda_t - mu s xi, s = sign(tau)). C is piecewise linear, so the set's rows are its
derivative (the semismooth Newton step); with mu = 0 every contact row is slip and C_t =
lambda_t: the frictionless rows.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from .sparse import CSR

#: A contact row sticks where |tau| < (1 + STICK_MARGIN) r: a slip row whose slip increment is
#: round-off (|tau| = r to round-off; a row at a symmetry line or the axis with the standard
#: basis, whose neighbours stick) is a stick row, not a slip row with an arbitrary direction
#: (docs/friction.md, "How it is solved").
STICK_MARGIN = 1e-10

#: Column order of the rows' derivatives: d/d(lambda_n, lambda_t, g_n, u_t).
VARIABLES = ("lambda_n", "lambda_t", "g_n", "u_t")


class Status(IntEnum):
    """A contact row's set: open (no contact), stick or slip (a frictionless contact is slip)."""

    OPEN = 0
    STICK = 1
    SLIP = 2


@dataclass(frozen=True)
class FrictionRows:
    """The semismooth Newton rows of the complementarity function at one state.

    dn, dt: (m, 4) derivatives of C_n and C_t with respect to VARIABLES; the Newton step for
    the increments (d lambda_n, d lambda_t, d g_n, d u_t) of each row is
    dn @ d = -C_n and dt @ d = -C_t, with d g_n = B_n du and d u_t = B_t du.
    """

    status: np.ndarray  # (m,) Status values
    cn: np.ndarray  # (m,) C_n at the state
    ct: np.ndarray  # (m,) C_t at the state
    dn: np.ndarray  # (m, 4)
    dt: np.ndarray  # (m, 4)


@dataclass(frozen=True)
class FrictionResult:
    """The tangential side of a frictional solve, per multiplier (global layout order).

    shear: lambda_t (the traction on the active body is -shear t, t = (n_y, -n_x) of the
    passive surface); slip: the tangential slip (weighted slip / weight, the active body's
    motion along t relative to the passive one); status: contact/friction.Status values.
    """

    mu: np.ndarray
    shear: np.ndarray
    slip: np.ndarray
    status: np.ndarray
    tangent: CSR  # the tangential rows B_t in the same order: -B_t^T shear is their force
    # The rows' columns of a rigid obstacle's motion (m, 2), zero on body pairs' rows: the
    # shear's force on an obstacle, -motion^T shear. None: no obstacle.
    tangent_motion: CSR | None = None


def _state(
    lam_n: np.ndarray,
    lam_t: np.ndarray,
    g_n: np.ndarray,
    u_t: np.ndarray,
    mu: float | np.ndarray,
    c_n: float,
    c_t: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """xi, tau and the friction bound r = mu max(xi, 0) of each row."""
    if np.any(np.asarray(mu) < 0) or not (c_n > 0 and c_t > 0):
        raise ValueError("friction: mu must be >= 0 and c_n, c_t > 0")
    xi = np.asarray(lam_n, dtype=float) - c_n * np.asarray(g_n, dtype=float)
    tau = np.asarray(lam_t, dtype=float) + c_t * np.asarray(u_t, dtype=float)
    return xi, tau, mu * np.maximum(xi, 0.0)


def classify(
    lam_n: np.ndarray,
    lam_t: np.ndarray,
    g_n: np.ndarray,
    u_t: np.ndarray,
    mu: float | np.ndarray,
    c_n: float,
    c_t: float,
) -> np.ndarray:
    """Each row's set: open where xi <= 0, else stick where |tau| < mu xi, else slip.

    "<" up to round-off: STICK_MARGIN.
    """
    xi, tau, r = _state(lam_n, lam_t, g_n, u_t, mu, c_n, c_t)
    status = np.full(xi.shape, Status.SLIP, dtype=np.int64)
    status[np.abs(tau) < (1.0 + STICK_MARGIN) * r] = Status.STICK
    status[xi <= 0.0] = Status.OPEN
    return status


def ncp(
    lam_n: np.ndarray,
    lam_t: np.ndarray,
    g_n: np.ndarray,
    u_t: np.ndarray,
    mu: float | np.ndarray,
    c_n: float,
    c_t: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The complementarity function (C_n, C_t) of each row: zero exactly where Coulomb holds."""
    xi, tau, r = _state(lam_n, lam_t, g_n, u_t, mu, c_n, c_t)
    return np.asarray(lam_n, dtype=float) - np.maximum(xi, 0.0), lam_t - np.clip(tau, -r, r)


def linearize(
    lam_n: np.ndarray,
    lam_t: np.ndarray,
    g_n: np.ndarray,
    u_t: np.ndarray,
    mu: float | np.ndarray,
    c_n: float,
    c_t: float,
) -> FrictionRows:
    """The rows' status, C and its derivative on the row's set (the semismooth Newton rows)."""
    status = classify(lam_n, lam_t, g_n, u_t, mu, c_n, c_t)
    cn, ct = ncp(lam_n, lam_t, g_n, u_t, mu, c_n, c_t)
    _, tau, _ = _state(lam_n, lam_t, g_n, u_t, mu, c_n, c_t)
    m = status.shape[0]
    mu_row = np.broadcast_to(np.asarray(mu, dtype=float), (m,))
    dn = np.zeros((m, 4))
    dt = np.zeros((m, 4))
    open_, stick, slip = (status == s for s in (Status.OPEN, Status.STICK, Status.SLIP))
    # open: C_n = lambda_n, C_t = lambda_t
    dn[open_, 0] = 1.0
    dt[open_, 1] = 1.0
    # contact (stick or slip): C_n = c_n g_n
    dn[~open_, 2] = c_n
    # stick: C_t = -c_t u_t
    dt[stick, 3] = -c_t
    # slip: C_t = lambda_t - mu s (lambda_n - c_n g_n)
    s = np.sign(tau[slip])
    dt[slip, 0] = -mu_row[slip] * s
    dt[slip, 1] = 1.0
    dt[slip, 2] = mu_row[slip] * s * c_n
    return FrictionRows(status=status, cn=cn, ct=ct, dn=dn, dt=dt)


def displacement_rows(rows: FrictionRows, normal: CSR, tangent: CSR) -> tuple[CSR, CSR]:
    """The Newton step's dC_n/du and dC_t/du, sparse like the contact operator's rows.

    The rows' g_n and u_t derivatives times the normal (d g_n = B_n du) and tangential
    (d u_t = B_t du) rows of the same kernel.
    """
    if normal.shape != tangent.shape or normal.shape[0] != rows.status.shape[0]:
        raise ValueError("displacement_rows: B_n, B_t and the rows must have the same rows")
    r = np.concatenate([normal.entry_rows, tangent.entry_rows])
    c = np.concatenate([normal.indices, tangent.indices])
    out = []
    for d in (rows.dn, rows.dt):
        vals = np.concatenate(
            [normal.data * d[normal.entry_rows, 2], tangent.data * d[tangent.entry_rows, 3]]
        )
        out.append(CSR.from_coo(r, c, vals, normal.shape, drop_zeros=True))
    return out[0], out[1]


@dataclass(frozen=True)
class RowState:
    """One iterate's row variables (lambda_n, lambda_t, g_n, u_t), each (m,)."""

    lam_n: np.ndarray
    lam_t: np.ndarray
    g_n: np.ndarray
    u_t: np.ndarray

    def toward(self, other: RowState, alpha: float) -> RowState:
        """The state alpha of the way from this one to `other` (all four are linear in u)."""
        return RowState(
            *(a + alpha * (b - a) for a, b in zip(self.arrays(), other.arrays(), strict=True))
        )

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The four arrays in VARIABLES order."""
        return self.lam_n, self.lam_t, self.g_n, self.u_t


def merit(state: RowState, mu: float | np.ndarray, c_n: float, c_t: float, w: np.ndarray) -> float:
    """This rank's sum of w (C_n^2 + C_t^2): zero exactly where Coulomb's law holds."""
    cn, ct = ncp(*state.arrays(), mu, c_n, c_t)
    return float(np.sum(w * (cn**2 + ct**2)))


def damped_length(
    start: RowState,
    target: RowState,
    mu: float | np.ndarray,
    c_n: float,
    c_t: float,
    w: np.ndarray,
    total: Callable[[float], float] = float,
    sigma: float = 1e-4,
    shortest: float = 2.0**-10,
) -> tuple[float, float, float]:
    """The semismooth Newton step's length from `start` toward `target` (Armijo backtracking).

    `target` is the solution on the set `start` classifies into (the full Newton step, as
    C is piecewise linear); the step is halved until the merit w (C_n^2 + C_t^2), summed over
    the ranks by `total`, falls by the fraction 2 sigma alpha (`armijo`: the length, the
    merit at the start and at the step's end). Where no length down to `shortest` does (a
    kink of C, where the set's derivative is not a descent direction), the full step.
    """
    return armijo(
        lambda alpha: total(merit(start.toward(target, alpha), mu, c_n, c_t, w)), sigma, shortest
    )


def armijo(
    theta: Callable[[float], float], sigma: float = 1e-4, shortest: float = 2.0**-10
) -> tuple[float, float, float]:
    """A step length by backtracking, with the merit before and after the step.

    The longest of 1, 1/2, 1/4, ... down to `shortest` with theta(alpha) <= (1 - 2 sigma
    alpha) theta(0); 1 where none is.
    """
    theta0 = theta(0.0)
    alpha = 1.0
    while alpha >= shortest:
        value = theta(alpha)
        if value <= (1.0 - 2.0 * sigma * alpha) * theta0:
            return alpha, theta0, value
        alpha /= 2.0
    return 1.0, theta0, theta(1.0)


class Epochs:
    """The cycle key's epoch of a damped iteration: how many iterates set a record low.

    A damped step lowers the merit, so its iterate is never met again and meeting its set
    again is no cycle; a full step where no length lowers it (a kink) may raise it. Iterates
    that come round again set no new record: their sets repeat within one epoch, which the
    active-set loop reports as a cycle.
    """

    def __init__(self) -> None:
        self.epoch = 0
        self.best = np.inf

    def update(self, before: float, after: float) -> None:
        """A step from merit `before` to `after`."""
        self.best = min(self.best, before)
        if after < self.best:
            self.best = after
            self.epoch += 1
