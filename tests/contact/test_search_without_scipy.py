"""The search and chain code without scipy.spatial / csgraph gives scipy's answers exactly.

A small search compares every point with every segment instead of querying the grid, and
the chains are walked without scipy.sparse.csgraph (docs/scale.md, "Time to the first
answer"). References: scipy's connected_components and depth_first_order (the previous
implementation, kept here), and the grid path of the same search (test_grid_search.py: both
against brute force).
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse.csgraph import connected_components, depth_first_order

from contactfx.contact import geometry
from contactfx.contact import search as search_module
from contactfx.contact.geometry import Surface, chains
from contactfx.contact.search import SegmentSearch

FAST = settings(max_examples=60, deadline=None)


@st.composite
def polylines(draw):
    """A surface of open polylines and closed loops (>= 3 segments), nodes randomly numbered."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    pieces = draw(st.lists(st.tuples(st.integers(2, 9), st.booleans()), min_size=1, max_size=5))
    xs, segs, n = [], [], 0
    for k, (nodes, loop) in enumerate(pieces):
        count = max(nodes, 3) if loop else nodes
        angle = np.linspace(0.0, 2 * np.pi, count, endpoint=False)
        xs.append(np.column_stack([10.0 * k + np.cos(angle), np.sin(angle)]))
        ids = n + np.arange(count)
        segs.append(
            np.column_stack([ids, np.roll(ids, -1)])
            if loop
            else np.column_stack([ids[:-1], ids[1:]])
        )
        n += count
    isolated = draw(st.integers(0, 3))  # nodes on no segment
    x = np.vstack([*xs, rng.uniform(-5, 5, (isolated, 2))])
    seg = np.vstack(segs)
    order = rng.permutation(len(x))  # new node i is old node order[i]
    new = np.empty_like(order)
    new[order] = np.arange(len(order))
    seg = new[seg][rng.permutation(len(seg))]
    flip = rng.random(len(seg)) < 0.5
    seg[flip] = seg[flip, ::-1]
    t = x[order][seg[:, 1]] - x[order][seg[:, 0]]
    normals = np.column_stack([-t[:, 1], t[:, 0]]) / np.linalg.norm(t, axis=1)[:, None]
    return Surface(x[order], seg, normals, 2 * np.arange(len(x))[:, None] + np.arange(2))


def chains_with_scipy(surface: Surface) -> tuple[np.ndarray, ...]:
    """The chain order as computed before, with scipy.sparse.csgraph."""
    n, m = surface.n_nodes, surface.n_segments
    deg = np.bincount(surface.segments.ravel(), minlength=n)
    s0, s1 = surface.segments[:, 0], surface.segments[:, 1]
    key = np.minimum(s0, s1) * n + np.maximum(s0, s1)
    key_order = np.argsort(key, kind="stable")
    adj = sp.coo_matrix((np.ones(m), (s0, s1)), shape=(n, n)).tocsr()
    _, label = connected_components(adj, directed=False)
    seg_comp = label[s0]
    order, position, closed = [], np.empty(m, np.int64), np.zeros(m, dtype=bool)
    for comp in np.unique(seg_comp):
        comp_nodes = np.flatnonzero(label == comp)
        ends = comp_nodes[deg[comp_nodes] == 1]
        is_loop = ends.size == 0
        first = comp_nodes.min() if is_loop else ends.min()
        graph = adj
        if is_loop:
            segs_here = np.flatnonzero(seg_comp == comp)
            cut = segs_here[(s0[segs_here] == first) | (s1[segs_here] == first)].min()
            keep = np.ones(m, dtype=bool)
            keep[cut] = False
            graph = sp.coo_matrix((np.ones(keep.sum()), (s0[keep], s1[keep])), shape=(n, n)).tocsr()
        walk = depth_first_order(graph, first, directed=False)[0]
        pairs = np.stack([walk[:-1], walk[1:]], axis=1)
        if is_loop:
            pairs = np.vstack([pairs, [[walk[-1], walk[0]]]])
        ids = key_order[
            np.searchsorted(key, pairs.min(axis=1) * n + pairs.max(axis=1), sorter=key_order)
        ]
        position[ids] = np.arange(len(ids))
        closed[ids] = is_loop
        order.append(ids)
    return np.concatenate(order), position, closed


@FAST
@given(polylines())
def test_chains_are_scipys(surface):
    ch = chains(surface)
    order, position, closed = chains_with_scipy(surface)
    assert np.array_equal(ch.order, order)
    assert np.array_equal(ch.position, position)
    assert np.array_equal(ch.closed, closed)


@FAST
@given(polylines())
def test_component_labels_are_scipys(surface):
    n, (s0, s1) = surface.n_nodes, surface.segments.T
    adj = sp.coo_matrix((np.ones(len(s0)), (s0, s1)), shape=(n, n))
    _, label = connected_components(adj, directed=False)
    assert np.array_equal(geometry._component_labels(n, s0, s1), label)


@FAST
@given(polylines(), st.integers(0, 2**32 - 1))
def test_all_pairs_search_is_the_grid_search(surface, seed):
    rng = np.random.default_rng(seed)
    lo, hi = surface.x.min(axis=0) - 1.0, surface.x.max(axis=0) + 1.0
    # Random points, the nodes themselves (ties between two segments) and a near-node point.
    pts = np.vstack([rng.uniform(lo, hi, (40, 2)), surface.x, surface.x[:1] + 1e-3])
    search = SegmentSearch(surface)
    small = search.closest(pts, 1e-8)  # npts * m below _ALL_PAIRS: every pair
    assert search._grid is None
    with pytest.MonkeyPatch.context() as m:
        m.setattr(search_module, "_ALL_PAIRS", 0)
        grid = search.closest(pts, 1e-8)
    assert search._grid is not None
    for a, b in zip(small, grid, strict=True):
        assert a.dtype == b.dtype and np.array_equal(a, b)


def test_component_labels_of_long_scrambled_chains_are_scipys():
    # Long polylines with random node numbering: the case a label propagation one hop per
    # round would take thousands of rounds on; the labels must still be scipy's.
    rng = np.random.default_rng(7)
    n = 20_000
    perm = rng.permutation(n)
    cuts = np.sort(rng.choice(np.arange(1, n - 1), 5, replace=False))
    keep = ~np.isin(np.arange(n - 1), cuts)
    s0, s1 = perm[:-1][keep], perm[1:][keep]
    adj = sp.coo_matrix((np.ones(len(s0)), (s0, s1)), shape=(n, n))
    ncomp, label = connected_components(adj, directed=False)
    assert ncomp == 6
    assert np.array_equal(geometry._component_labels(n, s0, s1), label)
