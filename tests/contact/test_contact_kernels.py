"""Contact kernels (NTS, STS, mortar) on small hand-checkable 2D surfaces."""

import numpy as np
import pytest
from conftest import polyline, reshuffled

from contactfx.contact import OPERATORS, ContactOperator, Surface, contact_operator
from contactfx.contact.mortar import mortar_matrices, subsegments

METHODS = sorted(OPERATORS)


def pair(xp, yp, xa, ya) -> tuple[Surface, Surface, int]:
    """Passive lower body surface, active upper body surface, total dof count."""
    passive = polyline(np.asarray(xp), np.asarray(yp), True, 0)
    active = polyline(np.asarray(xa), np.asarray(ya), False, 2 * len(xp))
    return active, passive, 2 * (len(xp) + len(xa))


def reference_dofs(ndofs: int, *surfaces: Surface) -> np.ndarray:
    """Global dof vector holding the reference coordinates of the surface nodes."""
    X = np.zeros(ndofs)
    for s in surfaces:
        X[s.dofs] = s.x
    return X


def hat_integral(xa: np.ndarray, g) -> np.ndarray:
    """int N_j g dx on a flat active line with nodes xa, for g linear on each segment."""
    out = np.zeros(len(xa))
    for k in range(len(xa) - 1):
        h = xa[k + 1] - xa[k]
        g0, g1 = g(xa[k]), g(xa[k + 1])
        out[k] += h * (2 * g0 + g1) / 6
        out[k + 1] += h * (g0 + 2 * g1) / 6
    return out


def test_registry_and_unknown_method():
    active, passive, nd = pair([0, 1], [0, 0], [0, 1], [0, 0])
    assert set(OPERATORS) == {"nts", "sts", "mortar"}
    op = contact_operator("mortar", active, passive, nd)
    assert isinstance(op, ContactOperator) and op.B.shape == (2, nd)
    with pytest.raises(ValueError, match="not a valid Kernel"):
        contact_operator("penalty", active, passive, nd)


def test_matching_flat_surfaces():
    x = np.array([0.0, 0.1, 0.25, 0.5, 0.6, 0.8, 1.0])
    active, passive, nd = pair(x, 0 * x, x, 0 * x)
    active = reshuffled(active, 1)
    ops = {m: OPERATORS[m](active, passive, nd) for m in METHODS}
    for op in ops.values():
        np.testing.assert_allclose(op.gap, 0.0, atol=1e-15)
    # STS (4 Gauss points, no cuts needed) and mortar integrate the same polynomials exactly.
    np.testing.assert_allclose(ops["sts"].B.toarray(), ops["mortar"].B.toarray(), atol=1e-14)
    # Mortar with D and M row-lumped: w_j n . (e_j - e_A(j)), A(j) the coinciding passive node.
    D, M = mortar_matrices(active, passive)
    np.testing.assert_allclose(M.toarray(), D.toarray(), atol=1e-15)  # same node numbering
    w = np.asarray(D.sum(axis=1)).ravel()
    lumped = np.zeros((len(x), nd))
    lumped[np.arange(len(x)), active.dofs[:, 1]] = w
    lumped[np.arange(len(x)), passive.dofs[:, 1]] = -w
    np.testing.assert_allclose(ops["nts"].B.toarray(), lumped, atol=1e-15)
    for op in ops.values():
        np.testing.assert_allclose(op.weights, w, rtol=1e-14)


