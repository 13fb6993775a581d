"""The bucket-grid searches (contact.grid) give the brute-force answers exactly.

SegmentSearch above `_ALL_PAIRS` and the coarse predictor used scipy.spatial's KD-tree; the
grid replaces it (docs/scale.md, "Time to the first answer"). References: a brute-force
closest segment written here from the definition (every segment, ties within eps broken by
the least (x, y) of the midpoints), scipy's cKDTree for the point queries, and the
predictor's previous cKDTree code (kept here).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import cKDTree

from contactfx.contact import search as search_module
from contactfx.contact.geometry import Surface
from contactfx.contact.grid import PointGrid
from contactfx.contact.search import SegmentSearch
from contactfx.methods.predictor import coarse_initial_set

FAST = settings(max_examples=40, deadline=None)


def surface_of(x: np.ndarray, seg: np.ndarray) -> Surface:
    """A Surface of nodes x and segments seg (normals from the segment directions)."""
    t = x[seg[:, 1]] - x[seg[:, 0]]
    norm = np.maximum(np.linalg.norm(t, axis=1), 1e-300)[:, None]
    normals = np.column_stack([-t[:, 1], t[:, 0]]) / norm
    return Surface(x, seg, normals, 2 * np.arange(len(x))[:, None] + np.arange(2))


@st.composite
def graded_surfaces(draw):
    """Graded polylines (spacing varying up to 100x) and circles, nodes randomly numbered."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    xs, segs, n = [], [], 0
    for k in range(draw(st.integers(1, 3))):
        count = draw(st.integers(3, 120))
        ratio = draw(st.sampled_from([1.0, 10.0, 100.0]))
        h = ratio ** rng.uniform(0.0, 1.0, count)
        if draw(st.booleans()):  # a closed circle, graded along its arc
            angle = 2 * np.pi * np.r_[0.0, np.cumsum(h)[:-1]] / h.sum()
            r = rng.uniform(0.2, 3.0)
            x = np.column_stack([5.0 * k + r * np.cos(angle), r * np.sin(angle)])
            ids = n + np.arange(count)
            segs.append(np.column_stack([ids, np.roll(ids, -1)]))
        else:  # a wavy open line
            s = np.r_[0.0, np.cumsum(h)] / h.sum() * rng.uniform(0.5, 4.0)
            x = np.column_stack([5.0 * k + s, 0.1 * np.sin(rng.uniform(1, 9) * s)])
            ids = n + np.arange(len(s))
            segs.append(np.column_stack([ids[:-1], ids[1:]]))
        xs.append(x)
        n += len(x)
    x, seg = np.vstack(xs), np.vstack(segs)
    order = rng.permutation(len(x))
    new = np.empty_like(order)
    new[order] = np.arange(len(order))
    seg = new[seg][rng.permutation(len(seg))]
    flip = rng.random(len(seg)) < 0.5
    seg[flip] = seg[flip, ::-1]
    return surface_of(x[order], seg)


def query_points(surface: Surface, rng: np.random.Generator) -> np.ndarray:
    """Near and far points, the nodes (ties on shared vertices), duplicates, midpoints."""
    lo, hi = surface.x.min(axis=0), surface.x.max(axis=0)
    span = float((hi - lo).max())
    mid = 0.5 * (surface.x[surface.segments[:, 0]] + surface.x[surface.segments[:, 1]])
    return np.vstack(
        [
            rng.uniform(lo - 0.2 * span, hi + 0.2 * span, (60, 2)),
            rng.uniform(lo - 50 * span, hi + 50 * span, (10, 2)),  # far away
            surface.x,
            surface.x[:5],  # duplicates
            mid + rng.normal(0.0, 1e-3 * span, mid.shape),
            0.5 * (lo + hi)[None, :],  # a circle's centre
        ]
    )


