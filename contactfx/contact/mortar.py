"""Segment-based mortar: active segments cut into sub-segments each facing one passive segment.

Multiplier bases (`basis=`): "standard" weights row j with the active shape function N_j;
"dual" weights it with the biorthogonal function psi_j (Wohlmuth's dual mortar), which makes
D = int psi_j N_k diagonal so that a solver can eliminate the multipliers.

Dual basis, per active segment e and from the integrals over its OVERLAPPED part only (the
union of its sub-segments; "consistent" duals, A_e = D_e M_e^-1 with D_e = diag int N_k and
M_e = int N_j N_k, so int psi_j N_k = delta_jk int N_k holds there exactly). About the overlap
centroid xbar (mean of xi over the overlap) this reads

    psi_0 = N_0(xbar) - beta (xi - xbar),  psi_1 = N_1(xbar) + beta (xi - xbar),
    beta = N_0(xbar) N_1(xbar) / var(xi),

which is how it is computed (`_dual_affine`): in the basis (1, xi - xbar), whose Gram matrix is
diagonal, instead of inverting M_e, whose two rows become nearly parallel on short overlaps.
psi_0 + psi_1 = 1, so a constant is reproduced, and int psi_j = int N_j: the dual weights equal
the standard ones. On a fully overlapped segment xbar = 1/2, var = 1/12 and
psi = (2 - 3 xi, 3 xi - 1).

Near-singular M_e: the dipole strength kappa = beta * std(xi) is <= sqrt(3) whenever the overlap
touches a node of the segment (every partly overlapped segment at a surface end), but grows like
1 / (overlap length) for an overlap lying strictly inside the segment (a passive surface much
shorter than one active segment); round-off in psi grows with it. Segments with
kappa > DUAL_MAX_DIPOLE (an inner overlap shorter than ~1e-4 of the segment) are DROPPED from
the dual operator and from its D, M and weights: keeping them with the standard or lumped
choice would break the diagonal D that the dual basis exists for (and lumping would make the
two rows of the segment proportional). The dropped overlap is reported by `dual_coefficients`.

Ends of the passive surface (both bases): a node with no overlap gets no row (weight 0). The
nodes whose support the passive surface covers only partly (beyond its end, lying on it, or
the last node before it) give their rows to the first node inside whose support it covers
wholly (operator.end_rows; Wohlmuth's modified dual basis at interface ends, the boundary
modification of Popp et al. and of Cichosz and Bischoff). Its basis there is the sum of the
merged ones: N_i + N_o = 1 or psi_i + psi_o = 1 on the end segments, so a constant is still
reproduced and the patch tests stay exact; the dual D stays diagonal on the nodes that keep
rows, a merged node's column holding int psi_i N_o (a condensing solver keeps that node's
displacement as a free unknown, like a passive node's).
Without the merge the multipliers of the segment straddling the end, restricted to its short
facing part, fit a corner's load by a steep slope: on a press fit the node beyond the end
carried 10-40x the corner's pressure and its neighbour inside was released (docs/edges.md).
`ends=False` gives the unmodified basis (its properties are tested on their own);
`dual_coefficients` and `overlap_weights` are always the unmodified ones.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .geometry import Surface, chains, nodal_normals, radial_weight, segment_lengths
from .operator import (
    REACH,
    ContactOperator,
    assemble,
    end_rows,
    frame_normals,
    gauss_unit,
    linear_shape,
    row_directions,
)
from .search import project

if TYPE_CHECKING:
    import scipy.sparse as sp

# Gauss points per sub-segment: the integrand N_j N_A is quadratic there, so 2 are exact.
GAUSS_POINTS = 2
# Sub-segments shorter than this fraction of their active segment are round-off slivers (an
# active node sitting on a cut line) and are dropped.
SLIVER = 1e-12
# Multiplier bases of `contact_operator` and `mortar_matrices`.
BASES = ("standard", "dual")
# Largest dual dipole strength kappa kept (see the module docstring). psi reaches ~sqrt(3) kappa
# on the overlap and its integrals lose ~kappa * 1e-16 to round-off: ~1e-12 at this bound.
DUAL_MAX_DIPOLE = 1e4


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
    """The z component of the 2D cross product, row by row."""
    return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]


def _end_rows(active: Surface, seg_a: np.ndarray, xi_int: np.ndarray) -> np.ndarray:
    """Each active node's row after the end modification (operator.end_rows), from the cuts."""
    m = active.n_segments
    some = np.bincount(seg_a, minlength=m) > 0
    lo = np.full(m, np.inf)
    hi = np.full(m, -np.inf)
    np.minimum.at(lo, seg_a, xi_int[:, 0])
    np.maximum.at(hi, seg_a, xi_int[:, 1])
    reach = np.stack([lo <= REACH, hi >= 1.0 - REACH], axis=1) & some[:, None]
    return end_rows(active.segments, active.n_nodes, some, reach)


