"""Contact surfaces: segment geometry, chain topology, spatial search, closest-point projection."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .grid import PointGrid

# Cell side of the search grid over the median sample spacing (docs/scale.md, "Time to the
# first answer").
_GRID_CELL = 1.0
# Bound on the (points x candidates) work arrays, to keep memory flat for far-away points.
_CHUNK_ENTRIES = 4_000_000
# Up to this many (points x segments) pairs a search compares every point with every
# segment (same segments and coordinates as the grid's): below it a few such searches cost
# less than building the grid (docs/scale.md, "Time to the first answer").
_ALL_PAIRS = 1 << 17


@dataclass(frozen=True)
class Surface:
    """A contact surface of one body: Q1 boundary segments (2-node lines)."""

    x: np.ndarray  # (n, 2) float64 reference coordinates of the surface nodes
    segments: np.ndarray  # (m, 2) int64, node indices (into x) of each segment
    normals: np.ndarray  # (m, 2) float64, unit OUTWARD normal of the body on each segment
    dofs: np.ndarray  # (n, 2) int64, global dof numbers (x and y component) of each node
    # The curve of an axisymmetric model (x = r): every contact integral over it is over the
    # revolved surface, with the measure 2 pi r ds (`radial_weight`).
    axisymmetric: bool = False

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


def radial_weight(surface: Surface, points: np.ndarray) -> np.ndarray:
    """The factor of ds at `points` (p, 2) of the surface: 2 pi x if axisymmetric, else 1.

    Every contact kernel multiplies its quadrature weights by it at its quadrature points,
    so that D, M, the gaps' weights and the nodal weights are integrals over the revolved
    surface (and the multipliers stay pressures, the nodal forces totals over the turn).
    """
    x = np.asarray(points, dtype=np.float64).reshape(-1, 2)[:, 0]
    return 2.0 * np.pi * x if surface.axisymmetric else np.ones_like(x)


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


class SegmentSearch:
    """Exact closest-segment queries on one surface (a bucket grid of sample points)."""

    def __init__(self, surface: Surface) -> None:
        self.surface = surface
        m = surface.n_segments
        a = surface.x[surface.segments[:, 0]]
        ab = surface.x[surface.segments[:, 1]] - a
        length = np.hypot(ab[:, 0], ab[:, 1])
        inv_len2 = 1.0 / np.maximum(length * length, np.finfo(float).tiny)
        self._segdata = (a[:, 0].copy(), a[:, 1].copy(), ab[:, 0].copy(), ab[:, 1].copy(), inv_len2)
        # Long segments are sampled at several points so that every point of every segment is
        # within `_reach` of one of its samples; this keeps the termination test below local
        # on graded meshes. The spacing is capped so there are at most 4 m samples in all.
        spacing = max(np.median(length), length.sum() / (3 * m)) if m else 1.0
        pieces = np.maximum(np.ceil(length / spacing), 1).astype(np.int64)
        self._owner = np.repeat(np.arange(m), pieces)
        frac = np.arange(len(self._owner)) - np.repeat(np.cumsum(pieces) - pieces, pieces) + 0.5
        frac /= np.repeat(pieces, pieces)
        samples = a[self._owner] + frac[:, None] * ab[self._owner]
        self._piece = np.repeat(length / pieces, pieces)
        self._reach = float(0.5 * self._piece.max()) if m else 0.0
        self._samples = samples
        self._grid: PointGrid | None = None
        # Distances within this of the minimum count as ties (e.g. a point on a shared vertex).
        self._eps = 1e-12 * max(float(length.max()) if m else 0.0, np.finfo(float).tiny)
        # Ties are broken by a rank that depends on geometry only, so that reordering or
        # reversing segments cannot change which segment wins.
        mid = segment_midpoints(surface)
        self._rank = np.empty(m, dtype=np.int64)
        self._rank[np.lexsort((mid[:, 1], mid[:, 0]))] = np.arange(m)
        self._is_end = node_degrees(surface) == 1

    @property
    def grid(self) -> PointGrid:
        """The bucket grid of the samples, built at the first search that needs one."""
        if self._grid is None:
            # Cells of the median sample spacing: about one sample per cell along the
            # surface where most samples are (_GRID_CELL in docs/scale.md).
            cell = _GRID_CELL * float(np.median(self._piece)) if len(self._piece) else 1.0
            self._grid = PointGrid(self._samples, cell)
        return self._grid

    def closest(
        self, points: np.ndarray, tol: float = 1e-8, group: int = 1
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closest segment, clamped local coordinate in [0, 1] and found flag for each point.

        `group` is accepted for the callers whose points come in runs (Gauss points); each
        point is searched on its own, which costs about as much.
        """
        points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        npts, m = len(points), self.surface.n_segments
        seg = np.zeros(npts, dtype=np.int64)
        t = np.zeros(npts)
        if m == 0 or npts == 0:
            return seg, t, np.zeros(npts, dtype=bool)
        if npts * m <= _ALL_PAIRS:
            # A small search takes every segment as a candidate of every point: the exact
            # closest segment, ties broken by the same rank, as with the grid.
            cand = np.broadcast_to(np.arange(m), (npts, m))
            self._settle(points[:, None], cand, np.full(npts, np.inf), np.arange(npts), seg, t)
        else:
            self._grid_search(points, seg, t)
        n0, n1 = self.surface.segments[seg, 0], self.surface.segments[seg, 1]
        beyond = ((t < -tol) & self._is_end[n0]) | ((t > 1.0 + tol) & self._is_end[n1])
        return seg, np.clip(t, 0.0, 1.0), ~beyond

    def _grid_search(self, points: np.ndarray, seg: np.ndarray, t: np.ndarray) -> None:
        """The closest segments by growing boxes of grid cells around each point."""
        grid = self.grid
        # The first box reaches `_reach` beyond the query's cell (every segment through it)
        # and the nearest row of samples (a point off the surface finds some at once).
        ring = grid.first_ring(points) + int(np.ceil(self._reach / grid.cell)) + 1
        todo = np.arange(len(points))
        while todo.size:
            unsettled, dmins = [], []
            # Chunks bound the (points x box rows) and (points x candidates) work arrays.
            rows = np.minimum(2 * ring[todo] + 1, grid.nrow)
            for idx in _chunks(todo, rows):
                start, count, owner, bound = grid.box(points[idx], ring[idx])
                # Segments outside the box are at least its bound less `_reach` away.
                whole = np.isinf(bound)
                bound -= self._reach
                per_point = np.bincount(owner, weights=count, minlength=len(idx))
                for sub in _chunks(np.arange(len(idx)), per_point):
                    lo, hi = np.searchsorted(owner, [sub[0], sub[-1] + 1])
                    ids = grid.expand(start[lo:hi], count[lo:hi])
                    at = np.repeat(owner[lo:hi] - sub[0], count[lo:hi])
                    p, b = points[idx[sub]], bound[sub]
                    at, ids, b = self._nearby_samples(p, at, ids, b, whole[sub])
                    left, dmin = self._settle_flat(p, at, self._owner[ids], b, idx[sub], seg, t)
                    unsettled.append(left)
                    dmins.append(dmin)
            left, dmin = np.concatenate(unsettled), np.concatenate(dmins)
            # A box of ring r reaches r cells from its point: enough rings to cover the best
            # distance found and the reach, at least one more (twice as many if none found).
            need = np.ceil((dmin + self._reach + 2.0 * self._eps) / grid.cell * (1 + 1e-9) + 1.0)
            old = ring[left]
            grown = np.where(np.isfinite(need), np.maximum(need, old + 1), 2 * old)
            ring[left] = np.minimum(grown, 2.0**60).astype(np.int64)
            todo = left

    def _nearby_samples(
        self, p: np.ndarray, at: np.ndarray, ids: np.ndarray, bound: np.ndarray, whole: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Drop the box's samples too far to matter; the bound drops accordingly.

        The nearest sample (on a segment) is at ds; a segment none of whose samples is within
        ds + 2 reach (+ slack) is farther than ds + reach, so it can neither win nor tie.
        Sample distances cost a fraction of the segment distances on the rest. Points whose
        box is the `whole` grid keep every sample (and an infinite bound): they settle.
        """
        dx = p[at, 0] - self._samples[ids, 0]
        dy = p[at, 1] - self._samples[ids, 1]
        dx *= dx
        dy *= dy
        dx += dy  # squared distances
        dsmin = np.sqrt(_group_min(dx, at, len(p)))
        slack = 4.0 * self._eps + 1e-9 * dsmin
        keep = (dx <= ((dsmin + 2.0 * self._reach + slack) ** 2)[at]) | whole[at]
        near = np.where(whole, bound, np.minimum(bound, dsmin + self._reach + slack))
        return at[keep], ids[keep], near

    def _settle_flat(
        self,
        p: np.ndarray,
        at: np.ndarray,
        cand: np.ndarray,
        bound: np.ndarray,
        idx: np.ndarray,
        seg: np.ndarray,
        t_out: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """`_settle` on ragged candidates: point at[j] has candidate segment cand[j].

        The entries of a point are contiguous. The same arithmetic as `_settle`, so the same
        distances, picks and t to the bit; returns the unsettled ids and their best distance
        (inf where a point had no candidate).
        """
        n = len(p)
        ax, ay, abx, aby, inv_len2 = (a[cand] for a in self._segdata)
        dx = p[at, 0] - ax
        dy = p[at, 1] - ay
        t = dx * abx
        t += dy * aby
        t *= inv_len2
        tc = np.clip(t, 0.0, 1.0)
        dx -= tc * abx
        dy -= tc * aby
        dx *= dx
        dy *= dy
        d2 = dx + dy
        dmin = np.sqrt(_group_min(d2, at, n))
        # Among the near-ties (all one segment unless on a shared vertex or the like), the
        # least geometric rank: `_settle`'s pick whether or not the tie has distinct segments.
        tie = d2 <= ((dmin + self._eps) ** 2)[at]
        big = np.iinfo(np.int64).max
        rank = np.where(tie, self._rank[cand], big)
        best = np.full(n, big)
        np.minimum.at(best, at, rank)
        win = np.flatnonzero(tie & (rank == best[at]))
        first = np.full(n, len(cand))
        np.minimum.at(first, at[win], win)  # the first entry of each point's winner
        settled = (bound * (1.0 - 1e-12) > dmin + 2.0 * self._eps) & (first < len(cand))
        seg[idx[settled]] = cand[first[settled]]
        t_out[idx[settled]] = t[first[settled]]
        return idx[~settled], dmin[~settled]

    def _settle(
        self,
        p: np.ndarray,
        cand: np.ndarray,
        bound: np.ndarray,
        idx: np.ndarray,
        seg: np.ndarray,
        t_out: np.ndarray,
    ) -> np.ndarray:
        """Closest of the candidate segments; store it where settled, return unsettled ids."""
        # p: (n, g, 2), runs of g points sharing the candidates cand (n, k); bound (n * g,):
        # every segment outside `cand` is farther than this from the point.
        n, g, k = p.shape[0], p.shape[1], cand.shape[1]
        ax, ay, abx, aby, inv_len2 = (a[cand][:, None, :] for a in self._segdata)
        dx = p[:, :, :1] - ax
        dy = p[:, :, 1:] - ay
        t = dx * abx
        t += dy * aby
        t *= inv_len2
        tc = np.clip(t, 0.0, 1.0)
        dx -= tc * abx
        dy -= tc * aby
        dx *= dx
        dy *= dy
        d2 = (dx + dy).reshape(n * g, k)
        t = t.reshape(n * g, k)
        rows = np.arange(n * g)
        crow = rows // g  # the candidate row of each point
        pick = np.argmin(d2, axis=1)
        dmin = np.sqrt(d2[rows, pick])
        # Resolve near-ties between distinct segments by the geometric rank.
        tie = d2 <= ((dmin + self._eps) ** 2)[:, None]
        multi = np.flatnonzero((tie & (cand[crow] != cand[crow, pick][:, None])).any(axis=1))
        if multi.size:
            rank = np.where(tie[multi], self._rank[cand[crow[multi]]], np.iinfo(np.int64).max)
            pick[multi] = np.argmin(rank, axis=1)
        settled = bound * (1.0 - 1e-12) > dmin + 2.0 * self._eps
        seg[idx[settled]] = cand[crow, pick][settled]
        t_out[idx[settled]] = t[rows, pick][settled]
        return idx[~settled]


def _group_min(values: np.ndarray, at: np.ndarray, n: int) -> np.ndarray:
    """Minimum of `values` per group (at sorted, groups 0..n-1); inf for empty groups."""
    out = np.full(n, np.inf)
    if len(at):
        starts = np.flatnonzero(np.r_[True, at[1:] != at[:-1]])
        out[at[starts]] = np.minimum.reduceat(values, starts)
    return out


def _chunks(ids: np.ndarray, weight: np.ndarray) -> list[np.ndarray]:
    """`ids` cut into runs of about `_CHUNK_ENTRIES` total weight (one id may exceed it)."""
    if ids.size == 0:
        return []
    cum = np.cumsum(weight)
    cuts = np.searchsorted(cum, np.arange(1, int(cum[-1] // _CHUNK_ENTRIES) + 1) * _CHUNK_ENTRIES)
    return [c for c in np.split(ids, np.unique(np.minimum(cuts + 1, ids.size))) if c.size]


def project(
    points: np.ndarray, passive: Surface, tol: float = 1e-8, group: int = 1
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest-point projection onto the passive polyline: (segment, xi in [0, 1], found)."""
    # group > 1 only speeds up the search when points come in runs of `group` close together.
    return SegmentSearch(passive).closest(points, tol, group)


@dataclass(frozen=True)
class Chains:
    """The segments of a surface ordered along its connected polylines (chains)."""

    order: np.ndarray  # (m,) segment ids, chain after chain, each in order along its chain
    position: np.ndarray  # (m,) index of each segment within its chain
    start: np.ndarray  # (m,) offset in `order` of the chain holding each segment
    length: np.ndarray  # (m,) number of segments of the chain holding each segment
    closed: np.ndarray  # (m,) bool, whether that chain is a closed loop


def _component_labels(n: int, s0: np.ndarray, s1: np.ndarray) -> np.ndarray:
    """Connected-component label of each of n nodes, numbered in the order of their least node.

    (scipy's connected_components numbering, without the scipy.sparse.csgraph import.) Each
    round hooks every tree's root onto the least root across its segments, then jumps the
    pointers to the roots: the roots stay their trees' least nodes, and on polylines every
    tree that is not a local minimum of its neighbours merges, so the rounds are logarithmic
    in the chain length whatever the node numbering.
    """
    parent = np.arange(n)
    while True:
        r0, r1 = parent[s0], parent[s1]
        lo, hi = np.minimum(r0, r1), np.maximum(r0, r1)
        join = lo != hi
        if not join.any():
            break
        np.minimum.at(parent, hi[join], lo[join])
        while True:
            up = parent[parent]
            if np.array_equal(up, parent):
                break
            parent = up
    # Roots are each component's least node: renumber them 0, 1, ... in that order.
    return np.unique(parent, return_inverse=True)[1].reshape(-1)


def _incidence(n: int, s0: np.ndarray, s1: np.ndarray) -> np.ndarray:
    """(n, 2): the (at most two) segments at each node, -1 where there are fewer."""
    ends = np.concatenate([s0, s1])
    order = np.argsort(ends, kind="stable")
    e = ends[order]
    slot = np.arange(len(e)) - np.searchsorted(e, e, side="left")
    inc = np.full((n, 2), -1, dtype=np.int64)
    inc[e, slot] = order % len(s0)
    return inc


def _walk(inc: np.ndarray, s0: np.ndarray, s1: np.ndarray, first: int, cut: int) -> np.ndarray:
    """The nodes of the path from `first` (an end, or a loop's node next to segment `cut`)."""
    nodes, node, came = [first], first, cut
    while True:
        a, b = inc[node]
        nxt_seg = int(b if a == came else a)
        if nxt_seg < 0 or nxt_seg == came or nxt_seg == cut:
            break
        node = int(s1[nxt_seg] if s0[nxt_seg] == node else s0[nxt_seg])
        nodes.append(node)
        came = nxt_seg
    return np.asarray(nodes, dtype=np.int64)


def chains(surface: Surface) -> Chains:
    """Order the segments along each connected polyline of the surface."""
    n, m = surface.n_nodes, surface.n_segments
    deg = node_degrees(surface)
    if np.any(deg > 2):
        raise ValueError("contact surface is not a set of simple polylines (node degree > 2)")
    s0, s1 = surface.segments[:, 0], surface.segments[:, 1]
    key = np.minimum(s0, s1) * n + np.maximum(s0, s1)
    key_order = np.argsort(key, kind="stable")
    label = _component_labels(n, s0, s1)
    inc = _incidence(n, s0, s1)
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
            walk = _walk(inc, s0, s1, int(first), int(cut))
        else:
            walk = _walk(inc, s0, s1, int(first), -1)
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


def arc_length(surface: Surface) -> tuple[np.ndarray, np.ndarray]:
    """(s, t): arc length and unit tangent of every node along the surface's polylines.

    Each polyline starts at its end with the smallest (x, y) so that s does not depend on
    the node numbering (and hence not on the number of ranks); polylines follow one
    another in that order, s continuing from one to the next.
    """
    ch = chains(surface)
    seg = surface.segments
    s = np.full(surface.n_nodes, np.nan)
    t = np.zeros((surface.n_nodes, 2))
    runs = [
        ch.order[st : st + ln]
        for st, ln in sorted({(int(a), int(b)) for a, b in zip(ch.start, ch.length, strict=True)})
    ]
    walks = []
    for run in runs:
        # Node sequence along the run, from the first segment's free end.
        a, b = seg[run[0]]
        if len(run) > 1 and a in seg[run[1]]:
            a, b = b, a
        nodes: list[np.integer] | np.ndarray
        nodes = [a, b]
        for e in run[1:]:
            p, q = seg[e]
            nodes.append(q if p == nodes[-1] else p)
        nodes = np.array(nodes)
        xa, xb = surface.x[nodes[0]], surface.x[nodes[-1]]
        if (xb[0], xb[1]) < (xa[0], xa[1]):
            nodes = nodes[::-1]
        walks.append(nodes)
    walks.sort(key=lambda w: (surface.x[w[0], 0], surface.x[w[0], 1]))
    start = 0.0
    for nodes in walks:
        d = np.diff(surface.x[nodes], axis=0)
        ds = np.hypot(d[:, 0], d[:, 1])
        s[nodes] = start + np.concatenate([[0.0], np.cumsum(ds)])
        start = float(s[nodes[-1]])
        tang = np.zeros((len(nodes), 2))
        tang[:-1] += d / ds[:, None]
        tang[1:] += d / ds[:, None]
        t[nodes] = tang / np.linalg.norm(tang, axis=1)[:, None]
    return s, t
