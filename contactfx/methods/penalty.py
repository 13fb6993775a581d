"""Penalty baseline: a contact gap operator enforced by a normal stiffness, no multipliers.

On any discretization (nts, sts, mortar: the weights w_j of its rows; the mortar operator
below) row j gives the weighted gap g~_j = gap_j + B_j u = int N_j g dGamma
and the weight w_j = int N_j dGamma, so g_j = g~_j / w_j is a nodal gap (cm). The penalty
energy 1/2 sum_{j in A} eps w_j g_j^2 = 1/2 sum_A eps g~_j^2 / w_j over the penetrating nodes A
gives the stiffness K + eps B_A^T W^-1 B_A and the nodal contact traction p_j = -eps g_j
(MPa): eps is a normal stiffness per unit area (MPa/cm), independent of the mesh size, and a
uniform pressure p is carried with the uniform penetration p / eps. The set A is found by the
same semi-smooth Newton (active-set) loop on the sign of the gap as the multiplier methods.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import cast

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..discretize.setup import ContactSetup, prepare_contact
from ..errors import SolverError
from ..linalg.petsc_options import petsc_error_message, petsc_options, reason_name
from ..request import SolveRequest
from ..scenes import Scene
from ..timers import Timers
from .active_set import ActiveSetOptions, Proposal, Step, run_active_set
from .cleanup import released
from .solution import PenaltyResult, Solution, finish
from .solvers import with_ordering

DEFAULT_FACTOR = 1e3
"""Default eps = DEFAULT_FACTOR * max E / h, h the median active-surface element size."""


# The stub types the Structure values as int but the parameter as Structure.
DIFFERENT = cast(PETSc.Mat.Structure, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)


def default_penalty(e_max: float, h: float) -> float:
    """The default normal stiffness eps (MPa/cm): 1e3 times the stiffer body's E over h."""
    return DEFAULT_FACTOR * e_max / h


@dataclass(frozen=True)
class ConditionOptions:
    """CG + Jacobi on the converged penalty matrix: its Lanczos condition estimate."""

    max_it: int = 20000
    rtol: float = 1e-10


def scaled_rows(B: PETSc.Mat, coef: np.ndarray) -> PETSc.Mat:
    """diag(coef) B: a copy of B with each owned row scaled."""
    d = B.createVecLeft()
    d.array[:] = coef
    out = B.copy()
    out.diagonalScale(L=d)
    d.destroy()
    return out


def add_product(A: PETSc.Mat | None, BT: PETSc.Mat, C: PETSc.Mat) -> PETSc.Mat:
    """A + BT C (BT C itself if A is None); the product is freed."""
    P = BT.matMult(C)
    if A is None:
        return P
    A.axpy(1.0, P, structure=DIFFERENT)
    P.destroy()
    return A


def transposed(B: PETSc.Mat) -> PETSc.Mat:
    """B^T as a new matrix."""
    BT = PETSc.Mat()
    B.transpose(BT)
    return BT


def _solve(
    K: PETSc.Mat,
    B: PETSc.Mat,
    f: PETSc.Vec,
    g: np.ndarray,
    coef: np.ndarray,
    options: Mapping[str, object],
    condition: bool,
    check: bool = True,
) -> tuple[np.ndarray, dict[str, float]]:
    """Solve (K + B^T diag(coef) B) u = f - B^T diag(coef) g; coef = eps / w on active rows."""
    BT = transposed(B)
    BA = scaled_rows(B, coef)
    A = add_product(None, BT, BA)
    A.axpy(1.0, K, structure=DIFFERENT)
    rhs = f.copy()
    d = B.createVecLeft()
    d.array[:] = -coef * g
    tmp = rhs.duplicate()
    BT.mult(d, tmp)
    rhs.axpy(1.0, tmp)
    with released(K.getComm().tompi4py(), BA, BT, tmp, d):
        return factor_solve(A, rhs, options, condition, check)


