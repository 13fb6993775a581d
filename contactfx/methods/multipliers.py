"""The multiplier methods (NTS, STS, mortar): saddle-point solves inside the active-set loop.

With a solver that holds an exact inverse the loop is helped by probes: the union of the
current and the updated set is solved once more with one right-hand side per candidate node,
and the small complementarity problem on the candidates predicts the converged set
(`active_set`).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import replace
from functools import partial

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from ..discretize.setup import ContactSetup
from ..errors import EliminationError, InputError
from ..linalg import LinearSolver, SaddleResult
from ..options import Linear, SolverKind, SolverSpec
from ..request import SolveRequest
from ..scenes import Scene
from ..timers import Timers
from .active_set import (
    ActiveSetOptions,
    InitialSet,
    Proposal,
    SetHistory,
    Step,
    run_active_set,
)
from .autosolve import Prepared, prepare_solver, warn_if_too_big
from .cleanup import released
from .solution import Solution, finish
from .solvers import setup_solver

log = logging.getLogger("contactfx")

# A row that a loose solve adds to a given first set with a penetration c g below this
# fraction of the largest traction is decided at the final tolerance (`_stationary`).
LOOSE_PENETRATION = 0.1


class MultiplierIteration:
    """Saddle-point solves on a set, the semi-smooth Newton update, and the probe policy."""

    def __init__(
        self,
        setup: ContactSetup,
        solver: LinearSolver,
        aso: ActiveSetOptions,
        given_start: bool,
        label: str = "active set",
    ) -> None:
        self.setup, self.solver, self.aso = setup, solver, aso
        # Semi-smooth Newton on min(lambda, c g): c = E / h makes both terms tractions.
        self.c = setup.e_max / setup.h
        # Probes need the exact inverse: only a factorization of the whole saddle point.
        self.direct = solver.can_probe
        self.given_start, self.label = given_start, label
        layout = setup.layout
        self.state = SetHistory(setup.comm, layout.mine, layout.size)
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
        comm = self.setup.comm
        if guess is None:
            layout = self.setup.layout
            size = layout.size
            if not (
                self.aso.start_all
                and self.aso.probes
                and self.direct
                and self.solver.cheap_responses
                and 0 < size
            ):
                return active
            if size > self.aso.max_probes:
                self._say(f"{size} rows exceed max_probes {self.aso.max_probes}: no start_all")
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
        if guess.uncertain is not None and self.aso.probes and self.direct:
            # Probe only the band where the guess is unsure: the rest of it stays in contact.
            self.band = np.asarray(guess.uncertain(x_mine), dtype=bool)
            if 0 < comm.allreduce(int((active & self.band).sum())) <= self.aso.max_probes:
                self.probe = self.state.global_indices(active & self.band)
        return active

    def solve(self, active: np.ndarray, it: int) -> Step:
        """One saddle-point solve on `active`, with the probe responses if probing."""
        comm = self.setup.comm
        g = self.setup.g
        try:
            res = self.solver.solve(
                g,
                active,
                fresh=self.probe is not None,
                stationary=None if self.solver.exact else partial(self._stationary, active),
            )
        except EliminationError as err:
            raise InputError(refusal(self.setup, err)) from None
        self._probes = None
        if self.probe is not None:
            # The complementarity problem and a later release read only the probed rows.
            rhs = self.state.probe_rhs(self.probe)
            self._probes = self.solver.responses(rhs, active, rhs.any(axis=1))
        lam, gap, new_active = self._update(res.u, res.mu)
        its = res.iterations
        c, w = self.c, self.setup.w
        ncp = np.where(active, np.minimum(lam, c * gap), np.minimum(0.0, c * gap))
        lam_max = comm.allreduce(float(np.abs(lam).max(initial=0.0)), op=MPI.MAX)
        resid = np.sqrt(comm.allreduce(float(np.sum(w * ncp**2)), op=MPI.SUM))
        resid /= max(lam_max * np.sqrt(comm.allreduce(float(w.sum()))), 1e-300)
        n_probes = 0 if self.probe is None else len(self.probe)
        record: dict[str, float] = {
            "linear_iterations": its,
            "probes": n_probes,
            "factorized": int(res.refactored),
        }
        text = f"complementarity {resid:.2e}, {its} linear its, " + (
            f"{n_probes} probes, " if n_probes else ""
        )
        return Step(lam, gap, new_active, float(resid), record, text, res.final)

    def _stationary(self, active: np.ndarray, loose: SaddleResult) -> bool:
        """Whether an inexact solver goes on from its loose answer to the final tolerance.

        Only a solve to the final tolerance may call a set stationary (the loop goes on if
        its signs differ). Asked (collectively) when the loose answer keeps the set, and
        after a given first set when it only adds rows that penetrate by less than
        LOOSE_PENETRATION of the largest traction (c g against lambda): from a coarse
        prediction such a row's sign is within the loose solve's error, and adding it made
        the exact set cycle; rows that truly enter penetrate several times more
        (docs/scale.md, "An exact first set").
        """
        lam, gap, new_active = self._update(loose.u, loose.mu)
        comm = self.setup.comm
        entering = new_active & ~active
        added = comm.allreduce(int(entering.sum()))
        left = comm.allreduce(int(np.sum(active & ~new_active)))
        if left or (added and not self.given_start):
            return False
        if not added:
            return True
        pen = comm.allreduce(float(np.max(-self.c * gap[entering], initial=0.0)), op=MPI.MAX)
        lam_max = comm.allreduce(float(np.abs(lam).max(initial=0.0)), op=MPI.MAX)
        return pen <= LOOSE_PENETRATION * lam_max

    def _update(self, u: np.ndarray, mu: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(lambda, normalized gap, the updated set) of a solve's u and multipliers."""
        self.u.x.petsc_vec.array[:] = u
        self.u.x.scatter_forward()
        lam = -mu
        gap = self.setup.normalized_gap(self.u)
        # Semi-smooth Newton on min(lambda, c g): with the active gaps solved exactly, c only
        # scales the test, so the update is lambda > 0 on active, penetration on inactive.
        return lam, gap, lam - self.c * gap > 0

    def next_set(self, active: np.ndarray, step: Step, entered: int) -> Proposal | None:
        """The predicted set after a probing solve, or the union to probe; None otherwise."""
        comm = self.setup.comm
        if self.probe is not None:
            # The set probed holds every candidate (rows outside it keep their status): the
            # small complementarity problem on it predicts the converged set; the next solve
            # checks it like any other iterate.
            assert self._probes is not None  # the probing solve returned its responses
            predicted = self.state.predict(self.probe, step.lam, self._probes, active)
            self.probe = None
            if predicted is None:
                self._say("the probes' complementarity problem has no solution: plain update")
                return None
            # Collective: every rank must take the same branch (the loop logs the change).
            if comm.allreduce(bool(np.array_equal(predicted, active)), op=MPI.LAND):
                return None
            return Proposal(predicted, "the probes' complementarity problem")
        if self.aso.probes and self.direct and not (entered == 0 and self.given_start):
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
            n_cand = comm.allreduce(int(cand.sum()))
            if 0 < n_new and n_cand <= self.aso.max_probes:
                self.probe = self.state.global_indices(cand)
                return Proposal(union, "both sets' union, probed")
            if n_cand > self.aso.max_probes:
                self._say(f"{n_cand} candidates exceed max_probes: plain update")
        return None

    def _say(self, text: str) -> None:
        """A log line for a fallback of the probe policy (rank 0)."""
        if self.setup.comm.rank == 0:
            log.info("%s: %s", self.label, text)


