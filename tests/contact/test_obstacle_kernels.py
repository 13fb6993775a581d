"""Rigid obstacles, pure numpy: exact closest points, and NTS/STS/mortar against them.

References are brute force (dense sampling of a circle, distances to every segment of a
polyline, fine composite quadrature of the gap) or the body-pair kernels on a straight line.
"""

import numpy as np
import pytest
from conftest import polyline
from hypothesis import given, settings
from hypothesis import strategies as st

from contactfx.contact import OPERATORS, Circle, Plane, Polyline, Surface, rigid_operator
from contactfx.contact.rigid_kernels import overlap_weights

FAST = settings(max_examples=30, deadline=None)
KERNELS = ("nts", "sts", "mortar")


def brute_polyline(points: np.ndarray, vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance to an open polyline, and whether the closest point is not beyond an end."""
    a, b = vertices[:-1], vertices[1:]
    ab = b - a
    t = np.einsum("pmd,md->pm", points[:, None] - a, ab) / np.einsum("md,md->m", ab, ab)
    d = np.linalg.norm(points[:, None] - (a + np.clip(t, 0, 1)[..., None] * ab), axis=2)
    beyond = np.zeros_like(t, dtype=bool)
    beyond[:, 0] |= t[:, 0] < -1e-8
    beyond[:, -1] |= t[:, -1] > 1 + 1e-8
    dmin = d.min(axis=1)
    return dmin, ((d <= dmin[:, None] + 1e-12) & ~beyond).any(axis=1)


@st.composite
def graphs(draw):
    """An open polyline y = f(x) through monotone x (the obstacle above it) and some points."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    n = draw(st.integers(2, 9))
    x = np.r_[0.0, np.cumsum(rng.uniform(0.2, 1.0, n - 1))]
    y = draw(st.sampled_from([0.0, 0.3, 1.0])) * rng.uniform(-1, 1, n)
    pts = np.column_stack([rng.uniform(-0.5, x[-1] + 0.5, 80), rng.uniform(-2.0, 2.0, 80)])
    return np.column_stack([x, y]), pts


@FAST
@given(graphs())
def test_polyline_gap_is_the_signed_distance(case):
    vertices, pts = case
    near = Polyline(tuple(map(tuple, vertices))).closest(pts)
    dist, found = brute_polyline(pts, vertices)
    np.testing.assert_array_equal(near.found, found)
    np.testing.assert_allclose(np.abs(near.gap), dist, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(near.normal, axis=1), 1.0, rtol=1e-12)
    # The obstacle is above the graph (on the left walking +x): below means a positive gap.
    inside = (pts[:, 0] > vertices[0, 0]) & (pts[:, 0] < vertices[-1, 0]) & (dist > 1e-9)
    below = pts[:, 1] < np.interp(pts[:, 0], vertices[:, 0], vertices[:, 1])
    np.testing.assert_array_equal((near.gap > 0)[inside], below[inside])
    # gap = n . (x - foot): the normal points from the closest point towards the point.
    g = np.einsum("pd,pd->p", near.normal, pts - near.foot)
    np.testing.assert_allclose(g, near.gap, atol=1e-12)


def test_circle_and_plane_are_exact() -> None:
    rng = np.random.default_rng(1)
    pts = rng.uniform(-3, 3, (200, 2))
    circle = Circle((0.3, -0.2), 1.7)
    near = circle.closest(pts)
    theta = np.linspace(0, 2 * np.pi, 100001)
    ring = np.array(circle.center) + 1.7 * np.column_stack([np.cos(theta), np.sin(theta)])
    # Distance to the chords next to the nearest sample: exact up to their sagitta.
    sagitta = 1.7 * (theta[1] - theta[0]) ** 2 / 8
    k = np.array([np.argmin(np.linalg.norm(ring - p, axis=1)) for p in pts])
    chords = [ring[np.mod(k + j, len(ring) - 1)] for j in (-2, -1, 0, 1, 2)]
    sampled = np.min(
        [brute_polyline(pts[i : i + 1], np.array([c[i] for c in chords]))[0] for i in range(200)],
        axis=1,
    ).ravel()
    np.testing.assert_allclose(np.abs(near.gap), sampled, rtol=0, atol=1.01 * sagitta)
    inside = np.linalg.norm(pts - np.array(circle.center), axis=1) < 1.7
    np.testing.assert_array_equal(near.gap < 0, inside)
    plane = Plane((1.0, 2.0), (3.0, 4.0))  # normalised to (0.6, 0.8)
    near = plane.closest(pts)
    np.testing.assert_allclose(near.gap, (pts - [1.0, 2.0]) @ [0.6, 0.8], atol=1e-14)
    np.testing.assert_allclose(near.normal, np.tile([0.6, 0.8], (len(pts), 1)), atol=1e-15)


def test_convex_corner_has_no_jump() -> None:
    """Around an obstacle's convex corner the gap and normal turn continuously."""
    tip = Polyline(((-1.0, 1.0), (0.0, 0.0), (1.0, 1.0)))  # a wedge pointing down, body below
    phi = np.linspace(np.radians(-175), np.radians(-5), 3401)
    pts = 0.3 * np.column_stack([np.cos(phi), np.sin(phi)])
    near = tip.closest(pts)
    assert near.found.all()
    step = phi[1] - phi[0]
    assert np.max(np.abs(np.diff(near.gap))) < 0.3 * step * 1.01
    assert np.max(np.linalg.norm(np.diff(near.normal, axis=0), axis=1)) < 1.01 * step
    # In the corner's own region the normal is the direction from the corner.
    mid = np.abs(phi + np.pi / 2) < np.radians(40)
    np.testing.assert_allclose(near.normal[mid], pts[mid] / 0.3, atol=1e-12)
    np.testing.assert_allclose(near.gap[mid], 0.3, atol=1e-12)


def test_closed_polygon_ties_do_not_depend_on_the_start() -> None:
    """A square indenter: the corners and the bisectors' ties give the same answer."""
    square = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]  # anticlockwise: body outside
    rng = np.random.default_rng(3)
    pts = np.vstack([rng.uniform(-2, 2, (300, 2)), [[0.0, 0.0], [0.5, 0.5], [2.0, 2.0]]])
    ref = Polyline((*square, square[0])).closest(pts)
    for k in range(1, 4):
        loop = square[k:] + square[:k]
        other = Polyline((*loop, loop[0])).closest(pts)
        np.testing.assert_allclose(other.gap, ref.gap, atol=1e-15)
        np.testing.assert_allclose(other.normal, ref.normal, atol=1e-15)
    assert ref.found.all()
    outside = np.max(np.abs(pts), axis=1) > 1
    np.testing.assert_array_equal(ref.gap > 0, outside)
    np.testing.assert_allclose(ref.gap[-1], np.sqrt(2.0), rtol=1e-14)  # from the corner


