"""Penalty baseline: the mortar gap operator enforced by a normal stiffness, no multipliers.

With the mortar operator row j gives the weighted gap g~_j = gap_j + B_j u = int N_j g dGamma
and the weight w_j = int N_j dGamma, so g_j = g~_j / w_j is a nodal gap (cm). The penalty
energy 1/2 sum_{j in A} eps w_j g_j^2 = 1/2 sum_A eps g~_j^2 / w_j over the penetrating nodes A
gives the stiffness K + eps B_A^T W^-1 B_A and the nodal contact traction p_j = -eps g_j
(MPa): eps is a normal stiffness per unit area (MPa/cm), independent of the mesh size, and a
uniform pressure p is carried with the uniform penetration p / eps. The set A is found by the
same semi-smooth Newton (active-set) loop on the sign of the gap as the multiplier methods.
"""

from __future__ import annotations

import logging
import time

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from .coupling import global_dirichlet_dofs, petsc_constraint
from .errors import ActiveSetError, InputError, SolverError
from .methods import Method
from .problem import ActiveSetOptions, Solution, _gather, prepare_contact
from .saddle import SOLVERS, _reason_name, petsc_error_message, petsc_options, uses_augmentation
from .scenes import Scene
from .timers import Timers

log = logging.getLogger("contactfx")

DEFAULT_FACTOR = 1e3
"""Default eps = DEFAULT_FACTOR * max(E1, E2) / h, h the median active-surface element size."""


def default_penalty(scene: Scene, h: float) -> float:
    """The default normal stiffness eps (MPa/cm): 1e3 times the stiffer body's E over h."""
    return DEFAULT_FACTOR * max(m.E for m in scene.materials) / h


