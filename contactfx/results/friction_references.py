"""Frictional reference solutions, computed independently of the solver (numpy and scipy only).

- Cattaneo-Mindlin (`cattaneo_mindlin`): two similar elastic bodies pressed by P, then pushed by
  a tangential Q < mu P. The pressure stays Hertz's; the shear is the full-slip shear mu p less
  a Hertz-shaped correction over the stick zone |x| < c. Line contact (a cylinder, plane strain)
  and point contact (a sphere, axisymmetric): Johnson, Contact Mechanics, sec. 7.1 and 7.2.
- Spence (`spence_stick_ratio`): a rigid cylinder pressed with friction into an elastic
  half-plane under increasing load. The stick half-width c is a fixed fraction of the contact
  half-width a, which depends on the friction coefficient and on Poisson's ratio (through the
  coupling constant beta). docs/friction_verification.md derives the formulation;
  benchmarks/spence_bem.py is the second, independent route (the loading history by a
  half-plane boundary-element method). `half_plane_influence` holds the surface Green's
  functions both use.

Conventions of the half-plane functions: x along the surface, p > 0 a compressive pressure on the
half-plane, q its shear along +x; u_z the surface displacement into the solid, u_x along +x;
E_star = E / (1 - nu^2) of the half-plane (the indenter is rigid) and

    beta = (1 - 2 nu) / (2 (1 - nu)),

    du_x/dx = -(2 / (pi E*)) [pi beta p(x) + pv int q(s) / (x - s) ds],
    du_z/dx = -(2 / (pi E*)) [pv int p(s) / (x - s) ds - pi beta q(x)]

(Johnson eqs. 2.25-2.26 divided by 2 (1 - nu^2) / E).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Geometries of `cattaneo_mindlin`: a cylinder (line contact, forces per unit length) or a sphere.
GEOMETRIES = ("cylinder", "sphere")


@dataclass(frozen=True)
class CattaneoMindlin:
    """Hertz pressure and Cattaneo-Mindlin shear of a contact of half-width (or radius) a."""

    geometry: str  # "cylinder" (x is the coordinate across the line) or "sphere" (x = r)
    a: float  # contact half-width (cylinder) or radius (sphere)
    p0: float  # peak Hertz pressure
    mu: float  # Coulomb friction coefficient
    c: float  # stick half-width or radius

    @property
    def normal_force(self) -> float:
        """P: per unit length for a cylinder (pi a p0 / 2), total for a sphere (2 pi a^2 p0 / 3)."""
        if self.geometry == "cylinder":
            return 0.5 * np.pi * self.a * self.p0
        return 2.0 * np.pi * self.a**2 * self.p0 / 3.0

    @property
    def tangential_force(self) -> float:
        """Q = mu P (1 - (c/a)^2) for a cylinder, mu P (1 - (c/a)^3) for a sphere."""
        k = 2 if self.geometry == "cylinder" else 3
        return self.mu * self.normal_force * (1.0 - (self.c / self.a) ** k)

    def pressure(self, x: np.ndarray) -> np.ndarray:
        """Hertz pressure p0 sqrt(1 - x^2/a^2) at x (0 outside the contact)."""
        return self.p0 * _ellipse(np.asarray(x, dtype=float), self.a)

    def shear(self, x: np.ndarray) -> np.ndarray:
        """Shear along the push: mu p, less mu p0 (c/a) sqrt(1 - x^2/c^2) inside the stick zone."""
        x = np.asarray(x, dtype=float)
        return self.mu * (self.pressure(x) - self.p0 * (self.c / self.a) * _ellipse(x, self.c))

    def stick(self, x: np.ndarray) -> np.ndarray:
        """Whether each point lies in the stick zone |x| < c."""
        return np.abs(np.asarray(x, dtype=float)) < self.c


@dataclass(frozen=True)
class CattaneoErrors:
    """A computed interface against Cattaneo-Mindlin (line contact)."""

    shear_l2: float  # ||q_h - q|| / ||q|| over the contact, q_h piecewise linear in the nodes
    c: float  # stick half-width read from the statuses (edges halfway to the slip neighbours)
    c_exact: float
    slip_law: float  # max over slip nodes of ||q_h| - mu p_h| / (mu p0)
    pressure_l2: float = 0.0  # ||p_h - p|| / ||p||: the pressure against Hertz's, the same way


def cattaneo_errors(
    ref: CattaneoMindlin,
    x: np.ndarray,
    shear: np.ndarray,
    pressure: np.ndarray,
    stick: np.ndarray,
) -> CattaneoErrors:
    """Compare nodal shear, pressure and stick flags at x (across the line, centred) with ref."""
    if ref.geometry != "cylinder":
        raise ValueError("cattaneo_errors: line contacts only")
    order = np.argsort(x)
    x, q, p, st = (np.asarray(v)[order] for v in (x, shear, pressure, stick))
    # Gauss points on every node interval, split at the closed form's kinks (+-c, +-a).
    cuts = np.unique(np.concatenate([x, [-ref.a, -ref.c, ref.c, ref.a]]))
    cuts = cuts[(cuts >= min(x[0], -ref.a)) & (cuts <= max(x[-1], ref.a))]
    gx, gw = np.polynomial.legendre.leggauss(16)
    mid, half = 0.5 * (cuts[1:] + cuts[:-1]), 0.5 * np.diff(cuts)
    pts = (mid[:, None] + half[:, None] * gx).ravel()
    wts = (half[:, None] * gw).ravel()
    exact = ref.shear(pts)
    computed = np.interp(pts, x, q, left=0.0, right=0.0)
    l2 = np.sqrt(wts @ (computed - exact) ** 2) / np.sqrt(wts @ exact**2)
    hertz = ref.pressure(pts)
    p_h = np.interp(pts, x, p, left=0.0, right=0.0)
    p_l2 = np.sqrt(wts @ (p_h - hertz) ** 2) / np.sqrt(wts @ hertz**2)
    c = 0.0
    idx = np.flatnonzero(st)
    if idx.size:
        lo, hi = idx[0], idx[-1]
        left = 0.5 * (x[lo] + x[lo - 1]) if lo > 0 else x[lo]
        right = 0.5 * (x[hi] + x[hi + 1]) if hi + 1 < len(x) else x[hi]
        c = 0.5 * (right - left)
    slip = ~st & (p > 0)
    excess = np.abs(np.abs(q[slip]) - ref.mu * p[slip])
    slip_law = float(excess.max(initial=0.0) / (ref.mu * ref.p0))
    return CattaneoErrors(
        shear_l2=float(l2), c=float(c), c_exact=ref.c, slip_law=slip_law, pressure_l2=float(p_l2)
    )


def _ellipse(x: np.ndarray, half: float) -> np.ndarray:
    """sqrt(1 - x^2/half^2) inside |x| < half, 0 outside (and 0 everywhere if half is 0)."""
    if half <= 0.0:
        return np.zeros_like(x)
    return np.sqrt(np.clip(1.0 - (x / half) ** 2, 0.0, None))


def hertz_half_width(P: float, R: float, E_star: float, geometry: str = "cylinder") -> float:
    """Hertz contact half-width a (cylinder: a^2 = 4 P R / (pi E*)) or radius (a^3 = 3 P R / 4 E*).

    R is the effective radius (1/R = 1/R1 + 1/R2), E* the contact modulus
    (1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2), P per unit length for a cylinder.
    """
    _check_geometry(geometry)
    if geometry == "cylinder":
        return float(np.sqrt(4.0 * P * R / (np.pi * E_star)))
    return float(np.cbrt(3.0 * P * R / (4.0 * E_star)))


def cattaneo_mindlin(
    P: float, Q: float, mu: float, R: float, E_star: float, geometry: str = "cylinder"
) -> CattaneoMindlin:
    """Cattaneo-Mindlin for similar materials: c = a sqrt(1 - Q/(mu P)) or a (1 - Q/(mu P))^(1/3).

    Holds when the normal approach makes no relative slip (similar materials, or a frictionless
    approach); 0 <= Q <= mu P is required (Q = mu P is gross sliding: c = 0).
    """
    _check_geometry(geometry)
    if not (P > 0 and R > 0 and E_star > 0):
        raise ValueError("cattaneo_mindlin: P, R and E_star must be positive")
    if not mu > 0:
        raise ValueError(f"cattaneo_mindlin: mu must be positive, got {mu}")
    if not 0.0 <= Q <= mu * P:
        raise ValueError(f"cattaneo_mindlin: need 0 <= Q <= mu P = {mu * P:g}, got Q = {Q:g}")
    a = hertz_half_width(P, R, E_star, geometry)
    if geometry == "cylinder":
        p0, ratio = 2.0 * P / (np.pi * a), np.sqrt(1.0 - Q / (mu * P))
    else:
        p0, ratio = 3.0 * P / (2.0 * np.pi * a**2), np.cbrt(1.0 - Q / (mu * P))
    return CattaneoMindlin(geometry=geometry, a=a, p0=p0, mu=mu, c=float(a * ratio))


def _check_geometry(geometry: str) -> None:
    """Reject an unknown geometry name."""
    if geometry not in GEOMETRIES:
        raise ValueError(f"unknown geometry {geometry!r} (known: {', '.join(GEOMETRIES)})")


def coupling_beta(nu: float) -> float:
    """Dundurs' beta of a rigid body on an elastic one: (1 - 2 nu) / (2 (1 - nu))."""
    if not -1.0 < nu <= 0.5:
        raise ValueError(f"Poisson's ratio must lie in (-1, 0.5], got {nu}")
    return (1.0 - 2.0 * nu) / (2.0 * (1.0 - nu))


