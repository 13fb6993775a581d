"""Segment-based mortar: active segments cut into sub-segments each facing one passive segment."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .geometry import Surface, chains, nodal_normals, project, segment_lengths
from .operator import ContactOperator, assemble, gauss_unit, linear_shape

# Gauss points per sub-segment: the integrand N_j N_A is quadratic there, so 2 are exact.
GAUSS_POINTS = 2
# Sub-segments shorter than this fraction of their active segment are round-off slivers (an
# active node sitting on a cut line) and are dropped.
SLIVER = 1e-12


def _chain_ranges(
    r0: np.ndarray, r1: np.ndarray, length: np.ndarray, closed: np.ndarray, margin: int
) -> tuple[np.ndarray, np.ndarray]:
    """First position and count of the chain stretch between positions r0 and r1, widened."""
    lo, hi = np.minimum(r0, r1), np.maximum(r0, r1)
    first = np.maximum(lo - margin, 0)
    count = np.minimum(hi + margin, length - 1) - first + 1
    # On a loop take the shorter way round; positions are reduced modulo the loop length later.
    fwd = np.mod(r1 - r0, np.maximum(length, 1))
    short_from_r0 = fwd <= length - fwd
    loop_first = np.where(short_from_r0, r0, r1) - margin
    loop_count = np.minimum(np.where(short_from_r0, fwd, length - fwd) + 1 + 2 * margin, length)
    return np.where(closed, loop_first, first), np.where(closed, loop_count, count)


def _halfplane_interval(fa: np.ndarray, fb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Interval of xi in [0, 1] where the affine f = (1 - xi) fa + xi fb is >= 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        cross = fa / (fa - fb)
    lo = np.where((fa < 0) & (fb >= 0), cross, 0.0)
    hi = np.where((fa >= 0) & (fb < 0), cross, 1.0)
    empty = (fa < 0) & (fb < 0)
    return np.where(empty, 1.0, lo), np.where(empty, 0.0, hi)


def _wedges(passive: Surface) -> np.ndarray:
    """Per passive segment and end node (m, 2, 5): node x, y, nodal normal x, y, inside sign."""
    # Segment A-B owns the wedge between the lines through A and B along the averaged nodal
    # normals; neighbours share a line with opposite sides, so the wedges tile exactly.
    nn = nodal_normals(passive)
    out = np.empty((passive.n_segments, 2, 5))
    for own in (0, 1):
        node = passive.segments[:, own]
        xn, n = passive.x[node], nn[node]
        out[:, own, :2] = xn
        out[:, own, 2:4] = n
        out[:, own, 4] = np.sign(_cross(n, passive.x[passive.segments[:, 1 - own]] - xn))
    return out


def _clip(
    active: Surface, wedges: np.ndarray, pair_e: np.ndarray, pair_s: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Interval [lo, hi] of each active segment's xi inside each paired passive wedge."""
    p0 = active.x[active.segments[pair_e, 0]]
    p1 = active.x[active.segments[pair_e, 1]]
    w = wedges[pair_s]
    lo = np.zeros(len(pair_e))
    hi = np.ones(len(pair_e))
    for own in (0, 1):
        xn, n, side = w[:, own, :2], w[:, own, 2:4], w[:, own, 4]
        a, b = _halfplane_interval(side * _cross(n, p0 - xn), side * _cross(n, p1 - xn))
        lo, hi = np.maximum(lo, a), np.minimum(hi, b)
    return lo, hi


