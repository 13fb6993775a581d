"""Property tests of the contact geometry and operators on random polylines (hypothesis)."""

import numpy as np
from conftest import polyline, renumbered, reshuffled
from hypothesis import given, settings
from hypothesis import strategies as st

from contactfx.contact import OPERATORS, Surface
from contactfx.contact.geometry import nodal_normals
from contactfx.contact.mortar import mortar_matrices, overlap_weights, subsegments
from contactfx.contact.search import project

FAST = settings(max_examples=40, deadline=None)


def random_line(rng: np.random.Generator, n: int, x0: float, wiggle: float) -> tuple:
    """Monotone x from x0 with steps in [0.2, 1], y perturbed by up to wiggle."""
    x = x0 + np.r_[0.0, np.cumsum(rng.uniform(0.2, 1.0, n - 1))]
    return x, wiggle * rng.uniform(-1, 1, n)


@st.composite
def surface_pairs(draw):
    """(active, passive, ndofs): random wavy lines (some with matching nodes), active on top."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n_p, n_a = draw(st.integers(2, 12)), draw(st.integers(2, 12))
    xp, yp = random_line(rng, n_p, 0.0, draw(st.sampled_from([0.0, 0.03])))
    if draw(st.booleans()):
        xa, ya = random_line(rng, n_a, draw(st.floats(-1.0, 1.0)), draw(st.sampled_from([0, 0.03])))
    else:  # matching nodes: every active node sits on (or right above) a passive node
        xa, ya = xp.copy(), yp.copy()
    ya += draw(st.sampled_from([0.0, 0.01, draw(st.floats(-0.02, 0.05))]))
    passive = polyline(xp, yp, True, 0)
    active = polyline(xa, ya, False, 2 * n_p)
    return active, passive, 2 * (n_p + len(xa))


def brute_force(points: np.ndarray, s: Surface, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Distance to the polyline and whether some closest point is not beyond an end."""
    a, b = s.x[s.segments[:, 0]], s.x[s.segments[:, 1]]
    ab = b - a
    t = np.einsum("pmd,md->pm", points[:, None] - a, ab) / np.einsum("md,md->m", ab, ab)
    tc = np.clip(t, 0, 1)
    d = np.linalg.norm(points[:, None] - (a + tc[..., None] * ab), axis=2)
    end = np.bincount(s.segments.ravel(), minlength=s.n_nodes) == 1
    beyond = ((t < -tol) & end[s.segments[:, 0]]) | ((t > 1 + tol) & end[s.segments[:, 1]])
    dmin = d.min(axis=1)
    closest = d <= dmin[:, None] + 1e-12
    return dmin, (closest & ~beyond).any(axis=1)


@FAST
@given(surface_pairs(), st.integers(0, 2**32 - 1))
def test_project_is_closest_point(surfaces, seed):
    _, passive, _ = surfaces
    passive = reshuffled(passive, seed)
    rng = np.random.default_rng(seed)
    lo, hi = passive.x.min(axis=0) - 1.0, passive.x.max(axis=0) + 1.0
    pts = np.vstack([rng.uniform(lo, hi, (60, 2)), passive.x, passive.x + 1e-3])
    seg, xi, found = project(pts, passive, 1e-8)
    assert np.all((xi >= 0) & (xi <= 1))
    a, b = passive.x[passive.segments[seg, 0]], passive.x[passive.segments[seg, 1]]
    foot = (1 - xi)[:, None] * a + xi[:, None] * b
    dmin, found_bf = brute_force(pts, passive, 1e-8)
    np.testing.assert_allclose(np.linalg.norm(pts - foot, axis=1), dmin, rtol=1e-12, atol=1e-14)
    np.testing.assert_array_equal(found, found_bf)


def inside_ends(active: Surface, passive: Surface) -> np.ndarray:
    """Length of the xi interval of each active segment between the passive end-node lines."""
    nn = nodal_normals(passive)
    end = np.flatnonzero(np.bincount(passive.segments.ravel()) == 1)
    p0, p1 = active.x[active.segments[:, 0]], active.x[active.segments[:, 1]]
    lo, hi = np.zeros(active.n_segments), np.ones(active.n_segments)
    for e in end:
        other = passive.segments[(passive.segments == e).any(axis=1)].ravel()
        other = other[other != e][0]
        n = nn[e]

        def side(p, e=e, n=n):
            return n[0] * (p[:, 1] - passive.x[e, 1]) - n[1] * (p[:, 0] - passive.x[e, 0])

        sign = np.sign(side(passive.x[[other]]))[0]
        fa, fb = sign * side(p0), sign * side(p1)
        with np.errstate(divide="ignore", invalid="ignore"):
            c = fa / (fa - fb)
        lo = np.maximum(lo, np.where((fa < 0) & (fb >= 0), c, np.where(fa < 0, 1.0, 0.0)))
        hi = np.minimum(hi, np.where((fa >= 0) & (fb < 0), c, np.where(fb < 0, 0.0, 1.0)))
    return np.clip(hi - lo, 0, None)


