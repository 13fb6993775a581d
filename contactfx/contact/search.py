"""Closest-segment search and projection on a contact surface, without scipy.spatial.

A small search compares every point with every segment; a larger one visits growing boxes of
a bucket grid of sample points (contact/grid.py): the same answers (docs/scale.md, "Time to
the first answer").
"""

from __future__ import annotations

import numpy as np

from .geometry import Surface, node_degrees, segment_midpoints
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


def _distance2(
    dx: np.ndarray, dy: np.ndarray, abx: np.ndarray, aby: np.ndarray, inv_len2: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(squared distance, unclamped t) of points at offsets (dx, dy) from segments' starts.

    Works in place on dx and dy; one arithmetic for every search, so that all give the same
    distances and t to the bit.
    """
    t = dx * abx
    t += dy * aby
    t *= inv_len2
    tc = np.clip(t, 0.0, 1.0)
    dx -= tc * abx
    dy -= tc * aby
    dx *= dx
    dy *= dy
    return dx + dy, t


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
        self, points: np.ndarray, tol: float = 1e-8
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closest segment, clamped local coordinate in [0, 1] and found flag for each point."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        npts, m = len(points), self.surface.n_segments
        seg = np.zeros(npts, dtype=np.int64)
        t = np.zeros(npts)
        if m == 0 or npts == 0:
            return seg, t, np.zeros(npts, dtype=bool)
        if npts * m <= _ALL_PAIRS:
            # A small search takes every segment as a candidate of every point: the exact
            # closest segment, ties broken by the same rank, as with the grid.
            at, cand = np.repeat(np.arange(npts), m), np.tile(np.arange(m), npts)
            self._settle(points, at, cand, np.full(npts, np.inf), np.arange(npts), seg, t)
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
                    left, dmin = self._settle(p, at, self._owner[ids], b, idx[sub], seg, t)
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

    def _settle(
        self,
        p: np.ndarray,
        at: np.ndarray,
        cand: np.ndarray,
        bound: np.ndarray,
        idx: np.ndarray,
        seg: np.ndarray,
        t_out: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Closest of the candidate segments; store it where settled.

        Point at[j] has candidate segment cand[j] (a point's entries contiguous); `bound`:
        every segment outside a point's candidates is farther than this. Returns the
        unsettled ids and their best distance (inf where a point had no candidate).
        """
        n = len(p)
        ax, ay, abx, aby, inv_len2 = (a[cand] for a in self._segdata)
        d2, t = _distance2(p[at, 0] - ax, p[at, 1] - ay, abx, aby, inv_len2)
        dmin = np.sqrt(_group_min(d2, at, n))
        # Among the near-ties (all one segment unless on a shared vertex or the like), the
        # least geometric rank, so that reordering segments cannot change the pick.
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
    points: np.ndarray, passive: Surface, tol: float = 1e-8
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest-point projection onto the passive polyline: (segment, xi in [0, 1], found)."""
    return SegmentSearch(passive).closest(points, tol)
