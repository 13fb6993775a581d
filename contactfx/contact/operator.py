"""The linearized contact operator and its assembly from point contributions."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import Surface
from .sparse import CSR


@dataclass(frozen=True)
class ContactOperator:
    """Weighted gap g_tilde(u) = gap + B @ u, one row per active-surface node."""

    B: CSR  # (n_active_nodes, ndofs): row j = active node j
    gap: np.ndarray  # (n_active_nodes,) weighted gap at u = 0 (reference config)
    weights: np.ndarray  # (n_active_nodes,) int over the overlapped part of N_j dGamma

    @property
    def rows(self) -> np.ndarray:
        """Active nodes with a non-empty constraint (weights > 0); the others are all zero."""
        return np.flatnonzero(self.weights > 0)

    @property
    def overlapping(self) -> np.ndarray:
        """Rows whose weight is above round-off of the largest: they face the passive surface."""
        return self.weights > overlap_tolerance(self.weights)


def overlap_tolerance(weights: np.ndarray) -> float:
    """Weights at or below this are round-off: the row's node does not face the other surface."""
    return 1e-12 * max(float(np.max(weights, initial=0.0)), 1e-300)


# Where the facing part of an active segment ends within this fraction of the segment from a
# node, it reaches that node: a sliver left by the geometry (the drawn overlap of a fit seen
# along a tilted end normal: ~5e-4 on the shrink-fit rings) does not move a row.
REACH = 1e-2


