"""The tangential rows of a frictional solve on this rank.

B_t, the slip that prescribed motions add and which rows can carry a shear: for the
multipliers (methods/friction.py) and the penalty (methods/penalty_friction.py).
"""

from __future__ import annotations

import numpy as np
from petsc4py import PETSc

from ..contact import ContactOperator
from ..contact.sparse import CSR
from ..discretize.coupling import (
    column_mask,
    constrained_rows,
    global_dirichlet_dofs,
    petsc_constraint,
)
from ..discretize.setup import ContactSetup, prescribed_gap_shift
from ..discretize.tangents import held_rows, tangent_rows
from ..options import Basis
from ..scenes import Scene

# The rows' frame: the bisector of the two surfaces (contact/operator.bisector_normals). In
# the passive surface's frame, mirrored cylinders pressed with friction locked in a shear that
# their symmetry rules out, and the pushed stick zone sat off-centre (docs/friction.md).
FRAME = "bisector"


def tangent_constraint(
    scene: Scene, setup: ContactSetup, basis: Basis, kernel: object
) -> tuple[PETSc.Mat, np.ndarray, CSR, np.ndarray, CSR | None]:
    """This rank's rows of B_t and the weighted slip that prescribed displacements add.

    B_t: the tangential rows of the same kernel, in the layout's order (owned rows); also
    all of them as a CSR, and which owned rows have a free tangential dof (a node on a
    symmetry line or the axis has none: it cannot slip, its row carries no shear). Against
    an obstacle the rows follow its exact tangent, and its prescribed rigid motion (this
    step's) enters the weighted slip: the body's motion relative to the obstacle; the last
    item is the rows' obstacle-motion columns (all rows, layout order; None: no obstacle).
    """
    el = setup.elasticity
    V = el.V
    ndofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    rows = setup.tangent or tangent_rows(setup.pairs, kernel, basis, FRAME, ndofs)
    Bt, motion, columns = rows.B, rows.motion, rows.columns
    op = ContactOperator(Bt, np.zeros(Bt.shape[0]), setup.operator.weights)
    dofs = np.vstack(
        [p.active.surface.dofs for p in setup.pairs]
        + [p.passive.surface.dofs for p in setup.pairs if p.passive is not None]
    )
    shift = prescribed_gap_shift(scene, el, op, dofs) + np.concatenate(motion)
    dirichlet = global_dirichlet_dofs(V, el.bc_dofs)
    fixed = column_mask(dirichlet, Bt.shape[1])
    B = petsc_constraint(V, op, setup.order, setup.layout, dirichlet)
    mine = setup.order[setup.layout.mine]
    moving = CSR.vstack(columns).rows(setup.order) if scene.obstacles else None
    held = held_rows(Bt, np.vstack([p.active.surface.dofs for p in setup.pairs]), fixed)
    free = constrained_rows(op, dirichlet) & ~held
    return B, shift[mine], Bt.rows(setup.order), free[mine], moving
