"""Rigid obstacles as exact geometry: closest point, signed gap and outward normal.

Three shapes, each with `closest(points) -> Closest`:

- `Circle(center, radius)`: the body lies outside the disc; exact gap |x - c| - R and normal
  (x - c) / |x - c|.
- `Plane(point, normal)`: the half-plane behind `point` against `normal` (which points from
  the obstacle towards the body); exact gap n . (x - point).
- `Polyline(points)`: the obstacle on the left of the points in order, the body on the right;
  closed when the last point repeats the first. The closest point is on the nearest segment
  or at the nearest vertex; the gap is the signed distance and the normal its gradient: the
  segment's normal on a segment, the direction from the vertex at a convex corner (so the
  gap and the normal are continuous from one segment to the next: no jump for the active
  set to chatter on). Points whose closest point is an open polyline's end vertex, beyond
  its end segment, are not found: the obstacle says nothing there (as a passive body's end).

Normals always point from the obstacle towards the body (the obstacle's outward normal); a
positive gap means separation. Pure numpy: the kernels in `rigid_kernels` use these.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .geometry import Surface, nodal_normals
from .search import SegmentSearch

# Points within this of an open polyline's end (in lengths of the end segment) still count as
# facing it (the tolerance of the body pairs' projection).
END_TOL = 1e-8


@dataclass(frozen=True)
class Closest:
    """Per point: signed gap, unit outward normal of the obstacle, closest point, found."""

    gap: np.ndarray  # (n,)
    normal: np.ndarray  # (n, 2)
    foot: np.ndarray  # (n, 2)
    found: np.ndarray  # (n,) bool


def _vector(value: object, what: str) -> np.ndarray:
    v = np.asarray(value, dtype=np.float64)
    if v.shape != (2,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{what} must be two finite numbers [x, y]")
    return v


@dataclass(frozen=True)
class Circle:
    """A rigid disc: the body lies outside it."""

    center: tuple[float, float]
    radius: float

    def __post_init__(self) -> None:
        _vector(self.center, "center")
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise ValueError(f"radius must be > 0 (got {self.radius})")

    def closest(self, points: np.ndarray) -> Closest:
        """Exact closest points on the circle (the centre itself maps to the top)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        d = p - np.asarray(self.center)
        r = np.hypot(d[:, 0], d[:, 1])
        n = np.tile([0.0, 1.0], (len(p), 1))
        np.divide(d, r[:, None], out=n, where=r[:, None] > 0)
        return Closest(
            r - self.radius, n, np.asarray(self.center) + self.radius * n, np.ones(len(p), bool)
        )

    def outline(self, samples: int = 720) -> np.ndarray:
        """Points around the circle (closed: the first point repeated at the end)."""
        t = np.linspace(0.0, 2.0 * np.pi, samples + 1)
        return np.asarray(self.center) + self.radius * np.column_stack([np.cos(t), np.sin(t)])


