"""meshes.cell_weights: bilinear basis weights of points in quadrilaterals.

References: points made from known reference coordinates by the cell's own bilinear map,
affine functions (which the Q1 basis reproduces, inside the cell and extrapolated), and
containment decided by the reference coordinates of that forward map.
"""

from __future__ import annotations

import numpy as np
import pytest

from contactfx.meshes.cell_weights import contains, q1_weights

RNG = np.random.default_rng(7)


def _quads(n: int) -> np.ndarray:
    """Convex quadrilaterals in DOLFINx's vertex order ((0,0), (1,0), (0,1), (1,1))."""
    base = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    stretch = np.exp(RNG.uniform(-2.0, 2.0, size=(n, 1, 2)))  # aspect up to e^4
    corners = (base + RNG.uniform(-0.2, 0.2, size=(n, 4, 2))) * stretch
    angle = RNG.uniform(0, 2 * np.pi, n)
    rot = np.stack([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    return np.einsum("ijn,nkj->nki", rot, corners) + RNG.uniform(-5, 5, size=(n, 1, 2))


def _bilinear(corners: np.ndarray, ref: np.ndarray) -> np.ndarray:
    s, t = ref[:, :1], ref[:, 1:]
    c = corners
    bottom = c[:, 0] * (1 - s) + c[:, 1] * s
    return bottom * (1 - t) + (c[:, 2] * (1 - s) + c[:, 3] * s) * t


@pytest.mark.parametrize("outside", [0.0, 0.3])
def test_quad_weights_invert_the_bilinear_map(outside: float) -> None:
    """Points made from reference coordinates (inside, or up to 0.3 outside the square) get
    those coordinates' bilinear basis back to 1e-10."""
    corners = _quads(500)
    ref = RNG.uniform(-outside, 1.0 + outside, size=(500, 2))
    w, ok = q1_weights(_bilinear(corners, ref), corners)
    s, t = ref[:, 0], ref[:, 1]
    expected = np.stack([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t], axis=1)
    assert ok.all()
    assert np.abs(w - expected).max() < 1e-10


def test_weights_reproduce_affine_functions() -> None:
    """sum_i w_i f(x_i) = f(x) for affine f, in the cell and extrapolated near it; weights
    sum to one."""
    corners = _quads(400)
    lam = RNG.uniform(-0.2, 1.2, size=(400, 4))
    lam /= lam.sum(axis=1, keepdims=True)
    points = np.einsum("nk,nkd->nd", lam, corners)  # near the cell, some outside
    w, ok = q1_weights(points, corners)
    a, b, c = 0.3, -1.7, 2.5
    f = a + b * corners[..., 0] + c * corners[..., 1]
    assert np.abs(w.sum(axis=1)[ok] - 1.0).max() < 1e-10
    err = (w * f).sum(axis=1) - (a + b * points[:, 0] + c * points[:, 1])
    assert ok.mean() > 0.9
    assert np.abs(err[ok]).max() < 1e-9


def test_contains_agrees_with_the_reference_coordinates() -> None:
    """The edge-sign test says inside exactly where the points' reference coordinates (from
    the forward map) lie in the reference square, away from its boundary by 1e-6."""
    corners = _quads(2000)
    ref = RNG.uniform(-0.5, 1.5, size=(2000, 2))
    points = _bilinear(corners, ref)
    inside = (ref > 1e-6).all(axis=1) & (ref < 1 - 1e-6).all(axis=1)
    outside = (ref < -1e-6).any(axis=1) | (ref > 1 + 1e-6).any(axis=1)
    got = contains(points, corners)
    assert got[inside].all() and not got[outside].any()
    assert inside.sum() > 100 and outside.sum() > 100
    # Either orientation: the same answer with the vertex order mirrored.
    assert np.array_equal(contains(points, corners[:, [1, 0, 3, 2]]), got)


def test_far_outside_is_flagged() -> None:
    """A point several cells away has no usable weights (the caller injects instead)."""
    corners = _quads(50)
    centre = corners.mean(axis=1)
    size = np.linalg.norm(corners[:, 3] - corners[:, 0], axis=1)[:, None]
    far = centre + 6.0 * size * np.array([1.0, 0.0])
    _, ok = q1_weights(far, corners)
    assert not ok.any()