def factor_solve(
    A: PETSc.Mat,
    rhs: PETSc.Vec,
    options: Mapping[str, object],
    condition: bool = False,
    check: bool = True,
) -> tuple[np.ndarray, dict[str, float]]:
    """Solve A u = rhs with the request's PETSc options (A and rhs are freed)."""
    x = rhs.duplicate()
    ksp = PETSc.KSP().create(A.getComm())
    ksp.setOperators(A)
    info: dict[str, float] = {}
    with released(A.getComm().tompi4py(), ksp, A, rhs, x):
        try:
            with petsc_options(with_ordering(options, A.getSize()[0])) as prefix:
                ksp.setOptionsPrefix(prefix)
                ksp.setFromOptions()
                if condition:
                    ksp.setComputeSingularValues(True)
                ksp.setUp()
                ksp.solve(rhs, x)
            # getConvergedReason() returns an int; the stub says the enum class.
            reason, its = cast(int, ksp.getConvergedReason()), ksp.getIterationNumber()
            if condition and its > 0:
                smax, smin = ksp.computeExtremeSingularValues()
                info["condition"] = float(smax / smin) if smin > 0 else float("inf")
            ok = reason > 0 and np.isfinite(x.norm())
            u = x.array.copy()
            ksp_type = ksp.getType()
        except PETSc.Error as err:
            raise SolverError(petsc_error_message(err, "penalty solve")) from None
    info["converged"] = float(ok)
    if check and not ok:
        raise SolverError(
            f"linear solve ({ksp_type}) did not converge: PETSc reason {reason} "
            f"({reason_name(reason)}) after {its} iterations"
        )
    info["linear_iterations"] = its
    return u, info


class PenaltyIteration:
    """Solves of K + eps B_A^T W^-1 B_A on a set A; the update is the penetrating nodes."""

    label = "penalty active set"
    probing = False

    def __init__(
        self, setup: ContactSetup, eps: float, options: Mapping[str, object], condition: bool
    ) -> None:
        self.setup, self.eps, self.options, self.condition = setup, eps, options, condition
        self.u = fem.Function(setup.elasticity.V, name="u")

    def solve(self, active: np.ndarray, it: int) -> Step:
        """One penalty solve with `active` penalized."""
        setup, el = self.setup, self.setup.elasticity
        comm = setup.comm
        x, info = _solve(
            el.K,
            setup.B,
            el.f,
            setup.g,
            np.where(active, self.eps / setup.w, 0.0),
            self.options,
            self.condition,
        )
        self.u.x.petsc_vec.array[:] = x
        self.u.x.scatter_forward()
        gap = setup.normalized_gap(self.u)
        pen = max(comm.allreduce(float(np.max(-gap, initial=0.0)), op=MPI.MAX), 0.0)
        text = f"max penetration {pen:.3e}, {int(info['linear_iterations'])} linear its, "
        # A penalty enforces g >= 0 only approximately: a node is in contact when its gap is
        # negative (penetration); there is no complementarity residual to check.
        return Step(
            -self.eps * gap,
            gap,
            gap < 0.0,
            0.0,
            {"penetration": pen, "penalty": self.eps, **info},
            text,
        )

    def next_set(self, active: np.ndarray, step: Step, entered: int) -> Proposal | None:
        """Always the plain update."""
        return None


def solve_penalty(
    scene: Scene,
    request: SolveRequest,
    timers: Timers | None = None,
    *,
    aso: ActiveSetOptions | None = None,
    condition: ConditionOptions | None = None,
) -> Solution:
    """Solve the unilateral contact of `scene` by the penalty method on the request's gap.

    Any discretization's operator serves (nts, sts or mortar: `request.kernel`); the
    request's solver is a factorization (SolveRequest refuses the others). `condition`: also
    estimate the condition number of the converged penalty matrix.
    """
    aso = aso or ActiveSetOptions(request.max_iterations)
    timers = timers or Timers()
    setup = prepare_contact(scene, request.kernel, aso.penetration_tol, timers)
    with released(scene.comm, setup):
        eps = default_penalty(setup.e_max, setup.h) if request.penalty is None else request.penalty
        iteration = PenaltyIteration(setup, eps, request.solver.petsc, False)
        active = setup.initial_active(aso.penetration_tol * setup.h)
        step, active, history = run_active_set(setup, iteration, active, aso, timers)
        estimate = None if condition is None else _condition(setup, eps, active, condition)
        sol = finish(
            setup, request.method, scene, iteration.u, step.lam, step.gap, active, history, timers
        )
    sol.penalty = PenaltyResult(eps, penetration(sol), estimate)
    return sol


def penetration(sol: Solution) -> float:
    """Largest penetration (max negative gap, cm) over the contact nodes; 0 if none."""
    return float(max(-sol.gap.min(initial=0.0), 0.0))


def _condition(
    setup: ContactSetup, eps: float, active: np.ndarray, opts: ConditionOptions
) -> dict[str, float]:
    """CG + Jacobi on the converged penalty matrix: Lanczos condition estimate and iterations.

    If CG stops at max_it the estimate so far is a lower bound ("converged" 0).
    """
    el = setup.elasticity
    options = {
        "ksp_type": "cg",
        "pc_type": "jacobi",
        "ksp_rtol": opts.rtol,
        "ksp_max_it": opts.max_it,
        "ksp_norm_type": "unpreconditioned",
    }
    coef = np.where(active, eps / setup.w, 0.0)
    _, info = _solve(el.K, setup.B, el.f, setup.g, coef, options, condition=True, check=False)
    return info
