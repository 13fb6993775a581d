"""The saddle-point solve [[K, B^T], [B, C]] [u; mu] = [f; -g] through a PETSc MatNest."""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
from petsc4py import PETSc

from .errors import SolverError

SOLVERS: dict[str, dict[str, object]] = {
    # MUMPS LU directly on the MatNest (PETSc converts it): the robust reference.
    "mumps": {
        "ksp_type": "preonly",
        "pc_type": "lu",
        "pc_factor_mat_solver_type": "mumps",
    },
    # Schur-complement fieldsplit, A00 = K + gamma B^T B factorized by MUMPS, S by Jacobi-GMRES.
    "fieldsplit": {
        "ksp_type": "fgmres",
        "ksp_rtol": 1e-12,
        "ksp_atol": 1e-14,
        "ksp_max_it": 200,
        "pc_type": "fieldsplit",
        "pc_fieldsplit_type": "schur",
        "pc_fieldsplit_schur_fact_type": "full",
        "pc_fieldsplit_schur_precondition": "selfp",
        "fieldsplit_u_ksp_type": "preonly",
        "fieldsplit_u_pc_type": "lu",
        "fieldsplit_u_pc_factor_mat_solver_type": "mumps",
        "fieldsplit_lambda_ksp_type": "gmres",
        "fieldsplit_lambda_ksp_rtol": 1e-12,
        "fieldsplit_lambda_ksp_max_it": 500,
        "fieldsplit_lambda_pc_type": "jacobi",
    },
    # Iterative A00 for large meshes: one GAMG V-cycle per application.
    "fieldsplit-gamg": {
        "ksp_type": "fgmres",
        "ksp_rtol": 1e-10,
        "ksp_max_it": 1000,
        "ksp_gmres_restart": 200,
        "pc_type": "fieldsplit",
        "pc_fieldsplit_type": "schur",
        "pc_fieldsplit_schur_fact_type": "full",
        "pc_fieldsplit_schur_precondition": "selfp",
        "fieldsplit_u_ksp_type": "preonly",
        "fieldsplit_u_pc_type": "gamg",
        "fieldsplit_lambda_ksp_type": "preonly",
        "fieldsplit_lambda_pc_type": "jacobi",
    },
}

_counter = itertools.count()


@contextmanager
def petsc_options(options: dict[str, object]) -> Iterator[str]:
    """Set `options` under a fresh unique prefix and remove them afterwards."""
    prefix = f"contactfx_{next(_counter)}_"
    db = PETSc.Options()
    for key, value in options.items():
        db[prefix + key] = value
    try:
        yield prefix
    finally:
        for key in options:
            db.delValue(prefix + key)


def uses_augmentation(options: dict[str, object]) -> bool:
    """True if the options ask for a fieldsplit, whose A00 must be invertible on its own."""
    return options.get("pc_type") == "fieldsplit"


@dataclass
class SaddleResult:
    """Solution blocks (owned parts) and what the Krylov solver reported."""

    u: np.ndarray
    mu: np.ndarray
    iterations: int
    reason: int
    info: dict[str, object] = field(default_factory=dict)


def solve_saddle(K: PETSc.Mat, B: PETSc.Mat, f: PETSc.Vec, g: np.ndarray, active: np.ndarray,
                 options: dict[str, object], gamma: float = 0.0) -> SaddleResult:
    """Solve for (u, mu) with the rows of `active` enforced as equalities and mu = 0 elsewhere."""
    comm = K.getComm()
    m = B.getLocalSize()[0]
    act = PETSc.Vec().createMPI((m, PETSc.DETERMINE), comm=comm)
    act.array[:] = active.astype(float)
    BA = B.copy()
    BA.diagonalScale(L=act)
    BAT = PETSc.Mat()
    BA.transpose(BAT)
    C = PETSc.Mat().createAIJ(size=((m, PETSc.DETERMINE), (m, PETSc.DETERMINE)), nnz=1, comm=comm)
    C.setUp()
    r0 = BA.getOwnershipRange()[0]
    for i in range(m):
        C.setValue(r0 + i, r0 + i, 0.0 if active[i] else 1.0)
    C.assemble()
    A00 = K
    rhs_u = f.copy()
    if gamma > 0.0:
        # Augmented Lagrangian: adding gamma B^T (B u + g) = 0 makes A00 invertible when a body
        # is held only by contact, and leaves the solution unchanged.
        A00 = BAT.matMult(BA)
        A00.scale(gamma)
        A00.axpy(1.0, K, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        gv = act.duplicate()
        gv.array[:] = -gamma * g * active
        tmp = rhs_u.duplicate()
        BAT.mult(gv, tmp)
        rhs_u.axpy(1.0, tmp)
    A = PETSc.Mat().createNest([[A00, BAT], [BA, C]], comm=comm)
    A.assemble()
    is_u, is_l = A.getNestISs()[0]
    b = A.createVecRight()
    x = A.createVecRight()
    for iset, values in ((is_u, rhs_u.array_r), (is_l, np.where(active, -g, 0.0))):
        sub = b.getSubVector(iset)
        sub.array[:] = values
        b.restoreSubVector(iset, sub)

    ksp = PETSc.KSP().create(comm)
    ksp.setOperators(A)
    with petsc_options(options) as prefix:
        ksp.setOptionsPrefix(prefix)
        pc = ksp.getPC()
        if options.get("pc_type") == "fieldsplit":
            pc.setType("fieldsplit")
            pc.setFieldSplitIS(("u", is_u), ("lambda", is_l))
        ksp.setFromOptions()
        ksp.setUp()
        ksp.solve(b, x)
    reason = ksp.getConvergedReason()
    its = ksp.getIterationNumber()
    ok = reason > 0 and np.isfinite(x.norm())
    if ok:
        u_sub, l_sub = x.getSubVector(is_u), x.getSubVector(is_l)
        u, mu = u_sub.array.copy(), l_sub.array.copy()
        x.restoreSubVector(is_u, u_sub)
        x.restoreSubVector(is_l, l_sub)
    ksp_type = ksp.getType()
    for obj in (ksp, A, C, BA, BAT, b, x, act, rhs_u):
        obj.destroy()
    if A00 is not K:
        A00.destroy()
    if not ok:
        raise SolverError(f"linear solve ({ksp_type}) did not converge: PETSc reason {reason} "
                          f"({_reason_name(reason)}) after {its} iterations")
    return SaddleResult(u, mu, its, reason)


def _reason_name(reason: int) -> str:
    names = {v: k for k, v in vars(PETSc.KSP.ConvergedReason).items() if isinstance(v, int)}
    return names.get(reason, "unknown")
