"""Alternating Dirichlet-Neumann (Schwarz) iteration between the two bodies, mortar transfer.

The body held only by contact (D) takes the Dirichlet data: its interface normal
displacement is prescribed, which fixes its rigid motion along the normal, so its subproblem
is well posed whatever the iterate. The body held by its supports (N) takes the Neumann
data: the interface force D exerts on it. The transfer uses the mortar matrices of the pair
(slave D, master N): u2_n = D^-1 (M u1_n - g~) and, for the traction lambda = D^-1 R2 of
B2's reaction R2, the force on B1 is -M^T lambda, so no force is lost across non-matching
meshes. The fixed point satisfies exactly the equations of the mortar Lagrange-multiplier
method with D active (full contact): the iteration is an independent solver for them.

`solve_schwarz` runs four steps: which body takes which data (`_roles`), the mortar transfer
between them (`_transfer`), the relaxed iteration (`_iterate`) and the multipliers on the
pair's active side (`_report`).
"""

from __future__ import annotations

import logging
import time
from typing import TYPE_CHECKING, Any

import numpy as np
from dolfinx import fem
from mpi4py import MPI

if TYPE_CHECKING:
    import scipy.sparse as sp

from ..contact import Kernel, contact_operator
from ..contact.mortar import mortar_matrices
from ..discretize.coupling import multiplier_layout
from ..discretize.elasticity import Elasticity
from ..discretize.pairs import PairData
from ..discretize.setup import assemble_and_gather
from ..discretize.supports import check_held
from ..discretize.surfaces import GatheredSurface
from ..errors import ConvergenceError, GeometryError, InputError
from ..options import Method
from ..request import SchwarzOptions, SolveRequest
from ..scenes import Scene
from ..timers import Timers
from .schwarz_sweep import OwnedNodes, Roles, Sweep, Transfer
from .solution import Fields, History, Solution, pair_views

log = logging.getLogger("contactfx")

# Largest angle (as |1 - |n_y||) between a contact-segment normal and the vertical: the
# Dirichlet condition is set on u_y, which is the normal component only on a flat interface.
_FLAT_TOL = 1e-10


def _check_flat(s1: GatheredSurface, s2: GatheredSurface) -> None:
    """Raise unless both contact lines are horizontal and face each other."""
    sign = float(np.sign(s1.surface.normals[0, 1]))
    for gs, sg in ((s1, sign), (s2, -sign)):
        ny = gs.surface.normals[:, 1]
        if sg == 0.0 or np.any(np.abs(sg * ny - 1.0) > _FLAT_TOL):
            raise InputError(
                "schwarz supports one straight horizontal contact line in full "
                "contact (it iterates on u_y): use nts, sts or mortar here"
            )


def _norm(D: sp.csr_matrix, v: np.ndarray) -> float:
    """Discrete L2 norm on the interface, sqrt(v^T D v)."""
    return float(np.sqrt(max(v @ (D @ v), 0.0)))


def _failed(history: History, message: str) -> ConvergenceError:
    """The error to raise, carrying the iteration history (for charts of failed runs)."""
    err = ConvergenceError(message)
    err.history = history
    return err


def _roles(scene: Scene, el: Elasticity, gathered: list[Any]) -> Roles:
    """Check the scene is a two-body full-contact one; pick the Dirichlet body."""
    pair, body_a, body_p, surf_act, surf_pas = gathered[0]
    loose = check_held(scene, el.V, el.bc_dofs, [(body_a, body_p, surf_act)])
    if len(loose) != 1:
        raise InputError(
            "schwarz needs one body held by its supports and one held only by "
            f"the contact ({'both are' if loose else 'neither is'} free): use "
            "nts, sts or mortar"
        )
    if loose[0] == body_a:
        surf1, surf2, bodies = surf_pas, surf_act, (body_p, body_a)
    else:
        surf1, surf2, bodies = surf_act, surf_pas, (body_a, body_p)
    _check_flat(surf1, surf2)
    return Roles(pair, body_a, body_p, surf_act, surf_pas, loose[0], surf1, surf2, bodies)


