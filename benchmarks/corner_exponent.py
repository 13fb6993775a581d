"""The pressure singularity at a sharp edge pressed frictionlessly on an elastic body.

A wedge of angle phi (body 1: 0 <= theta <= phi; phi = pi/2 for a square hub edge) is pressed
on an elastic half-plane (body 2: -pi <= theta <= 0) along theta = 0, without friction; the
corner is the origin. Near it every field is a sum of Williams terms: in each body the Airy
function r^(lam + 1) F(theta) with

    F = A cos((lam + 1) theta) + B sin((lam + 1) theta) + C cos((lam - 1) theta)
        + D sin((lam - 1) theta),

    sigma_tt = lam (lam + 1) r^(lam - 1) F,  sigma_rt = -lam r^(lam - 1) F',
    sigma_rr = r^(lam - 1) ((lam + 1) F + F''),

and (plane strain, kappa = 3 - 4 nu; `_fields` checks them against Hooke's law)

    2 mu u_r = r^lam (-(lam + 1)(A cos + B sin)((lam + 1) theta)
                      + (kappa - lam)(C cos + D sin)((lam - 1) theta)),
    2 mu u_t = r^lam ((lam + 1)(A sin - B cos)((lam + 1) theta)
                      + (kappa + lam)(C sin - D cos)((lam - 1) theta)).

Eight conditions on the eight coefficients: the free wedge face (sigma_tt = sigma_rt = 0 at
theta = phi), the free half-plane surface beyond the edge (the same at theta = -pi), and on
the contact line theta = 0 no shear on either side, equal normal stress and equal normal
displacement u_t. A non-zero solution needs det M(lam) = 0; the smallest root in (0, 1) gives
the pressure p ~ r^(lam - 1): the singularity exponent is s = 1 - lam. The same condition is
Dundurs and Lee's (1972) and Comninou's (1976, frictionless limit) for a sharp edge.

Checks (tests/contact/test_corner_exponent.py): a rigid wedge (mu1 -> inf) gives the flat
punch's lam = 1/2; the same machinery for a free 270-degree corner gives Williams' 0.5445.
For a square edge of the same material as the half-plane lam = 0.77401, s = 0.22599, for
every nu (the wedge and the half-plane then share kappa, which leaves the determinant).

Run: python benchmarks/corner_exponent.py   (prints s for a few material pairs)
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq


def _fields(lam: float, theta: float, nu: float, mu: float = 1.0) -> tuple[np.ndarray, ...]:
    """Rows mapping (A, B, C, D) to sigma_rr, sigma_tt, sigma_rt, u_r, u_t at r = 1."""
    kappa = 3.0 - 4.0 * nu
    a, b = lam + 1.0, lam - 1.0
    ca, sa, cb, sb = np.cos(a * theta), np.sin(a * theta), np.cos(b * theta), np.sin(b * theta)
    F = np.array([ca, sa, cb, sb])
    dF = np.array([-a * sa, a * ca, -b * sb, b * cb])
    d2F = np.array([-a * a * ca, -a * a * sa, -b * b * cb, -b * b * sb])
    ur = np.array([-a * ca, -a * sa, (kappa - lam) * cb, (kappa - lam) * sb]) / (2.0 * mu)
    ut = np.array([a * sa, -a * ca, (kappa + lam) * sb, -(kappa + lam) * cb]) / (2.0 * mu)
    return a * F + d2F, lam * a * F, -lam * dF, ur, ut


def contact_determinant(
    lam: float, phi: float, nu1: float, nu2: float, mu_ratio: float = 1.0
) -> float:
    """det M(lam): wedge (0..phi, shear modulus mu_ratio) on a half-plane (-pi..0, modulus 1)."""
    M = np.zeros((8, 8))
    _, stt, srt, _, _ = _fields(lam, phi, nu1, mu_ratio)
    M[0, :4], M[1, :4] = stt, srt
    _, stt, srt, _, _ = _fields(lam, -np.pi, nu2)
    M[2, 4:], M[3, 4:] = stt, srt
    _, stt1, srt1, _, ut1 = _fields(lam, 0.0, nu1, mu_ratio)
    _, stt2, srt2, _, ut2 = _fields(lam, 0.0, nu2)
    M[4, :4], M[5, 4:] = srt1, srt2
    M[6, :4], M[6, 4:] = stt1, -stt2
    M[7, :4], M[7, 4:] = ut1, -ut2
    return float(np.linalg.det(M))


def free_corner_determinant(lam: float, angle: float, nu: float = 0.3) -> float:
    """det of a single wedge -angle/2..angle/2 with both faces free (Williams' corner)."""
    rows = []
    for theta in (-angle / 2, angle / 2):
        _, stt, srt, _, _ = _fields(lam, theta, nu)
        rows += [stt, srt]
    return float(np.linalg.det(np.array(rows)))


def smallest_root(f, lo: float = 1e-3, hi: float = 0.999, n: int = 2000) -> float:
    """The smallest sign change of f on [lo, hi], refined by Brent's method."""
    x = np.linspace(lo, hi, n)
    y = np.array([f(v) for v in x])
    change = np.flatnonzero(np.sign(y[:-1]) != np.sign(y[1:]))
    if not change.size:
        raise ValueError("no root in (lo, hi)")
    k = int(change[0])
    return float(brentq(f, x[k], x[k + 1], xtol=1e-14))


def edge_exponent(
    phi: float = np.pi / 2, nu1: float = 0.3, nu2: float = 0.3, mu_ratio: float = 1.0
) -> float:
    """The pressure singularity exponent s (p ~ r^-s) at the edge of a wedge of angle phi."""
    lam = smallest_root(lambda v: contact_determinant(v, phi, nu1, nu2, mu_ratio))
    return 1.0 - lam


if __name__ == "__main__":
    print(f"square edge, same material:        s = {edge_exponent():.5f}")
    print(f"square edge, rigid wedge (punch):  s = {edge_exponent(mu_ratio=1e9):.5f}")
    print(f"square edge, steel on aluminium:   s = {edge_exponent(mu_ratio=3.0, nu2=0.33):.5f}")
    print(f"120-degree edge, same material:    s = {edge_exponent(phi=2 * np.pi / 3):.5f}")