def subsegments(
    active: Surface, passive: Surface, near: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sub-segments (active segment, passive segment, active xi interval (s, 2)), sorted."""
    # `near` (closest passive segment of each active node) may be passed to skip the search.
    ma = active.n_segments
    if ma == 0 or passive.n_segments == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 2))
    ch = chains(passive)
    wedges = _wedges(passive)
    if near is None:
        near = project(active.x, passive)[0]
    sa = near[active.segments[:, 0]]
    sb = near[active.segments[:, 1]]
    same = ch.start[sa] == ch.start[sb]
    # Candidate passive segments of each active segment: the chain stretch between the segments
    # its two nodes project onto (one stretch per node if they land on different chains),
    # widened by a margin because the wedge holding a node may be a neighbour of the segment
    # it projects onto. A stretch whose outermost segment is still cut is widened and redone.
    req_e = np.concatenate([np.arange(ma), np.flatnonzero(~same)])
    req_from = np.concatenate([sa, sb[~same]])
    req_to = np.concatenate([np.where(same, sb, sa), sb[~same]])
    todo = np.arange(len(req_e))
    margin = 1
    found_e, found_s, found_lo, found_hi = [], [], [], []
    while todo.size:
        s_from = req_from[todo]
        length, closed = ch.length[s_from], ch.closed[s_from]
        first, count = _chain_ranges(
            ch.position[s_from], ch.position[req_to[todo]], length, closed, margin
        )
        pair_req = np.repeat(np.arange(len(todo)), count)
        step = np.arange(len(pair_req)) - np.repeat(np.cumsum(count) - count, count)
        local = np.mod(first[pair_req] + step, length[pair_req])
        pair_s = ch.order[ch.start[s_from][pair_req] + local]
        pair_e = req_e[todo][pair_req]
        lo, hi = _clip(active, wedges, pair_e, pair_s)
        cut = hi - lo > SLIVER
        open_lo = np.where(closed, count < length, first > 0)
        open_hi = np.where(closed, count < length, first + count < length)
        at_edge = ((step == 0) & open_lo[pair_req]) | (
            (step == count[pair_req] - 1) & open_hi[pair_req]
        )
        widen = np.zeros(len(todo), dtype=bool)
        widen[pair_req[cut & at_edge]] = True
        accept = cut & ~widen[pair_req]
        found_e.append(pair_e[accept])
        found_s.append(pair_s[accept])
        found_lo.append(lo[accept])
        found_hi.append(hi[accept])
        todo = todo[widen]
        margin *= 4
    pair_e, pair_s = np.concatenate(found_e), np.concatenate(found_s)
    lo, hi = np.concatenate(found_lo), np.concatenate(found_hi)
    order = np.lexsort((lo, pair_e))
    return pair_e[order], pair_s[order], np.stack([lo[order], hi[order]], axis=1)


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """z component of the 2D cross product, row by row."""
    return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]


def _gauss_points(
    active: Surface, passive: Surface
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Gauss points on all sub-segments: (active seg, passive seg, xi, eta, weight)."""
    seg_a, seg_p, xi_int = subsegments(active, passive)
    gx, gw = gauss_unit(GAUSS_POINTS)
    span = xi_int[:, 1] - xi_int[:, 0]
    xi = (xi_int[:, :1] + span[:, None] * gx).ravel()
    w = (span[:, None] * gw * segment_lengths(active)[seg_a][:, None]).ravel()
    seg_a = np.repeat(seg_a, GAUSS_POINTS)
    seg_p = np.repeat(seg_p, GAUSS_POINTS)
    na = linear_shape(xi)
    x = np.einsum("pk,pkd->pd", na, active.x[active.segments[seg_a]])
    # Orthogonal projection onto the line of the paired passive segment (not clamped: it may
    # fall just outside it where the nodal normals tilt the cut; the foot stays on the line).
    xa, xb = passive.x[passive.segments[seg_p, 0]], passive.x[passive.segments[seg_p, 1]]
    ab = xb - xa
    eta = np.einsum("pd,pd->p", x - xa, ab) / np.einsum("pd,pd->p", ab, ab)
    return seg_a, seg_p, xi, eta, w


def overlap_weights(
    active: Surface, passive: Surface, near: np.ndarray | None = None
) -> np.ndarray:
    """int N_j dGamma over the part of the active surface facing the passive one, (n_active,)."""
    seg_a, _, xi_int = subsegments(active, passive, near)
    lo, hi = xi_int[:, 0], xi_int[:, 1]
    length = segment_lengths(active)[seg_a]
    # Exact integrals of 1 - xi and xi over [lo, hi].
    half_sq = 0.5 * (hi - lo) * (hi + lo)
    w1 = length * half_sq
    w0 = length * (hi - lo) - w1
    nodes = active.segments[seg_a]
    return np.bincount(
        nodes.ravel(), weights=np.stack([w0, w1], axis=1).ravel(), minlength=active.n_nodes
    )


def mortar_matrices(active: Surface, passive: Surface) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """D = int N_j N_k (n_active x n_active) and M = int N_j N_A (n_active x n_passive)."""
    seg_a, seg_p, xi, eta, w = _gauss_points(active, passive)
    nj = linear_shape(xi) * w[:, None]
    rows = active.segments[seg_a]
    d_vals = nj[:, :, None] * linear_shape(xi)[:, None, :]
    m_vals = nj[:, :, None] * linear_shape(eta)[:, None, :]
    d_cols = np.broadcast_to(rows[:, None, :], d_vals.shape)
    m_cols = np.broadcast_to(passive.segments[seg_p][:, None, :], m_vals.shape)
    r = np.broadcast_to(rows[:, :, None], d_vals.shape).ravel()
    na, npas = active.n_nodes, passive.n_nodes
    D = sp.coo_matrix((d_vals.ravel(), (r, d_cols.ravel())), shape=(na, na)).tocsr()
    M = sp.coo_matrix((m_vals.ravel(), (r, m_cols.ravel())), shape=(na, npas)).tocsr()
    D.sum_duplicates()
    M.sum_duplicates()
    return D, M


def contact_operator(active: Surface, passive: Surface, ndofs: int) -> ContactOperator:
    """Mortar operator: exact Gauss integration on sub-segments, normal of the paired segment."""
    seg_a, seg_p, xi, eta, w = _gauss_points(active, passive)
    na = linear_shape(xi)
    nodes = active.segments[seg_a]
    return assemble(
        active,
        passive,
        ndofs,
        rows=nodes,
        row_coef=w[:, None] * na,
        act_nodes=nodes,
        act_coef=na,
        pas_nodes=passive.segments[seg_p],
        pas_coef=linear_shape(eta),
        normal=passive.normals[seg_p],
        group=GAUSS_POINTS,
    )
