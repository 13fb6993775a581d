"""The linear programs of the free-body check (load_paths.py): which rows can carry load.

On the free rigid modes, a^T lam + load = 0 with lam >= 0 (a the rows B m on the free
modes); with friction also the tangential rows, their multipliers bounded by Coulomb's cone.
Plain numpy and scipy (HiGHS, imported only where a program runs): no mesh, no MPI.
"""

from __future__ import annotations

import numpy as np

from ..errors import SingularSystemError


def carrying_rows(
    a: np.ndarray,
    load: np.ndarray,
    at: np.ndarray | None = None,
    mu: np.ndarray | None = None,
) -> np.ndarray | None:
    """Rows (of a (n, k)) positive in some lam >= 0 with a^T lam + load = 0; None: no such lam.

    A row of zeros (no free mode acts on it) counts as carrying: statics do not bound it.
    With friction, `at` (n, k) the tangential rows and `mu` (n,) their coefficients: the
    equilibrium is a^T lam + at^T lam_t + load = 0 with |lam_t| <= mu lam.
    """
    n = a.shape[0]
    on = np.abs(a).max(axis=1, initial=0.0) > 0.0
    # Tangential rows count where friction acts and a free mode moves them (else: as before).
    tangent = None
    if at is not None and mu is not None:
        tangent = np.where((mu > 0)[:, None], at, 0.0)
        if not tangent.any():
            tangent = None
    if tangent is not None:
        on |= np.abs(tangent).max(axis=1, initial=0.0) > 0.0
    out = np.ones(n, dtype=bool)
    j = np.flatnonzero(on)
    if not j.size:
        return out if not load.any() else None
    if tangent is not None:
        assert mu is not None
        return _friction_lp(a, tangent, mu, load, j, out)
    if a.shape[1] == 1:
        return _one_mode(a[:, 0], float(load[0]), out)
    return _carrying_lp(a, load, j, out)


def _one_mode(a: np.ndarray, load: float, out: np.ndarray) -> np.ndarray | None:
    """carrying_rows with one free mode (a body free along one direction), in closed form.

    sum a_i lam_i = -load, lam >= 0: the rows of the sign of -load can carry it, and then
    every other nonzero row too (its share is balanced by more on the first); with no load
    the nonzero rows carry only if both signs are present (the body squeezed). The LP's
    answer without scipy.optimize (imported only for two or more free modes).
    """
    pos, neg = bool((a > 0).any()), bool((a < 0).any())
    if (load < 0 and not pos) or (load > 0 and not neg):
        return None
    out[a != 0] = load != 0 or (pos and neg)
    return out


def _carrying_lp(
    a: np.ndarray, load: np.ndarray, j: np.ndarray, out: np.ndarray
) -> np.ndarray | None:
    """carrying_rows by the linear program (HiGHS), `j` the rows some free mode acts on."""
    # Each lam_i scaled by its row's size: the same signs, a well-scaled program.
    aj = a[j] / np.abs(a[j]).max(axis=1, keepdims=True)
    fl = load / max(float(np.abs(load).max()), 1e-300)
    m, k = len(j), a.shape[1]
    # Unknowns (lam, s, t): a^T lam + load s = 0, t <= lam, s >= 1, 0 <= t <= 1.
    import scipy.sparse as sp  # with scipy.optimize below: only for 2+ free modes

    a_eq = sp.hstack([sp.csr_matrix(aj.T), sp.csr_matrix(fl.reshape(k, 1)), sp.csr_matrix((k, m))])
    eye = sp.identity(m, format="csr")
    a_ub = sp.hstack([-eye, sp.csr_matrix((m, 1)), eye])
    c = np.concatenate([np.zeros(m + 1), -np.ones(m)])
    bounds = [(0.0, None)] * m + [(1.0, None)] + [(0.0, 1.0)] * m
    from scipy.optimize import linprog  # scipy.optimize (~0.15 s) only for 2+ free modes

    res = linprog(c, a_ub, np.zeros(m), a_eq, np.zeros(k), bounds=bounds, method="highs")
    if res.status == 2:
        return None
    if res.status != 0:
        raise SingularSystemError(
            f"the check of which contacts can hold the bodies failed: {res.message}"
        )
    out[j] = res.x[m + 1 :] > 0.5
    return out


def _friction_lp(
    a: np.ndarray, at: np.ndarray, mu: np.ndarray, load: np.ndarray, j: np.ndarray, out: np.ndarray
) -> np.ndarray | None:
    """carrying_rows with Coulomb-bounded tangential unknowns (HiGHS), `j` the rows acted on.

    Unknowns (lam, tp, tm, s, t), lam_t = tp - tm: a^T lam + at^T (tp - tm) + load s = 0,
    tp + tm <= mu lam, t <= lam, s >= 1, 0 <= t <= 1; each row's unknowns scaled by its
    size (a row no mode acts on: scale 1).
    """
    import scipy.sparse as sp  # with scipy.optimize below: only for a frictional scene
    from scipy.optimize import linprog

    rn = np.abs(a[j]).max(axis=1)
    rt = np.abs(at[j]).max(axis=1)
    rn, rt = np.where(rn > 0, rn, 1.0), np.where(rt > 0, rt, 1.0)
    an, atn = a[j] / rn[:, None], at[j] / rt[:, None]
    fl = load / max(float(np.abs(load).max()), 1e-300)
    m, k = len(j), a.shape[1]
    z = sp.csr_matrix((k, m))
    a_eq = sp.hstack(
        [
            sp.csr_matrix(an.T),
            sp.csr_matrix(atn.T),
            sp.csr_matrix(-atn.T),
            sp.csr_matrix(fl.reshape(k, 1)),
            z,
        ]
    )
    eye = sp.identity(m, format="csr")
    col = sp.csr_matrix((m, 1))
    bound = sp.diags(mu[j] * rt / rn)
    cone = sp.hstack([-bound, eye, eye, col, sp.csr_matrix((m, m))])
    stick = sp.hstack([-eye, sp.csr_matrix((m, 2 * m)), col, eye])
    c = np.concatenate([np.zeros(3 * m + 1), -np.ones(m)])
    bounds = [(0.0, None)] * (3 * m) + [(1.0, None)] + [(0.0, 1.0)] * m
    res = linprog(
        c,
        sp.vstack([cone, stick]),
        np.zeros(2 * m),
        a_eq,
        np.zeros(k),
        bounds=bounds,
        method="highs",
    )
    if res.status == 2:
        return None
    if res.status != 0:
        raise SingularSystemError(
            f"the check of which contacts can hold the bodies failed: {res.message}"
        )
    out[j] = res.x[3 * m + 1 :] > 0.5
    return out


def pulled_away(a: np.ndarray, load: np.ndarray) -> np.ndarray:
    """A free-mode combination y with a y >= 0 (no gap closes) and load . y = 1 (Farkas)."""
    k = a.shape[1]
    on = np.abs(a).max(axis=1, initial=0.0) > 0.0
    aj = a[on] / np.abs(a[on]).max(axis=1, keepdims=True)
    fl = load / max(float(np.abs(load).max()), 1e-300)
    from scipy.optimize import linprog  # scipy.optimize (~0.15 s) only for a refusal

    res = linprog(
        np.zeros(k),
        -aj if aj.size else None,
        np.zeros(len(aj)) if aj.size else None,
        fl.reshape(1, k),
        np.ones(1),
        bounds=[(None, None)] * k,
        method="highs",
    )
    return np.asarray(res.x) if res.status == 0 else np.ones(k)
