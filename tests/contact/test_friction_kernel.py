"""The Coulomb complementarity kernel (contact/friction.py) and the tangential contact rows."""

import numpy as np
import pytest
from conftest import polyline
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from contactfx.contact import contact_operator
from contactfx.contact.friction import Status, classify, linearize, ncp
from contactfx.contact.operator import tangents

FAST = settings(max_examples=60, deadline=None)
positive = st.floats(0.05, 20.0)
value = st.floats(-5.0, 5.0)


def pair_surfaces(xp, yp, xa, ya):
    """Passive lower surface (normal +y), active upper surface (normal -y), total dof count."""
    passive = polyline(np.asarray(xp), np.asarray(yp), True, 0)
    active = polyline(np.asarray(xa), np.asarray(ya), False, 2 * len(xp))
    return active, passive, 2 * (len(xp) + len(xa))


# ---------------------------------------------------------------- the law itself


def coulomb_state(status: Status, lam: float, frac: float, g: float, u: float, mu: float):
    """A state satisfying Coulomb's law and the normal complementarity in the given set.

    Written from the law, not from the kernel: open (lambda = 0, g > 0, any slip), stick
    (g = 0, lambda_n > 0, |lambda_t| < mu lambda_n, no slip), slip (g = 0, lambda_t = mu
    lambda_n s, slip u_t = s |u| along it).
    """
    if status == Status.OPEN:
        return 0.0, 0.0, abs(g) + 1e-3, u
    if status == Status.STICK:
        return lam, mu * lam * frac, 0.0, 0.0
    s = 1.0 if u >= 0 else -1.0
    return lam, mu * lam * s, 0.0, s * (abs(u) + 1e-3)


@FAST
@given(
    status=st.sampled_from(list(Status)),
    lam=positive,
    frac=st.floats(-0.99, 0.99),
    g=value,
    u=value,
    mu=st.floats(0.01, 2.0),
    c_n=positive,
    c_t=positive,
)
def test_law_states_are_roots_in_their_set(status, lam, frac, g, u, mu, c_n, c_t):
    """Every state of Coulomb's law is a root of C in its own set, whatever c_n, c_t > 0."""
    state = [np.array([v]) for v in coulomb_state(status, lam, frac, g, u, mu)]
    assert classify(*state, mu, c_n, c_t)[0] == status
    cn, ct = ncp(*state, mu, c_n, c_t)
    assert abs(cn[0]) <= 1e-12 * (1 + lam) and abs(ct[0]) <= 1e-12 * (1 + lam)


@FAST
@given(lam_n=value, lam_t=value, g=value, u=value, mu=st.floats(0.0, 2.0), c=positive)
def test_classification_against_brute_force(lam_n, lam_t, g, u, mu, c):
    """The set of any state is the branch a brute-force projection picks.

    Brute force: the candidate tangential multipliers are tau itself (stick), +-mu xi (slip)
    and 0 (open); the projection of tau = lambda_t + c u_t onto the friction interval
    [-mu xi+, mu xi+] is the admissible candidate nearest to tau, searched over a fine grid.
    """
    xi, tau = lam_n - c * g, lam_t + c * u
    bound = mu * max(xi, 0.0)
    assume(abs(xi) > 1e-6 and abs(abs(tau) - bound) > 2e-4 * (1.0 + bound))
    grid = np.linspace(-bound, bound, 20001)
    nearest = grid[np.argmin(np.abs(grid - tau))]
    if xi <= 0:
        expect = Status.OPEN
    elif abs(nearest - tau) <= (grid[1] - grid[0] if bound > 0 else 0.0):
        expect = Status.STICK
    else:
        expect = Status.SLIP
    got = classify(np.array([lam_n]), np.array([lam_t]), np.array([g]), np.array([u]), mu, c, c)
    assert got[0] == expect


