"""The end modification at the ends of a passive surface against brute-force integrals.

Nodes whose support the passive surface covers only partly (beyond its end, on it, or the
last node before it) carry no multiplier: their basis functions merge into the first node
inside whose support it covers wholly (contact/operator.py, `end_rows`; docs/edges.md).
"""

import numpy as np
import pytest
from conftest import polyline, reshuffled

from contactfx.contact import OPERATORS

H = 0.1  # active segment length
FRACTIONS = [0.0, 0.3, 0.5, 0.72, 0.9, 0.999]


def shifted_pair(f: float):
    """Passive [0, 1] (7 nodes, y = 0, normal +y) and an active line y = 0.01 + 0.02 x above it,
    nodes spaced H from (f + 2) H before x = 0 to 2 cells beyond x = 1: f moves the nodes
    across both ends by a fraction of a cell (at x = 1 they fall by 1 - f - 0.1 mod 1)."""
    xa = -(f + 2) * H + H * np.arange(int(np.ceil((1 + (f + 4) * H) / H)) + 1)
    xp = np.array([0.0, 0.13, 0.3, 0.42, 0.61, 0.77, 1.0])
    ya = 0.01 + 0.02 * xa
    passive = polyline(xp, 0 * xp, True, 0)
    active = polyline(xa, ya, False, 2 * len(xp))
    return active, passive, 2 * (len(xp) + len(xa)), xa, ya


def merged_groups(xa: np.ndarray) -> dict[int, list[int]]:
    """Independent rule: each node whose support [x_{j-1}, x_{j+1}] lies in [0, 1] keeps a row;
    a node whose support crosses 0 or 1 joins the nearest such node on its side. A support
    within 1 % of a cell of [0, 1] counts as inside (operator.REACH: slivers keep their row)."""
    lo = np.r_[xa[0], xa[:-1]]
    hi = np.r_[xa[1:], xa[-1]]
    whole = (lo >= -0.01 * H) & (hi <= 1 + 0.01 * H)
    partial = ~whole & (hi > 1e-12) & (lo < 1 - 1e-12)
    groups = {j: [j] for j in np.flatnonzero(whole)}
    first, last = np.flatnonzero(whole)[[0, -1]]
    for j in np.flatnonzero(partial):
        groups[first if j < first else last].append(j)
    assert all(j < first or j > last for j in np.flatnonzero(partial))
    return {int(k): [int(v) for v in g] for k, g in groups.items()}


def hat(xa: np.ndarray, j: int, x: np.ndarray) -> np.ndarray:
    """The active surface's piecewise-linear shape function of node j at x."""
    e = np.zeros(len(xa))
    e[j] = 1.0
    return np.interp(x, xa, e)


def pieces(xa: np.ndarray, xp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A 6-point Gauss rule on every piece between breakpoints of both surfaces in [0, 1]."""
    cuts = np.unique(np.clip(np.r_[xa, xp], 0.0, 1.0))
    g, w = np.polynomial.legendre.leggauss(6)
    a, b = cuts[:-1, None], cuts[1:, None]
    return (a + 0.5 * (b - a) * (g + 1)).ravel(), (0.5 * (b - a) * w).ravel()


def dual_basis(xa: np.ndarray, j: int, x: np.ndarray) -> np.ndarray:
    """Consistent dual psi_j of the unmodified basis at x: D_e M_e^-1 on each segment's overlap."""
    out = np.zeros_like(x)
    for e in (j - 1, j):
        if e < 0 or e + 1 >= len(xa):
            continue
        a, b = xa[e], xa[e + 1]
        lo, hi = max(a, 0.0), min(b, 1.0)
        if hi <= lo:
            continue
        g, w = np.polynomial.legendre.leggauss(6)
        s = lo + 0.5 * (hi - lo) * (g + 1)
        w = 0.5 * (hi - lo) * w
        N = np.column_stack([(b - s) / (b - a), (s - a) / (b - a)])
        M = N.T @ (w[:, None] * N)
        A = np.diag(N.T @ w) @ np.linalg.inv(M)
        k = j - e  # which end of segment e node j is
        inside = (x >= lo) & (x <= hi) & (x >= a) & (x < b)
        Nx = np.column_stack([(b - x) / (b - a), (x - a) / (b - a)])
        out[inside] = (Nx @ A[k])[inside]
    return out


@pytest.mark.parametrize("basis", ["standard", "dual"])
@pytest.mark.parametrize("f", FRACTIONS)
def test_mortar_rows_against_brute_force(basis, f):
    active, passive, nd, xa, ya = shifted_pair(f)
    op = OPERATORS["mortar"](active, passive, nd, basis=basis)
    groups = merged_groups(xa)
    assert sorted(groups) == op.rows.tolist()
    xp = passive.x[:, 0]
    x, w = pieces(xa, xp)
    w = w * np.hypot(1.0, 0.02)  # dGamma on the tilted active line
    # A displacement field of both bodies: the weighted gap of row j is
    # int phi_j (y_a + u_ay - u_py) dx, phi_j the sum of the merged basis functions.
    rng = np.random.default_rng(7)
    ua, up = rng.normal(size=(len(xa), 2)) * 1e-3, rng.normal(size=(len(xp), 2)) * 1e-3
    u = np.zeros(nd)
    u[active.dofs] = ua
    u[passive.dofs] = up
    gap = np.interp(x, xa, ya + ua[:, 1]) - np.interp(x, xp, up[:, 1])
    shape = hat if basis == "standard" else dual_basis
    for j, members in groups.items():
        phi = sum(shape(xa, k, x) for k in members)
        np.testing.assert_allclose(op.weights[j], w @ phi, rtol=1e-12)
        np.testing.assert_allclose(op.gap[j] + (op.B @ u)[j], w @ (phi * gap), rtol=1e-10)
    # The merged rows still reproduce a constant: the rows' weights sum to the overlap.
    np.testing.assert_allclose(op.weights.sum(), np.hypot(1.0, 0.02), rtol=1e-13)


@pytest.mark.parametrize("f", [0.3, 0.72])
def test_sts_has_the_same_rows_and_merged_weights(f):
    active, passive, nd, _, _ = shifted_pair(f)
    sts = OPERATORS["sts"](active, passive, nd)
    mortar = OPERATORS["mortar"](active, passive, nd)
    np.testing.assert_array_equal(sts.rows, mortar.rows)
    # 4 Gauss points per segment: the straddling segments count from their first found point
    # on, so only the anchors' weights differ, by less than one straddling segment's length.
    assert np.all(np.abs(sts.weights - mortar.weights) < H)
    inner = np.setdiff1d(mortar.rows, mortar.rows[[0, -1]])
    np.testing.assert_allclose(sts.weights[inner], mortar.weights[inner], rtol=1e-12)


@pytest.mark.parametrize("method", ["mortar", "sts"])
def test_end_rows_do_not_depend_on_segment_orientation_or_order(method):
    active, passive, nd, _, _ = shifted_pair(0.72)
    op = OPERATORS[method](active, passive, nd)
    op2 = OPERATORS[method](reshuffled(active, 5), passive, nd)
    np.testing.assert_array_equal(op2.rows, op.rows)
    np.testing.assert_allclose(op2.weights, op.weights, rtol=1e-13)
    np.testing.assert_allclose(op2.gap, op.gap, rtol=1e-12)
