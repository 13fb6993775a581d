"""The multiplier methods (NTS, STS, mortar): saddle-point solves inside the active-set loop.

With a direct solver the loop is helped by probes: the union of the current and the updated
set is solved once more with one right-hand side per candidate node, and the small
complementarity problem on the candidates predicts the converged set (`active_set`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from typing import cast

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from .active_set import (
    ActiveSetOptions,
    InitialSet,
    SetHistory,
    Step,
    coarse_initial_set,
    lcp_active_set,
    run_active_set,
)
from .condensed import CondensedSolver, is_condensed, owned_node_dofs
from .errors import InputError
from .methods import IMPLEMENTED, Method
from .nullspace import near_nullspace, rigid_body_modes
from .prepare import ContactSetup, prepare_contact
from .saddle import SaddleSolver
from .scenes import Scene
from .solution import Solution
from .solvers import SOLVERS, is_direct, uses_augmentation
from .timers import Timers

__all__ = [
    "ActiveSetOptions",
    "InitialSet",
    "coarse_initial_set",
    "lcp_active_set",
    "solve_contact",
]


DEFAULT_OPTIONS = ActiveSetOptions()


class MultiplierIteration:
    """Saddle-point solves on a set, the semi-smooth Newton update, and the probe policy."""

    label = "active set"

    def __init__(
        self,
        setup: ContactSetup,
        solver: SaddleSolver | CondensedSolver,
        aso: ActiveSetOptions,
        c: float,
        direct: bool,
        given_start: bool,
    ) -> None:
        self.setup, self.solver, self.aso, self.c = setup, solver, aso, c
        self.direct, self.given_start = direct, given_start
        layout = setup.layout
        self.state = SetHistory(setup.scene.comm, layout.mine, layout.size)
        self.u = fem.Function(setup.elasticity.V, name="u")
        self.probe: np.ndarray | None = None  # global indices of the candidates probed
        self.band = np.zeros(len(layout.mine), dtype=bool)  # rows the first set is unsure of
        self._probes: np.ndarray | None = None

    @property
    def probing(self) -> bool:
        """Whether the next solve is a probing one (it may repeat the last set)."""
        return self.probe is not None

    def start(self, active: np.ndarray, guess: InitialSet | None) -> np.ndarray:
        """Add a given first set (and probe its uncertain band) to the touching nodes.

        Without one, and when probe responses are cheap (`SaddleSolver.cheap_responses`),
        every row is put in contact and probed (`ActiveSetOptions.start_all`): a superset of
        any converged set, so the loop factorizes once and then only releases rows. Rows of
        a node that several pairs constrain keep their touching status (two such rows may be
        dependent: the saddle point would be singular).
        """
        comm = self.setup.scene.comm
        if guess is None:
            layout = self.setup.layout
            size = layout.size
            if not (
                self.aso.start_all
                and self.aso.predictor
                and self.direct
                and self.solver.cheap_responses
                and 0 < size <= self.aso.max_probes
            ):
                return active
            node = np.asarray(layout.gblock)
            counts = np.unique(node, return_counts=True)
            shared = np.isin(node, counts[0][counts[1] > 1])[layout.mine]
            every = active | ~shared
            self.band = every.copy()
            self.probe = self.state.global_indices(every)
            self.given_start = True
            return every
        x_mine = self.setup.layout.x[self.setup.layout.mine]
        active = active | np.asarray(guess.active(x_mine), dtype=bool)
        if guess.uncertain is not None and self.aso.predictor and self.direct:
            # Probe only the band where the guess is unsure: the rest of it stays in contact.
            self.band = np.asarray(guess.uncertain(x_mine), dtype=bool)
            if 0 < comm.allreduce(int((active & self.band).sum())) <= self.aso.max_probes:
                self.probe = self.state.global_indices(active & self.band)
        return active

    def solve(self, active: np.ndarray, it: int) -> Step:
        """One saddle-point solve on `active`, with the probe right-hand sides if probing."""
        comm = self.setup.scene.comm
        probes = None if self.probe is None else self.state.probe_rhs(self.probe)
        res = self.solver.solve(self.setup.g, active, probes)
        self._probes = cast(np.ndarray | None, res.info.get("probes"))
        lam, gap, new_active = self._update(res.u, res.mu)
        its = res.iterations
        if isinstance(self.solver, CondensedSolver) and not comm.allreduce(
            bool(np.any(new_active != active)), op=MPI.LOR
        ):
            # The loose solve says the set is stationary: only a solve to the final
            # tolerance may say so (the loop goes on if its signs differ).
            res = self.solver.polish(self.setup.g, active)
            lam, gap, new_active = self._update(res.u, res.mu)
            its += res.iterations
        c, w = self.c, self.setup.w
        ncp = np.where(active, np.minimum(lam, c * gap), np.minimum(0.0, c * gap))
        lam_max = comm.allreduce(float(np.abs(lam).max(initial=0.0)), op=MPI.MAX)
        resid = np.sqrt(comm.allreduce(float(np.sum(w * ncp**2)), op=MPI.SUM))
        resid /= max(lam_max * np.sqrt(comm.allreduce(float(w.sum()))), 1e-300)
        n_probes = 0 if self.probe is None else len(self.probe)
        record: dict[str, float] = {
            "linear_iterations": its,
            "probes": n_probes,
            "factorized": int(bool(res.info.get("refactored", True))),
        }
        text = f"complementarity {resid:.2e}, {its} linear its, " + (
            f"{n_probes} probes, " if n_probes else ""
        )
        return Step(lam, gap, new_active, float(resid), record, text)

    def _update(self, u: np.ndarray, mu: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(lambda, normalized gap, the updated set) of a solve's u and multipliers."""
        self.u.x.petsc_vec.array[:] = u
        self.u.x.scatter_forward()
        lam = -mu
        gap = self.setup.normalized_gap(self.u)
        # Semi-smooth Newton on min(lambda, c g): with the active gaps solved exactly, c only
        # scales the test, so the update is lambda > 0 on active, penetration on inactive.
        return lam, gap, lam - self.c * gap > 0

    def next_set(self, active: np.ndarray, step: Step, entered: int) -> np.ndarray | None:
        """The predicted set after a probing solve, or the union to probe; None otherwise."""
        comm = self.setup.scene.comm
        if self.probe is not None:
            # The set probed holds every candidate (rows outside it keep their status): the
            # small complementarity problem on it predicts the converged set; the next solve
            # checks it like any other iterate.
            assert self._probes is not None  # the probing solve returned its responses
            predicted = self.state.predict(self.probe, step.lam, self._probes, active)
            self.probe = None
            if predicted is not None and not np.array_equal(predicted, active):
                return predicted
            return None
        if self.aso.predictor and self.direct and not (entered == 0 and self.given_start):
            # Probe the union of the current and the updated set: on the Hertz scene the plain
            # update adds every penetrating node and then drops one or two edge nodes per
            # iteration; one multi-right-hand-side solve replaces those iterations. If nodes
            # only leave, the union is the current set, solved again with probes. (Not after
            # a given first set, a superset: releasing rows costs two back-substitutions.)
            new = step.new_active
            union = active | new
            # After a given first set only its uncertain band and the rows that change.
            cand = union if not self.given_start else union & (self.band | (new != active))
            n_new = comm.allreduce(int(new.sum()))
            if 0 < n_new and comm.allreduce(int(cand.sum())) <= self.aso.max_probes:
                self.probe = self.state.global_indices(cand)
                return union
        return None