@FAST
@given(
    lam_n=value, lam_t=value, g=value, u=value, mu=st.floats(0.0, 2.0), c_n=positive, c_t=positive
)
def test_linearization_is_the_derivative(lam_n, lam_t, g, u, mu, c_n, c_t):
    """Each set's rows equal central differences of C (away from the kinks between sets)."""
    x = np.array([lam_n, lam_t, g, u])
    xi, tau = lam_n - c_n * g, lam_t + c_t * u
    eps = 1e-6
    kink = 10 * eps * (1 + c_n + c_t) * (1 + mu)
    assume(abs(xi) > kink and abs(abs(tau) - mu * max(xi, 0.0)) > kink and abs(tau) > kink)
    rows = linearize(*[np.array([v]) for v in x], mu, c_n, c_t)
    for k in range(4):
        d = np.zeros(4)
        d[k] = eps
        hi = ncp(*[np.array([v]) for v in x + d], mu, c_n, c_t)
        lo = ncp(*[np.array([v]) for v in x - d], mu, c_n, c_t)
        np.testing.assert_allclose(rows.dn[0, k], (hi[0] - lo[0])[0] / (2 * eps), atol=1e-6)
        np.testing.assert_allclose(rows.dt[0, k], (hi[1] - lo[1])[0] / (2 * eps), atol=1e-6)
    # C is linear and homogeneous on each set: the set's rows reproduce C itself.
    cn, ct = ncp(*[np.array([v]) for v in x], mu, c_n, c_t)
    np.testing.assert_allclose([rows.dn[0] @ x, rows.dt[0] @ x], [cn[0], ct[0]], atol=1e-10)


def test_frictionless_rows():
    """mu = 0: no row sticks, C_t = lambda_t, and the Newton rows set lambda_t = 0 alone."""
    rng = np.random.default_rng(3)
    lam_n, lam_t, g, u = rng.normal(size=(4, 200))
    status = classify(lam_n, lam_t, g, u, 0.0, 2.0, 3.0)
    assert not np.any(status == Status.STICK)
    assert np.any(status == Status.SLIP) and np.any(status == Status.OPEN)
    np.testing.assert_array_equal(ncp(lam_n, lam_t, g, u, 0.0, 2.0, 3.0)[1], lam_t)
    rows = linearize(lam_n, lam_t, g, u, 0.0, 2.0, 3.0)
    np.testing.assert_array_equal(rows.dt, np.tile([0.0, 1.0, 0.0, 0.0], (200, 1)))
    # The normal rows are the frictionless ones: c_n on g in contact, 1 on lambda_n when open.
    contact = status != Status.OPEN
    np.testing.assert_array_equal(rows.dn[contact], np.tile([0, 0, 2.0, 0], (contact.sum(), 1)))
    np.testing.assert_array_equal(rows.dn[~contact], np.tile([1.0, 0, 0, 0], ((~contact).sum(), 1)))


def test_bad_parameters():
    one = np.ones(1)
    with pytest.raises(ValueError, match="mu must be >= 0"):
        classify(one, one, one, one, -0.1, 1.0, 1.0)
    with pytest.raises(ValueError, match="c_n, c_t > 0"):
        ncp(one, one, one, one, 0.3, 0.0, 1.0)


# ---------------------------------------------------------------- the tangential rows


KERNELS = [("nts", {}), ("mortar", {}), ("mortar", {"basis": "dual"})]


