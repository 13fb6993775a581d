"""A uniform bucket grid over 2D points: box and nearest-point queries in numpy only.

The closest-segment search and the coarse predictor used scipy.spatial's KD-tree, whose
import is a fixed cost of every solve that searches (measured against the solve itself:
docs/scale.md, "Time to the first answer").

Here the points are sorted by the key row * ncol + col of their cell; the cells of one row of a
box are consecutive keys, so a box is one `np.searchsorted` range per row holding points,
vectorized over the query points. Only the sorted keys are stored (O(points) whatever the cell
size). Rows run across the shorter side of the bounding box, so a tall box costs at most that
many ranges.

A query returns every point of the box of cells within ring r of the query's cell and a
lower bound on the distance to every point outside it: the exact answers follow from
growing r until that bound exceeds the best distance found.
"""

from __future__ import annotations

import numpy as np

# Keys stay below 2**60: the cell is at least the bounding box's longer side over this.
_MAX_CELLS_PER_SIDE = 1 << 30
# Rings (in cells) are capped here: a box of this ring about any finite query holds the grid.
_MAX_RING = 1 << 60


class PointGrid:
    """Points bucketed by a uniform grid of square cells of side `cell`."""

    def __init__(self, points: np.ndarray, cell: float) -> None:
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        self.points = pts
        lo = pts.min(axis=0) if len(pts) else np.zeros(2)
        extent = pts.max(axis=0) - lo if len(pts) else np.zeros(2)
        # Columns along the longer side: a box then spans at most the shorter side in rows.
        self._axes = (0, 1) if extent[0] >= extent[1] else (1, 0)
        floor = float(extent.max()) / _MAX_CELLS_PER_SIDE
        h = max(float(cell), floor, np.finfo(float).tiny)
        if not np.isfinite(h):
            h = 1.0
        self.cell = h
        self._lo = lo[list(self._axes)]
        u, v = self._cell_coords(pts)
        self.ncol = int(np.floor(u.max())) + 1 if len(pts) else 1
        self.nrow = int(np.floor(v.max())) + 1 if len(pts) else 1
        key = np.floor(v).astype(np.int64) * self.ncol + np.floor(u).astype(np.int64)
        self._order = np.argsort(key, kind="stable")
        self._keys = key[self._order]
        # The rows holding points: a box visits only those (a surface crosses few rows).
        self._rows = np.unique(self._keys // self.ncol)
        # Rounding of the cell coordinates: bounds are lowered by this many cells.
        self._slack = 1e-12 * (self.ncol + self.nrow + 1.0)

    def _cell_coords(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(u, v): column and row coordinates in cells (the same formula for points and queries)."""
        c, r = self._axes
        return (pts[:, c] - self._lo[0]) / self.cell, (pts[:, r] - self._lo[1]) / self.cell

    def box(
        self, queries: np.ndarray, ring: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The points within about `ring` cells (per query) of each query.

        Returns (start, count, owner, bound): sorted-point ranges start[j]:start[j] + count[j]
        of the query owner[j] (query-major: one range per row of its box), and per query a
        lower bound on the distance from it to every point outside them (inf when they are
        the whole grid). Expand the ranges with `expand`.
        """
        q = np.asarray(queries, dtype=np.float64).reshape(-1, 2)
        ring = np.minimum(np.broadcast_to(np.asarray(ring, dtype=np.int64), (len(q),)), _MAX_RING)
        u, v = self._cell_coords(q)
        # The square of cells within `ring` of the query's cell, clipped to the grid; a far
        # query counts as in the ring of cells just outside it (the square's bound below is
        # then a distance to half-planes: still a bound).
        cap = self.ncol + self.nrow + 2
        sq = np.minimum(ring, cap)
        cu = np.clip(np.floor(u), -1, self.ncol).astype(np.int64)
        cv = np.clip(np.floor(v), -1, self.nrow).astype(np.int64)
        c0, c1 = np.maximum(cu - sq, 0), np.minimum(cu + sq, self.ncol - 1)
        r0, r1 = np.maximum(cv - sq, 0), np.minimum(cv + sq, self.nrow - 1)
        a = np.searchsorted(self._rows, r0, side="left")
        nrows = np.where(c0 <= c1, np.maximum(np.searchsorted(self._rows, r1, "right") - a, 0), 0)
        owner = np.repeat(np.arange(len(q)), nrows)
        pos = np.arange(len(owner)) - np.repeat(np.cumsum(nrows) - nrows, nrows) + a[owner]
        row = self._rows[pos]
        # Cut to the disc of radius `ring` cells about the query: in each row only the
        # columns of its chord (a point off the surface then scans a short stretch of it, not
        # the whole width of the square).
        radius = ring.astype(np.float64)
        uo, vo = u[owner], v[owner]
        dv = np.maximum(np.maximum(row - vo, vo - (row + 1)), 0.0)
        w = np.sqrt(np.maximum(radius[owner] ** 2 - dv * dv, 0.0))
        inside = dv <= radius[owner]
        lo_c = np.maximum(c0[owner], np.floor(np.maximum(uo - w, -1.0)).astype(np.int64))
        hi_c = np.minimum(c1[owner], np.floor(np.minimum(uo + w, self.ncol)).astype(np.int64))
        hi_c = np.where(inside, hi_c, lo_c - 1)
        first = row * self.ncol
        start = np.searchsorted(self._keys, first + lo_c, side="left")
        count = np.maximum(np.searchsorted(self._keys, first + hi_c, side="right") - start, 0)
        # The outside of the square is four half-planes; those holding no cell of the grid
        # hold no point.
        inf = np.inf
        sides = np.stack(
            [
                np.where(cu - sq > 0, np.maximum(u - (cu - sq), 0.0), inf),
                np.where(cu + sq < self.ncol - 1, np.maximum(cu + sq + 1 - u, 0.0), inf),
                np.where(cv - sq > 0, np.maximum(v - (cv - sq), 0.0), inf),
                np.where(cv + sq < self.nrow - 1, np.maximum(cv + sq + 1 - v, 0.0), inf),
            ]
        ).min(axis=0)
        # Outside the disc: at least its radius away (a cell left of a chord is w across and
        # dv up or down), unless the disc holds the whole grid.
        far_u = np.maximum(np.abs(u), np.abs(u - self.ncol))
        far_v = np.maximum(np.abs(v), np.abs(v - self.nrow))
        covered = np.hypot(far_u, far_v) <= radius * (1.0 - 1e-9)
        sides = np.where(covered, sides, np.minimum(sides, radius * (1.0 - 1e-9)))
        bound = np.maximum(sides * (1.0 - 1e-12) - self._slack, 0.0) * self.cell
        return start, count, owner, bound

    def first_ring(self, queries: np.ndarray) -> np.ndarray:
        """A first ring per query: no box of a smaller ring holds a point.

        The cells from the query's cell into the grid or to the nearest row holding points,
        whichever is more.
        """
        q = np.asarray(queries, dtype=np.float64).reshape(-1, 2)
        u = np.floor(self._cell_coords(q)[0])
        out = np.minimum(np.maximum(np.maximum(-u, u - (self.ncol - 1)), 0.0), _MAX_RING)
        return np.maximum(out.astype(np.int64), self.row_gap(q))

    def row_gap(self, queries: np.ndarray) -> np.ndarray:
        """Rows between each query's row and the nearest row holding points.

        A lower bound on the ring a box needs to reach any point: a first ring for far queries.
        """
        q = np.asarray(queries, dtype=np.float64).reshape(-1, 2)
        cv = np.floor(self._cell_coords(q)[1])  # not clipped: a query far off the grid too
        if len(self._rows) == 0:
            return np.zeros(len(q), dtype=np.int64)
        k = np.searchsorted(self._rows, cv)
        above = self._rows[np.minimum(k, len(self._rows) - 1)] - cv
        below = cv - self._rows[np.maximum(k - 1, 0)]
        gap = np.minimum(np.where(above >= 0, above, np.inf), np.where(below >= 0, below, np.inf))
        gap = np.minimum(gap, _MAX_RING)
        return gap.astype(np.int64)

    def expand(self, start: np.ndarray, count: np.ndarray) -> np.ndarray:
        """The point ids of the ranges, concatenated in order."""
        total = int(count.sum())
        offset = np.repeat(start - (np.cumsum(count) - count), count)
        return self._order[offset + np.arange(total)]

    def nearest(self, queries: np.ndarray, exclude: np.ndarray | None = None) -> np.ndarray:
        """Distance from each query to the nearest point (other than point exclude[i]).

        inf where there is none. The distance is sqrt(dx * dx + dy * dy), as the KD-tree's.
        """
        q = np.asarray(queries, dtype=np.float64).reshape(-1, 2)
        out = np.full(len(q), np.inf)
        todo = np.arange(len(q))
        ring = self.first_ring(q) + 1
        while todo.size:
            start, count, owner, bound = self.box(q[todo], ring[todo])
            ids = self.expand(start, count)
            at = np.repeat(owner, count)
            d = self._distances(q[todo][at], ids)
            if exclude is not None:
                d[ids == exclude[todo][at]] = np.inf
            best = np.full(len(todo), np.inf)
            np.minimum.at(best, at, d)
            done = (best <= bound) | np.isinf(bound)
            out[todo[done]] = best[done]
            left = todo[~done]
            # Enough rings to reach the best distance found (a box of ring r reaches at
            # least r cells from the query), at least twice as many if none was found.
            need = np.ceil(best[~done] / self.cell * (1 + 1e-9) + 1.0)
            grown = np.where(np.isfinite(need), np.maximum(need, ring[left] + 1), 2 * ring[left])
            ring[left] = np.minimum(grown, _MAX_RING).astype(np.int64)
            todo = left
        return out

    def any_within(self, queries: np.ndarray, d: float) -> np.ndarray:
        """Whether some point is at most `d` from each query (one box of ring d / cell)."""
        q = np.asarray(queries, dtype=np.float64).reshape(-1, 2)
        if len(self.points) == 0 or len(q) == 0:
            return np.zeros(len(q), dtype=bool)
        ring = min(int(np.ceil(d / self.cell * (1 + 1e-9))) + 1, _MAX_RING)
        start, count, owner, _ = self.box(q, np.full(len(q), ring, dtype=np.int64))
        ids = self.expand(start, count)
        at = np.repeat(owner, count)
        hit = np.zeros(len(q), dtype=bool)
        hit[at[self._distances(q[at], ids) <= d]] = True
        return hit

    def _distances(self, q: np.ndarray, ids: np.ndarray) -> np.ndarray:
        dx = q[:, 0] - self.points[ids, 0]
        dy = q[:, 1] - self.points[ids, 1]
        return np.sqrt(dx * dx + dy * dy)
