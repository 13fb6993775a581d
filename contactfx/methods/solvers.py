"""One factory for every linear solver: it owns gamma, the near-nullspace and the reuse policy.

The methods turn a SolverSpec into a solver here; contactfx/linalg itself knows no spec.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from petsc4py import PETSc

from ..linalg.condensed import CondensedSolver
from ..linalg.nullspace import near_nullspace
from ..linalg.policy import FactorizationPolicy
from ..linalg.protocol import LinearSolver
from ..linalg.saddle import SaddleSolver
from ..options import SolverKind, SolverSpec


def augmentation(spec: SolverSpec, e_max: float, h: float) -> float:
    """Gamma of A00 = K + gamma B^T B: E_max / h^2 for a fieldsplit (scales as K), else 0."""
    return e_max / h**2 if spec.augmented else 0.0


def make_solver(
    spec: SolverSpec,
    K: PETSc.Mat,
    B: PETSc.Mat,
    f: PETSc.Vec,
    *,
    e_max: float,
    h: float,
    modes: Callable[[], list[PETSc.Vec]],
    node_dofs: np.ndarray,
    reuse: bool = True,
) -> LinearSolver:
    """The solver `spec` asks for, on K, B (this rank's rows) and f.

    `modes()`: the rigid-body modes (called only by the solvers that use GAMG on the
    displacements); `node_dofs` (m, 2): the dofs of each multiplier row's active node (the
    condensed solver's pivots); `reuse` False: a throwaway solver for one set.
    """
    if spec.kind.condensed:
        factorized = spec.kind is SolverKind.CONDENSED_DIRECT
        return CondensedSolver(
            K,
            B,
            f,
            spec.petsc,
            node_dofs,
            [] if factorized else modes(),
            rtol=spec.rtol,
            loose_rtol=spec.loose_rtol,
            reuse=reuse,
            # A kept Cholesky factorization pays per CG iteration (one back-substitution):
            # the cost rule of the saddle-point solver decides when to refactor.
            policy=FactorizationPolicy(reuse) if factorized else None,
        )
    nullspace = None
    if spec.augmented:
        vectors = modes()
        nullspace = near_nullspace(vectors)
        for v in vectors:
            v.destroy()
    direct = spec.kind is SolverKind.DIRECT
    return SaddleSolver(
        K,
        B,
        f,
        spec.petsc,
        direct=direct,
        gamma=augmentation(spec, e_max, h),
        nullspace=nullspace,
        policy=FactorizationPolicy(reuse) if direct else None,
        fieldsplit=spec.kind is SolverKind.FIELDSPLIT,
        # PETSc then asks the code for the Schur preconditioning matrix: -I/gamma.
        schur_user=spec.petsc.get("pc_fieldsplit_schur_precondition") == "user",
    )