def _solve(K: PETSc.Mat, B: PETSc.Mat, f: PETSc.Vec, g: np.ndarray, coef: np.ndarray,
           options: dict[str, object], condition: bool, check: bool = True
           ) -> tuple[np.ndarray, dict[str, float]]:
    """Solve (K + B^T diag(coef) B) u = f - B^T diag(coef) g; coef = eps / w on active rows."""
    d = B.createVecLeft()
    d.array[:] = np.sqrt(coef)
    BA = B.copy()
    BA.diagonalScale(L=d)
    BAT = PETSc.Mat()
    BA.transpose(BAT)
    A = BAT.matMult(BA)
    A.axpy(1.0, K, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    rhs = f.copy()
    d.array[:] = -coef * g
    tmp = rhs.duplicate()
    B.multTranspose(d, tmp)
    rhs.axpy(1.0, tmp)
    x = rhs.duplicate()
    ksp = PETSc.KSP().create(K.getComm())
    ksp.setOperators(A)
    info: dict[str, float] = {}
    try:
        with petsc_options(options) as prefix:
            ksp.setOptionsPrefix(prefix)
            ksp.setFromOptions()
            if condition:
                ksp.setComputeSingularValues(True)
            ksp.setUp()
            ksp.solve(rhs, x)
        reason, its = ksp.getConvergedReason(), ksp.getIterationNumber()
        if condition and its > 0:
            smax, smin = ksp.computeExtremeSingularValues()
            info["condition"] = float(smax / smin) if smin > 0 else float("inf")
        ok = reason > 0 and np.isfinite(x.norm())
        u = x.array.copy()
        ksp_type = ksp.getType()
    except PETSc.Error as err:
        raise SolverError(petsc_error_message(err, "penalty solve")) from None
    finally:
        for obj in (ksp, A, BA, BAT, rhs, tmp, x, d):
            obj.destroy()
    info["converged"] = float(ok)
    if check and not ok:
        raise SolverError(f"linear solve ({ksp_type}) did not converge: PETSc reason {reason} "
                          f"({_reason_name(reason)}) after {its} iterations")
    info["linear_iterations"] = its
    return u, info


def solve_penalty(scene: Scene, penalty: float | None = None,
                  solver: str | dict[str, object] = "mumps",
                  aso: ActiveSetOptions | None = None, timers: Timers | None = None,
                  condition: bool = False) -> Solution:
    """Solve the unilateral contact of `scene` by the penalty method on the mortar gap."""
    options = SOLVERS[solver] if isinstance(solver, str) else solver
    aso = aso or ActiveSetOptions()
    if uses_augmentation(options):
        raise InputError("the penalty method has no multiplier block: use the mumps solver or "
                         "single-field PETSc options, not a fieldsplit")
    timers = timers or Timers()
    comm = scene.mesh.comm
    setup = prepare_contact(scene, Method.PENALTY.operator, aso, timers)
    el, B, g, w, h = setup.elasticity, setup.B, setup.g, setup.w, setup.h
    V = el.V
    eps = default_penalty(scene, h) if penalty is None else float(penalty)
    if not (np.isfinite(eps) and eps > 0):
        raise InputError(f"the penalty parameter must be a positive number (got {eps})")
    # A penalty enforces g >= 0 only approximately: a node is in contact when its gap is
    # negative (penetration), with the same round-off margin as the multiplier methods.
    active = setup.initial_active(aso.penetration_tol * h)
    seen: set[bytes] = set()
    history: list[dict[str, float]] = []
    u = fem.Function(V, name="u")
    gap_u = g / w
    entered = left = 0
    for it in range(1, aso.max_iterations + 1):
        n_active = comm.allreduce(int(active.sum()))
        setup.check_not_floating(n_active)
        key = _gather(comm, active).tobytes()
        if key in seen:
            raise ActiveSetError(f"active set cycles at iteration {it} ({n_active} active nodes)")
        seen.add(key)
        t0 = time.perf_counter()
        with timers("solve"):
            x, info = _solve(el.K, B, el.f, g, np.where(active, eps / w, 0.0), options,
                             condition)
        t_solve = time.perf_counter() - t0
        u.x.petsc_vec.array[:] = x
        u.x.scatter_forward()
        gap_u = setup.normalized_gap(u)
        new_active = gap_u < 0.0
        entered = comm.allreduce(int(np.sum(new_active & ~active)))
        left = comm.allreduce(int(np.sum(active & ~new_active)))
        pen = comm.allreduce(float(np.max(-gap_u, initial=0.0)), op=MPI.MAX)
        history.append({"iteration": it, "active": n_active, "entered": entered, "left": left,
                        "penetration": max(pen, 0.0), "penalty": eps, "solve_time": t_solve,
                        **info})
        if comm.rank == 0:
            log.info("penalty active set %2d: %5d active, +%d -%d, max penetration %.3e cm, "
                     "%d linear its, %.3f s", it, n_active, entered, left, max(pen, 0.0),
                     info["linear_iterations"], t_solve)
        if entered == 0 and left == 0:
            break
        active = new_active
    else:
        raise ActiveSetError(f"active set did not converge in {aso.max_iterations} iterations "
                             f"(last change: +{entered} -{left})")
    return setup.solution(Method.PENALTY, u, -eps * gap_u, gap_u, active, history, timers)


def penetration(sol: Solution) -> float:
    """Largest penetration (max negative gap, cm) over the contact nodes; 0 if none."""
    return float(max(-sol.gap.min(initial=0.0), 0.0))


def condition_estimate(sol: Solution, eps: float, max_it: int = 20000,
                       rtol: float = 1e-10) -> dict[str, float]:
    """CG + Jacobi on the converged penalty matrix: Lanczos condition estimate and iterations."""
    el = sol.elasticity
    V = el.V
    B = petsc_constraint(V, sol.operator, sol.order, sol.layout,
                         global_dirichlet_dofs(V, el.bc_dofs))
    mine = sol.layout.mine
    w, g = sol.layout.weights[mine], sol.operator.gap[sol.order][mine]
    options = {"ksp_type": "cg", "pc_type": "jacobi", "ksp_rtol": rtol, "ksp_max_it": max_it,
               "ksp_norm_type": "unpreconditioned"}
    try:
        # If CG stops at max_it the Lanczos estimate so far is a lower bound ("converged" 0).
        _, info = _solve(el.K, B, el.f, g, np.where(sol.active[mine], eps / w, 0.0), options,
                         condition=True, check=False)
    finally:
        B.destroy()
    return info