def brute_force(surface: Surface, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closest segment and unclamped t of each point over all segments (same arithmetic)."""
    a = surface.x[surface.segments[:, 0]]
    ab = surface.x[surface.segments[:, 1]] - a
    length = np.hypot(ab[:, 0], ab[:, 1])
    inv_len2 = 1.0 / np.maximum(length * length, np.finfo(float).tiny)
    eps = 1e-12 * max(float(length.max()), np.finfo(float).tiny)
    mid = 0.5 * (surface.x[surface.segments[:, 0]] + surface.x[surface.segments[:, 1]])
    rank = np.empty(len(mid), dtype=np.int64)
    rank[np.lexsort((mid[:, 1], mid[:, 0]))] = np.arange(len(mid))
    seg, tt = np.empty(len(pts), dtype=np.int64), np.empty(len(pts))
    for i, p in enumerate(pts):
        dx, dy = p[0] - a[:, 0], p[1] - a[:, 1]
        t = dx * ab[:, 0]
        t += dy * ab[:, 1]
        t *= inv_len2
        tc = np.clip(t, 0.0, 1.0)
        ex, ey = dx - tc * ab[:, 0], dy - tc * ab[:, 1]
        d2 = ex * ex + ey * ey
        dmin = np.sqrt(d2.min())
        ties = np.flatnonzero(d2 <= (dmin + eps) ** 2)
        seg[i] = ties[np.argmin(rank[ties])]
        tt[i] = t[seg[i]]
    return seg, tt


@FAST
@given(graded_surfaces(), st.integers(0, 2**32 - 1))
def test_grid_search_is_brute_force(surface, seed):
    pts = query_points(surface, np.random.default_rng(seed))
    with pytest.MonkeyPatch.context() as m:
        m.setattr(search_module, "_ALL_PAIRS", 0)  # every search through the grid
        search = SegmentSearch(surface)
        seg, t, found = search.closest(pts, 1e-8)
        assert search._grid is not None
    ref_seg, ref_t = brute_force(surface, pts)
    assert np.array_equal(seg, ref_seg)
    assert np.array_equal(t, np.clip(ref_t, 0.0, 1.0))
    small = SegmentSearch(surface).closest(pts, 1e-8)  # every pair (below _ALL_PAIRS or not)
    with pytest.MonkeyPatch.context() as m:
        m.setattr(search_module, "_ALL_PAIRS", 1 << 62)
        small = SegmentSearch(surface).closest(pts, 1e-8)
    for a, b in zip(small, (seg, t, found), strict=True):
        assert a.dtype == b.dtype and np.array_equal(a, b)


def test_grid_search_chunks_give_the_same_answer():
    # Tiny chunks: many rounds of the chunk loops, the same answer as one chunk.
    rng = np.random.default_rng(3)
    s = np.r_[0.0, np.cumsum(100.0 ** rng.uniform(0, 1, 3000))]
    x = np.column_stack([s / s[-1], 0.01 * np.sin(20 * s / s[-1])])
    surface = surface_of(x, np.column_stack([np.arange(3000), np.arange(1, 3001)]))
    pts = np.vstack([x + rng.normal(0, 1e-4, x.shape), rng.uniform(-2, 2, (50, 2))])
    one = SegmentSearch(surface).closest(pts)
    with pytest.MonkeyPatch.context() as m:
        m.setattr(search_module, "_CHUNK_ENTRIES", 500)
        many = SegmentSearch(surface).closest(pts)
    for a, b in zip(one, many, strict=True):
        assert np.array_equal(a, b)
    ref_seg, ref_t = brute_force(surface, pts)
    assert np.array_equal(one[0], ref_seg) and np.array_equal(one[1], np.clip(ref_t, 0, 1))


@FAST
@given(st.integers(0, 2**32 - 1), st.sampled_from([1e-3, 0.05, 1.0, 30.0]))
def test_point_grid_queries_are_the_kdtrees(seed, cell):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 400))
    x = rng.uniform(0, 1, (n, 2)) * rng.uniform(0.01, 10, 2)
    x[rng.random(n) < 0.1] = x[0]  # duplicates
    q = np.vstack([x, rng.uniform(-20, 20, (30, 2))])
    grid = PointGrid(x, cell)
    tree = cKDTree(x)
    sub = rng.choice(n, size=min(n, 50), replace=False)
    assert np.array_equal(grid.nearest(x[sub], sub), tree.query(x[sub], k=2)[0][:, 1])
    assert np.array_equal(grid.nearest(q), tree.query(q)[0])
    # (d = 0 differs: the KD-tree's upper bound is strict, so it finds no coincident point.)
    for d in (1e-3, 0.1, 3.0):
        ref = tree.query(q, distance_upper_bound=d * (1 + 1e-9))[0] <= d
        assert np.array_equal(grid.any_within(q, d), ref)


def initial_set_with_kdtree(x: np.ndarray, act: np.ndarray, margin: float, band: float):
    """coarse_initial_set as it was, with scipy's cKDTree."""
    spacing = cKDTree(x).query(x[act], k=2)[0][:, 1]
    r = margin * float(spacing.max())
    tree_a = cKDTree(x[act])
    tree_i = cKDTree(x[~act]) if (~act).any() else None

    def near(tree, p, d):
        if tree is None or len(p) == 0:
            return np.zeros(len(p), dtype=bool)
        return tree.query(p, distance_upper_bound=d * (1 + 1e-9))[0] <= d

    return (lambda p: near(tree_a, p, r)), (lambda p: near(tree_i, p, r * band / margin))


@pytest.mark.parametrize("shape", ["graded line", "arc", "two bodies"])
def test_predictor_sets_are_the_kdtrees(shape):
    rng = np.random.default_rng(11)
    s = np.r_[0.0, np.cumsum(30.0 ** rng.uniform(0, 1, 400))]
    s /= s[-1]
    if shape == "graded line":
        x = np.column_stack([s, 0.02 * s**2])
    elif shape == "arc":
        x = np.column_stack([np.cos(np.pi * s), np.sin(np.pi * s)])
    else:
        x = np.vstack([np.column_stack([s, 0 * s]), np.column_stack([s + 3.0, 1.0 + 0 * s])])
    act = np.abs(x[:, 0] - 0.5) < 0.2
    coarse = SimpleNamespace(layout=SimpleNamespace(x=np.column_stack([x, 0 * x[:, 0]])))
    coarse.active = act
    fine = np.vstack([x + rng.normal(0, 0.01, x.shape), rng.uniform(-1, 4, (500, 2))])
    for margin, band in ((1.5, 2.0), (0.5, 2.0)):
        got = coarse_initial_set(coarse, margin, band)
        ref_active, ref_uncertain = initial_set_with_kdtree(x, act, margin, band)
        assert np.array_equal(got.active(fine), ref_active(fine))
        assert got.uncertain is not None
        assert np.array_equal(got.uncertain(fine), ref_uncertain(fine))
        assert got.active(fine).any() and got.uncertain(fine).any()
