"""Contact surfaces: segment geometry and chain topology (the closest-point search: search.py)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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


def incidence(n: int, s0: np.ndarray, s1: np.ndarray) -> np.ndarray:
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
    inc = incidence(n, s0, s1)
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