@pytest.mark.parametrize("method", METHODS)
def test_uniform_gap_non_matching(method):
    xp = np.array([0.0, 0.13, 0.3, 0.42, 0.61, 0.77, 0.9, 1.0])
    xa = np.array([0.05, 0.2, 0.37, 0.55, 0.8, 0.95])
    d = 0.0123
    active, passive, nd = pair(xp, 0 * xp, xa, d + 0 * xa)
    op = OPERATORS[method](active, passive, nd)
    np.testing.assert_allclose(op.gap, d * op.weights, rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(op.weights.sum(), xa[-1] - xa[0], rtol=1e-14)
    np.testing.assert_allclose(op.weights, hat_integral(xa, lambda s: 1.0), rtol=1e-13)


@pytest.mark.parametrize("method", METHODS)
def test_linear_gap_reproduced(method):
    # Tilted active line over a flat non-matching passive line: g(x) = d0 + a x exactly.
    xp = np.array([0.0, 0.13, 0.3, 0.42, 0.61, 0.77, 0.9, 1.0])
    xa = np.array([0.05, 0.2, 0.37, 0.55, 0.8, 0.95])
    d0, slope = 0.01, 0.03
    active, passive, nd = pair(xp, 0 * xp, xa, d0 + slope * xa)
    op = OPERATORS[method](active, passive, nd)
    stretch = np.sqrt(1 + slope**2)  # dGamma along the tilted active line
    if method == "nts":
        expected = op.weights * (d0 + slope * xa)
        np.testing.assert_allclose(op.weights, stretch * hat_integral(xa, lambda s: 1.0))
    else:
        expected = stretch * hat_integral(xa, lambda s: d0 + slope * s)
    np.testing.assert_allclose(op.gap, expected, rtol=1e-13)


def test_kinked_passive_mortar_exact_sts_not():
    # Valley y = s |x|: the averaged normal at the kink is vertical, so mortar cuts at x = 0.
    s, h = 0.2, 0.5
    xp = np.array([-1.0, -0.55, 0.0, 0.45, 1.0])
    xa = np.linspace(-0.9, 0.9, 6)  # the segment [-0.18, 0.18] straddles the kink
    active, passive, nd = pair(xp, s * np.abs(xp), xa, h + 0 * xa)
    # On each side of the kink the gap is the distance to that side's line, linear in x.
    gap_exact = sum(
        _clipped_hat_integral(xa, side, lambda x, side=side: h - side * s * x)
        for side in (-1.0, 1.0)
    ) / np.sqrt(1 + s * s)
    mortar = OPERATORS["mortar"](active, passive, nd)
    sts = OPERATORS["sts"](active, passive, nd)
    np.testing.assert_allclose(mortar.gap, gap_exact, rtol=1e-13)
    straddle = np.abs(xa) < 0.5  # nodes whose hat support contains x = 0
    np.testing.assert_allclose(sts.gap[~straddle], gap_exact[~straddle], rtol=1e-13)
    assert np.all(np.abs(sts.gap[straddle] - gap_exact[straddle]) > 1e-6)


def _clipped_hat_integral(xa: np.ndarray, side: float, g) -> np.ndarray:
    """int over {side * x >= 0} of N_j g dx on a flat active line (2-point Gauss per piece)."""
    gx = 0.5 + np.array([-0.5, 0.5]) / np.sqrt(3)
    out = np.zeros(len(xa))
    for k in range(len(xa) - 1):
        lo, hi = xa[k], xa[k + 1]
        a, b = (max(lo, 0.0), hi) if side > 0 else (lo, min(hi, 0.0))
        if b <= a:
            continue
        x = a + (b - a) * gx
        n1 = (x - lo) / (hi - lo)
        out[k] += 0.5 * (b - a) * np.sum((1 - n1) * g(x))
        out[k + 1] += 0.5 * (b - a) * np.sum(n1 * g(x))
    return out


def wavy_pair(overhang: bool = True) -> tuple[Surface, Surface, int]:
    """Non-matching kinked surfaces with a small gap; the active one overhangs both ends."""
    rng = np.random.default_rng(7)
    xp = np.sort(np.r_[0.0, rng.uniform(0, 1, 9), 1.0])
    xa = np.linspace(-0.15, 1.2, 8) if overhang else np.linspace(0.02, 0.97, 8)
    yp = 0.02 * rng.uniform(-1, 1, len(xp))
    ya = 0.01 + 0.02 * rng.uniform(-1, 1, len(xa))
    active, passive, nd = pair(xp, yp, xa, ya)
    return reshuffled(active, 3), reshuffled(passive, 4), nd


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("overhang", [False, True])
def test_gap_equals_B_times_reference_coordinates(method, overhang):
    active, passive, nd = wavy_pair(overhang)
    op = OPERATORS[method](active, passive, nd)
    X = reference_dofs(nd, active, passive)
    assert np.any(op.gap != 0)
    np.testing.assert_allclose(op.B @ X, op.gap, rtol=1e-12, atol=1e-15)
    # Rows with no weight are empty and vice versa.
    row_nnz = np.diff(op.B.indptr)
    assert np.array_equal(row_nnz > 0, op.weights > 0)
    np.testing.assert_array_equal(op.rows, np.flatnonzero(op.weights > 0))


@pytest.mark.parametrize("method", METHODS)
def test_force_balance_constant_multiplier(method):
    active, passive, nd = wavy_pair()
    op = OPERATORS[method](active, passive, nd)
    f = op.B.transpose_matmul(np.ones(active.n_nodes))
    for c in range(2):
        on_passive, on_active = f[passive.dofs[:, c]].sum(), f[active.dofs[:, c]].sum()
        assert abs(on_passive + on_active) < 1e-14
    # B^T lambda with lambda > 0 (compression) pushes the active (upper) body up, the passive
    # one down.
    assert f[active.dofs[:, 1]].sum() > 0 > f[passive.dofs[:, 1]].sum()


def test_mortar_d_is_symmetric():
    # Partition of unity and the weights as D's row sums: test_geometry_properties.py.
    # Before the end modification (merged end rows weight several nodes' columns).
    active, passive, _ = wavy_pair()
    D, _ = mortar_matrices(active, passive, ends=False)
    assert np.allclose(D.toarray(), D.toarray().T)


def test_mortar_normal_part_is_D_minus_M_on_flat_surfaces():
    xp = np.array([0.0, 0.13, 0.3, 0.42, 0.61, 0.77, 0.9, 1.0])
    xa = np.array([-0.1, 0.2, 0.37, 0.55, 0.8, 1.05])
    active, passive, nd = pair(xp, 0 * xp, xa, 0.01 + 0 * xa)
    op = OPERATORS["mortar"](active, passive, nd)
    D, M = mortar_matrices(active, passive)
    B = op.B.toarray()
    np.testing.assert_allclose(B[:, active.dofs[:, 1]], D.toarray(), atol=1e-15)
    np.testing.assert_allclose(B[:, passive.dofs[:, 1]], -M.toarray(), atol=1e-15)
    assert np.all(B[:, active.dofs[:, 0]] == 0) and np.all(B[:, passive.dofs[:, 0]] == 0)


@pytest.mark.parametrize("method", METHODS)
def test_overhang(method):
    # Passive [0, 1]; active nodes every 0.3 from -0.7: [-0.7, -0.4] is wholly outside, the
    # segment [-0.1, 0.2] straddles the passive end at x = 0.
    xp = np.linspace(0.0, 1.0, 6)
    xa = np.linspace(-0.7, 1.1, 7)
    active, passive, nd = pair(xp, 0 * xp, xa, 0.01 + 0 * xa)
    op = OPERATORS[method](active, passive, nd)
    outside = xa < -0.3
    assert np.all(op.weights[outside] == 0)
    assert op.B.rows(np.flatnonzero(outside)).nnz == 0
    if method == "mortar":
        # End rows (operator.end_rows): only node 4's support [0.2, 0.8] lies wholly on the
        # passive surface; the straddling segments' nodes (2, 6 beyond, 3, 5 the last
        # reached) merge into it, and its weight is the whole overlap.
        np.testing.assert_allclose(op.weights, [0, 0, 0, 0, 1.0, 0, 0], atol=1e-15)
        ea, _, xi = subsegments(active, passive)
        lengths = np.bincount(ea, weights=0.3 * (xi[:, 1] - xi[:, 0]), minlength=6)
        np.testing.assert_allclose(lengths, [0, 0, 0.2, 0.3, 0.3, 0.2], atol=1e-15)
    elif method == "nts":
        # Nodes off the passive surface carry no constraint (no collocation point).
        assert np.all(op.weights[[2, 6]] == 0)
        np.testing.assert_allclose(op.weights[3:6], [0.04 / 0.3 + 0.15, 0.3, 0.15 + 0.04 / 0.3])
    else:
        # Gauss points beyond the passive end are dropped; the end rows merge as for mortar,
        # the straddling segments counted from their first found point.
        np.testing.assert_array_equal(op.rows, [4])
        assert 0.6 < op.weights[4] < 1.0
    np.testing.assert_allclose(op.gap, 0.01 * op.weights, rtol=1e-13, atol=1e-17)


def test_project_ends_and_tolerance():
    from contactfx.contact.search import project

    _active, passive, _ = pair([0.0, 0.5, 1.0], [0, 0, 0], [0.0, 1.0], [0.0, 0.0])
    pts = np.array([[-1e-10, 0.3], [-1e-3, 0.3], [0.25, -0.2], [1.0 + 1e-3, 0.0], [0.5, 0.1]])
    seg, xi, found = project(pts, passive, 1e-8)
    assert found.tolist() == [True, False, True, False, True]
    np.testing.assert_allclose(xi[[0, 2, 3]], [0.0, 0.5, 1.0])
    x_proj = (1 - xi)[:, None] * passive.x[passive.segments[seg, 0]]
    x_proj += xi[:, None] * passive.x[passive.segments[seg, 1]]
    np.testing.assert_allclose(x_proj[4], [0.5, 0.0])
