"""Node-to-surface: the gap collocated at each active node, scaled by its tributary length."""

from __future__ import annotations

import numpy as np

from .geometry import Surface, nodal_normals
from .mortar import overlap_weights
from .operator import FRAMES, ContactOperator, assemble, linear_shape, row_directions
from .search import project

# Active nodes beyond the passive surface's end by more than this (in passive segment lengths)
# get no constraint.
TOL = 1e-8


def contact_operator(
    active: Surface,
    passive: Surface,
    ndofs: int,
    direction: str = "normal",
    frame: str = "passive",
) -> ContactOperator:
    """NTS operator: row j = w_j n . (e_j - sum_A N_A(xi_j) e_A), w_j the overlapped int N_j.

    direction="tangent" gives the same rows with the passive segment's tangent t instead of n
    (operator.tangents): the weighted slip of friction; its `gap` is the weighted tangential
    offset of the reference configuration, not a gap. frame="bisector": the frame of the
    bisector of the passive segment and the active node's normal (operator.bisector_normals).
    """
    if frame not in FRAMES:
        raise ValueError(f"unknown frame {frame!r} (known: {', '.join(FRAMES)})")
    seg, xi, found = project(active.x, passive, TOL)
    # Scaling by int N_j turns the multiplier into a traction comparable with STS and mortar.
    w = overlap_weights(active, passive, seg)
    j = np.flatnonzero(found & (w > 0))
    s = seg[j]
    return assemble(
        active,
        passive,
        ndofs,
        rows=j[:, None],
        row_coef=w[j][:, None],
        act_nodes=j[:, None],
        act_coef=np.ones((len(j), 1)),
        pas_nodes=passive.segments[s],
        pas_coef=linear_shape(xi[j]),
        normal=row_directions(
            passive.normals[s],
            direction,
            nodal_normals(active)[j] if frame == "bisector" else None,
        ),
    )