@FAST
@given(surface_pairs())
def test_subsegments_tile_the_overlap(surfaces):
    active, passive, _ = surfaces
    ea, sp_, xi = subsegments(active, passive)
    assert np.all(xi[:, 1] > xi[:, 0])
    assert np.all((xi >= 0) & (xi <= 1))
    # Sorted by active segment, disjoint and contiguous within one active segment.
    same = ea[1:] == ea[:-1]
    assert np.all(np.diff(ea) >= 0)
    np.testing.assert_allclose(xi[1:, 0][same], xi[:-1, 1][same], atol=1e-12)
    covered = np.bincount(ea, weights=xi[:, 1] - xi[:, 0], minlength=active.n_segments)
    np.testing.assert_allclose(covered, inside_ends(active, passive), atol=1e-12)
    # Each sub-segment faces one passive segment; consecutive ones face neighbours.
    shared = (passive.segments[sp_[1:]][:, :, None] == passive.segments[sp_[:-1]][:, None]).any(
        axis=(1, 2)
    )
    assert np.all(shared[same])


@FAST
@given(surface_pairs())
def test_mortar_partition_of_unity(surfaces):
    active, passive, _ = surfaces
    D, M = mortar_matrices(active, passive)
    d, m = np.asarray(D.sum(axis=1)).ravel(), np.asarray(M.sum(axis=1)).ravel()
    np.testing.assert_allclose(m, d, rtol=1e-12, atol=1e-15)
    assert np.all(d >= 0)


@FAST
@given(surface_pairs(), st.integers(0, 2**32 - 1))
def test_operators_invariant_under_reversal_and_permutation(surfaces, seed):
    active, passive, nd = surfaces
    active2, passive2 = reshuffled(active, seed), reshuffled(passive, seed + 1)
    X = np.zeros(nd)
    X[active.dofs], X[passive.dofs] = active.x, passive.x
    for method, build in OPERATORS.items():
        op, op2 = build(active, passive, nd), build(active2, passive2, nd)
        np.testing.assert_allclose(op2.B.toarray(), op.B.toarray(), atol=1e-12, err_msg=method)
        np.testing.assert_allclose(op2.gap, op.gap, atol=1e-12, err_msg=method)
        np.testing.assert_allclose(op2.weights, op.weights, atol=1e-12, err_msg=method)
        np.testing.assert_allclose(op.B @ X, op.gap, atol=1e-12, err_msg=method)


@FAST
@given(surface_pairs(), st.integers(0, 2**32 - 1))
def test_operators_invariant_under_node_renumbering(surfaces, seed):
    active, passive, nd = surfaces
    rng = np.random.default_rng(seed)
    order = rng.permutation(active.n_nodes)
    active2 = renumbered(active, order)
    passive2 = renumbered(passive, rng.permutation(passive.n_nodes))
    for method, build in OPERATORS.items():
        op, op2 = build(active, passive, nd), build(active2, passive2, nd)
        np.testing.assert_allclose(op2.B.toarray(), op.B.toarray()[order], atol=1e-12)
        np.testing.assert_allclose(op2.gap, op.gap[order], atol=1e-12, err_msg=method)


# Operator-level consistency.


@FAST
@given(surface_pairs(), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
def test_rigid_translation_leaves_gap_unchanged(surfaces, tx, ty):
    # Moving both bodies together must not change any weighted gap: B t = 0 for a translation.
    # For mortar this is partition of unity at the operator level (sum_A M_jA = sum_k D_jk).
    active, passive, nd = surfaces
    t = np.zeros(nd)
    t[active.dofs[:, 0]] = t[passive.dofs[:, 0]] = tx
    t[active.dofs[:, 1]] = t[passive.dofs[:, 1]] = ty
    for method, build in OPERATORS.items():
        op = build(active, passive, nd)
        np.testing.assert_allclose(op.B @ t, 0.0, atol=1e-12, err_msg=method)


@FAST
@given(surface_pairs())
def test_mortar_weights_are_row_sums_of_d(surfaces):
    # The nodal weight w_j = int N_j (which turns a weighted gap into a gap) is the D row sum.
    active, passive, nd = surfaces
    D, _ = mortar_matrices(active, passive)
    op = OPERATORS["mortar"](active, passive, nd)
    d = np.asarray(D.sum(axis=1)).ravel()
    np.testing.assert_allclose(op.weights, d, rtol=1e-12, atol=1e-15)
    # overlap_weights (NTS's scaling) are the unmodified int N_j: D before the end rows.
    d_raw = np.asarray(mortar_matrices(active, passive, ends=False)[0].sum(axis=1)).ravel()
    np.testing.assert_allclose(overlap_weights(active, passive), d_raw, rtol=1e-12, atol=1e-15)


@FAST
@given(surface_pairs())
def test_sub_segments_sum_to_whole_segment_inside_overlap(surfaces):
    # An active segment whose both ends project inside the passive polyline is covered once,
    # so its sub-segment lengths sum to its length.
    active, passive, _ = surfaces
    ea, _, xi = subsegments(active, passive)
    covered = np.bincount(ea, weights=xi[:, 1] - xi[:, 0], minlength=active.n_segments)
    xmin, xmax = passive.x[:, 0].min(), passive.x[:, 0].max()
    ends = active.x[active.segments]
    # Passive nodal normals tilt by at most ~0.1 rad here: keep a margin from the ends.
    inside = (ends[:, :, 0].min(axis=1) > xmin + 0.1) & (ends[:, :, 0].max(axis=1) < xmax - 0.1)
    np.testing.assert_allclose(covered[inside], 1.0, atol=1e-12)