@dataclass(frozen=True)
class Plane:
    """A rigid half-plane: `normal` points from the obstacle towards the body."""

    point: tuple[float, float]
    normal: tuple[float, float]

    def __post_init__(self) -> None:
        _vector(self.point, "point")
        n = _vector(self.normal, "normal")
        if not np.hypot(n[0], n[1]) > 0:
            raise ValueError("normal must not be the zero vector")

    @property
    def unit_normal(self) -> np.ndarray:
        """The normal scaled to length 1."""
        n = np.asarray(self.normal, dtype=np.float64)
        return n / np.hypot(n[0], n[1])

    def closest(self, points: np.ndarray) -> Closest:
        """Exact: the foot of the perpendicular onto the line."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        n = self.unit_normal
        g = (p - np.asarray(self.point)) @ n
        normal = np.tile(n, (len(p), 1))
        return Closest(g, normal, p - g[:, None] * n, np.ones(len(p), bool))

    def outline(self, near: np.ndarray, margin: float = 0.25) -> np.ndarray:
        """Two points of the line spanning the projections of `near`, widened by `margin`."""
        n = self.unit_normal
        t = np.array([-n[1], n[0]])
        s = (np.asarray(near, dtype=np.float64).reshape(-1, 2) - np.asarray(self.point)) @ t
        lo, hi = (float(s.min()), float(s.max())) if s.size else (-1.0, 1.0)
        pad = margin * max(hi - lo, 1e-12 * max(abs(lo), abs(hi), 1.0))
        return np.asarray(self.point) + np.outer([lo - pad, hi + pad], t)


@dataclass(frozen=True)
class Polyline:
    """A rigid polyline: the obstacle on the left of its points, in order."""

    points: tuple[tuple[float, float], ...]

    def __post_init__(self) -> None:
        x = np.asarray(self.points, dtype=np.float64)
        if x.ndim != 2 or x.shape[1] != 2 or len(x) < 2 or not np.all(np.isfinite(x)):
            raise ValueError("points must be two or more finite points [[x, y], ...]")
        _check_polyline(x)

    @property
    def closed(self) -> bool:
        """Whether the last point repeats the first (a closed loop)."""
        x = np.asarray(self.points, dtype=np.float64)
        return len(x) > 3 and bool(np.array_equal(x[0], x[-1]))

    @property
    def vertices(self) -> np.ndarray:
        """The distinct points in order (the repeated last point of a loop dropped)."""
        x = np.asarray(self.points, dtype=np.float64)
        return x[:-1] if self.closed else x

    def surface(self) -> Surface:
        """The polyline as a Surface (normals from the obstacle towards the body; no dofs)."""
        x = self.vertices
        n = len(x)
        seg = np.column_stack([np.arange(n - 1), np.arange(1, n)])
        if self.closed:
            seg = np.vstack([seg, [[n - 1, 0]]])
        d = x[seg[:, 1]] - x[seg[:, 0]]
        normal = np.column_stack([d[:, 1], -d[:, 0]]) / np.hypot(d[:, 0], d[:, 1])[:, None]
        return Surface(x, seg, normal, np.zeros((n, 2), dtype=np.int64))

    def closest(self, points: np.ndarray) -> Closest:
        """Nearest segment or vertex; ties between segments are broken by geometry only."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
        surf = self.surface()
        seg, t, found = SegmentSearch(surf).closest(p, END_TOL)
        a, b = surf.x[surf.segments[seg, 0]], surf.x[surf.segments[seg, 1]]
        foot = a + t[:, None] * (b - a)
        normal = surf.normals[seg].copy()
        gap = np.einsum("pd,pd->p", p - foot, normal)
        # At a vertex the gap is the signed distance, its sign that of the (two-segment)
        # pseudo-normal there; the normal is the direction from the vertex. Both do not depend
        # on which of the vertex's two segments won the search.
        vert = np.where(t <= 0.0, surf.segments[seg, 0], surf.segments[seg, 1])
        at_vertex = (t <= 0.0) | (t >= 1.0)
        d = p - foot
        dist = np.hypot(d[:, 0], d[:, 1])
        pseudo = nodal_normals(surf)[vert]
        radial = at_vertex & (dist > 0)
        sign = np.where(np.einsum("pd,pd->p", d, pseudo) < 0, -1.0, 1.0)
        normal[radial] = (sign[radial, None] * d[radial]) / dist[radial, None]
        gap[radial] = sign[radial] * dist[radial]
        normal[at_vertex & ~radial] = pseudo[at_vertex & ~radial]
        return Closest(gap, normal, foot, found)

    def outline(self) -> np.ndarray:
        """The points, in order."""
        return np.asarray(self.points, dtype=np.float64)

    def cut_lines(self) -> tuple[np.ndarray, np.ndarray]:
        """(origin (k, 2), direction (k, 2)) of the lines where the closest feature changes.

        Through every inner vertex along both segment normals and the bisector, and through
        an open polyline's ends along the end segment's normal.
        """
        surf = self.surface()
        x, seg, nrm = surf.x, surf.segments, surf.normals
        n = len(x)
        before = np.full(n, -1)
        after = np.full(n, -1)
        before[seg[:, 1]] = np.arange(len(seg))
        after[seg[:, 0]] = np.arange(len(seg))
        origin, direction = [], []
        for v in range(n):
            for s in (before[v], after[v]):
                if s >= 0:
                    origin.append(x[v])
                    direction.append(nrm[s])
            if before[v] >= 0 and after[v] >= 0:
                bis = nrm[before[v]] + nrm[after[v]]
                if np.hypot(bis[0], bis[1]) > 1e-12:
                    origin.append(x[v])
                    direction.append(bis / np.hypot(bis[0], bis[1]))
        return np.array(origin).reshape(-1, 2), np.array(direction).reshape(-1, 2)


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _check_polyline(x: np.ndarray) -> None:
    """ValueError for a degenerate polyline: repeated points, a fold-back, a self-crossing."""
    closed = len(x) > 3 and np.array_equal(x[0], x[-1])
    d = np.diff(x, axis=0)
    length = np.hypot(d[:, 0], d[:, 1])
    extent = float(np.ptp(x, axis=0).max())
    if extent == 0.0 or np.any(length <= 1e-12 * extent):
        k = int(np.argmin(length))
        raise ValueError(f"points {k} and {k + 1} coincide (a segment of zero length)")
    u = d / length[:, None]
    turns = [(u[k], u[k + 1], k + 1) for k in range(len(u) - 1)]
    if closed:
        turns.append((u[-1], u[0], 0))
    for a, b, k in turns:
        if abs(_cross(a, b)) <= 1e-12 and float(a @ b) < 0:
            raise ValueError(f"the polyline folds back on itself at point {k}")
    # Proper crossings of non-adjacent segments (adjacent ones share a point by definition).
    m = len(d)
    i, j = np.triu_indices(m, 2)
    keep = ~(closed & (i == 0) & (j == m - 1))
    i, j = i[keep], j[keep]
    p, r, q, s = x[i], d[i], x[j], d[j]
    den = _cross(r, s)
    ok = np.abs(den) > 1e-14 * length[i] * length[j]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(ok, _cross(q - p, s) / den, -1.0)
        w = np.where(ok, _cross(q - p, r) / den, -1.0)
    hit = ok & (t >= 0) & (t <= 1) & (w >= 0) & (w <= 1)
    if hit.any():
        k = int(np.flatnonzero(hit)[0])
        raise ValueError(f"segments {i[k]} and {j[k]} of the polyline cross each other")


RigidShape = Circle | Plane | Polyline
