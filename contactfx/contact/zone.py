"""A contact zone's extent along a surface from a coarser solve: where each edge lies.

The coarse predictor's fine set was every fine node near a coarse active node, which puts
each zone edge anywhere within the coarse element past the last active coarse node. Here the
edge inside that element is estimated from the coarse pressures: at a smooth edge (a
non-conforming contact, Hertz's or any other) the pressure goes like the square root of the
distance to it, so p^2 is extrapolated linearly from the last active nodes to its zero.
Where the pressure does not fall towards the edge (a corner of the geometry, a lone active
node) nothing says where in the element the edge is, and the coverage is a given fallback
distance (the former rule's).
"""

from __future__ import annotations

import numpy as np

from .geometry import Surface, incidence
from .search import SegmentSearch

# The two extrapolated zeros of a resolved smooth edge agree within this many elements of
# the coarse mesh; a zone of a few coarse nodes disagrees by more (both measured in
# docs/scale.md, "An exact first set").
AGREE = 0.25


def _beyond(
    seg: np.ndarray, other: np.ndarray, k: np.ndarray, node: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The segment past `node` (an end of segments `k`) and its far node; -1 where none."""
    ok = (k >= 0) & (node >= 0)
    k0 = np.where(ok, k, 0)
    nk = np.where(ok, other[k0, np.where(seg[k0, 0] == node, 0, 1)], -1)
    nk0 = np.maximum(nk, 0)
    far = np.where(seg[nk0, 0] == node, seg[nk0, 1], seg[nk0, 0])
    return nk, np.where(nk >= 0, far, -1)


def edge_distances(
    x: np.ndarray,
    segments: np.ndarray,
    active: np.ndarray,
    p: np.ndarray,
    fallback: float,
    margin: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """How far along each segment the zone reaches from either end: (from_a, from_b).

    `active` and `p` (pressure, compression > 0) are per node of the polyline `x`,
    `segments`. A segment between two active nodes is covered whole (its length from
    either end). From an active end A towards an inactive one, to the estimated edge plus
    `margin` times the segment's length: the zeros of p^2 extrapolated linearly from A and
    its inner neighbour A2 and from A2 and the next, A3, averaged (A's own pressure is the
    most perturbed by the edge inside its element). Only where the pressure rises over A,
    A2, A3 and the two zeros agree within AGREE segment lengths is the edge smooth and
    resolved; elsewhere (a corner, a zone of a few coarse nodes) `fallback`. Clamped to
    [0, length]; -1 from an inactive end.
    """
    seg = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
    length = np.linalg.norm(x[seg[:, 1]] - x[seg[:, 0]], axis=1)
    # The other segment through each end of each segment (a polyline: two per node at most).
    inc = incidence(len(x), seg[:, 0], seg[:, 1])
    k = np.arange(len(seg))
    other = np.column_stack(
        [np.where(inc[seg[:, e], 0] == k, inc[seg[:, e], 1], inc[seg[:, e], 0]) for e in (0, 1)]
    )
    on = np.append(np.asarray(active, dtype=bool), False)  # index -1: no node
    q = np.append(np.asarray(p, dtype=float), 0.0) ** 2
    xx = np.vstack([x, np.zeros((1, 2))])

    def reach(end: int) -> np.ndarray:
        """Distance covered from node seg[:, end] into each segment."""
        a0, far = seg[:, end], seg[:, 1 - end]
        k1, a1 = _beyond(seg, other, np.arange(len(seg)), a0)
        a2 = _beyond(seg, other, k1, a1)[1]
        d01 = np.linalg.norm(xx[a0] - xx[a1], axis=1)
        d12 = np.linalg.norm(xx[a1] - xx[a2], axis=1)
        ok = on[a0] & on[a1] & on[a2] & (q[a1] > q[a0]) & (q[a2] > q[a1])
        e1 = q[a0] * d01 / np.where(ok, q[a1] - q[a0], 1.0)
        e2 = q[a1] * d12 / np.where(ok, q[a2] - q[a1], 1.0) - d01
        ok &= np.abs(e1 - e2) <= AGREE * length
        est = np.clip(0.5 * (e1 + e2), 0.0, length) + margin * length
        out = np.where(ok, est, np.minimum(fallback, length))
        out = np.where(on[far], length, out)
        return np.where(on[a0], out, -1.0)

    return reach(0), reach(1)


def covered(
    points: np.ndarray,
    surface: Surface,
    from_a: np.ndarray,
    from_b: np.ndarray,
    tol: float,
) -> np.ndarray:
    """Which `points` lie on the covered part of `surface` (within `tol` of it).

    A point projects onto its closest segment; it is covered if its distance from the
    segment's first node is at most from_a, or from its second node at most from_b (both
    per segment, as `edge_distances` gives them).
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    if len(pts) == 0 or surface.n_segments == 0:
        return np.zeros(len(pts), dtype=bool)
    seg, t, _ = SegmentSearch(surface).closest(pts)
    xa = surface.x[surface.segments[seg, 0]]
    xb = surface.x[surface.segments[seg, 1]]
    length = np.linalg.norm(xb - xa, axis=1)
    foot = xa + t[:, None] * (xb - xa)
    near = np.linalg.norm(pts - foot, axis=1) <= tol
    along = t * length
    return near & ((along <= from_a[seg]) | (length - along <= from_b[seg]))