def _gauss_points(
    active: Surface, passive: Surface, ends: bool = True
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Gauss points on all sub-segments: (active seg, passive seg, xi, eta, weight), end rows."""
    seg_a, seg_p, xi_int = subsegments(active, passive)
    rows = _end_rows(active, seg_a, xi_int) if ends else np.arange(active.n_nodes)
    gx, gw = gauss_unit(GAUSS_POINTS)
    span = xi_int[:, 1] - xi_int[:, 0]
    xi = (xi_int[:, :1] + span[:, None] * gx).ravel()
    w = (span[:, None] * gw * segment_lengths(active)[seg_a][:, None]).ravel()
    seg_a = np.repeat(seg_a, GAUSS_POINTS)
    seg_p = np.repeat(seg_p, GAUSS_POINTS)
    na = linear_shape(xi)
    x = np.einsum("pk,pkd->pd", na, active.x[active.segments[seg_a]])
    if active.axisymmetric:
        w = w * radial_weight(active, x)
    # Orthogonal projection onto the line of the paired passive segment (not clamped: it may
    # fall just outside it where the nodal normals tilt the cut; the foot stays on the line).
    xa, xb = passive.x[passive.segments[seg_p, 0]], passive.x[passive.segments[seg_p, 1]]
    ab = xb - xa
    eta = np.einsum("pd,pd->p", x - xa, ab) / np.einsum("pd,pd->p", ab, ab)
    return seg_a, seg_p, xi, eta, w, rows


def _check_basis(basis: str) -> None:
    """Reject an unknown multiplier basis name."""
    if basis not in BASES:
        raise ValueError(f"unknown multiplier basis {basis!r} (known: {', '.join(BASES)})")


def _overlap_moments(
    n_segments: int, seg_a: np.ndarray, xi: np.ndarray, w: np.ndarray
) -> tuple[np.ndarray, ...]:
    """Per active segment: int 1, int N_k (m, 2), centroid c, int (xi - c), int (xi - c)^2."""

    def total(v: np.ndarray) -> np.ndarray:
        return np.bincount(seg_a, weights=w * v, minlength=n_segments)

    # Gauss sums, exact for these (at most quadratic) integrands. The first moment about the
    # rounded centroid is kept: beta times it would otherwise be an O(eps / overlap) error.
    size = total(np.ones_like(xi))
    d = np.stack([total(sh) for sh in linear_shape(xi).T], axis=1)
    c = d[:, 1] / np.where(size > 0, size, 1.0)
    t = xi - c[seg_a]
    return size, d, c, total(t), total(t * t)


def _dual_affine(
    n_segments: int, seg_a: np.ndarray, xi: np.ndarray, w: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """psi_j = a[:, j] + b[:, j] (xi - c) on each segment: (a, b, c, usable)."""
    # int psi_j = int N_j and int psi_j (xi - c) = int psi_j (N_1 - c) = (delta_j1 - c) int N_j
    # (biorthogonality) fix (a_j, b_j) through the Gram matrix [[int 1, t1], [t1, t2]] of
    # (1, xi - c); t1 is round-off, so det = int 1 * t2 - t1^2 suffers no cancellation.
    size, d, c, t1, t2 = _overlap_moments(n_segments, seg_a, xi, w)
    det = size * t2 - t1 * t1
    with np.errstate(divide="ignore", invalid="ignore"):
        a = np.stack([d[:, 0] * (t2 + t1 * c), d[:, 1] * (t2 - t1 * (1.0 - c))], axis=1)
        b = np.stack([-d[:, 0] * (t1 + c * size), d[:, 1] * (size * (1.0 - c) - t1)], axis=1)
        a, b = a / det[:, None], b / det[:, None]
        kappa = d[:, 0] * d[:, 1] / (size * np.sqrt(size * t2))
    usable = (size > 0) & (det > 0) & (kappa <= DUAL_MAX_DIPOLE)
    a[~usable] = b[~usable] = 0.0
    return a, b, c, usable


def _dual_values(
    n_segments: int, seg_a: np.ndarray, xi: np.ndarray, w: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """psi_0, psi_1 at the points (p, 2) and which points lie on usable segments."""
    a, b, c, usable = _dual_affine(n_segments, seg_a, xi, w)
    t = (xi - c[seg_a])[:, None]
    return a[seg_a] + b[seg_a] * t, usable[seg_a]


def _multiplier_points(
    active: Surface, passive: Surface, basis: str, ends: bool = True
) -> tuple[np.ndarray, ...]:
    """Gauss points (seg_a, seg_p, xi, eta, w), multiplier shape values (p, 2), rows (p, 2).

    rows[p, k] is the multiplier row that node k of the point's segment weights: the node
    itself, or its inside neighbour at an end of the passive surface (`_end_rows`).
    """
    _check_basis(basis)
    seg_a, seg_p, xi, eta, w, end_map = _gauss_points(active, passive, ends)
    rows = end_map[active.segments[seg_a]]
    if basis == "standard":
        return seg_a, seg_p, xi, eta, w, linear_shape(xi), rows
    psi, keep = _dual_values(active.n_segments, seg_a, xi, w)
    # Whole segments are dropped, so the runs of GAUSS_POINTS points stay intact.
    return seg_a[keep], seg_p[keep], xi[keep], eta[keep], w[keep], psi[keep], rows[keep]


def dual_coefficients(active: Surface, passive: Surface) -> tuple[np.ndarray, np.ndarray]:
    """Dual coefficients A (m, 2, 2), psi_j = sum_k A[e, j, k] N_k on segment e, and usable (m,)."""
    # A[e, j, k] is the value of psi_j at node k. Segments with no overlap or dropped as near
    # singular (usable False) have A = 0.
    seg_a, _, xi, _, w, _ = _gauss_points(active, passive)
    a, b, c, usable = _dual_affine(active.n_segments, seg_a, xi, w)
    node_xi = np.array([0.0, 1.0])
    A = a[:, :, None] + b[:, :, None] * (node_xi - c[:, None])[:, None, :]
    return A, usable


def overlap_weights(
    active: Surface, passive: Surface, near: np.ndarray | None = None
) -> np.ndarray:
    """Integrals of N_j dGamma over the part of the active surface facing the passive one.

    Returns an array of shape (n_active,).
    """
    seg_a, _, xi_int = subsegments(active, passive, near)
    lo, hi = xi_int[:, 0], xi_int[:, 1]
    length = segment_lengths(active)[seg_a]
    nodes = active.segments[seg_a]
    if active.axisymmetric:
        # int N_j 2 pi r ds: quadratic in xi, 2 Gauss points are exact.
        gx, gw = gauss_unit(GAUSS_POINTS)
        xi = lo[:, None] + (hi - lo)[:, None] * gx
        na = linear_shape(xi)  # (s, g, 2)
        x = np.einsum("sgk,skd->sgd", na, active.x[nodes])
        r = radial_weight(active, x.reshape(-1, 2)).reshape(xi.shape)
        wq = (length * (hi - lo))[:, None] * gw * r
        vals = np.einsum("sg,sgk->sk", wq, na)
        return np.bincount(nodes.ravel(), weights=vals.ravel(), minlength=active.n_nodes)
    # Exact integrals of 1 - xi and xi over [lo, hi].
    half_sq = 0.5 * (hi - lo) * (hi + lo)
    w1 = length * half_sq
    w0 = length * (hi - lo) - w1
    return np.bincount(
        nodes.ravel(), weights=np.stack([w0, w1], axis=1).ravel(), minlength=active.n_nodes
    )


def mortar_matrices(
    active: Surface, passive: Surface, basis: str = "standard", ends: bool = True
) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """D = int phi_j N_k (n_active x n_active), M = int phi_j N_A (n_active x n_passive)."""
    # phi = N (standard) or psi (dual: D is diagonal up to round-off; a solver takes D.diagonal()).
    seg_a, seg_p, xi, eta, w, phi, rows = _multiplier_points(active, passive, basis, ends)
    nj = phi * w[:, None]
    d_vals = nj[:, :, None] * linear_shape(xi)[:, None, :]
    m_vals = nj[:, :, None] * linear_shape(eta)[:, None, :]
    d_cols = np.broadcast_to(active.segments[seg_a][:, None, :], d_vals.shape)
    m_cols = np.broadcast_to(passive.segments[seg_p][:, None, :], m_vals.shape)
    r = np.broadcast_to(rows[:, :, None], d_vals.shape).ravel()
    na, npas = active.n_nodes, passive.n_nodes
    import scipy.sparse as sp  # the Schwarz reference only: not on a plain solve (docs/scale.md)

    D = sp.coo_matrix((d_vals.ravel(), (r, d_cols.ravel())), shape=(na, na)).tocsr()
    M = sp.coo_matrix((m_vals.ravel(), (r, m_cols.ravel())), shape=(na, npas)).tocsr()
    D.sum_duplicates()
    M.sum_duplicates()
    return D, M


def contact_operator(
    active: Surface,
    passive: Surface,
    ndofs: int,
    basis: str = "standard",
    ends: bool = True,
    direction: str = "normal",
    frame: str = "passive",
) -> ContactOperator:
    """Mortar operator: exact Gauss integration on sub-segments, normal of the paired segment.

    direction="tangent": the same D/M weights with the paired segment's tangent (friction's
    slip rows; `gap` the weighted tangential offset). frame="bisector": operator.FRAMES.
    """
    # Row j = int phi_j n . (x_active - x_passive), phi = N_j (standard) or psi_j (dual).
    seg_a, seg_p, xi, eta, w, phi, rows = _multiplier_points(active, passive, basis, ends)
    na = linear_shape(xi)
    nodes = active.segments[seg_a]
    return assemble(
        active,
        passive,
        ndofs,
        rows=rows,
        row_coef=w[:, None] * phi,
        act_nodes=nodes,
        act_coef=na,
        pas_nodes=passive.segments[seg_p],
        pas_coef=linear_shape(eta),
        normal=row_directions(
            passive.normals[seg_p], direction, frame_normals(active, seg_a, frame)
        ),
        group=GAUSS_POINTS,
    )
