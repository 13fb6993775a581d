"""An estimate of the contact pressure's L2 error, segment by segment, and the sizes it asks.

The energy estimate is bulk-dominated and does not ask for the cells a pressure needs at
the edge of the contact zone (docs/adapt.md). This one measures the multipliers' own
piecewise-linear interpolant p_h on each active surface: the interpolation error of a
function f on a segment of length h is |f - I f|^2 = h^5 f''^2 / 120 (f'' constant), with
f'' at each node from the two slopes around it. Across the zone's edge, where p ~ sqrt(a - x),
the slope changes by about p_last / h in one segment and the estimate scales like the error
there, h^2 (checked on the exact Hertz pressure in tests/adapt/test_pressure_estimate.py). It
does not see a pressure that is smooth and wrong (a polluted bulk): the energy estimate
sizes the bulk.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..contact import Surface
from ..methods.solution import Solution


@dataclass(frozen=True)
class PairPressure:
    """One pair's active surface, its nodal pressure and the indicator of each segment."""

    surface: Surface
    passive: Surface | None  # the passive body's surface (None against a rigid obstacle)
    p: np.ndarray  # (n_nodes,) the multipliers at the surface's nodes (0 off the rows)
    eta: np.ndarray  # (n_segments,) estimated L2 error of p_h on each segment
    edge: np.ndarray  # (n_segments,) bool: one of the two segments at an edge of the zone
    norm: float  # ||p_h||_L2 on the surface


@dataclass(frozen=True)
class PressureEstimate:
    """The pairs' pressure indicators (the same on every rank: surfaces are gathered)."""

    pairs: list[PairPressure]

    @property
    def total(self) -> float:
        """sqrt(sum of the squared indicators) over all pairs."""
        return float(np.sqrt(sum(float(np.sum(q.eta**2)) for q in self.pairs)))

    @property
    def norm(self) -> float:
        """||p_h||_L2 over all active surfaces."""
        return float(np.sqrt(sum(q.norm**2 for q in self.pairs)))

    @property
    def relative(self) -> float:
        """Total / ||p_h||_L2 (0 without pressure)."""
        n = self.norm
        return self.total / n if n > 0 else 0.0


