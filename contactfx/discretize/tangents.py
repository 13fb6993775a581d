"""The tangential rows of friction: the same kernel's rows along the contact tangent.

Friction's slip rows (methods/friction.py) and the free-body check (load_paths.py: a body
held sideways by stick friction) both need them, in the stacked operator's order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..contact import contact_operator, rigid_operator
from ..contact.sparse import CSR
from ..options import Basis
from .pairs import PairData


@dataclass(frozen=True)
class TangentRows:
    """B_t stacked over the pairs, and per pair an obstacle's rigid-motion columns.

    `columns[k]` ((n_k, 2)): pair k's rows applied to its obstacle's rigid displacement
    (empty for a pair between bodies); `motion[k]` that times the obstacle's displacement.
    """

    B: CSR
    motion: list[np.ndarray]
    columns: list[CSR]


def pair_friction(pairs: list[PairData]) -> np.ndarray:
    """Each stacked row's mu (its pair's, or its obstacle's)."""
    return np.concatenate(
        [
            np.full(p.active.surface.n_nodes, p.obstacle.mu if p.obstacle else p.pair.mu)
            for p in pairs
        ]
    )


def tangent_rows(
    pairs: list[PairData], kernel: object, basis: Basis, frame: str, ndofs: int
) -> TangentRows:
    """The tangential rows of `kernel` for every pair (stacked as the normal rows are)."""
    options: dict[str, object] = {"direction": "tangent", "frame": frame}
    if basis is Basis.DUAL:
        options["basis"] = basis
    ops, motion, columns = [], [], []
    for p in pairs:
        n = p.active.surface.n_nodes
        if p.passive is None:
            assert p.obstacle is not None
            ob = p.obstacle
            rop = rigid_operator(kernel, p.active.surface, ob.geometry, ndofs, **options)  # type: ignore[arg-type]
            ops.append(rop.operator.B)
            motion.append(rop.motion @ np.asarray(ob.displacement, dtype=np.float64))
            columns.append(rop.motion)
        else:
            op = contact_operator(kernel, p.active.surface, p.passive.surface, ndofs, **options)  # type: ignore[arg-type]
            ops.append(op.B)
            motion.append(np.zeros(n))
            empty = np.zeros(0, dtype=np.int64)
            columns.append(CSR.from_coo(empty, empty, np.zeros(0), (n, 2)))
    return TangentRows(CSR.vstack(ops) if len(ops) > 1 else ops[0], motion, columns)


# A tangential row whose own node moves along it by less than this fraction of the row's
# own entries is held: a node on a symmetry line or the axis, whose row in the bisector
# frame is tilted from the line by half a segment's angle (a few per cent on a coarse arc),
# not by a real freedom (docs/friction.md, "How it is solved").
HELD_FRACTION = 0.1


def held_rows(B: CSR, node_dofs: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    """True on the rows of B_t (stacked order) whose own node is held along them.

    `node_dofs` ((m, 2)): each row's own (active) node's dofs; `fixed`: a column mask of the
    prescribed dofs. Such a row's stick multiplier duplicates the support's reaction (with
    the standard basis the row still touches its neighbour's dof, and the multipliers came
    out as an alternating shear of mu p decaying along the rows): it carries no shear.
    """
    r = B.entry_rows
    own = np.zeros(B.shape[0])
    free = np.zeros(B.shape[0])
    for c in (0, 1):
        at = B.indices == node_dofs[r, c]
        np.maximum.at(own, r[at], np.abs(B.data[at]))
        at &= ~fixed[B.indices]
        np.maximum.at(free, r[at], np.abs(B.data[at]))
    return (own > 0.0) & (free <= HELD_FRACTION * own)
