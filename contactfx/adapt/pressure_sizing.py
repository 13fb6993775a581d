"""The sizes the pressure estimate asks of the cells along the contact surfaces.

Each active segment's indicator scales like h^r: r = 1 at the zone's edges (the square-root
law: error^2 ~ h^2), r = 5/2 inside (a quadratic's interpolation error). Equidistribution
asks every new segment for the same eta_t, h'_e = h_e (eta_t / eta_e)^(1/r_e), with eta_t
such that N' eta_t^2 = (tol ||p_h||)^2 over the N' = sum h_e / h'_e new segments. A cell
with a vertex on a contact surface (either body; the passive one through its projection on
the active surface) gets the smallest size asked at its vertices; the others none (inf).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..contact.geometry import segment_lengths
from ..contact.search import project
from .pressure_estimate import PairPressure, PressureEstimate

EDGE_RATE = 1.0
INTERIOR_RATE = 2.5


def _segment_sizes(pairs: list[PairPressure], tol: float, norm: float) -> list[np.ndarray]:
    """h'_e of every pair's active segments (inf where the indicator is 0)."""
    h = [segment_lengths(q.surface) for q in pairs]
    eta = [np.maximum(q.eta, 1e-300) for q in pairs]
    rate = [np.where(q.edge, EDGE_RATE, INTERIOR_RATE) for q in pairs]
    T2 = (tol * norm) ** 2

    def sizes(t: float) -> list[np.ndarray]:
        return [hk * (t / ek) ** (1.0 / rk) for hk, ek, rk in zip(h, eta, rate, strict=True)]

    def excess(t: float) -> float:
        n_new = sum(float(np.sum(hk / sk)) for hk, sk in zip(h, sizes(t), strict=True))
        return n_new * t**2 - T2

    # N'(t) t^2 grows with t (every rate >= 1 > 1/2): bisect in log t.
    lo, hi = 1e-300, max(float(e.max()) for e in eta) * 1e6
    for _ in range(200):
        mid = np.sqrt(lo * hi)
        lo, hi = (mid, hi) if excess(mid) < 0 else (lo, mid)
    out = sizes(lo)
    return [np.where(q.eta > 0, s, np.inf) for q, s in zip(pairs, out, strict=True)]


def _node_sizes(q: PairPressure, seg_size: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(points, size) on both surfaces of a pair: at each node the size asked there."""
    node = np.full(q.surface.n_nodes, np.inf)
    for c in range(2):
        np.minimum.at(node, q.surface.segments[:, c], seg_size)
    pts, size = [q.surface.x[:, :2]], [node]
    if q.passive is not None:
        seg, _, found = project(q.passive.x, q.surface)
        pts.append(q.passive.x[:, :2])
        size.append(np.where(found, seg_size[seg], np.inf))
    return np.concatenate(pts), np.concatenate(size)


def pressure_cell_sizes(
    pe: PressureEstimate, tol: float, quads: np.ndarray, h: np.ndarray, finest: float
) -> np.ndarray:
    """Per cell (quads: (n, 4, 2) vertices, h: current sizes) the size the pressure asks.

    At most `finest` times smaller than today's (the indicators are asymptotic); inf for a
    cell without a vertex on a contact surface.
    """
    out = np.full(len(quads), np.inf)
    if not pe.pairs or pe.norm == 0.0 or len(quads) == 0:
        return out
    seg_sizes = _segment_sizes(pe.pairs, tol, pe.norm)
    parts = [_node_sizes(q, s) for q, s in zip(pe.pairs, seg_sizes, strict=True)]
    pts = np.concatenate([p for p, _ in parts])
    size = np.concatenate([s for _, s in parts])
    # A vertex on a surface is one of its nodes (the same coordinates); the tolerance is
    # relative to the surfaces' extent, the same on every rank.
    tol = 1e-9 * float(np.ptp(pts, axis=0).max())
    dist, idx = cKDTree(pts).query(quads.reshape(-1, 2))
    at = np.where(dist <= tol, size[idx], np.inf)
    out = at.reshape(-1, 4).min(axis=1)
    return np.maximum(out, finest * h)