def _transfer(r: Roles, ndofs: int, comm: MPI.Comm) -> Transfer:
    """The mortar matrices of the pair with the Dirichlet body as slave, and the layout."""
    # The unmodified basis (ends=False): the transfer maps the whole interface, every node
    # with its own row, and the full-contact check needs no corner treatment.
    op2 = contact_operator(Kernel.MORTAR, r.surf2.surface, r.surf1.surface, ndofs, ends=False)
    D_all, M_all = mortar_matrices(r.surf2.surface, r.surf1.surface, ends=False)
    keep = np.flatnonzero(op2.overlapping)
    if keep.size == 0:
        raise GeometryError(
            f"the contact surfaces '{r.pair.active}' and '{r.pair.passive}' do not overlap"
        )
    D = D_all[keep][:, keep].tocsc()
    M = M_all[keep].tocsr()
    y1, y2 = r.surf1.surface.x[:, 1], r.surf2.surface.x[:, 1]
    wgap = D @ y2[keep] - M @ y1
    h = float(np.median(op2.weights[keep]))
    if np.max(np.abs(wgap / op2.weights[keep])) > 1e-6 * h:
        raise InputError(
            "schwarz supports full-contact scenes only: the bodies do not "
            "touch along the whole contact line (non-zero initial gap)"
        )
    # The reported multipliers live on the pair's active body, as for the other methods.
    if r.dirichlet == r.body_a:
        surf_a, op = r.surf2, op2
    else:
        surf_a = r.surf1
        op = contact_operator(Kernel.MORTAR, r.surf1.surface, r.surf2.surface, ndofs, ends=False)
    layout, order = multiplier_layout(comm, surf_a, op)
    import scipy.sparse.linalg as spla  # only where used (first-answer time: docs/scale.md)

    return Transfer(keep, D, M, spla.splu(D), wgap, op, layout, order)


def solve_schwarz(scene: Scene, request: SolveRequest, timers: Timers | None = None) -> Solution:
    """Solve a two-body full-contact scene by the relaxed Dirichlet-Neumann iteration.

    Body N (held by its supports) takes Neumann data, body D (held only by the contact)
    Dirichlet data; the contact line must be straight, horizontal and closed everywhere.
    The transfer is the mortar discretization's (the request's, which only mortar passes);
    `request.schwarz_options` are the iteration's controls.
    """
    options = request.schwarz_options
    if scene.obstacles:
        raise InputError(
            "schwarz does not take rigid obstacles ([[obstacle]]): use nts, sts, mortar or penalty"
        )
    if len(scene.bodies) != 2 or len(scene.contacts) != 1:
        raise InputError(
            f"schwarz supports two bodies with one contact pair (this scene has "
            f"{len(scene.bodies)} bodies and {len(scene.contacts)} pairs): use "
            "nts, sts or mortar"
        )
    if any(p.interference is not False for p in scene.contacts):
        raise InputError(
            "schwarz does not take interference fits (interference on a [[contact]]): "
            "use nts, sts, mortar or penalty"
        )
    timers = timers or Timers()
    el, ndofs, gathered = assemble_and_gather(scene, timers)
    roles = _roles(scene, el, gathered)
    with timers("contact"):
        tr = _transfer(roles, ndofs, scene.comm)
    u = fem.Function(el.V, name="u")
    lam, history = _iterate(scene, el, roles, tr, u, options, timers)
    return _report(scene, el, roles, tr, u, lam, history, ndofs, timers)


