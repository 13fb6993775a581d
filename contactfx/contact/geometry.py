"""Contact surfaces: segment geometry, chain topology, spatial search, closest-point projection."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components, depth_first_order
from scipy.spatial import cKDTree

# Candidates fetched per point in the first KD-tree round; doubled for points not yet settled.
_FIRST_K = 8
# Bound on the (points x candidates) work arrays, to keep memory flat for far-away points.
_CHUNK_ENTRIES = 4_000_000


@dataclass(frozen=True)
class Surface:
    """A contact surface of one body: Q1 boundary segments (2-node lines)."""

    x: np.ndarray  # (n, 2) float64 reference coordinates of the surface nodes
    segments: np.ndarray  # (m, 2) int64, node indices (into x) of each segment
    normals: np.ndarray  # (m, 2) float64, unit OUTWARD normal of the body on each segment
    dofs: np.ndarray  # (n, 2) int64, global dof numbers (x and y component) of each node

    def __post_init__(self) -> None:
        x = np.ascontiguousarray(self.x, dtype=np.float64).reshape(-1, 2)
        segments = np.ascontiguousarray(self.segments, dtype=np.int64).reshape(-1, 2)
        normals = np.ascontiguousarray(self.normals, dtype=np.float64).reshape(-1, 2)
        dofs = np.ascontiguousarray(self.dofs, dtype=np.int64).reshape(-1, 2)
        if normals.shape != segments.shape:
            raise ValueError("Surface: one normal per segment is required")
        if dofs.shape != x.shape:
            raise ValueError("Surface: one dof pair per node is required")
        if segments.size and (segments.min() < 0 or segments.max() >= len(x)):
            raise ValueError("Surface: segment node index out of range")
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "segments", segments)
        object.__setattr__(self, "normals", normals)
        object.__setattr__(self, "dofs", dofs)

    @property
    def n_nodes(self) -> int:
        """Number of surface nodes."""
        return len(self.x)

    @property
    def n_segments(self) -> int:
        """Number of surface segments."""
        return len(self.segments)


def segment_lengths(surface: Surface) -> np.ndarray:
    """Length of every segment, shape (m,)."""
    d = surface.x[surface.segments[:, 1]] - surface.x[surface.segments[:, 0]]
    return np.hypot(d[:, 0], d[:, 1])


def segment_midpoints(surface: Surface) -> np.ndarray:
    """Midpoint of every segment, shape (m, 2)."""
    # Sum before scaling: symmetric in the two nodes, so reversing a segment changes no bit.
    return 0.5 * (surface.x[surface.segments[:, 0]] + surface.x[surface.segments[:, 1]])


def node_degrees(surface: Surface) -> np.ndarray:
    """Number of segments touching each node, shape (n,)."""
    return np.bincount(surface.segments.ravel(), minlength=surface.n_nodes)


def nodal_normals(surface: Surface) -> np.ndarray:
    """Unit averaged outward normal at each node (mean of the adjacent segment normals), (n, 2)."""
    acc = np.zeros((surface.n_nodes, 2))
    for c in range(2):
        acc[:, c] = np.bincount(
            surface.segments.ravel(),
            weights=np.repeat(surface.normals[:, c], 2),
            minlength=surface.n_nodes,
        )
    norm = np.hypot(acc[:, 0], acc[:, 1])
    out = np.zeros_like(acc)
    np.divide(acc, norm[:, None], out=out, where=norm[:, None] > 0)
    return out


def closest_on_segments(
    points: np.ndarray, a: np.ndarray, b: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Unclamped local coordinate t of the foot on line a-b and distance to segment [a, b]."""
    ab = b - a
    t = np.einsum("...d,...d->...", points - a, ab) / np.einsum("...d,...d->...", ab, ab)
    tc = np.clip(t, 0.0, 1.0)[..., None]
    # (1 - t) a + t b gives the node coordinates bit-exactly at t = 0 and t = 1.
    diff = points - ((1.0 - tc) * a + tc * b)
    return t, np.hypot(diff[..., 0], diff[..., 1])