@pytest.mark.parametrize(("kernel", "options"), KERNELS)
def test_tangential_rows(kernel, options):
    """Tangential rows: zero weighted slip for a rigid translation of both bodies, the weights
    times d for the active body slid by d along the interface, and the normal rows unchanged."""
    xp = np.array([0.0, 0.13, 0.3, 0.42, 0.61, 0.77, 0.9, 1.0])
    xa = np.array([0.05, 0.2, 0.37, 0.55, 0.8, 0.95])
    active, passive, nd = pair_surfaces(xp, 0 * xp, xa, 0.01 + 0 * xa)
    normal = contact_operator(kernel, active, passive, nd, **options)
    same = contact_operator(kernel, active, passive, nd, direction="normal", **options)
    slip = contact_operator(kernel, active, passive, nd, direction="tangent", **options)
    np.testing.assert_array_equal(same.B.toarray(), normal.B.toarray())
    np.testing.assert_array_equal(same.gap, normal.gap)
    np.testing.assert_array_equal(slip.weights, normal.weights)
    t = tangents(passive.normals)
    assert np.allclose(t, [1.0, 0.0])  # the lower body's normal is +y
    rng = np.random.default_rng(0)
    for shift in rng.normal(size=(3, 2)):
        u = np.zeros(nd)
        u[passive.dofs] = shift
        u[active.dofs] = shift
        np.testing.assert_allclose(slip.B @ u, 0.0, atol=1e-14)
        np.testing.assert_allclose(normal.B @ u, 0.0, atol=1e-14)
    u = np.zeros(nd)
    u[active.dofs[:, 0]] = 0.02
    np.testing.assert_allclose(slip.B @ u, 0.02 * slip.weights, rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(normal.B @ u, 0.0, atol=1e-15)
    with pytest.raises(ValueError, match="unknown row direction"):
        contact_operator(kernel, active, passive, nd, direction="binormal", **options)


def test_tangential_rows_on_a_tilted_line():
    """On a tilted interface the rows use the segments' own tangent: sliding the active body
    along the line by d gives d times the weights, moving it along the normal gives no slip."""
    angle = 0.5
    t, n = np.array([np.cos(angle), np.sin(angle)]), np.array([-np.sin(angle), np.cos(angle)])
    sp = np.array([0.0, 0.21, 0.4, 0.62, 0.8, 1.0])
    sa = np.array([0.1, 0.3, 0.55, 0.9])
    passive = polyline(sp * t[0], sp * t[1], True, 0)
    active = polyline(sa * t[0] + 0.003 * n[0], sa * t[1] + 0.003 * n[1], False, 2 * len(sp))
    nd = 2 * (len(sp) + len(sa))
    for kernel in ("nts", "mortar"):
        slip = contact_operator(kernel, active, passive, nd, direction="tangent")
        np.testing.assert_allclose(tangents(passive.normals), np.tile(t, (len(sp) - 1, 1)))
        for move, expect in ((t, 1.0), (n, 0.0)):
            u = np.zeros(nd)
            u[active.dofs] = 0.01 * move
            np.testing.assert_allclose(slip.B @ u, 0.01 * expect * slip.weights, atol=1e-15)


@pytest.mark.parametrize(("kernel", "options"), KERNELS)
def test_bisector_frame_of_mirrored_arcs(kernel, options):
    """Two arcs mirrored about y = 0 (y = -+x^2 / 2, R = 1, segments h = 0.075): closing the
    gap (the active arc moved by d towards the passive one) reads as a slip of d times the
    tilt of the rows' tangent from the interface (x). In the bisector frame that tilt is at
    most half a segment's turn (h / 2R), whichever arc is active; in the passive arc's frame
    it is the slope, about 0.25 at the ends."""
    x = np.linspace(-0.3, 0.3, 9)
    lower = polyline(x, -0.5 * x**2, True, 0)
    upper = polyline(x, 0.5 * x**2, False, 2 * len(x))
    nd, d, h = 4 * len(x), 0.01, 0.075
    for active, passive in ((upper, lower), (lower, upper)):
        tangent = {"direction": "tangent", **options}
        bis = contact_operator(kernel, active, passive, nd, frame="bisector", **tangent)
        own = contact_operator(kernel, active, passive, nd, **tangent)
        close = np.zeros(nd)
        close[active.dofs[:, 1]] = d * np.sign(passive.normals[0, 1]) * -1.0
        assert np.all(np.abs(bis.B @ close) <= d * h / 2 * bis.weights + 1e-16)
        assert np.max(np.abs(own.B @ close) / np.maximum(own.weights, 1e-300)) > 0.2 * d
    with pytest.raises(ValueError, match="unknown frame"):
        contact_operator(kernel, upper, lower, nd, frame="active", **options)
