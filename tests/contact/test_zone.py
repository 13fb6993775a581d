"""contact/zone: a zone edge estimated from coarse pressures, and the fine points it covers."""

from __future__ import annotations

import numpy as np
import pytest

from contactfx.contact.geometry import Surface
from contactfx.contact.zone import covered, edge_distances


def line(n: int, h: float) -> tuple[np.ndarray, np.ndarray]:
    """n nodes at spacing h along y = 0 from x = 0, and their segments."""
    x = np.c_[np.arange(n) * h, np.zeros(n)]
    return x, np.c_[np.arange(n - 1), np.arange(1, n)]


def surface(x: np.ndarray, seg: np.ndarray) -> Surface:
    """A Surface of the polyline (normals and dofs unused here)."""
    return Surface(x, seg, np.zeros(seg.shape), np.zeros((len(x), 2), dtype=np.int64))


def reach(x, seg, active, p, fallback=0.0) -> float:
    """Where the zone ends along the line: the last active node plus its coverage."""
    from_a, _ = edge_distances(x, seg, active, p, fallback)
    last = int(np.flatnonzero(active).max())
    return float(x[last, 0] + from_a[last])


@pytest.mark.parametrize("frac", [0.05, 0.3, 0.5, 0.7, 0.95])
def test_a_square_root_edge_is_found_within_the_element(frac: float) -> None:
    """Hertz's p = sqrt(a^2 - x^2) on nodes 0.2 apart: the edge within 0.1 element of a.

    The former rule put it anywhere in the element past the last active node (the edge
    at `frac` of it): the estimate is never short of a (p^2 is concave: a superset).
    """
    h = 0.2
    x, seg = line(40, h)
    a = (20 + frac) * h
    p = np.sqrt(np.clip(a**2 - x[:, 0] ** 2, 0.0, None))
    end = reach(x, seg, p > 0, p)
    assert a <= end <= a + 0.1 * h


def test_reversed_numbering_gives_the_same_edge() -> None:
    """Segments listed backwards with their nodes swapped: the same edge position."""
    h, a = 0.2, 2.33
    x, seg = line(20, h)
    p = np.sqrt(np.clip(a**2 - x[:, 0] ** 2, 0.0, None))
    perm = np.random.default_rng(0).permutation(len(x))
    inv = np.argsort(perm)
    seg_r = inv[seg[::-1, ::-1]]
    from_a, from_b = edge_distances(x[perm], seg_r, (p > 0)[perm], p[perm], 0.0)
    last = int(np.flatnonzero(p > 0).max())
    k = int(
        np.flatnonzero((seg_r == inv[last]).any(axis=1) & (seg_r == inv[last + 1]).any(axis=1))[0]
    )
    got = from_a[k] if seg_r[k, 0] == inv[last] else from_b[k]
    assert got == pytest.approx(reach(x, seg, p > 0, p) - x[last, 0], rel=1e-12)


def test_a_corner_edge_takes_the_fallback() -> None:
    """A flat punch's p ~ 1 / sqrt(a - x) rises towards the edge: the fallback distance."""
    h = 0.1
    x, seg = line(30, h)
    a = 1.55
    active = x[:, 0] < a
    p = np.where(active, 1.0 / np.sqrt(np.abs(a - x[:, 0]) + 1e-3), 0.0)
    assert reach(x, seg, active, p, fallback=0.03) == pytest.approx(1.5 + 0.03)
    # A lone active node has no inner neighbour either.
    one = np.zeros(len(x), dtype=bool)
    one[10] = True
    from_a, from_b = edge_distances(x, seg, one, one * 1.0, 0.04)
    assert from_a[10] == pytest.approx(0.04) and from_b[9] == pytest.approx(0.04)
    assert (from_a[np.arange(29) != 10] == -1.0).all()


def test_disagreeing_extrapolations_take_the_fallback() -> None:
    """A zone of a few coarse nodes (44, 130, 157 at its end): the two zeros differ by
    more than AGREE elements, so nothing is estimated; a smooth one keeps its estimate."""
    h = 0.1
    x, seg = line(12, h)
    p = np.zeros(len(x))
    p[:6] = [170.0, 165.0, 160.0, 157.0, 130.0, 44.0]
    assert reach(x, seg, p > 0, p, fallback=0.05) == pytest.approx(0.5 + 0.05)
    # The same end of a resolved smooth zone (20 nodes) keeps its estimate.
    x, seg = line(30, h)
    a = 2.06
    smooth = np.sqrt(np.clip(a**2 - x[:, 0] ** 2, 0.0, None))
    assert a <= reach(x, seg, smooth > 0, smooth, fallback=0.05) <= a + 0.1 * h


def test_margin_is_added_to_estimates_only() -> None:
    """`margin` segment lengths past an estimated edge, none past a fallback one."""
    h, a = 0.2, 4.13
    x, seg = line(40, h)
    p = np.sqrt(np.clip(a**2 - x[:, 0] ** 2, 0.0, None))
    plain = reach(x, seg, p > 0, p)
    from_a, _ = edge_distances(x, seg, p > 0, p, 0.0, margin=0.25)
    assert from_a[20] == pytest.approx(plain - x[20, 0] + 0.25 * h)
    flat = np.where(p > 0, 1.0, 0.0)
    from_a, _ = edge_distances(x, seg, p > 0, flat, 0.07, margin=0.25)
    assert from_a[20] == pytest.approx(0.07)


def test_covered_points() -> None:
    """Points on the covered part only, near the surface."""
    h = 0.2
    x, seg = line(11, h)
    active = x[:, 0] < 0.9  # nodes 0..4 (x = 0.8 last)
    from_a, from_b = edge_distances(x, seg, active, np.where(active, 1.0, 0.0), 0.05)
    pts = np.array([[0.3, 0.0], [0.84, 0.0], [0.86, 0.0], [0.3, 0.5], [1.5, 0.0], [0.3, 0.09]])
    got = covered(pts, surface(x, seg), from_a, from_b, tol=0.1)
    assert got.tolist() == [True, True, False, False, False, True]