@pytest.mark.parametrize(
    ("points", "message"),
    [
        (((0.0, 0.0),), "two or more"),
        (((0.0, 0.0), (0.0, 0.0)), "coincide"),
        (((0.0, 0.0), (1.0, 0.0), (0.5, 0.0)), "folds back"),
        (((0.0, 1.0), (1.0, 0.0), (1.0, 1.0), (0.0, 0.0)), "cross"),
    ],
)
def test_degenerate_polylines_are_refused(points, message) -> None:
    with pytest.raises(ValueError, match=message):
        Polyline(points)


def flat_active(n: int = 11, y: float = 0.0) -> Surface:
    """A graded straight active surface along y = const, outward normal +y (the body below)."""
    x = np.linspace(-1, 1, n) ** 3
    return polyline(x, np.full(n, y), True, 0)


@pytest.mark.parametrize("kernel", KERNELS)
def test_straight_obstacles_equal_a_passive_body_line(kernel: str) -> None:
    """A plane, a straight polyline (with extra vertices) and a passive straight line agree."""
    active = flat_active()
    nd = 2 * active.n_nodes
    line = polyline(np.array([-2.0, 2.0]), np.array([0.1, 0.1]), False, nd)
    ref = OPERATORS[kernel](active, line, nd + 4)
    shapes = (
        Plane((0.0, 0.1), (0.0, -1.0)),
        Polyline(((-2.0, 0.1), (2.0, 0.1))),
        Polyline(((-2.0, 0.1), (-0.31, 0.1), (0.05, 0.1), (2.0, 0.1))),
    )
    for shape in shapes:
        rop = rigid_operator(kernel, active, shape, nd)
        np.testing.assert_allclose(rop.operator.B.toarray(), ref.B.toarray()[:, :nd], atol=1e-15)
        body_line = ref.B.toarray()[:, nd : nd + 2] + ref.B.toarray()[:, nd + 2 :]
        np.testing.assert_allclose(rop.motion.toarray(), body_line, atol=1e-15)
        np.testing.assert_allclose(rop.operator.gap, ref.gap, atol=1e-15)
        np.testing.assert_allclose(rop.operator.weights, ref.weights, atol=1e-15)


