"""Surface-to-surface: 4-point Gauss rule per active segment, each point projected independently."""

from __future__ import annotations

import numpy as np

from .geometry import Surface, radial_weight, segment_lengths
from .operator import ContactOperator, assemble, end_rows, gauss_unit, linear_shape
from .search import project

GAUSS_POINTS = 4
# Gauss points beyond the passive surface's end by more than this (in passive segment lengths)
# contribute nothing.
TOL = 1e-8


def gauss_points(active: Surface) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """STS's points on every active segment: weights w, shape values na, the segments' nodes."""
    gx, gw = gauss_unit(GAUSS_POINTS)
    ma = active.n_segments
    e = np.repeat(np.arange(ma), GAUSS_POINTS)
    w = np.tile(gw, ma) * segment_lengths(active)[e]
    na, nodes = linear_shape(np.tile(gx, ma)), active.segments[e]
    if active.axisymmetric:
        w = w * radial_weight(active, np.einsum("pk,pkd->pd", na, active.x[nodes]))
    return w, na, nodes


def contact_operator(
    active: Surface, passive: Surface, ndofs: int, ends: bool = True
) -> ContactOperator:
    """STS operator: row j = sum_gp w N_j n . (e_active(gp) - sum_A N_A(xi_gp) e_A)."""
    w, na, nodes = gauss_points(active)
    points = np.einsum("pk,pkd->pd", na, active.x[nodes])
    seg, eta, found = project(points, passive, TOL)
    # No cutting at passive nodes: a segment straddling a passive node or kink is integrated
    # as if the integrand were smooth (the method's known source of oscillations).
    f = np.flatnonzero(found)
    # End modification (operator.end_rows): a segment whose first (last) Gauss point is found
    # reaches its node 0 (1); the node beyond the passive end merges into its inside neighbour.
    hit = found.reshape(-1, GAUSS_POINTS)
    end_map = (
        end_rows(active.segments, active.n_nodes, hit.any(axis=1), hit[:, [0, -1]])
        if ends
        else np.arange(active.n_nodes)
    )
    return assemble(
        active,
        passive,
        ndofs,
        rows=end_map[nodes[f]],
        row_coef=w[f, None] * na[f],
        act_nodes=nodes[f],
        act_coef=na[f],
        pas_nodes=passive.segments[seg[f]],
        pas_coef=linear_shape(eta[f]),
        normal=passive.normals[seg[f]],
    )