class SegmentSearch:
    """Closest-segment queries on one surface (KD-tree on segment midpoints, exact result)."""

    def __init__(self, surface: Surface) -> None:
        self.surface = surface
        self._a = surface.x[surface.segments[:, 0]]
        self._b = surface.x[surface.segments[:, 1]]
        mid = segment_midpoints(surface)
        half = 0.5 * segment_lengths(surface)
        self._hmax = float(half.max()) if len(half) else 0.0
        # Distances within this of the minimum count as ties (e.g. a point on a shared vertex).
        self._eps = 1e-12 * max(self._hmax, np.finfo(float).tiny)
        self._tree = cKDTree(mid) if len(mid) else None
        # Ties are broken by a rank that depends on geometry only, so that reordering or
        # reversing segments cannot change which segment wins.
        order = np.lexsort((mid[:, 1], mid[:, 0]))
        self._rank = np.empty(len(mid), dtype=np.int64)
        self._rank[order] = np.arange(len(mid))
        self._is_end = node_degrees(surface) == 1

    def closest(
        self, points: np.ndarray, tol: float = 1e-8
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closest segment, clamped local coordinate in [0, 1] and found flag for each point."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        npts, m = len(points), self.surface.n_segments
        seg = np.zeros(npts, dtype=np.int64)
        t = np.zeros(npts)
        if m == 0 or npts == 0:
            return seg, t, np.zeros(npts, dtype=bool)
        todo = np.arange(npts)
        k = min(_FIRST_K, m)
        while todo.size:
            chunk = max(1, _CHUNK_ENTRIES // k)
            unsettled = []
            for lo in range(0, todo.size, chunk):
                idx = todo[lo : lo + chunk]
                done, s, tt = self._round(points[idx], k, m)
                seg[idx[done]] = s[done]
                t[idx[done]] = tt[done]
                unsettled.append(idx[~done])
            todo = np.concatenate(unsettled)
            k = min(2 * k, m)
        n0, n1 = self.surface.segments[seg, 0], self.surface.segments[seg, 1]
        beyond = ((t < -tol) & self._is_end[n0]) | ((t > 1.0 + tol) & self._is_end[n1])
        return seg, np.clip(t, 0.0, 1.0), ~beyond

    def _round(self, p: np.ndarray, k: int, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """One search round with k candidates; returns (settled, segment, unclamped t)."""
        if k >= m:
            cand = np.broadcast_to(np.arange(m), (len(p), m))
            rk = np.full(len(p), np.inf)
        else:
            rmid, cand = self._tree.query(p, k=k, workers=-1)
            rk = rmid[:, -1]
        t, d = closest_on_segments(p[:, None, :], self._a[cand], self._b[cand])
        dmin = d.min(axis=1)
        tie = d <= (dmin + self._eps)[:, None]
        pick = np.argmin(np.where(tie, self._rank[cand], m), axis=1)
        rows = np.arange(len(p))
        # A segment outside the candidate set has its midpoint farther than rk, hence lies
        # farther than rk - hmax from p: the answer is settled once that exceeds dmin + eps.
        settled = rk > dmin + 2.0 * self._eps + self._hmax * (1.0 + 1e-12)
        return settled, cand[rows, pick], t[rows, pick]


def project(
    points: np.ndarray, passive: Surface, tol: float = 1e-8
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest-point projection onto the passive polyline: (segment, xi in [0, 1], found)."""
    return SegmentSearch(passive).closest(points, tol)


@dataclass(frozen=True)
class Chains:
    """The segments of a surface ordered along its connected polylines (chains)."""

    order: np.ndarray  # (m,) segment ids, chain after chain, each in order along its chain
    position: np.ndarray  # (m,) index of each segment within its chain
    start: np.ndarray  # (m,) offset in `order` of the chain holding each segment
    length: np.ndarray  # (m,) number of segments of the chain holding each segment
    closed: np.ndarray  # (m,) bool, whether that chain is a closed loop


def chains(surface: Surface) -> Chains:
    """Order the segments along each connected polyline of the surface."""
    n, m = surface.n_nodes, surface.n_segments
    deg = node_degrees(surface)
    if np.any(deg > 2):
        raise ValueError("contact surface is not a set of simple polylines (node degree > 2)")
    s0, s1 = surface.segments[:, 0], surface.segments[:, 1]
    key = np.minimum(s0, s1) * n + np.maximum(s0, s1)
    key_order = np.argsort(key, kind="stable")
    adj = sp.coo_matrix((np.ones(m), (s0, s1)), shape=(n, n)).tocsr()
    ncomp, label = connected_components(adj, directed=False)
    seg_comp = label[s0]
    order, position = np.empty(m, np.int64), np.empty(m, np.int64)
    start, length = np.empty(m, np.int64), np.empty(m, np.int64)
    closed = np.zeros(m, dtype=bool)
    offset = 0
    # One pass per polyline: a contact surface has a handful of them.
    for comp in np.unique(seg_comp):
        comp_nodes = np.flatnonzero(label == comp)
        ends = comp_nodes[deg[comp_nodes] == 1]
        is_loop = ends.size == 0
        first = comp_nodes.min() if is_loop else ends.min()
        if is_loop:
            # Cut the loop at `first` by dropping one of its segments, then walk the path.
            segs_here = np.flatnonzero(seg_comp == comp)
            cut = segs_here[(s0[segs_here] == first) | (s1[segs_here] == first)].min()
            keep = np.ones(m, dtype=bool)
            keep[cut] = False
            graph = sp.coo_matrix((np.ones(keep.sum()), (s0[keep], s1[keep])), shape=(n, n))
            walk = depth_first_order(graph.tocsr(), first, directed=False)[0].astype(np.int64)
        else:
            walk = depth_first_order(adj, first, directed=False)[0].astype(np.int64)
        pairs = np.stack([walk[:-1], walk[1:]], axis=1)
        if is_loop:
            pairs = np.vstack([pairs, [[walk[-1], walk[0]]]])
        pkey = pairs.min(axis=1) * n + pairs.max(axis=1)
        ids = key_order[np.searchsorted(key, pkey, sorter=key_order)]
        order[offset : offset + len(ids)] = ids
        position[ids] = np.arange(len(ids))
        start[ids] = offset
        length[ids] = len(ids)
        closed[ids] = is_loop
        offset += len(ids)
    return Chains(order=order, position=position, start=start, length=length, closed=closed)
