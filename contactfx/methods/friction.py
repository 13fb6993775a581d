"""Coulomb friction by multipliers: a tangential row beside each normal row, three sets.

Each contact row j carries a normal multiplier lambda_n (a pressure) and a tangential one
lambda_t (the traction on the active body is -lambda_t t, t = (n_y, -n_x) of the bisector of
the two surfaces, FRAME). A set of the primal-dual active set (Hueber, Stadler and Wohlmuth
2008) fixes each row's law, and the saddle point
[[K, B_n^T, B_t^T], [B_n', C_nn, 0], [B_t', C_tn, C_tt]] is linear on it (multipliers
mu_n = -lambda_n, mu_t = +lambda_t, so K u + B^T mu = f):

    open:  lambda_n = 0, lambda_t = 0                 (B rows off, C = 1)
    stick: weighted gap 0, weighted slip increment 0  (B_n, B_t rows on)
    slip:  weighted gap 0, lambda_t = mu s lambda_n   (B_n row on; mu_t + mu s mu_n = 0: C_tn)

C_tn makes the system unsymmetric: it is factored by LU (MUMPS) on one fixed pattern whose
analysis and last factorization serve the later sets (methods/friction_linear.py), or, with
dual mortar and the condensed solver, the multipliers are eliminated node by node and GMRES
solves the unsymmetric displacement system (linalg/condensed_friction.py). The next set is
contact/friction.py's classification of the solution, with the complementarity constants
c_n = c_t = E_max / h (tractions against E times a strain: no user constant, no units), each
solve a semismooth Newton step shortened where it does not lower the complementarity
residual (contact/friction.py, damped_length). The loop is the one of active_set.py: the
normal set is its `active`, and a change of a row's stick/slip status or slip direction keeps
it going (`Step.changed`, `SetHistory.visit`'s key). The slip increment is measured from the
previous load step (quasi-static).

Supported: nts and mortar (standard and dual basis) with Lagrange multipliers on the direct
saddle-point path, dual mortar on the condensed path, every model, pairs between bodies and
against rigid obstacles (their rows along the obstacle's exact tangent; the obstacle's
prescribed motion enters the slip). The first step's first set adds the frictionless coarse
predictor's contact set where the scene can be remeshed. The penalty enforcement's
regularized Coulomb law on the same rows: methods/penalty_friction.py. Refused in one line
(`refuse_friction`): sts (either enforcement), Schwarz, the fieldsplit solvers, the condensed
solver on nts or standard mortar.
With every mu = 0 nothing here runs: the frictionless path is unchanged.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..contact.friction import (
    FrictionResult,
    Status,
)
from ..discretize.setup import prepare_contact
from ..errors import InputError, MeshError, SingularSystemError, SolverError
from ..linalg.condensed_friction import FrictionCondensedSolver
from ..options import Basis, Discretization, Enforcement, Predictor, SolverKind, System
from ..request import SolveRequest
from ..scenes import Scene
from ..scenes.steps import step_scenes
from ..timers import Timers
from .active_set import ActiveSetOptions, InitialSet, run_active_set
from .friction_iteration import FrictionIteration, pair_mu
from .friction_linear import CondensedFriction, DirectFriction
from .friction_tangents import FRAME, tangent_constraint
from .predictor import predict
from .solution import Solution, finish
from .solvers import setup_solver

log = logging.getLogger("contactfx")

# The first set's band of normalized gaps, relative to the contact element size.
START_BAND = 0.1

SUPPORTED = (
    "nts or mortar (standard or dual) with multipliers and a direct solver (mumps), dual "
    "mortar with the condensed solver, or the penalty enforcement on nts or mortar"
)


def frictional_pairs(scene: Scene) -> list[int]:
    """Pair indices (into `scene.contacts`, then the obstacles) of the pairs with mu > 0."""
    return [k for k, mu in enumerate(pair_mu(scene)) if mu > 0.0]


def _pair_label(scene: Scene, k: int) -> str:
    """How a refusal names pair `k`: a contact pair or an obstacle."""
    if k < len(scene.contacts):
        pair = scene.contacts[k]
        return f"contact {k} ('{pair.active}' on '{pair.passive}') has mu = {pair.mu:g}"
    ob = scene.obstacles[k - len(scene.contacts)]
    return f"obstacle '{ob.name}' ('{ob.surface}' on it) has mu = {ob.mu:g}"


def refuse_friction(scene: Scene, request: SolveRequest) -> None:
    """InputError naming the first frictional pair if `request` cannot solve friction."""
    pairs = frictional_pairs(scene)
    if not pairs:
        return
    why = ""
    multipliers = request.enforcement is Enforcement.MULTIPLIERS
    dual = request.discretization is Discretization.MORTAR and request.basis is Basis.DUAL
    if request.enforcement is Enforcement.SCHWARZ:
        why = f"the {request.enforcement.value} enforcement"
    elif request.discretization is Discretization.STS:
        why = "sts"  # its kernel has no tangential rows
    elif multipliers and request.solver.kind is SolverKind.CONDENSED and not dual:
        how = f"{request.discretization.value} ({request.basis.value} basis)"
        why = f"the {request.solver.name} solver on {how}, which needs dual mortar"
    elif multipliers and request.solver.kind not in (
        SolverKind.DIRECT,
        SolverKind.AUTO,
        SolverKind.CONDENSED,
    ):
        why = f"the {request.solver.name} solver"
    if why:
        raise InputError(
            f"{_pair_label(scene, pairs[0])}: Coulomb friction is not solved with {why}; it "
            f"is solved by {SUPPORTED} (or set mu = 0)"
        )


@dataclass(frozen=True)
class StepState:
    """What a converged load step hands the next (owned rows): its sets and tangential motion."""

    active: np.ndarray
    sign: np.ndarray
    ut: np.ndarray  # the weighted tangential displacement B_t u (+ prescribed) at its end


def solve_friction(
    scene: Scene, request: SolveRequest, timers: Timers, aso: ActiveSetOptions
) -> Solution:
    """Solve `scene` with Coulomb friction on its pairs, step by step.

    `refuse_friction` has passed. Each load step's slip increment is measured from the step
    before (quasi-static).
    """
    # One LU for the whole load history: its pattern and analysis outlive the steps.
    condensed = request.solver.traits.system is System.CONDENSED
    direct = None if condensed else DirectFriction()
    guesses = [_coarse_guess(step_scenes(scene)[0], request, aso, timers)]

    def one(s: Scene, before: StepState | None) -> tuple[Solution, StepState]:
        guess = guesses.pop() if guesses else None
        return _solve_step(s, request, timers, aso, before, direct, guess)

    try:
        return in_steps(scene, one)
    finally:
        if direct is not None:
            direct.destroy()


def _coarse_guess(
    scene: Scene, request: SolveRequest, aso: ActiveSetOptions, timers: Timers
) -> InitialSet | None:
    """The frictionless coarse predictor's contact set for the first step's first set.

    A frictional set differs from it by the stick and slip zones: fewer sets to visit (it
    halved the first step's iterations on tests/scenes/cylinder_block.toml:
    benchmarks/friction_overhead.py). Wherever the scene can be remeshed, no probes. None
    where the frictionless scene is not held (a body held by friction alone) or a coarser
    mesh is refused (only the guess is lost).
    """
    coarse = request.predictor is Predictor.AUTO and scene.can_remesh
    try:
        return predict(
            scene, replace(request, predictor=Predictor.COARSE) if coarse else request, aso, timers
        )
    except (SingularSystemError, MeshError) as err:
        if scene.comm.rank == 0:
            log.info("coarse predictor: %s; starting without it", err)
        return None
    except InputError as err:  # the coarse scene's sizes refused: only a guess is lost
        if request.predictor is not Predictor.AUTO:
            raise
        if scene.comm.rank == 0:
            log.info("coarse predictor: %s; starting without it", err)
        return None


def in_steps[S](scene: Scene, one: Callable[[Scene, S | None], tuple[Solution, S]]) -> Solution:
    """Solve each load step of `scene` by `one`, handing each step's state to the next.

    The last step's solution, holding every step's in `steps` where the scene has steps.
    """
    sols: list[Solution] = []
    state: S | None = None
    for k, step_scene in enumerate(step_scenes(scene)):
        sol, state = one(step_scene, state)
        if scene.steps and scene.comm.rank == 0:
            log.info("step %d: %d iterations", k + 1, sol.iterations)
        sols.append(sol)
    if scene.steps:
        sols[-1].steps = sols
    return sols[-1]


def _solve_step(
    scene: Scene,
    request: SolveRequest,
    timers: Timers,
    aso: ActiveSetOptions,
    before: StepState | None,
    direct: DirectFriction | None,
    guess: InitialSet | None = None,
) -> tuple[Solution, StepState]:
    """One load step of `solve_friction`, from the state the step before left."""
    kernel = request.discretization.kernel
    setup = prepare_contact(
        scene, kernel, aso.penetration_tol, timers, request.basis, frame=FRAME, friction=True
    )
    try:
        with timers("contact"):
            Bt, shift_t, tangent, free_t, moving = tangent_constraint(
                scene, setup, request.basis, kernel
            )
        el = setup.elasticity
        linear: DirectFriction | CondensedFriction
        if direct is not None:
            direct.bind(el.K, setup.B, Bt, el.f)
            linear = direct
        else:
            solver = setup_solver(setup, request.solver, scene, reuse=True, tangent=Bt)
            assert isinstance(solver, FrictionCondensedSolver)
            linear = CondensedFriction(solver)
        iteration = FrictionIteration(scene, setup, Bt, shift_t, free_t, linear)
        # The first set: the rows within h / 10 of touching, with the coarse predictor's (a
        # curved contact touching at one node would leave the body free to rotate).
        active = setup.initial_active(START_BAND * setup.h)
        if guess is not None:
            active = active | np.asarray(guess.active(setup.layout.x[setup.layout.mine]), bool)
        if before is not None:
            if len(before.active) != len(active):
                raise SolverError("the contact rows changed between load steps")
            active = active | before.active
            # A new step starts from stick wherever friction acts (as the first step does):
            # the increment is small, and starting from the last step's slip made an
            # unloading step cycle (tests/methods/test_friction.py, the pull back).
            iteration.sign, iteration.ut_prev = before.sign.copy(), before.ut.copy()
        try:
            step, active, history = run_active_set(setup, iteration, active, aso, timers)
        finally:
            Bt.destroy()
            if direct is None:
                linear.destroy()
        sol = finish(
            setup, request.method, scene, iteration.u, step.lam, step.gap, active, history, timers
        )
    finally:
        setup.destroy()
    sol.basis = request.basis
    status = np.where(active, iteration.status, Status.OPEN)
    comm = setup.comm
    sol.friction = FrictionResult(
        mu=np.concatenate(comm.allgather(iteration.mu)),
        shear=np.concatenate(comm.allgather(np.where(active, iteration.lam_t, 0.0))),
        slip=np.concatenate(comm.allgather(iteration.slip)),
        status=np.concatenate(comm.allgather(status)),
        tangent=tangent,
        tangent_motion=moving,
    )
    after = StepState(active, iteration.sign, iteration.slip * setup.w)
    return sol, after
