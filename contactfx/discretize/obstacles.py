"""Rigid obstacles as contact pairs: the body's gathered surface against the exact shape.

An obstacle pair is an ordinary pair of the stacked operator (its rows follow the body
pairs'), whose passive side is no body: B holds the body's dofs only, and the obstacle's
prescribed rigid motion enters the gap (`moved`) once the initial penetration is checked at
the obstacle's reference position.
"""

from __future__ import annotations

import numpy as np
from dolfinx import fem

from ..contact import ContactOperator, Kernel, rigid_operator
from ..contact.rigid_kernels import facing_angle
from ..errors import GeometryError
from ..scenes import Body, ContactPair, Obstacle, Scene
from .coupling import column_mask
from .pairs import PairData
from .surfaces import GatheredSurface, gather_surface

# An obstacle with the body it may touch and that body's gathered surface.
GatheredObstacle = tuple[Obstacle, Body, GatheredSurface]


def gather_obstacles(scene: Scene, V: fem.FunctionSpace) -> list[GatheredObstacle]:
    """Each obstacle with its body and the gathered curve group it may touch (collective)."""
    return [
        (ob, scene.body_of_curve(ob.surface), gather_surface(scene, V, ob.surface))
        for ob in scene.obstacles
    ]


def build_obstacle_pairs(
    gathered: list[GatheredObstacle],
    kernel: Kernel,
    ndofs: int,
    first_index: int,
    first_row: int,
    **kernel_options: object,
) -> list[PairData]:
    """The operator of `kernel` against every obstacle, as pairs first_index, first_index+1..."""
    out, row = [], first_row
    for i, (ob, body, surf) in enumerate(gathered):
        rop = rigid_operator(kernel, surf.surface, ob.geometry, ndofs, **kernel_options)
        out.append(
            PairData(
                first_index + i,
                ContactPair(ob.surface, ob.name),
                body,
                None,
                surf,
                None,
                rop.operator,
                row,
                obstacle=ob,
                motion=rop.motion,
            )
        )
        row += surf.surface.n_nodes
    return out


def check_obstacle_geometry(p: PairData) -> None:
    """GeometryError if the obstacle faces no part of its surface, or the surface turns away."""
    assert p.obstacle is not None  # only called on obstacle pairs
    ob = p.obstacle
    if not p.operator.overlapping.any():
        raise GeometryError(
            f"obstacle '{ob.name}' faces no part of the surface '{ob.surface}' (every node "
            "lies beyond the ends of its polyline)"
        )
    bad = facing_angle(p.active.surface, ob.geometry, p.operator)
    if bad is not None:
        x, angle = bad
        hints = {
            "plane": " (does its normal point from the obstacle towards the body?)",
            # The obstacle lies on the left of its points in order: a polyline walked the
            # other way has the body on the obstacle's side.
            "polyline": " (the obstacle lies on the left of its points in order, the body on "
            "the right: is the polyline walked the wrong way? reverse its points)",
        }
        raise GeometryError(
            f"the surface '{ob.surface}' does not face obstacle '{ob.name}': at ({x[0]:.4g}, "
            f"{x[1]:.4g}) the outward normals of the body and the obstacle make an angle of "
            f"{angle:.0f} degrees (180 expected)" + hints.get(ob.shape, "")
        )


def moved(op: ContactOperator, pairs: list[PairData]) -> ContactOperator:
    """The stacked operator with every obstacle at its prescribed position (gap shifted)."""
    shift = np.zeros_like(op.gap)
    for p in pairs:
        if p.obstacle is not None and p.motion is not None and any(p.obstacle.displacement):
            rows = slice(p.first_row, p.first_row + p.active.surface.n_nodes)
            shift[rows] += p.motion @ np.asarray(p.obstacle.displacement)
    return ContactOperator(op.B, op.gap + shift, op.weights) if np.any(shift) else op


def node_free_rows(
    op: ContactOperator, node_dofs: np.ndarray, pairs: list[PairData], dirichlet: np.ndarray
) -> np.ndarray:
    """False on the obstacle rows whose own node cannot move along them (prescribed).

    Such a row still touches the neighbours' dofs (STS, mortar), but with a rigid side
    that has no dofs the rows outnumber the free normal motions they constrain: the
    multipliers would not be unique (a singular saddle point). Body pairs keep theirs: the
    passive body's dofs take up the slack.
    """
    keep = np.ones(op.B.shape[0], dtype=bool)
    fixed = column_mask(dirichlet, op.B.shape[1])
    for p in pairs:
        if p.obstacle is None:
            continue
        rows = np.arange(p.first_row, p.first_row + p.active.surface.n_nodes)
        sub = op.B.rows(rows)
        whole = sub.row_max_abs()
        r = sub.entry_rows
        own = np.zeros(len(rows))
        for c in (0, 1):
            dof = node_dofs[rows, c]
            at = (sub.indices == dof[r]) & ~fixed[sub.indices]  # the row's own dof, free
            np.maximum.at(own, r[at], np.abs(sub.data[at]))
        # Relative to the row, as constrained_rows: "prescribed" is up to round-off.
        keep[rows] = own > 1e-10 * whole
    return keep
