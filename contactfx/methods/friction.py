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
c_n = c_t = E_max / h (tractions against E times a strain: no user constant, no units). The
loop is the one of active_set.py: the normal set is its `active`, and a change of a row's
stick/slip status or slip direction keeps it going (`Step.changed`, `SetHistory.visit`'s key).
The slip increment is measured from the previous load step (quasi-static).

Supported: nts and mortar (standard and dual basis) with Lagrange multipliers on the direct
saddle-point path, dual mortar on the condensed path, every model, pairs between bodies and
against rigid obstacles (their rows along the obstacle's exact tangent; the obstacle's
prescribed motion enters the slip). The first step's first set adds the frictionless coarse
predictor's contact set where the scene can be remeshed. Refused in one line
(`refuse_friction`): sts, penalty, Schwarz, the fieldsplit solvers, the condensed solver on
nts or standard mortar.
With every mu = 0 nothing here runs: the frictionless path is unchanged.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..contact import ContactOperator, contact_operator, rigid_operator
from ..contact.friction import FrictionResult, Status, classify, ncp
from ..contact.sparse import CSR
from ..discretize.coupling import constrained_rows, global_dirichlet_dofs, petsc_constraint
from ..discretize.setup import ContactSetup, prepare_contact, prescribed_gap_shift
from ..errors import InputError, MeshError, SingularSystemError, SolverError
from ..linalg.condensed_friction import FrictionCondensedSolver
from ..options import Basis, Discretization, Enforcement, Predictor, SolverKind, System
from ..request import SolveRequest
from ..scenes import Scene
from ..scenes.steps import step_scenes
from ..timers import Timers
from .active_set import ActiveSetOptions, InitialSet, Proposal, Step, run_active_set
from .friction_linear import CondensedFriction, DirectFriction, FrictionSystem
from .predictor import predict
from .solution import Solution, finish
from .solvers import setup_solver

log = logging.getLogger("contactfx")

# The first set's band of normalized gaps, relative to the contact element size.
START_BAND = 0.1

# The rows' frame: the bisector of the two surfaces (contact/operator.bisector_normals). In
# the passive surface's frame, mirrored cylinders pressed with friction locked in a shear that
# their symmetry rules out, and the pushed stick zone sat off-centre (docs/friction.md).
FRAME = "bisector"

SUPPORTED = (
    "nts or mortar (standard or dual) with multipliers and a direct solver (mumps), or dual "
    "mortar with the condensed solver"
)


def pair_mu(scene: Scene) -> list[float]:
    """Each pair's mu, by pair index: the contact pairs, then the obstacles."""
    return [pair.mu for pair in scene.contacts] + [ob.mu for ob in scene.obstacles]


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
    dual = request.discretization is Discretization.MORTAR and request.basis is Basis.DUAL
    if request.enforcement is not Enforcement.MULTIPLIERS:
        why = f"the {request.enforcement.value} enforcement"
    elif request.discretization is Discretization.STS:
        why = "sts"
    elif request.solver.kind is SolverKind.CONDENSED and not dual:
        how = f"{request.discretization.value} ({request.basis.value} basis)"
        why = f"the {request.solver.name} solver on {how}, which needs dual mortar"
    elif request.solver.kind not in (SolverKind.DIRECT, SolverKind.AUTO, SolverKind.CONDENSED):
        why = f"the {request.solver.name} solver"
    if why:
        raise InputError(
            f"{_pair_label(scene, pairs[0])}: Coulomb friction is not solved with {why}; it "
            f"is solved by {SUPPORTED} (or set mu = 0)"
        )


def tangent_constraint(
    scene: Scene, setup: ContactSetup, basis: Basis, kernel: object
) -> tuple[PETSc.Mat, np.ndarray, CSR, np.ndarray, CSR | None]:
    """This rank's rows of B_t and the weighted slip that prescribed displacements add.

    B_t: the tangential rows of the same kernel, in the layout's order (owned rows); also
    all of them as a CSR, and which owned rows have a free tangential dof (a node on a
    symmetry line or the axis has none: it cannot slip, its row carries no shear). Against
    an obstacle the rows follow its exact tangent, and its prescribed rigid motion (this
    step's) enters the weighted slip: the body's motion relative to the obstacle; the last
    item is the rows' obstacle-motion columns (all rows, layout order; None: no obstacle).
    """
    el = setup.elasticity
    V = el.V
    ndofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    options: dict[str, object] = {"direction": "tangent", "frame": FRAME}
    if basis is Basis.DUAL:
        options["basis"] = basis
    ops, motion, columns = [], [], []
    for p in setup.pairs:
        if p.passive is None:
            assert p.obstacle is not None
            ob = p.obstacle
            rop = rigid_operator(kernel, p.active.surface, ob.geometry, ndofs, **options)  # type: ignore[arg-type]
            ops.append(rop.operator)
            motion.append(rop.motion @ np.asarray(ob.displacement, dtype=np.float64))
            columns.append(rop.motion)
        else:
            pas = p.passive.surface
            ops.append(contact_operator(kernel, p.active.surface, pas, ndofs, **options))  # type: ignore[arg-type]
            n = p.active.surface.n_nodes
            motion.append(np.zeros(n))
            empty = np.zeros(0, dtype=np.int64)
            columns.append(CSR.from_coo(empty, empty, np.zeros(0), (n, 2)))
    Bt = CSR.vstack([o.B for o in ops]) if len(ops) > 1 else ops[0].B
    op = ContactOperator(Bt, np.zeros(Bt.shape[0]), setup.operator.weights)
    dofs = np.vstack(
        [p.active.surface.dofs for p in setup.pairs]
        + [p.passive.surface.dofs for p in setup.pairs if p.passive is not None]
    )
    shift = prescribed_gap_shift(scene, el, op, dofs) + np.concatenate(motion)
    dirichlet = global_dirichlet_dofs(V, el.bc_dofs)
    B = petsc_constraint(V, op, setup.order, setup.layout, dirichlet)
    mine = setup.order[setup.layout.mine]
    moving = CSR.vstack(columns).rows(setup.order) if scene.obstacles else None
    return B, shift[mine], Bt.rows(setup.order), constrained_rows(op, dirichlet)[mine], moving


def _vec(comm: MPI.Comm, values: np.ndarray) -> PETSc.Vec:
    """A distributed vector holding this rank's `values`."""
    v = PETSc.Vec().createMPI((len(values), PETSc.DETERMINE), comm=comm)  # type: ignore[arg-type]
    v.array[:] = values
    return v


class FrictionIteration:
    """Frictional saddle-point solves on a set, and the three-set update (the loop's Iteration)."""

    label = "friction"
    probing = False

    def __init__(
        self,
        scene: Scene,
        setup: ContactSetup,
        Bt: PETSc.Mat,
        shift_t: np.ndarray,
        free_t: np.ndarray,
        linear: DirectFriction | CondensedFriction,
    ) -> None:
        self.setup, self.Bt, self.shift_t, self.free_t = setup, Bt, shift_t, free_t
        self.linear = linear
        self.krylov = 0
        layout = setup.layout
        mus = pair_mu(scene)
        self.mu = np.array([mus[int(k)] for k in layout.pair[layout.mine]])
        self.c = setup.e_max / setup.h
        m = len(layout.mine)
        # The first set sticks wherever friction acts; the sign of a slip row is its tau's.
        self.stick = self.mu > 0.0
        self.sign = np.ones(m)
        self.ut_prev = np.zeros(m)  # the weighted slip at the previous load step
        self.u = fem.Function(setup.elasticity.V, name="u")
        self.lam_t = np.zeros(m)
        self.slip = np.zeros(m)
        self.status = np.zeros(m, dtype=np.int64)
        self.offset = layout.offset

    def key(self, active: np.ndarray) -> np.ndarray:
        """The rows' full set: contact, stick, and the slip direction (for cycle detection)."""
        return np.where(active, np.where(self.stick, 1, 2 + (self.sign > 0)), 0)

    def solve(self, active: np.ndarray, it: int) -> Step:
        """One solve of the frictional saddle point on `active` and the friction sets."""
        setup, comm = self.setup, self.setup.comm
        # A row without a free tangential dof neither sticks nor slips: lambda_t = 0.
        stick = active & self.stick & self.free_t
        slip = active & ~self.stick & self.free_t
        coef = np.where(slip, self.mu * self.sign, 0.0)
        system = FrictionSystem(active, stick, coef, setup.g, self.shift_t - self.ut_prev)
        answer = self.linear.solve(system)
        self.krylov += answer.iterations
        u, mu_n, mu_t = answer.u, answer.mu_n, answer.mu_t
        self.u.x.petsc_vec.array[:] = u
        self.u.x.scatter_forward()
        lam_n, lam_t = np.where(active, -mu_n, 0.0), np.where(active, mu_t, 0.0)
        gap = setup.normalized_gap(self.u)
        y = self.Bt.createVecLeft()
        self.Bt.mult(self.u.x.petsc_vec, y)
        ut = y.array_r + self.shift_t
        y.destroy()
        w = setup.w
        inc = np.where(self.free_t, (ut - self.ut_prev) / w, 0.0)  # fixed rows: no slip
        status = classify(lam_n, lam_t, gap, inc, self.mu, self.c, self.c)
        tau = lam_t + self.c * inc
        new_active = status != Status.OPEN
        new_stick = status == Status.STICK
        new_sign = np.where(status == Status.SLIP, np.where(tau >= 0.0, 1.0, -1.0), self.sign)
        changed = (
            new_active
            & active
            & ((new_stick != self.stick) | (~new_stick & (new_sign != self.sign)))
        )
        n_changed = comm.allreduce(int(changed.sum()))
        self.stick = np.where(new_active, new_stick, self.stick)
        self.sign = new_sign
        cn, ct = ncp(lam_n, lam_t, gap, inc, self.mu, self.c, self.c)
        lam_max = comm.allreduce(float(np.abs(lam_n).max(initial=0.0)), op=MPI.MAX)
        resid = np.sqrt(comm.allreduce(float(np.sum(w * (cn**2 + ct**2)))))
        resid /= max(lam_max * np.sqrt(comm.allreduce(float(w.sum()))), 1e-300)
        self.lam_t, self.slip, self.status = lam_t, ut / w, status
        n_stick = comm.allreduce(int(np.sum(status == Status.STICK)))
        n_slip = comm.allreduce(int(np.sum(status == Status.SLIP)))
        record: dict[str, float] = {"stick": n_stick, "slip": n_slip, "friction_changed": n_changed}
        text = f"{n_stick} stick, {n_slip} slip, {n_changed} changed, complementarity {resid:.2e}, "
        return Step(lam_n, gap, new_active, float(resid), record, text, True, n_changed)

    def next_set(self, active: np.ndarray, step: Step, entered: int) -> Proposal | None:
        """The update's set (no probes on the frictional path)."""
        return None


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
    sols: list[Solution] = []
    state: StepState | None = None
    condensed = request.solver.traits.system is System.CONDENSED
    # One LU for the whole load history: its pattern and analysis outlive the steps.
    direct = None if condensed else DirectFriction()
    scenes = step_scenes(scene)
    # The frictionless coarse predictor's contact set joins the first step's first set (a
    # frictional set differs from it by the stick and slip zones): fewer sets to visit.
    # No probes here: the coarse solve pays wherever the scene can be remeshed.
    coarse = request.predictor is Predictor.AUTO and scenes[0].can_remesh
    try:
        guess = predict(
            scenes[0],
            replace(request, predictor=Predictor.COARSE) if coarse else request,
            aso,
            timers,
        )
    except SingularSystemError as err:
        raise SingularSystemError(f"{err} (friction does not hold a body yet)") from None
    except MeshError as err:  # a geometry gmsh cannot mesh coarser: start without the guess
        if scene.comm.rank == 0:
            log.info("coarse predictor: %s; starting without it", err)
        guess = None
    try:
        for k, step_scene in enumerate(scenes):
            sol, state = _solve_step(step_scene, request, timers, aso, state, direct, guess)
            guess = None
            if scene.steps and scene.comm.rank == 0:
                log.info("step %d: %d iterations", k + 1, sol.iterations)
            sols.append(sol)
    finally:
        if direct is not None:
            direct.destroy()
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
    try:
        setup = prepare_contact(
            scene, kernel, aso.penetration_tol, timers, request.basis, frame=FRAME
        )
    except SingularSystemError as err:
        raise SingularSystemError(f"{err} (friction does not hold a body yet)") from None
    except MeshError as err:  # a geometry gmsh cannot mesh coarser: start without the guess
        if scene.comm.rank == 0:
            log.info("coarse predictor: %s; starting without it", err)
        guess = None
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
        # The first set: the rows within h / 10 of touching (no predictor on this path; a
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