def _lengths(x: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Length of every segment (as contact.geometry.segment_lengths, from arrays)."""
    d = x[segments[:, 1], :2] - x[segments[:, 0], :2]
    return np.hypot(d[:, 0], d[:, 1])


def curvatures(segments: np.ndarray, h: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The second derivative f'' at each node, from the slopes of the segments around it.

    With s_k = (p_other - p_node) / h_k the slope away from the node along segment k, a
    linear p gives s_1 + s_2 = 0 and a quadratic one s_1 + s_2 = f'' (h_1 + h_2) / 2. Nodes
    with one segment (chain ends) get 0. h: the segments' lengths.
    """
    a, b = segments[:, 0], segments[:, 1]
    n = len(p)
    slope = (p[b] - p[a]) / np.maximum(h, 1e-300)
    total = np.bincount(a, slope, n) - np.bincount(b, slope, n)
    length = np.bincount(a, h, n) + np.bincount(b, h, n)
    two = np.bincount(segments.ravel(), minlength=n) == 2
    out = np.zeros(n)
    out[two] = 2.0 * total[two] / length[two]
    return out


def segment_indicators(
    x: np.ndarray, segments: np.ndarray, p: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Estimated ||p - p_h||_L2 on each segment, and which segments are at an edge.

    Inside the zone sqrt(h^5 (f''_a^2 + f''_b^2) / 240), the interpolation error of a
    quadratic; on the two segments at each edge of the zone the error of p_h against the
    square-root law through the last two active nodes (edge_errors).
    """
    h = _lengths(x, segments)
    c = curvatures(segments, h, p)
    eta = np.sqrt(h**5 * (c[segments[:, 0]] ** 2 + c[segments[:, 1]] ** 2) / 240.0)
    edge = np.zeros(len(segments), dtype=bool)
    for (inner, outer), err in edge_errors(segments, h, p).items():
        eta[inner], eta[outer] = err
        edge[[inner, outer]] = True
    return eta, edge


# Gauss-Legendre points on [0, 1] for the edge integrals (the integrand is smooth on each
# piece: the pieces break at the square root's zero).
_GL_X, _GL_W = np.polynomial.legendre.leggauss(24)
_GL_X, _GL_W = 0.5 * (_GL_X + 1.0), 0.5 * _GL_W


def _integral(f: Callable[[np.ndarray], np.ndarray], lo: float, hi: float) -> float:
    """int_lo^hi f (Gauss-Legendre)."""
    if hi <= lo:
        return 0.0
    return float((hi - lo) * np.sum(_GL_W * f(lo + (hi - lo) * _GL_X)))


def edge_errors(
    segments: np.ndarray, h: np.ndarray, p: np.ndarray
) -> dict[tuple[int, int], tuple[float, float]]:
    """At each edge of a contact zone: the L2 errors of p_h on its last two segments.

    The edge is a node k with p_k > 0, one neighbour i with p_i > p_k and the other j with
    p_j = 0. With t the distance from k towards j, the pressure of a smooth frictionless
    contact near the zone's edge is C sqrt(A - t): fitted through (t_i, p_i) and (t_k, p_k)
    (A clipped to [0, h_kj]: the edge lies before the open node j). Returns
    {(segment ik, segment kj): (error on ik, error on kj)}.
    """
    n, m = len(p), len(segments)
    ends = segments.T.ravel()  # each segment once from either end
    other = segments[:, ::-1].T.ravel()
    seg = np.tile(np.arange(m), 2)
    order = np.argsort(ends, kind="stable")
    degree = np.bincount(ends, minlength=n)
    first = np.concatenate([[0], np.cumsum(degree)[:-1]])
    k = np.flatnonzero((degree == 2) & (p > 0))
    s1, s2 = order[first[k]], order[first[k] + 1]
    n1, n2 = other[s1], other[s2]
    open1 = (p[n1] == 0) & (p[n2] > p[k])  # j = n1, i = n2
    open2 = (p[n2] == 0) & (p[n1] > p[k])  # j = n2, i = n1
    at = open1 | open2
    ei = np.where(open1, seg[s2], seg[s1])[at]
    ej = np.where(open1, seg[s1], seg[s2])[at]
    i = np.where(open1, n2, n1)[at]
    return {
        (int(a), int(b)): edge_pair_errors(float(p[c]), float(p[d]), float(h[a]), float(h[b]))
        for a, b, c, d in zip(ei, ej, i, k[at], strict=True)
    }


def l2_norm(x: np.ndarray, segments: np.ndarray, p: np.ndarray) -> float:
    """||p_h||_L2 of the piecewise-linear nodal function p on the segments."""
    h = _lengths(x, segments)
    pa, pb = p[segments[:, 0]], p[segments[:, 1]]
    return float(np.sqrt(np.sum(h * (pa**2 + pa * pb + pb**2) / 3.0)))


def pressure_estimate(sol: Solution) -> PressureEstimate:
    """The pressure indicators of every pair of a multiplier-method solution."""
    out = []
    for pv in sol.pairs:
        surf = pv.active.surface
        p = pv.nodal(sol.pressure)
        eta, edge = segment_indicators(surf.x, surf.segments, p)
        norm = l2_norm(surf.x, surf.segments, p)
        passive = pv.passive.surface if pv.passive is not None else None
        out.append(PairPressure(surf, passive, p, eta, edge, norm))
    return PressureEstimate(out)


def edge_pair_errors(pi: float, pk: float, hi: float, hj: float) -> tuple[float, float]:
    """L2 errors of p_h on (i, k) and (k, j) against C sqrt(A - t) through p_i and p_k.

    t is the distance from node k towards the open node j (t_i = -hi, t_j = hj).
    """
    c2 = (pi**2 - pk**2) / hi
    A = min(pk**2 / c2, hj)

    def inner(t: np.ndarray) -> np.ndarray:
        return (np.sqrt(c2 * (A - t)) - (pk + (pk - pi) * t / hi)) ** 2

    def outer(t: np.ndarray) -> np.ndarray:
        return (np.sqrt(c2 * np.clip(A - t, 0.0, None)) - pk * (1.0 - t / hj)) ** 2

    err_i = _integral(inner, -hi, 0.0)
    err_j = _integral(outer, 0.0, A) + _integral(outer, A, hj)
    return float(np.sqrt(err_i)), float(np.sqrt(err_j))