def half_plane_influence(
    edges: np.ndarray, points: np.ndarray, beta: float, E_star: float = 1.0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Surface displacements at `points` of unit uniform tractions on the cells between `edges`.

    Returns (G, H, K), each (points, cells): u_z from p and u_x from q are both G (the
    logarithmic kernel, up to a rigid constant), u_x from p is -H and u_z from q is +H (the
    coupling, H = (beta / E*) int sgn(x - s) ds): with p, q the cell values,

        u_z = G p + H q,   u_x = G q - H p.

    K is the cells' (points, cells) indicator of the point inside the cell (for tests).
    """
    e = np.asarray(edges, dtype=float)
    x = np.asarray(points, dtype=float)[:, None]
    lo, hi = e[None, :-1], e[None, 1:]

    def prim(y: np.ndarray) -> np.ndarray:
        # int ln|y| dy = y ln|y| - y, continuous through 0.
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(y == 0.0, 0.0, y * np.log(np.abs(y))) - y

    # u_z(x) = -(2 / (pi E*)) int p(s) ln|x - s| ds, and over a cell
    # int_lo^hi ln|x - s| ds = prim(x - lo) - prim(x - hi).
    G = -(2.0 / (np.pi * E_star)) * (prim(x - lo) - prim(x - hi))
    # int_lo^hi sgn(x - s) ds = (length left of x) - (length right of x)
    left = np.clip(x, lo, hi) - lo
    H = (beta / E_star) * (left - (hi - lo - left))
    K = ((x >= lo) & (x < hi)).astype(float)
    return G, H, K


def _graded(lo: float, hi: float, n: int) -> np.ndarray:
    """Edges of n cells on [lo, hi], clustered towards both ends (cosine spacing)."""
    t = 0.5 * (1.0 - np.cos(np.linspace(0.0, np.pi, n + 1)))
    return lo + (hi - lo) * t


def _flat_punch_increment(
    kappa: float, mu: float, beta: float, n: int, coupled: bool
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The load increment d/da of the self-similar problem for the stick ratio kappa.

    On 0 < x < 1 (a = 1); returns the cells' edges, midpoints, dp, dq and du_x.

    d/da turns the Hertz problem into a flat punch: du_z = 1 on the whole contact, du_x = 0 on
    the stick zone, dq = mu dp on the slip zone (shear outwards), dp = dq = 0 outside. Symmetry
    (p even, q odd) halves the unknowns: a cell at x > 0 has a mirror at -x.
    """
    ns = min(max(round(n * kappa), n // 4), n - n // 4)
    e_in = np.concatenate([_graded(-kappa, kappa, 2 * ns)[ns:], _graded(kappa, 1.0, n - ns)[1:]])
    # Both halves of the mirror: cell edges on (-1, 1), the x > 0 ones first.
    xm = 0.5 * (e_in[:-1] + e_in[1:])
    edges = np.concatenate([-e_in[::-1], e_in[1:]])
    G, H, _ = half_plane_influence(edges, xm, beta)
    m = len(xm)
    # Columns of the left half (x < 0) are the mirrors of the right ones, in reverse order.
    Gs = G[:, m:] + G[:, :m][:, ::-1]  # p even: p(-x) = p(x)
    Ga = G[:, m:] - G[:, :m][:, ::-1]  # q odd: q(-x) = -q(x)
    Hs = H[:, m:] + H[:, :m][:, ::-1]
    Ha = H[:, m:] - H[:, :m][:, ::-1]
    if not coupled:
        Ha = np.zeros_like(Ha)  # Goodman: the shear does not move the surface normally
    stick = xm < kappa
    # Unknowns [dp, dq, dz0]: u_z = Gs dp + Ha dq + const (the log kernel's rigid constant).
    A = np.zeros((2 * m + 1, 2 * m + 1))
    b = np.zeros(2 * m + 1)
    A[:m, :m], A[:m, m : 2 * m], A[:m, 2 * m] = Gs, Ha, -1.0
    b[:m] = 1.0
    rows = np.arange(m, 2 * m)
    A[rows[stick], :m] = -Hs[stick]
    A[rows[stick], m : 2 * m] = Ga[stick]
    slip = ~stick
    A[rows[slip], np.flatnonzero(slip)] = -mu
    A[rows[slip], m + np.flatnonzero(slip)] = 1.0
    # The normal load increment fixes the scale: dP = 2 int_0^1 dp = 1.
    A[2 * m, :m] = 2.0 * np.diff(e_in)
    b[2 * m] = 1.0
    sol = np.linalg.solve(A, b)
    dp, dq = sol[:m], sol[m : 2 * m]
    dux = Ga @ dq - Hs @ dp
    return e_in, xm, dp, dq, dux


def _edge_slip(kappa: float, mu: float, beta: float, n: int, coupled: bool) -> float:
    """Slip rate du_x at the first slip cell past the stick edge, scaled by the largest."""
    _, xm, _, _, dux = _flat_punch_increment(kappa, mu, beta, n, coupled)
    first = int(np.flatnonzero(xm > kappa)[0])
    scale = np.abs(dux).max()
    return float(dux[first] / scale)


def spence_stick_ratio(mu: float, nu: float, n: int = 300, coupled: bool = True) -> float:
    """c/a of a rigid cylinder pressed with friction mu into a half-plane of Poisson's ratio nu.

    Spence's self-similar reduction (docs/friction_verification.md): the load increment is a
    flat-punch problem whose stick zone is c/a; c/a is the root of the slip rate's sqrt(x - c)
    term at the stick edge (a wrong c gives a slip against the shear on one side of the root,
    or a shear above mu p inside the stick zone on the other). coupled=False is Goodman's
    approximation (the shear's effect on the pressure dropped): c/a then depends on mu / beta
    only.
    """
    # scipy only here: a run with a Cattaneo reference imports this module, and the command
    # line loads no scipy (tests/cli/test_import_cost.py).
    from scipy.optimize import brentq

    if not mu > 0:
        raise ValueError(f"spence_stick_ratio: mu must be positive, got {mu}")
    beta = coupling_beta(nu)
    if beta == 0.0:
        raise ValueError("spence_stick_ratio: nu = 0.5 has no slip (beta = 0): c/a = 1")
    lo, hi = 0.02, 0.995
    f_lo, f_hi = _edge_slip(lo, mu, beta, n, coupled), _edge_slip(hi, mu, beta, n, coupled)
    if np.sign(f_lo) == np.sign(f_hi):
        raise ValueError(f"spence_stick_ratio: no stick edge in [{lo}, {hi}] for mu={mu}, nu={nu}")
    return float(brentq(_edge_slip, lo, hi, args=(mu, beta, n, coupled), xtol=1e-10))