def solve_contact(
    scene: Scene,
    method: Method,
    solver: str | Mapping[str, object] = "mumps",
    aso: ActiveSetOptions = DEFAULT_OPTIONS,
    timers: Timers | None = None,
    reference_timing: bool = False,
    initial_active: InitialSet | Callable[[np.ndarray], np.ndarray] | None = None,
    basis: str = "standard",
) -> Solution:
    """Solve the frictionless unilateral contact problem of `scene` with `method`.

    `initial_active` (node coordinates -> bool, or an InitialSet) adds nodes to the first
    active set; only the loop's cost depends on it, never the converged solution. `basis`
    "dual" takes mortar's biorthogonal multipliers (D diagonal).
    """
    if method not in IMPLEMENTED:
        raise InputError(
            f"method '{method.value}' is not implemented yet "
            f"(available: {', '.join(sorted(m.value for m in IMPLEMENTED))})"
        )
    if method in (Method.PENALTY, Method.SCHWARZ):
        raise InputError(
            f"the {method.value} method has no saddle-point multipliers: call "
            "contactfx.solve (it dispatches every method)"
        )
    options = SOLVERS[solver] if isinstance(solver, str) else solver
    timers = timers or Timers()
    if basis != "standard" and method != Method.MORTAR:
        raise InputError(f"the {basis} multiplier basis applies to the mortar method only")
    kernel = {"basis": basis} if basis != "standard" else {}
    setup = prepare_contact(scene, method.operator, aso.penetration_tol, timers, **kernel)
    el, h = setup.elasticity, setup.h
    e_max = max(b.material.E for b in scene.bodies)
    gamma = e_max / h**2 if uses_augmentation(options) else 0.0
    condensed = is_condensed(options)
    if condensed and not (method == Method.NTS or (method == Method.MORTAR and basis == "dual")):
        raise InputError(
            "the condensed solver needs a diagonal D: use --method nts or "
            "--method mortar --basis dual"
        )
    nullspace = near_nullspace(el.V, scene) if uses_augmentation(options) else None
    modes = rigid_body_modes(el.V, scene) if condensed else []
    node_dofs = owned_node_dofs(setup.layout.gblock, setup.layout.mine)

    def make_solver(fresh: bool) -> SaddleSolver | CondensedSolver:
        """The loop's solver (fresh=False: it keeps and reuses its setup) or a throwaway one."""
        if condensed:
            solver = CondensedSolver(el.K, setup.B, el.f, options, node_dofs, modes)
            solver.reuse = not fresh
            return solver
        return SaddleSolver(
            el.K, setup.B, el.f, options, gamma, nullspace, reuse_factorization=not fresh
        )

    # One solver for the whole loop: fixed matrix pattern, reused analysis and factorization.
    saddle = make_solver(fresh=False)
    guess = (
        initial_active
        if isinstance(initial_active, InitialSet) or initial_active is None
        else InitialSet(initial_active)
    )
    # Probes need the exact inverse: only a factorization of the whole saddle point gives it.
    iteration = MultiplierIteration(
        setup, saddle, aso, e_max / h, is_direct(options), guess is not None
    )
    active = iteration.start(setup.initial_active(aso.penetration_tol * h), guess)
    try:
        step, active, history = run_active_set(setup, iteration, active, aso, timers)
    finally:
        saddle.destroy()
    if reference_timing:
        # The cost floor: one fresh solve of the final system by the same solver.
        scene.comm.Barrier()
        t0 = time.perf_counter()
        fresh = make_solver(fresh=True)
        try:
            if isinstance(fresh, CondensedSolver):
                ref = fresh.polish(setup.g, active)  # from zero, to the final tolerance
            else:
                ref = fresh.solve(setup.g, active)
        finally:
            fresh.destroy()
        timers.seconds["reference_solve"] = time.perf_counter() - t0
        reference_iterations = ref.iterations
    sol = setup.solution(method, iteration.u, step.lam, step.gap, active, history, timers)
    if reference_timing:
        sol.info["reference_linear_iterations"] = reference_iterations
    if basis != "standard":
        sol.info["basis"] = basis
    return sol