def refusal(setup: ContactSetup, err: EliminationError) -> str:
    """The condensed solver's refusal with the pair and the reason (the solver knows rows)."""
    layout = setup.layout
    rows = np.flatnonzero(layout.gblock == err.node_dofs[0] // 2)
    if not rows.size:
        return str(err)
    p = setup.pairs[int(layout.pair[rows[0]])]
    x = layout.x[rows[0]]
    where = f"pair {p.index} ({p.pair.active} on {p.pair.passive}) at ({x[0]:.4g}, {x[1]:.4g})"
    return (
        f"the condensed solver cannot eliminate the contact row of {where}: its active "
        f"node is fully prescribed ({err.reason}); use --solver mumps"
    )


def _timed_fresh_solve(
    setup: ContactSetup, spec: SolverSpec, scene: Scene, active: np.ndarray
) -> tuple[SaddleResult, float]:
    """One fresh solve of the final system by `spec` (a throwaway solver), and its seconds."""
    setup.comm.Barrier()
    t0 = time.perf_counter()
    fresh = setup_solver(setup, spec, scene, reuse=False)
    try:
        return fresh.solve(setup.g, active, fresh=True), time.perf_counter() - t0
    finally:
        fresh.destroy()


def floor_spec(spec: SolverSpec, pc: str) -> SolverSpec:
    """The plain direct factorization (`pc`: lu or cholesky) with the spec's other options."""
    linear = Linear.LU if pc == "lu" else Linear.LDLT
    petsc = {**spec.petsc, "pc_type": pc}
    return replace(
        spec, kind=SolverKind.DIRECT, petsc=petsc, name=f"{spec.name}:{pc}", linear=linear
    )


def reference_solve(
    setup: ContactSetup, spec: SolverSpec, scene: Scene, active: np.ndarray, timers: Timers
) -> SaddleResult:
    """The cost floor: one fresh solve of the final system by the same solver, timed.

    For a direct solver also a fresh LU and a fresh LDL^T of the same saddle point with the
    spec's other options (ordering, ICNTLs), as times.reference_lu and times.reference_ldlt:
    the two floors a factorization can reach.
    """
    res, seconds = _timed_fresh_solve(setup, spec, scene, active)
    timers.seconds["reference_solve"] = seconds
    if spec.traits.factorizes:
        # The plain factorizations.
        for key, pc in (("reference_lu", "lu"), ("reference_ldlt", "cholesky")):
            floor = floor_spec(spec, pc)
            same = floor == replace(spec, name=floor.name)
            timers.seconds[key] = (
                seconds if same else _timed_fresh_solve(setup, floor, scene, active)[1]
            )
    return res


def solve_contact(
    scene: Scene,
    request: SolveRequest,
    timers: Timers | None = None,
    *,
    aso: ActiveSetOptions | None = None,
    initial_active: InitialSet | Callable[[np.ndarray], np.ndarray] | None = None,
    label: str = "active set",
    prepared: Prepared | None = None,
) -> Solution:
    """Solve the frictionless unilateral contact problem of `scene` with Lagrange multipliers.

    `request` gives the discretization, the basis, the solver and the iteration limit (its
    enforcement is the multipliers': `contactfx.solve` dispatches the others); `aso` other
    loop controls. `initial_active` (node coordinates -> bool, or an InitialSet) adds nodes
    to the first active set; only the loop's cost depends on it, never the converged
    solution. `label` heads the log lines. `prepared`: the setup (and solver) made already
    (`autosolve.prepare_solver`, which also resolves an `auto` solver); this call owns it.
    """
    aso = aso or ActiveSetOptions(request.max_iterations)
    timers = timers or Timers()
    if prepared is None:
        prepared = prepare_solver(scene, request, aso.penetration_tol, timers)
    setup, request = prepared.setup, prepared.request
    spec = request.solver
    with released(scene.comm, setup):
        # One solver for the whole loop: fixed matrix pattern, reused analysis and setup.
        linear = prepared.linear
        if linear is None:
            linear = setup_solver(setup, spec, scene, reuse=True)
            warn_if_too_big(linear, scene, request, timers)
        guess = (
            initial_active
            if isinstance(initial_active, InitialSet) or initial_active is None
            else InitialSet(initial_active)
        )
        iteration = MultiplierIteration(setup, linear, aso, guess is not None, label)
        active = iteration.start(setup.initial_active(aso.penetration_tol * setup.h), guess)
        with released(scene.comm, linear):
            step, active, history = run_active_set(setup, iteration, active, aso, timers)
        ref = (
            reference_solve(setup, spec, scene, active, timers)
            if request.reference_timing
            else None
        )
        sol = finish(
            setup, request.method, scene, iteration.u, step.lam, step.gap, active, history, timers
        )
    sol.basis = request.basis
    sol.solver_choice = prepared.choice
    if ref is not None:
        sol.reference_linear_iterations = ref.iterations
    return sol
