"""Solve a contact scene: elasticity, contact operator, active-set loop over saddle-point solves."""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from .contact import ContactOperator, contact_operator
from .coupling import Multipliers, global_dirichlet_dofs, multiplier_layout, petsc_constraint
from .elasticity import Elasticity, assemble_elasticity
from .errors import ActiveSetError, GeometryError, InputError, SingularSystemError
from .methods import IMPLEMENTED, Method
from .saddle import SOLVERS, solve_saddle, uses_augmentation
from .scenes import Scene
from .surfaces import GatheredSurface, gather_surface
from .timers import Timers

log = logging.getLogger("contactfx")


@dataclass
class Solution:
    """Everything a run produces: the displacement, the multipliers and what it cost."""

    scene: Scene
    method: Method
    elasticity: Elasticity
    u: fem.Function
    layout: Multipliers
    pressure: np.ndarray       # (n,) contact traction per multiplier node, global order (MPa)
    gap: np.ndarray            # (n,) normalized gap (weighted gap / weight) at the solution (cm)
    active: np.ndarray         # (n,) bool, converged active set, global order
    operator: ContactOperator
    order: np.ndarray
    surfaces: tuple[GatheredSurface, GatheredSurface]
    iterations: int
    history: list[dict[str, float]] = field(default_factory=list)
    timers: Timers = field(default_factory=Timers)


@dataclass(frozen=True)
class ActiveSetOptions:
    """Controls of the primal-dual active-set iteration."""

    max_iterations: int = 50
    penetration_tol: float = 1e-6  # allowed initial penetration relative to the element size


def body_supported(el: Elasticity, scene: Scene, body: int) -> bool:
    """True if `body` has Dirichlet conditions on both displacement components."""
    msh = el.V.mesh
    cells = scene.cell_tags.find(scene.tags[f"body{body}"])
    blocks = np.unique(el.V.dofmap.list[cells].ravel())
    comps = set()
    in_body = np.isin(el.bc_dofs // 2, blocks)
    comps.update((el.bc_dofs[in_body] % 2).tolist())
    allcomps = set().union(*msh.comm.allgather(comps))
    return allcomps == {0, 1}


def _gather(comm: MPI.Comm, local: np.ndarray) -> np.ndarray:
    return np.concatenate(comm.allgather(np.asarray(local)))


def solve_contact(scene: Scene, method: Method, solver: str | dict[str, object] = "mumps",
                  aso: ActiveSetOptions = ActiveSetOptions(),
                  timers: Timers | None = None) -> Solution:
    """Solve the frictionless unilateral contact problem of `scene` with `method`."""
    if method not in IMPLEMENTED:
        raise InputError(f"method '{method.value}' is not implemented yet "
                         f"(available: {', '.join(sorted(m.value for m in IMPLEMENTED))})")
    options = SOLVERS[solver] if isinstance(solver, str) else solver
    timers = timers or Timers()
    comm = scene.mesh.comm
    with timers("assemble"):
        el = assemble_elasticity(scene)
    V = el.V
    ndofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    with timers("search"):
        surf_a = gather_surface(scene, V, scene.active)
        surf_p = gather_surface(scene, V, scene.passive)
    with timers("contact"):
        op = contact_operator(method.operator, surf_a.surface, surf_p.surface, ndofs)
        layout, order = multiplier_layout(comm, surf_a, op)
        if layout.size == 0:
            raise GeometryError(f"the active surface contact{scene.active} does not overlap the "
                                f"passive surface contact{scene.passive}")
        B = petsc_constraint(V, op, order, layout, global_dirichlet_dofs(V, el.bc_dofs))
    w_all = layout.weights
    g_all = op.gap[order] / w_all
    h = float(np.median(w_all))
    if g_all.min() < -aso.penetration_tol * h:
        j = int(np.argmin(g_all))
        raise GeometryError(f"initial penetration {-g_all[j]:.3e} cm at x = {layout.x[j, 0]:.4g} "
                            f"exceeds the tolerance {aso.penetration_tol * h:.1e} cm")
    mine = layout.mine
    w, g = w_all[mine], op.gap[order][mine]
    e_max = max(m.E for m in scene.materials)
    c = e_max / h
    gamma = e_max / h**2 if uses_augmentation(options) else 0.0
    needs_contact = [b for b in (1, 2) if not body_supported(el, scene, b)]

    active = g / w <= aso.penetration_tol * h
    if needs_contact and comm.allreduce(int(active.sum())) == 0 and layout.size:
        # A body held only by contact needs a first contact point: take the closest node(s).
        active = g / w <= g_all.min() + aso.penetration_tol * h
    seen: set[bytes] = set()
    history: list[dict[str, float]] = []
    u = fem.Function(V, name="u")
    lam = np.zeros(len(mine))
    for it in range(1, aso.max_iterations + 1):
        n_active = comm.allreduce(int(active.sum()))
        if n_active == 0 and needs_contact:
            raise SingularSystemError(
                f"body {needs_contact[0]} has no support in the load direction and no node in "
                "contact (empty active set): the load pulls the bodies apart")
        key = _gather(comm, active).tobytes()
        if key in seen:
            raise ActiveSetError(f"active set cycles at iteration {it} ({n_active} active nodes)")
        seen.add(key)
        t0 = time.perf_counter()
        with timers("solve"):
            res = solve_saddle(el.K, B, el.f, g, active, options, gamma)
        t_solve = time.perf_counter() - t0
        u.x.petsc_vec.array[:] = res.u
        u.x.scatter_forward()
        lam = -res.mu
        gap_u = np.empty(len(mine))
        ub = u.x.petsc_vec.copy()
        y = B.createVecLeft()
        B.mult(ub, y)
        gap_u[:] = (g + y.array_r) / w
        ub.destroy()
        y.destroy()
        new_active = lam - c * gap_u > 0
        ncp = np.where(active, np.minimum(lam, c * gap_u), np.minimum(0.0, c * gap_u))
        lam_max = comm.allreduce(float(np.abs(lam).max(initial=0.0)), op=MPI.MAX)
        resid = np.sqrt(comm.allreduce(float(np.sum(w * ncp**2)), op=MPI.SUM))
        resid /= max(lam_max * np.sqrt(comm.allreduce(float(w.sum()))), 1e-300)
        entered = comm.allreduce(int(np.sum(new_active & ~active)))
        left = comm.allreduce(int(np.sum(active & ~new_active)))
        history.append({"iteration": it, "active": n_active, "entered": entered, "left": left,
                        "residual": resid, "linear_iterations": res.iterations,
                        "solve_time": t_solve})
        if comm.rank == 0:
            log.info("active set %2d: %5d active, +%d -%d, complementarity %.2e, "
                     "%d linear its, %.3f s", it, n_active, entered, left, resid, res.iterations,
                     t_solve)
        if entered == 0 and left == 0:
            # PDAS is exact once the set is fixed: the residual left is solver round-off.
            break
        active = new_active
    else:
        raise ActiveSetError(f"active set did not converge in {aso.max_iterations} iterations "
                             f"(last change: +{entered} -{left})")
    B.destroy()
    return Solution(scene, method, el, u, layout,
                    pressure=_gather(comm, np.where(active, lam, 0.0)),
                    gap=_gather(comm, gap_u), active=_gather(comm, active), operator=op,
                    order=order, surfaces=(surf_a, surf_p) if scene.active == 1 else
                    (surf_p, surf_a), iterations=len(history), history=history, timers=timers)
