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


# Where an overlap interval ends within this fraction of its active segment from a node, it
# reaches that node (round-off of the clipping).
REACH = 1e-9
TWO_CELLS = True


def end_rows(segments: np.ndarray, n_nodes: int, some: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """The row of each active node after the end modification at the passive surface's ends.

    `some` (m,): active segment e faces the passive surface somewhere; `reach` (m, 2): that
    part reaches node k of e. A node o whose only facing segment e reaches the other node i
    of e but not o (e straddles the end of the passive surface, o lies beyond it) gets no row
    of its own: its basis function on e is merged into i's, so i's multiplier is constant on
    the facing part of e (N_i + N_o = 1, psi_i + psi_o = 1 for the dual basis). Without it the
    two functions, restricted to a short facing part, are nearly dependent: their two
    multipliers fit the corner's load by a steep slope, o's grows large and i's turns tensile
    (docs/edges.md). This is the boundary modification of the dual-mortar literature
    (Wohlmuth; Popp et al.; Cichosz and Bischoff): the node whose support is only partly
    covered leaves the multiplier space. A segment facing the passive surface only strictly
    inside (both of its nodes beyond a passive surface shorter than one segment) keeps its
    two rows. Returns `rows` (n_nodes,): rows[j] = j, or i for a merged o.
    """
    rows = np.arange(n_nodes)
    facing = np.bincount(segments[some].ravel(), minlength=n_nodes)
    full = reach[:, 0] & reach[:, 1]
    degree = np.bincount(segments.ravel(), minlength=n_nodes)
    n_full = np.bincount(segments[full].ravel(), minlength=n_nodes)
    for k in (0, 1):
        o, i = segments[:, k], segments[:, 1 - k]
        merge = some & reach[:, 1 - k] & ~reach[:, k] & (facing[o] == 1)
        rows[o[merge]] = i[merge]
    if TWO_CELLS:
        # The last reached node: its outward segment faces only partly or not at all.
        last = np.zeros(n_nodes, dtype=bool)
        last[rows[rows != np.arange(n_nodes)]] = True
        last |= (degree == 2) & (n_full == 1) & (facing == 1)
        for k in (0, 1):
            o, i = segments[:, k], segments[:, 1 - k]
            merge = full & last[o] & (n_full[o] == 1) & (n_full[i] == 2)
            rows[o[merge]] = i[merge]
        rows = rows[rows]
    return rows


def gauss_unit(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss-Legendre points and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


def linear_shape(xi: np.ndarray) -> np.ndarray:
    """Values (..., 2) of the two linear shape functions (node 0, node 1) at xi."""
    return np.stack([1.0 - xi, xi], axis=-1)


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