def end_rows(segments: np.ndarray, n_nodes: int, some: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """The multiplier row of each active node after the end modification (docs/edges.md).

    `some` (m,): active segment e faces the passive surface somewhere; `reach` (m, 2): the
    facing part of e reaches node k of e. At an end of the passive surface the active
    segment that straddles it faces only partly: restricted to that part its two basis
    functions are nearly dependent, their two multipliers fit the corner's load by a steep
    slope, the node beyond the end carries a large value and its neighbour inside turns
    tensile and is released. Here, as in the boundary modification of the mortar literature
    (Wohlmuth's modified dual basis; Popp et al.; Cichosz and Bischoff), the nodes whose
    support the passive surface covers only partly leave the multiplier space and their basis
    functions merge into the first node whose support it covers wholly:

    - a node o beyond the end (its only facing segment reaches the other node but not o) and
    - the last node reached (o's neighbour inside, or a node lying on the end itself: one
      segment faces wholly, the other not at all)

    both give their rows to the next node inside, whose multiplier is then constant from one
    cell inside to the end (sum of the merged N, or psi for the dual basis, = 1 there). The
    constant part is 1 to 2 cells long wherever the nodes fall, so the end value reads the
    corner's load over a length ~h (merging the node beyond only would leave 0 to 1 cell:
    the end value then swings by ~1.6x as the nodes move across the end). A constant is
    still reproduced (patch tests exact). A segment facing only strictly inside (both nodes
    beyond a passive surface shorter than a segment) keeps its two rows; an active surface
    that ends inside the passive one (a one-segment node) is left alone.
    Returns `rows` (n_nodes,): rows[j] = j, or the node j's row merged into.
    """
    rows = np.arange(n_nodes)
    facing = np.bincount(segments[some].ravel(), minlength=n_nodes)
    full = reach[:, 0] & reach[:, 1]
    degree = np.bincount(segments.ravel(), minlength=n_nodes)
    n_full = np.bincount(segments[full].ravel(), minlength=n_nodes)
    for k in (0, 1):
        o, i = segments[:, k], segments[:, 1 - k]
        beyond = some & reach[:, 1 - k] & ~reach[:, k] & (facing[o] == 1)
        rows[o[beyond]] = i[beyond]
    last = np.zeros(n_nodes, dtype=bool)
    last[rows[rows != np.arange(n_nodes)]] = True
    last |= (degree == 2) & (n_full == 1) & (facing == 1)
    for k in (0, 1):
        o, i = segments[:, k], segments[:, 1 - k]
        inward = full & last[o] & (n_full[o] == 1) & (n_full[i] == 2)
        rows[o[inward]] = i[inward]
    return rows[rows]


def gauss_unit(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss-Legendre points and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


def linear_shape(xi: np.ndarray) -> np.ndarray:
    """Values (..., 2) of the two linear shape functions (node 0, node 1) at xi."""
    return np.stack([1.0 - xi, xi], axis=-1)


#: Directions of a contact operator's rows: the normal (the gap) or the tangent (the slip).
DIRECTIONS = ("normal", "tangent")


def tangents(normals: np.ndarray) -> np.ndarray:
    """Unit tangents t = (n_y, -n_x) of unit normals (m, 2): +x for the upward normal (0, 1)."""
    return np.stack([normals[:, 1], -normals[:, 0]], axis=1)


#: Frames of a contact operator's rows: the passive surface's, or the bisector of both (the
#: passive and the facing active segment's; friction's, `bisector_normals`).
FRAMES = ("passive", "bisector")


def bisector_normals(passive_normals: np.ndarray, active_normals: np.ndarray) -> np.ndarray:
    """Unit normals of the bisector of two facing surfaces, oriented as the passive ones.

    On curved surfaces the passive normal is tilted from the interface the two press into by
    half the angle between them. Friction needs that interface's frame: along the passive
    tangent, the closing of the initial gap reads as slip, and a pressure along the passive
    normal carries a shear, so mirrored cylinders pressed with friction locked in a shear
    that the physics (their mirror symmetry) rules out (docs/friction_verification.md,
    Cattaneo-Mindlin).
    The bisector is the same whichever side is active, and the passive normal on flat faces.
    """
    n = passive_normals - active_normals
    return n / np.linalg.norm(n, axis=1)[:, None]


def frame_normals(active: Surface, seg: np.ndarray, frame: str) -> np.ndarray | None:
    """The active normals on segments `seg` that set a bisector frame; None: the passive one."""
    if frame not in FRAMES:
        raise ValueError(f"unknown frame {frame!r} (known: {', '.join(FRAMES)})")
    return active.normals[seg] if frame == "bisector" else None


def row_directions(
    normals: np.ndarray,
    direction: str,
    active_normals: np.ndarray | None = None,
) -> np.ndarray:
    """The normals themselves (the gap rows) or their tangents (the slip rows of friction).

    `active_normals` (the facing active surface's outward normals at the same points): the
    frame is the bisector's (`bisector_normals`), not the passive surface's.
    """
    if active_normals is not None:
        normals = bisector_normals(normals, active_normals)
    if direction == "normal":
        return normals
    if direction == "tangent":
        return tangents(normals)
    raise ValueError(f"unknown row direction {direction!r} (known: {', '.join(DIRECTIONS)})")


def assemble(
    active: Surface,
    passive: Surface,
    ndofs: int,
    rows: np.ndarray,
    row_coef: np.ndarray,
    act_nodes: np.ndarray,
    act_coef: np.ndarray,
    pas_nodes: np.ndarray,
    pas_coef: np.ndarray,
    normal: np.ndarray,
    group: int = 1,
) -> ContactOperator:
    """Sum point contributions row_coef * n . (sum act_coef x_act - sum pas_coef x_pas)."""
    # Point p adds to rows[p, r] (active nodes, weight row_coef[p, r]) the linearized gap
    # n_p . (x_active(p) - x_passive(p)), both sides written as shape-function sums. Points
    # come in runs of `group` sharing rows, nodes and normal (the Gauss points of one mortar
    # sub-segment); their values are summed before the scatter to shrink the COO arrays.
    na = active.n_nodes
    if max(active.dofs.max(initial=-1), passive.dofs.max(initial=-1)) >= ndofs:
        raise ValueError("a surface dof number is >= ndofs")
    x_act = np.einsum("pk,pkd->pd", act_coef, active.x[act_nodes])
    x_pas = np.einsum("pk,pkd->pd", pas_coef, passive.x[pas_nodes])
    g = np.einsum("pd,pd->p", normal, x_act - x_pas)
    flat_rows = rows.ravel()
    gap = np.bincount(flat_rows, weights=(row_coef * g[:, None]).ravel(), minlength=na)
    weights = np.bincount(flat_rows, weights=row_coef.ravel(), minlength=na)

    cols = np.concatenate([active.dofs[act_nodes], passive.dofs[pas_nodes]], axis=1)
    coef = np.concatenate([act_coef, -pas_coef], axis=1)
    vals = row_coef[:, :, None, None] * coef[:, None, :, None] * normal[:, None, None, :]
    if group > 1:
        vals = vals.reshape(-1, group, *vals.shape[1:]).sum(axis=1)
        rows, cols = rows[::group], cols[::group]
    shape = vals.shape
    r = np.broadcast_to(rows[:, :, None, None], shape).ravel()
    c = np.broadcast_to(cols[:, None, :, :], shape).ravel()
    B = CSR.from_coo(r, c, vals.ravel(), (na, ndofs), drop_zeros=True)
    return ContactOperator(B=B, gap=gap, weights=weights)
