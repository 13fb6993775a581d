"""Solve a contact scene: elasticity, contact operator, active-set loop over saddle-point solves."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from .contact import ContactOperator, contact_operator
from .coupling import Multipliers, global_dirichlet_dofs, multiplier_layout, petsc_constraint
from .elasticity import Elasticity, assemble_elasticity
from .errors import ActiveSetError, GeometryError, InputError, SingularSystemError
from .methods import IMPLEMENTED, Method
from .nullspace import near_nullspace
from .saddle import SOLVERS, SaddleSolver, is_direct, reference_solve, uses_augmentation
from .scenes import Scene
from .surfaces import GatheredSurface, check_facing, gather_surface
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
    tolerance: float = 1e-6        # complementarity residual (relative) required at the end
    predictor: bool = True         # probe candidate sets with multi-RHS solves (direct solvers)
    max_probes: int = 2000         # largest candidate set probed


@dataclass(frozen=True)
class InitialSet:
    """A first active set by position: `active(x)` in contact, `uncertain(x)` worth probing.

    Both map (n, 2) node coordinates to (n,) bools. A superset of the converged set makes the
    loop factorize once and then only release rows (solved without refactoring); probing only
    the uncertain band keeps the multi-right-hand-side solve small.
    """

    active: Callable[[np.ndarray], np.ndarray]
    uncertain: Callable[[np.ndarray], np.ndarray] | None = None


def coarse_initial_set(coarse: Solution, margin: float = 1.5, band: float = 2.0
                       ) -> InitialSet:
    """An InitialSet from the solution of the same scene on a coarser mesh.

    In contact: nodes within `margin` coarse elements of a coarse active node; uncertain:
    those within `band` coarse elements of a coarse inactive node (the zone's edge, wider
    inwards: a coarse node-to-segment zone overshoots the fine one by up to two elements).
    The coarse element size is the largest node spacing in the coarse contact zone.
    """
    from scipy.spatial import cKDTree

    x = np.asarray(coarse.layout.x)[:, :2]
    act = np.asarray(coarse.active, dtype=bool)
    if not act.any():
        return InitialSet(lambda p: np.zeros(len(p), dtype=bool))
    spacing = cKDTree(x).query(x[act], k=2)[0][:, 1] if len(x) > 1 else np.zeros(1)
    r = margin * float(spacing.max())
    tree_a = cKDTree(x[act])
    tree_i = cKDTree(x[~act]) if (~act).any() else None

    def near(tree: cKDTree | None, p: np.ndarray, d: float) -> np.ndarray:
        if tree is None or len(p) == 0:
            return np.zeros(len(p), dtype=bool)
        return tree.query(np.asarray(p)[:, :2], distance_upper_bound=d * (1 + 1e-9))[0] <= d

    return InitialSet(lambda p: near(tree_a, p, r), lambda p: near(tree_i, p, r * band / margin))


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


class _ActiveSet:
    """Bookkeeping of the active-set iteration: visited sets, probes, the small predictor."""

    def __init__(self, comm: MPI.Comm, mine: np.ndarray, size: int) -> None:
        self.comm, self.mine, self.size = comm, np.asarray(mine), size
        self.seen: set[bytes] = set()
        self.last = b""

    def to_global(self, local: np.ndarray) -> np.ndarray:
        """A per-row local array in the global multiplier order."""
        out = np.zeros((self.size, *local.shape[1:]), dtype=local.dtype)
        for idx, vals in self.comm.allgather((self.mine, local)):
            out[idx] = vals
        return out

    def visit(self, active: np.ndarray, it: int, n_active: int, probing: bool) -> None:
        """Record a set about to be solved; raise if it was solved before (a cycle)."""
        key = self.to_global(active).tobytes()
        repeat = probing and key == self.last  # the same set again, now with probes
        self.last = key
        if key in self.seen and not repeat:
            raise ActiveSetError(f"active set cycles at iteration {it} ({n_active} active nodes)")
        self.seen.add(key)

    def global_indices(self, local_mask: np.ndarray) -> np.ndarray:
        """Global multiplier indices of a local row mask."""
        return np.flatnonzero(self.to_global(local_mask))

    def probe_rhs(self, probe: np.ndarray) -> np.ndarray:
        """Unit right-hand sides (local rows x candidates): open one weighted gap each."""
        rhs = np.zeros((len(self.mine), len(probe)))
        rows = np.flatnonzero(np.isin(self.mine, probe))
        rhs[rows, np.searchsorted(probe, self.mine[rows])] = 1.0
        return rhs

    def predict(self, probe: np.ndarray, lam: np.ndarray, dmu: np.ndarray,
                active: np.ndarray) -> np.ndarray | None:
        """Active set (local mask) solving the complementarity problem restricted to `probe`.

        Rows of `active` (local mask) outside `probe` stay as they are.
        """
        lam0 = self.to_global(lam)[probe]
        # Column j: change of the tractions when the weighted gap of candidate j opens by 1.
        kq = -self.to_global(dmu)[probe]
        kq = 0.5 * (kq + kq.T)
        act = lcp_active_set(kq, lam0)
        if act is None:
            return None
        mask = self.to_global(np.asarray(active, dtype=bool))
        mask[probe] = False
        mask[probe[act]] = True
        return mask[self.mine]


def lcp_active_set(k: np.ndarray, lam0: np.ndarray, max_iterations: int = 100
                   ) -> np.ndarray | None:
    """Active set of lam = lam0 + k s >= 0, s >= 0, lam s = 0 by dense primal-dual steps.

    Starts from everything in contact (lam0 itself); returns None on cycling, on an empty
    set (the body would float: left to the full solve to report) or a singular block.
    """
    n = len(lam0)
    act = np.ones(n, dtype=bool)
    seen: set[bytes] = set()
    for _ in range(max_iterations):
        seen.add(act.tobytes())
        ina = ~act
        s = np.zeros(n)
        if ina.any():
            if not act.any():
                return None
            try:
                s[ina] = np.linalg.solve(k[np.ix_(ina, ina)], -lam0[ina])
            except np.linalg.LinAlgError:
                return None
        lam = lam0 + k @ s
        lam[ina] = 0.0
        new = np.where(act, lam > 0.0, s < 0.0)
        if np.array_equal(new, act):
            return act
        act = new
        if act.tobytes() in seen:
            return None
    return None


def _gather(comm: MPI.Comm, local: np.ndarray) -> np.ndarray:
    return np.concatenate(comm.allgather(np.asarray(local)))


@dataclass
class ContactSetup:
    """What every contact solver needs before its first solve: K, f, B, gaps, the layout."""

    scene: Scene
    elasticity: Elasticity
    surfaces: tuple[GatheredSurface, GatheredSurface]  # (active, passive)
    operator: ContactOperator
    layout: Multipliers
    order: np.ndarray
    B: PETSc.Mat
    g: np.ndarray              # weighted gaps of the rows owned here
    w: np.ndarray              # weights of the rows owned here
    h: float                   # median contact element size (cm)
    needs_contact: list[int]   # bodies held in the load direction only by contact

    def normalized_gap(self, u: fem.Function) -> np.ndarray:
        """Nodal gap (weighted gap / weight, cm) of the owned rows at displacement u."""
        y = self.B.createVecLeft()
        self.B.mult(u.x.petsc_vec, y)
        gap = (self.g + y.array_r) / self.w
        y.destroy()
        return gap

    def initial_active(self, tol: float) -> np.ndarray:
        """Touching nodes; if none and a body floats, the closest node(s) as a first contact."""
        comm = self.scene.mesh.comm
        gap = self.g / self.w
        active = gap <= tol
        if self.needs_contact and comm.allreduce(int(active.sum())) == 0:
            gmin = comm.allreduce(float(gap.min(initial=np.inf)), op=MPI.MIN)
            active = gap <= gmin + tol
        return active

    def check_not_floating(self, n_active: int) -> None:
        """Raise SingularSystemError if a body held only by contact has lost every contact."""
        if n_active == 0 and self.needs_contact:
            raise SingularSystemError(
                f"body {self.needs_contact[0]} has no support in the load direction and no node "
                "in contact (empty active set): the load pulls the bodies apart")

    def solution(self, method: Method, u: fem.Function, pressure: np.ndarray, gap: np.ndarray,
                 active: np.ndarray, history: list[dict[str, float]], timers: Timers
                 ) -> Solution:
        """Gather the owned rows into a Solution (and free B)."""
        comm = self.scene.mesh.comm
        self.B.destroy()
        surf_a, surf_p = self.surfaces
        bodies = (surf_a, surf_p) if self.scene.active == 1 else (surf_p, surf_a)
        return Solution(self.scene, method, self.elasticity, u, self.layout,
                        pressure=_gather(comm, np.where(active, pressure, 0.0)),
                        gap=_gather(comm, gap), active=_gather(comm, active),
                        operator=self.operator, order=self.order, surfaces=bodies,
                        iterations=len(history), history=history, timers=timers)


def assemble_and_gather(scene: Scene, bodies: tuple[int, int], timers: Timers
                        ) -> tuple[Elasticity, int, GatheredSurface, GatheredSurface]:
    """Assemble K and f, and gather the contact surfaces of `bodies` (in that order)."""
    with timers("assemble"):
        el = assemble_elasticity(scene)
    V = el.V
    ndofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    with timers("search"):
        first, second = (gather_surface(scene, V, body) for body in bodies)
    return el, ndofs, first, second


def prepare_contact(scene: Scene, operator: str, aso: ActiveSetOptions,
                    timers: Timers) -> ContactSetup:
    """Assemble K and f, gather the surfaces, build B and check the geometry."""
    comm = scene.mesh.comm
    el, ndofs, surf_a, surf_p = assemble_and_gather(scene, (scene.active, scene.passive), timers)
    V = el.V
    with timers("contact"):
        op = contact_operator(operator, surf_a.surface, surf_p.surface, ndofs)
        layout, order = multiplier_layout(comm, surf_a, op)
        if layout.size == 0:
            raise GeometryError(f"the active surface contact{scene.active} does not overlap the "
                                f"passive surface contact{scene.passive}")
        check_facing(surf_a.surface, surf_p.surface, op)
        B = petsc_constraint(V, op, order, layout, global_dirichlet_dofs(V, el.bc_dofs))
    w_all = layout.weights
    g_all = op.gap[order] / w_all
    h = float(np.median(w_all))
    if g_all.min() < -aso.penetration_tol * h:
        j = int(np.argmin(g_all))
        raise GeometryError(f"initial penetration {-g_all[j]:.3e} cm at x = {layout.x[j, 0]:.4g} "
                            f"exceeds the tolerance {aso.penetration_tol * h:.1e} cm")
    needs_contact = [b for b in (1, 2) if not body_supported(el, scene, b)]
    if len(needs_contact) == 2:
        raise SingularSystemError("neither body has supports in both directions: contact alone "
                                  "cannot hold bodies 1 and 2")
    mine = layout.mine
    return ContactSetup(scene, el, (surf_a, surf_p), op, layout, order, B,
                        op.gap[order][mine], w_all[mine], h, needs_contact)


def solve_contact(scene: Scene, method: Method, solver: str | dict[str, object] = "mumps",
                  aso: ActiveSetOptions = ActiveSetOptions(),
                  timers: Timers | None = None, reference_timing: bool = False,
                  initial_active: InitialSet | Callable[[np.ndarray], np.ndarray] | None = None
                  ) -> Solution:
    """Solve the frictionless unilateral contact problem of `scene` with `method`.

    `initial_active` (node coordinates -> bool, or an InitialSet) adds nodes to the first
    active set; only the loop's cost depends on it, never the converged solution.
    """
    if method not in IMPLEMENTED:
        raise InputError(f"method '{method.value}' is not implemented yet "
                         f"(available: {', '.join(sorted(m.value for m in IMPLEMENTED))})")
    if method == Method.PENALTY:
        raise InputError("the penalty method has no multipliers: call penalty.solve_penalty "
                         "(api.run_case does)")
    options = SOLVERS[solver] if isinstance(solver, str) else solver
    timers = timers or Timers()
    comm = scene.mesh.comm
    setup = prepare_contact(scene, method.operator, aso, timers)
    el, B, g, w, h = setup.elasticity, setup.B, setup.g, setup.w, setup.h
    V, layout, mine = el.V, setup.layout, setup.layout.mine
    e_max = max(m.E for m in scene.materials)
    c = e_max / h
    gamma = e_max / h**2 if uses_augmentation(options) else 0.0
    active = setup.initial_active(aso.penetration_tol * h)
    # Probes need the exact inverse: only a factorization of the whole saddle point gives it.
    direct = is_direct(options)
    state = _ActiveSet(comm, mine, layout.size)
    history: list[dict[str, float]] = []
    u = fem.Function(V, name="u")
    probe: np.ndarray | None = None   # global indices of the candidate set being probed
    band = np.zeros(len(mine), dtype=bool)  # rows whose status the initial set is unsure of
    if initial_active is not None:
        guess = (initial_active if isinstance(initial_active, InitialSet)
                 else InitialSet(initial_active))
        x_mine = layout.x[mine]
        active = active | np.asarray(guess.active(x_mine), dtype=bool)
        if guess.uncertain is not None and aso.predictor and direct:
            # Probe only the band where the guess is unsure: the rest of it stays in contact.
            band = np.asarray(guess.uncertain(x_mine), dtype=bool)
            if 0 < comm.allreduce(int((active & band).sum())) <= aso.max_probes:
                probe = state.global_indices(active & band)
    # One solver for the whole loop: fixed matrix pattern, reused analysis and factorization.
    nullspace = near_nullspace(V, scene) if uses_augmentation(options) else None
    solver = SaddleSolver(el.K, B, el.f, options, gamma, nullspace)
    converged = False
    for it in range(1, aso.max_iterations + 1):
        n_active = comm.allreduce(int(active.sum()))
        setup.check_not_floating(n_active)
        state.visit(active, it, n_active, probe is not None)
        probes = None if probe is None else state.probe_rhs(probe)
        t0 = time.perf_counter()
        with timers("solve"):
            res = solver.solve(g, active, probes)
        t_solve = time.perf_counter() - t0
        u.x.petsc_vec.array[:] = res.u
        u.x.scatter_forward()
        lam = -res.mu
        gap_u = setup.normalized_gap(u)
        # Semi-smooth Newton on min(lambda, c g): with the active gaps solved exactly, c only
        # scales the test, so the update is lambda > 0 on active, penetration on inactive.
        new_active = lam - c * gap_u > 0
        ncp = np.where(active, np.minimum(lam, c * gap_u), np.minimum(0.0, c * gap_u))
        lam_max = comm.allreduce(float(np.abs(lam).max(initial=0.0)), op=MPI.MAX)
        resid = np.sqrt(comm.allreduce(float(np.sum(w * ncp**2)), op=MPI.SUM))
        resid /= max(lam_max * np.sqrt(comm.allreduce(float(w.sum()))), 1e-300)
        entered = comm.allreduce(int(np.sum(new_active & ~active)))
        left = comm.allreduce(int(np.sum(active & ~new_active)))
        history.append({"iteration": it, "active": n_active, "entered": entered, "left": left,
                        "residual": resid, "linear_iterations": res.iterations,
                        "probes": 0 if probe is None else len(probe), "solve_time": t_solve,
                        "factorized": int(bool(res.info.get("refactored", True)))})
        if comm.rank == 0:
            log.info("active set %2d: %5d active, +%d -%d, complementarity %.2e, "
                     "%d linear its, %s%.3f s", it, n_active, entered, left, resid,
                     res.iterations, "" if probe is None else f"{len(probe)} probes, ", t_solve)
        if entered == 0 and left == 0:
            if resid > aso.tolerance:
                raise ActiveSetError(f"active set is stationary at iteration {it} but the "
                                     f"complementarity residual {resid:.2e} exceeds "
                                     f"{aso.tolerance:.1e}: the linear solves are too inexact")
            converged = True
            break
        if probe is not None:
            # The set probed holds every candidate (rows outside it keep their status): the
            # small complementarity problem on it predicts the converged set; the next solve
            # checks it like any other iterate.
            predicted = state.predict(probe, lam, res.info["probes"], active)
            probe = None
            if predicted is not None and not np.array_equal(predicted, active):
                active = predicted
                continue
        elif aso.predictor and direct and not (entered == 0 and initial_active is not None):
            # Probe the union of the current and the updated set: on the Hertz scene the plain
            # update adds every penetrating node and then drops one or two edge nodes per
            # iteration; one multi-right-hand-side solve replaces those iterations. If nodes
            # only leave, the union is the current set, solved again with probes. (Not after
            # a given first set, a superset: releasing rows costs two back-substitutions.)
            union = active | new_active
            # After a given first set only its uncertain band and the rows that change.
            cand = union if initial_active is None else union & (band | (new_active != active))
            n_new = comm.allreduce(int(new_active.sum()))
            if 0 < n_new and comm.allreduce(int(cand.sum())) <= aso.max_probes:
                probe = state.global_indices(cand)
                active = union
                continue
        active = new_active
    if not converged:
        raise ActiveSetError(f"active set did not converge in {aso.max_iterations} iterations "
                             f"(last change: +{entered} -{left}, residual {resid:.2e})")
    solver.destroy()
    if reference_timing:
        # The cost floor: one fresh solve of the final system by the same solver.
        _, timers.seconds["reference_solve"] = reference_solve(el.K, B, el.f, g, active,
                                                              options, gamma, nullspace)
    return setup.solution(method, u, lam, gap_u, active, history, timers)
