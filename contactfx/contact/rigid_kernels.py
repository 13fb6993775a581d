"""NTS, STS and mortar against a rigid obstacle, written as point contributions.

Each point x (an active node, or a Gauss point of an active segment) adds
row_coef * (g(x) + n(x) . (u_active(x) - u_obstacle)) to its rows, g and n the exact gap and
outward normal of the obstacle at x (`contact.rigid`). The obstacle's rigid displacement is
carried by two phantom columns beyond the body's dofs (`contact.operator.assemble` with the
closest points as a passive "surface" of one node per point); they are split off as
`motion`, so the pair's B sees the body's dofs only and the prescribed motion enters the gap.

- NTS: collocation at the active nodes, weighted by the node's overlapped int N_j.
- STS: 4 Gauss points per active segment, each with its own closest point.
- Mortar: the active segments cut where the closest feature of a polyline changes (lines
  through its vertices along the segment normals and the bisectors, and through an open
  polyline's ends), then Gauss points on each piece: 2 for a plane (N_j g is quadratic: exact),
  6 for a circle or a polyline (exact on pieces facing a segment, to ~(h/R)^12 on round ones).
  The dual basis is built from the same points (`mortar`'s biorthogonal construction).

direction="tangent" (friction's slip rows): the same weights along the obstacle's exact tangent
t = (n_y, -n_x) at each point; `gap` is then zero (the closest point lies along n) and `motion`
the weighted slip that the obstacle's rigid motion adds. frame: accepted for the body pairs'
signature; the rows' frame is always the obstacle's exact normal (a rigid surface is the
interface the body presses into).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .geometry import Surface, nodal_normals, radial_weight, segment_lengths
from .mortar import SLIVER, _check_basis, _dual_values
from .operator import FRAMES, ContactOperator, assemble, gauss_unit, linear_shape, row_directions
from .rigid import Circle, Closest, Plane, Polyline, RigidShape
from .sparse import CSR
from .sts import gauss_points

GAUSS_FLAT = 2
GAUSS_ROUND = 6
# Bound on the (segments x cut lines) work arrays of the polyline cuts.
_CHUNK_ENTRIES = 2_000_000


@dataclass(frozen=True)
class RigidOperator:
    """A body surface against an obstacle: the operator on the body's dofs, and the motion.

    `operator.gap` is the weighted gap with the obstacle at its reference position; the
    obstacle displaced by d adds `motion @ d` ((n_active, 2) sparse) to it.
    """

    operator: ContactOperator
    motion: CSR

    def moved(self, displacement: np.ndarray) -> ContactOperator:
        """The operator with the obstacle displaced rigidly by `displacement` (2,)."""
        op = self.operator
        shift = self.motion @ np.asarray(displacement, dtype=np.float64)
        return ContactOperator(op.B, op.gap + shift, op.weights)


def _points(active: Surface, nodes: np.ndarray, coef: np.ndarray) -> np.ndarray:
    # The same sum as contact.operator.assemble: the points are bit for bit those it uses.
    return np.einsum("pk,pkd->pd", coef, active.x[nodes])


def _assemble(
    active: Surface,
    ndofs: int,
    rows: np.ndarray,
    row_coef: np.ndarray,
    act_nodes: np.ndarray,
    act_coef: np.ndarray,
    near: Closest,
    direction: str = "normal",
    frame: str = "passive",
) -> RigidOperator:
    """Point contributions against the closest points `near`; phantom columns split off."""
    if frame not in FRAMES:
        raise ValueError(f"unknown frame {frame!r} (known: {', '.join(FRAMES)})")
    k = len(near.gap)
    phantom = Surface(
        near.foot, np.zeros((0, 2)), np.zeros((0, 2)), np.tile([ndofs, ndofs + 1], (k, 1))
    )
    full = assemble(
        active,
        phantom,
        ndofs + 2,
        rows=rows,
        row_coef=row_coef,
        act_nodes=act_nodes,
        act_coef=act_coef,
        pas_nodes=np.arange(k)[:, None],
        pas_coef=np.ones((k, 1)),
        normal=row_directions(near.normal, direction),
    )
    body = full.B.columns(0, ndofs)  # assemble dropped the exact zeros already
    return RigidOperator(
        ContactOperator(body, full.gap, full.weights), full.B.columns(ndofs, ndofs + 2)
    )


def _cuts(active: Surface, shape: RigidShape) -> list[np.ndarray]:
    """Per active segment, the xi in (0, 1) where the obstacle's closest feature may change."""
    ma = active.n_segments
    if not isinstance(shape, Polyline):
        return [np.zeros(0)] * ma
    origin, direction = shape.cut_lines()
    p0 = active.x[active.segments[:, 0]]
    e = active.x[active.segments[:, 1]] - p0
    out: list[list[float]] = [[] for _ in range(ma)]
    chunk = max(1, _CHUNK_ENTRIES // max(len(origin), 1))
    for lo in range(0, ma, chunk):
        a, d = p0[lo : lo + chunk, None, :], e[lo : lo + chunk, None, :]
        den = direction[None, :, 0] * d[..., 1] - direction[None, :, 1] * d[..., 0]
        rel = origin[None] - a
        num = direction[None, :, 0] * rel[..., 1] - direction[None, :, 1] * rel[..., 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            xi = np.where(np.abs(den) > 0, num / den, -1.0)
        s, _ = np.nonzero((xi > SLIVER) & (xi < 1.0 - SLIVER))
        for seg, v in zip(s + lo, xi[(xi > SLIVER) & (xi < 1.0 - SLIVER)], strict=True):
            out[seg].append(float(v))
    return [np.unique(v) for v in map(np.asarray, out)]


def _piece_points(
    active: Surface, shape: RigidShape, n_gauss: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gauss points on the pieces of every active segment: (segment, xi, weight)."""
    gx, gw = gauss_unit(n_gauss)
    length = segment_lengths(active)
    seg, lo, hi = [], [], []
    for e, cut in enumerate(_cuts(active, shape)):
        edges = np.concatenate([[0.0], cut, [1.0]])
        keep = np.diff(edges) > SLIVER
        seg.append(np.full(int(keep.sum()), e))
        lo.append(edges[:-1][keep])
        hi.append(edges[1:][keep])
    s, a, b = (np.concatenate(v) if v else np.zeros(0) for v in (seg, lo, hi))
    s = s.astype(np.int64)
    span = b - a
    xi = (a[:, None] + span[:, None] * gx).ravel()
    w = (span[:, None] * gw * length[s][:, None]).ravel()
    on = np.repeat(s, n_gauss)
    if active.axisymmetric:
        w = w * radial_weight(active, _points(active, active.segments[on], linear_shape(xi)))
    return on, xi, w


def _round(shape: RigidShape) -> int:
    return GAUSS_FLAT if isinstance(shape, Plane) else GAUSS_ROUND


def overlap_weights(active: Surface, shape: RigidShape) -> np.ndarray:
    """The integrals of N_j dGamma over the part of the surface facing the obstacle, (n,)."""
    seg, xi, w = _piece_points(active, shape, GAUSS_FLAT)
    nodes = active.segments[seg]
    na = linear_shape(xi)
    found = shape.closest(_points(active, nodes, na)).found
    vals = (w[:, None] * na)[found]
    return np.bincount(nodes[found].ravel(), weights=vals.ravel(), minlength=active.n_nodes)


def _select(near: Closest, keep: np.ndarray) -> Closest:
    return Closest(near.gap[keep], near.normal[keep], near.foot[keep], near.found[keep])


def nts_operator(
    active: Surface,
    shape: RigidShape,
    ndofs: int,
    direction: str = "normal",
    frame: str = "passive",
) -> RigidOperator:
    """NTS: row j = w_j (g(x_j) + n(x_j) . (u_j - u_obstacle))."""
    w = overlap_weights(active, shape)
    near = shape.closest(active.x)
    j = np.flatnonzero(near.found & (w > 0))
    return _assemble(
        active,
        ndofs,
        rows=j[:, None],
        row_coef=w[j][:, None],
        act_nodes=j[:, None],
        act_coef=np.ones((len(j), 1)),
        near=_select(near, j),
        direction=direction,
        frame=frame,
    )


def sts_operator(
    active: Surface,
    shape: RigidShape,
    ndofs: int,
    direction: str = "normal",
    frame: str = "passive",
) -> RigidOperator:
    """STS: row j = sum_gp w N_j (g + n . (u_active - u_obstacle)), 4 points per segment."""
    w, na, nodes = gauss_points(active)
    near = shape.closest(_points(active, nodes, na))
    f = np.flatnonzero(near.found)
    return _assemble(
        active,
        ndofs,
        rows=nodes[f],
        row_coef=w[f, None] * na[f],
        act_nodes=nodes[f],
        act_coef=na[f],
        near=_select(near, f),
        direction=direction,
        frame=frame,
    )


def mortar_operator(
    active: Surface,
    shape: RigidShape,
    ndofs: int,
    basis: str = "standard",
    direction: str = "normal",
    frame: str = "passive",
) -> RigidOperator:
    """Mortar: row j = int phi_j (g + n . (u_active - u_obstacle)) on the facing pieces."""
    _check_basis(basis)
    seg, xi, w = _piece_points(active, shape, _round(shape))
    nodes = active.segments[seg]
    na = linear_shape(xi)
    near = shape.closest(_points(active, nodes, na))
    f = near.found
    seg, xi, w, nodes, na, near = seg[f], xi[f], w[f], nodes[f], na[f], _select(near, f)
    phi = na
    if basis == "dual":
        phi, usable = _dual_values(active.n_segments, seg, xi, w)
        w, nodes, na, phi = w[usable], nodes[usable], na[usable], phi[usable]
        near = _select(near, usable)
    return _assemble(
        active,
        ndofs,
        rows=nodes,
        row_coef=w[:, None] * phi,
        act_nodes=nodes,
        act_coef=na,
        near=near,
        direction=direction,
        frame=frame,
    )


RIGID_OPERATORS: dict[str, Callable[..., RigidOperator]] = {
    "nts": nts_operator,
    "sts": sts_operator,
    "mortar": mortar_operator,
}


def rigid_operator(
    kernel: str, active: Surface, shape: RigidShape, ndofs: int, **options: object
) -> RigidOperator:
    """The operator of `kernel` (nts, sts, mortar) against `shape`.

    options: mortar's basis, direction ("normal" or "tangent"), frame.
    """
    return RIGID_OPERATORS[str(kernel)](active, shape, ndofs, **options)


def facing_angle(
    active: Surface, shape: RigidShape, op: ContactOperator
) -> tuple[np.ndarray, float] | None:
    """(node, angle in degrees) where the surface turns away from the obstacle, or None.

    Only the nodes within one element of the smallest gap that face the obstacle matter (as
    for body pairs): there the body's outward normal must oppose the obstacle's by more than
    90 degrees (exactly 90 is legal: a node beside a corner of the obstacle).
    """
    nodes = np.flatnonzero(op.overlapping)
    if nodes.size == 0:
        return None
    gap = op.gap[nodes] / op.weights[nodes]
    h = float(np.median(segment_lengths(active)))
    near = nodes[gap <= gap.min() + h]
    closest = shape.closest(active.x[near])
    near = near[closest.found]
    dot = np.einsum("ij,ij->i", nodal_normals(active)[near], closest.normal[closest.found])
    if not np.any(dot > 1e-8):
        return None
    j = int(np.argmax(dot))
    return active.x[near[j]], float(np.degrees(np.arccos(min(dot[j], 1.0))))


__all__ = [
    "Circle",
    "Plane",
    "Polyline",
    "RigidOperator",
    "facing_angle",
    "overlap_weights",
    "rigid_operator",
]
