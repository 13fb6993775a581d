"""Surface-to-surface: 4-point Gauss rule per active segment, each point projected independently."""

from __future__ import annotations

import numpy as np

from .geometry import Surface, project, segment_lengths
from .operator import ContactOperator, assemble, gauss_unit, linear_shape

GAUSS_POINTS = 4
# Gauss points beyond the passive surface's end by more than this (in passive segment lengths)
# contribute nothing.
TOL = 1e-8


def contact_operator(active: Surface, passive: Surface, ndofs: int) -> ContactOperator:
    """STS operator: row j = sum_gp w N_j n . (e_active(gp) - sum_A N_A(xi_gp) e_A)."""
    gx, gw = gauss_unit(GAUSS_POINTS)
    ma = active.n_segments
    e = np.repeat(np.arange(ma), GAUSS_POINTS)
    xi = np.tile(gx, ma)
    w = np.tile(gw, ma) * segment_lengths(active)[e]
    na = linear_shape(xi)
    nodes = active.segments[e]
    points = np.einsum("pk,pkd->pd", na, active.x[nodes])
    seg, eta, found = project(points, passive, TOL, group=GAUSS_POINTS)
    # No cutting at passive nodes: a segment straddling a passive node or kink is integrated
    # as if the integrand were smooth (the method's known source of oscillations).
    f = np.flatnonzero(found)
    return assemble(
        active,
        passive,
        ndofs,
        rows=nodes[f],
        row_coef=w[f, None] * na[f],
        act_nodes=nodes[f],
        act_coef=na[f],
        pas_nodes=passive.segments[seg[f]],
        pas_coef=linear_shape(eta[f]),
        normal=passive.normals[seg[f]],
    )
