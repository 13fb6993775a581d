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


def row_directions(normals: np.ndarray, direction: str) -> np.ndarray:
    """The normals themselves (the gap rows) or their tangents (the slip rows of friction)."""
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