def _iterate(
    scene: Scene,
    el: Elasticity,
    roles: Roles,
    tr: Transfer,
    u: fem.Function,
    options: SchwarzOptions,
    timers: Timers,
) -> tuple[np.ndarray, History]:
    """The relaxed (Aitken) fixed-point iteration on B2's interface u_y: (traction, history)."""
    comm, D = scene.comm, tr.D
    history: History = []
    t_solve = time.perf_counter()
    with timers("solve"), timers("factorize"):
        sweep = Sweep(scene, el, roles, tr, u)
    d = np.zeros(tr.keep.size)  # B2's interface u_y, the iterated quantity
    lam_prev: np.ndarray | None = None
    r_prev, omega, r_first = None, options.relaxation, None
    aitken = "on" if options.aitken else "off"
    try:
        for it in range(1, options.max_iterations + 1):
            t0 = time.perf_counter()
            with timers("solve"):
                lam, u1 = sweep.step(d)
            target = tr.D_lu.solve(tr.M @ u1 - tr.wgap)
            r = target - d
            e_u = _norm(D, r) / max(_norm(D, target), 1e-300)
            e_t = (
                np.inf
                if lam_prev is None
                else _norm(D, lam - lam_prev) / max(_norm(D, lam), 1e-300)
            )
            if it > 1 and options.aitken and r_prev is not None:
                dr = r - r_prev
                omega = -omega * float(r_prev @ (D @ dr)) / max(float(dr @ (D @ dr)), 1e-300)
            history.append(
                {
                    "iteration": it,
                    "residual": e_u,
                    "traction_change": None if lam_prev is None else e_t,
                    "relaxation": omega,
                    "solve_time": time.perf_counter() - t0,
                }
            )
            if comm.rank == 0:
                log.info(
                    "schwarz %3d: interface residual %.3e, traction change %.3e, relaxation %.4f",
                    it,
                    e_u,
                    e_t,
                    omega,
                )
            r_abs = _norm(D, r)
            r_first = r_first or max(r_abs, 1e-300)
            if max(e_u, e_t) < options.tol:
                break
            if not np.isfinite(r_abs) or r_abs > options.divergence * r_first:
                raise _failed(
                    history,
                    f"schwarz iteration diverged at iteration {it}: interface residual grew "
                    f"by {r_abs / r_first:.1e} (relaxation {omega:.3g}, Aitken {aitken})",
                )
            d = d + omega * r
            r_prev, lam_prev = r, lam
        else:
            raise _failed(
                history,
                f"schwarz iteration did not converge in {options.max_iterations} iterations: "
                f"interface residual {e_u:.2e}, traction change {e_t:.2e} > tol "
                f"{options.tol:.0e} (relaxation {omega:.3g}, Aitken {aitken})",
            )
    finally:
        sweep.destroy()
    u.x.scatter_forward()
    if comm.rank == 0:
        log.info(
            "schwarz converged in %d iterations, %.3f s",
            len(history),
            time.perf_counter() - t_solve,
        )
    return lam, history


def _report(
    scene: Scene,
    el: Elasticity,
    r: Roles,
    tr: Transfer,
    u: fem.Function,
    lam: np.ndarray,
    history: History,
    ndofs: int,
    timers: Timers,
) -> Solution:
    """The multipliers on the pair's active side, the gap, and the Solution."""
    comm, order, layout, op = scene.comm, tr.order, tr.layout, tr.op
    lam2 = np.zeros(r.surf2.surface.n_nodes)
    lam2[tr.keep] = lam
    if r.dirichlet == r.body_a:
        pressure = lam2[order]
    else:
        # Same force on B1's nodes, expressed as the traction of B1's own mortar multipliers.
        Da, _ = mortar_matrices(r.surf1.surface, r.surf2.surface, ends=False)
        force = tr.M.T @ lam
        import scipy.sparse.linalg as spla  # only where used: docs/scale.md

        pressure = np.atleast_1d(spla.spsolve(Da[order][:, order].tocsc(), force[order]))
    if np.any(pressure < -1e-8 * np.abs(pressure).max(initial=0.0)) and comm.rank == 0:
        log.warning(
            "schwarz: tensile contact traction (min %.3g MPa): the full-contact "
            "assumption does not hold for this scene",
            pressure.min(),
        )
    # Gap at the solution through the reported operator (both components of both surfaces).
    ufull = np.zeros(ndofs)
    for gs in (r.surf1, r.surf2):
        nodes = OwnedNodes(gs, el.V)
        for comp in (0, 1):
            ufull[gs.surface.dofs[:, comp]] = nodes.read(u.x.array, comp)
    gap = (op.gap + op.B @ ufull)[order] / layout.weights
    pd = PairData(0, r.pair, r.body_a, r.body_p, r.surf_act, r.surf_pas, op, 0)
    return Solution(
        scene,
        Method.SCHWARZ,
        Fields(el.V, u, el.E, el.nu),
        layout,
        pressure=pressure,
        gap=gap,
        active=np.ones(layout.size, dtype=bool),
        pairs=pair_views([pd], layout, op.B, order),
        history=history,
        timers=timers,
        schwarz_dirichlet_body=r.dirichlet.name,
    )