def wavy_active() -> Surface:
    """A curved active surface below the obstacles, normals pointing up (towards them)."""
    x = np.linspace(-1.5, 1.5, 17) + 0.02 * np.sin(np.arange(17))
    return polyline(x, -0.05 - 0.04 * x**2, True, 0)


SHAPES = {
    "circle": Circle((0.1, 2.0), 2.0),
    "plane": Plane((0.0, 0.02), (0.1, -1.0)),
    "kinked": Polyline(((-1.2, 0.3), (-0.4, 0.0), (0.3, 0.05), (0.6, -0.02), (1.1, 0.4))),
    "straight": Polyline(((-2.0, 0.1), (-0.3, 0.1), (2.0, 0.1))),
}


def brute_gap(shape, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Signed gap, normal, found and the closest feature, without the code under test."""
    ones = np.ones(len(pts), bool)
    if isinstance(shape, Circle):
        d = pts - np.array(shape.center)
        r = np.linalg.norm(d, axis=1)
        return r - shape.radius, d / r[:, None], ones, ones.astype(int)
    if isinstance(shape, Plane):
        n = np.array(shape.normal) / np.linalg.norm(shape.normal)
        return (pts - shape.point) @ n, np.tile(n, (len(pts), 1)), ones, ones.astype(int)
    v = np.array(shape.points)
    a, ab = v[:-1], v[1:] - v[:-1]
    t = np.clip(np.einsum("pmd,md->pm", pts[:, None] - a, ab) / np.sum(ab * ab, axis=1), 0, 1)
    foot = a + t[..., None] * ab
    d = np.linalg.norm(pts[:, None] - foot, axis=2)
    k = np.argmin(d, axis=1)
    f = foot[np.arange(len(pts)), k]
    below = pts[:, 1] < np.interp(pts[:, 0], v[:, 0], v[:, 1])  # the obstacle is above
    sign = np.where(below, 1.0, -1.0)
    dist, found = brute_polyline(pts, v)
    # The feature: which segment, and whether its foot is an end of it (a vertex).
    tk = t[np.arange(len(pts)), k]
    feature = np.where(found, 3 * k + (tk <= 0) + 2 * (tk >= 1), -1)
    return sign * dist, sign[:, None] * (pts - f) / dist[:, None], found, feature


@pytest.mark.parametrize("name", list(SHAPES))
def test_mortar_integrates_the_exact_gap(name: str) -> None:
    """Row j's weighted gap and motion: int N_j g and -int N_j n, to a fine quadrature."""
    active, shape = wavy_active(), SHAPES[name]
    nd = 2 * active.n_nodes
    rop = rigid_operator("mortar", active, shape, nd)
    gx, gw = np.polynomial.legendre.leggauss(3)
    gap = np.zeros(active.n_nodes)
    motion = np.zeros((active.n_nodes, 2))
    for i, j in active.segments:

        def facing(t, i=i, j=j):
            pts = (1 - t)[:, None] * active.x[i] + t[:, None] * active.x[j]
            return brute_gap(shape, pts)[3]

        # 4000 sub-intervals, plus where the closest feature changes (found by bisection).
        sub = np.linspace(0, 1, 4001)
        flips = np.flatnonzero(facing(sub[1:]) != facing(sub[:-1]))
        ends = []
        for k in flips:
            a, b = sub[k], sub[k + 1]
            for _ in range(60):
                m = 0.5 * (a + b)
                a, b = (m, b) if facing(np.array([m]))[0] == facing(np.array([a]))[0] else (a, m)
            ends.append(0.5 * (a + b))
        sub = np.unique(np.r_[sub, ends])
        lo, hi = sub[:-1], sub[1:]
        xi = (0.5 * (lo + hi)[:, None] + 0.5 * (hi - lo)[:, None] * gx).ravel()
        w = (0.5 * (hi - lo)[:, None] * gw).ravel()
        pts = (1 - xi)[:, None] * active.x[i] + xi[:, None] * active.x[j]
        g, n, found, _ = brute_gap(shape, pts)
        length = np.linalg.norm(active.x[j] - active.x[i])
        for node, N in ((i, 1 - xi), (j, xi)):
            gap[node] += np.sum((w * N * g)[found]) * length
            motion[node] -= np.sum(((w * N)[:, None] * n)[found], axis=0) * length
    scale = np.abs(rop.operator.weights).max()
    np.testing.assert_allclose(rop.operator.gap, gap, atol=1e-8 * scale)
    np.testing.assert_allclose(rop.motion.toarray(), motion, atol=1e-7 * scale)


@pytest.mark.parametrize("name", list(SHAPES))
@pytest.mark.parametrize("kernel", KERNELS)
def test_forces_balance_and_rows_are_linear(kernel: str, name: str) -> None:
    """Each row's body and obstacle columns sum to zero; the motion is the body's translation."""
    active, shape = wavy_active(), SHAPES[name]
    nd = 2 * active.n_nodes
    for options in ({}, {"basis": "dual"}) if kernel == "mortar" else ({},):
        rop = rigid_operator(kernel, active, shape, nd, **options)
        B = rop.operator.B.toarray()
        for c in (0, 1):
            np.testing.assert_allclose(
                B[:, c::2].sum(axis=1), -rop.motion.toarray()[:, c], atol=1e-14
            )


def test_plane_motion_is_exact() -> None:
    """A plane moved by d: the operator of the moved plane, to round-off."""
    active = wavy_active()
    nd = 2 * active.n_nodes
    d = np.array([0.03, -0.07])
    for kernel in KERNELS:
        rop = rigid_operator(kernel, active, SHAPES["plane"], nd)
        moved = Plane(tuple(np.array(SHAPES["plane"].point) + d), SHAPES["plane"].normal)
        ref = rigid_operator(kernel, active, moved, nd)
        np.testing.assert_allclose(rop.moved(d).gap, ref.operator.gap, atol=1e-15)
        np.testing.assert_allclose(rop.operator.B.toarray(), ref.operator.B.toarray(), atol=1e-15)


def test_circle_motion_is_first_order() -> None:
    """A circle moved by d: the linearized gap is off by O(|d|^2) only."""
    active = wavy_active()
    nd = 2 * active.n_nodes
    circle = SHAPES["circle"]
    rop = rigid_operator("mortar", active, circle, nd)
    errors = []
    for size in (1e-2, 1e-3):
        d = size * np.array([0.6, -0.8])
        ref = rigid_operator("mortar", active, Circle(tuple(circle.center + d), 2.0), nd)
        errors.append(np.abs(rop.moved(d).gap - ref.operator.gap).max())
    assert errors[1] < 0.02 * errors[0]  # quadratic: 100 times smaller


def test_open_polyline_ends_give_no_rows() -> None:
    """Nodes beyond a polyline's ends face nothing: no NTS row, no overlap weight."""
    active = flat_active(21)
    shape = Polyline(((-0.5, 0.1), (0.4, 0.1)))
    w = overlap_weights(active, shape)
    x = active.x[:, 0]
    assert np.all(w[(x < -0.5 - 0.2) | (x > 0.4 + 0.2)] == 0)
    # The overlap is exactly the polyline's span: int of sum N_j over [-0.5, 0.4].
    np.testing.assert_allclose(w.sum(), 0.9, rtol=1e-14)
    rop = rigid_operator("nts", active, shape, 2 * active.n_nodes)
    rows = np.flatnonzero(rop.operator.weights > 0)
    assert np.all((x[rows] >= -0.5) & (x[rows] <= 0.4))
