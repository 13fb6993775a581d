"""Coulomb friction by penalty (regularized Coulomb): the approximate baseline of the multipliers.

The normal side is the frictionless penalty's (methods/penalty.py): a node in contact where
its nodal gap g_j < 0 carries p_j = -eps_n g_j. Beside it each row has a tangential
stiffness eps_t and a return map on its nodal slip s_j = (B_t u + shift)_j / w_j (the
tangential rows of the same kernel as the multipliers', contact/friction.py's sign: the
traction on the active body is -lambda_t t):

    trial:  t_j = lambda_t,old + eps_t (s_j - s_j,old)      (the previous load step's values)
    stick:  |t_j| < mu p_j       lambda_t = t_j             (an elastic slip t_j / eps_t)
    slip:   otherwise            lambda_t = mu p_j sign(t_j)

With a row's set (open, stick, slip and its direction) fixed, lambda_t is linear in u and the
set's system is K + B_n^T (eps_n / w) B_n + B_t^T (eps_t / w) B_t on stick rows and
+ B_t^T (-mu s eps_n / w) B_n on slip rows: the consistent tangent of the return map (in 2D
the direction's derivative vanishes), unsymmetric where a row slips: factored by LU then,
by the request's factorization (LDL^T by default) while no row slips. The loop is
active_set.py's; it stops when the solution's set is the set solved (its residual R below
is then 0 to round-off). Three stages, each from where the one before left:

1. Full steps: the set of the solution is the next set (a slipping row whose trial turns
   against its direction sticks first), as long as no set comes back. With eps_t per row
   far stiffer than the bodies (1e3 E / h), releasing a row can move its neighbours' trials
   past the cone, and on coarse meshes the sets cycle (the blocks with 1 cm elements).
2. From the iterate u whose next set was solved before: the set is u's own and its solve is
   the semismooth Newton step of the piecewise linear R(u) = K u - f - B_n^T p(u) +
   B_t^T lambda_t(u), damped by Armijo's rule on |R| (penalty_return.py; Pang 1990, the
   damped Newton method for B-differentiable equations, as Christensen, Klarbring, Pang and
   Stromberg 1998 apply it to frictional contact). |R| falls at every step, so no iterate
   comes back.
3. Where no step of 1/2^MAX_HALVINGS or longer lowers |R| (an iterate at a kink of |R|, a
   row at the cone's edge): the Tresca-Coulomb fixed point. With the bound mu p of the
   iterate frozen, Tresca's problem is the minimum of a convex energy (a Huber term per
   row); Newton steps on it with Armijo's rule on that energy (each a descent direction,
   the matrix symmetric) until its set stays; then the Coulomb set's own solve ends the
   step if its set is its own, else the bound takes the new mu p (the outer fixed point:
   a contraction for small mu, Necas, Jarusek and Haslinger 1980).

The counts on the built-in blocks are in docs/friction.md, "The penalty baseline". The
history carried from step to step is the traction lambda_t and the slip s at the step's end
(an open row keeps none: its lambda_t is 0).

eps_t = eps_n = the request's penalty, by default 1e3 E_max / h (penalty.default_penalty):
both are stiffnesses per unit area of the interface, and the stick state's elastic slip
shear / eps_t is then of the penetration's size (docs/friction.md, "The penalty baseline").
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..contact.friction import FrictionResult, Status
from ..discretize.setup import ContactSetup, prepare_contact
from ..errors import SingularSystemError, SolverError
from ..request import SolveRequest
from ..scenes import Scene
from ..timers import Timers
from .active_set import ActiveSetOptions, Proposal, Step, run_active_set
from .cleanup import released
from .friction import FRAME, in_steps, pair_mu, tangent_constraint
from .penalty import (
    DIFFERENT,
    add_product,
    default_penalty,
    factor_solve,
    penetration,
    scaled_rows,
)
from .penalty_return import ARMIJO, MAX_HALVINGS_TRESCA, Point, ReturnMap
from .solution import PenaltyResult, Solution, finish


def lu_options(petsc: Mapping[str, object]) -> dict[str, object]:
    """The request's factorization as LU: the frictional system is unsymmetric where a row slips."""
    return {**petsc, "pc_type": "lu"} if petsc.get("pc_type") == "cholesky" else dict(petsc)


@dataclass(frozen=True)
class PenaltyState:
    """What a converged load step hands the next (owned rows)."""

    active: np.ndarray
    sign: np.ndarray
    ut: np.ndarray  # the weighted slip B_t u (+ prescribed) at its end
    shear: np.ndarray  # lambda_t at its end (0 where open)


class PenaltyFrictionIteration(ReturnMap):
    """Penalty solves on a set (open, stick, slip and direction) and the return map's update."""

    label = "penalty friction"
    probing = False

    def __init__(
        self,
        scene: Scene,
        setup: ContactSetup,
        tangential: tuple[PETSc.Mat, np.ndarray, np.ndarray],
        eps: float,
        options: Mapping[str, object],
    ) -> None:
        mus = pair_mu(scene)
        layout = setup.layout
        super().__init__(
            setup, tangential, eps, np.array([mus[int(k)] for k in layout.pair[layout.mine]])
        )
        self.options, self.lu = options, lu_options(options)
        m = len(layout.mine)
        # The first set sticks wherever friction acts (as the multipliers' does).
        self.stick = self.mu > 0.0
        self.sign = np.ones(m)
        self.u = fem.Function(setup.elasticity.V, name="u")
        self.lam_t = np.zeros(m)
        self.slip = np.zeros(m)
        self.status = np.zeros(m, dtype=np.int64)
        self.probe = False  # Tresca's problem is solved: try the Coulomb set's solution
        self.plain = True  # full steps to each set's solution until a set comes back
        self.seen: set[bytes] = set()  # the sets the plain iteration solved

    def key(self, active: np.ndarray) -> np.ndarray:
        """The rows' full set: contact, stick, and the slip direction (for cycle detection)."""
        return np.where(active, np.where(self.stick, 1, 2 + (self.sign > 0)), 0)

    def _system(
        self, active: np.ndarray, bound: np.ndarray | None = None
    ) -> tuple[PETSc.Mat, PETSc.Vec, bool]:
        """The set's matrix and right-hand side (module docstring), whether a row slips.

        A slipping row makes the matrix unsymmetric. `bound`: Tresca's problem, the slip
        rows carry bound * sign, fixed (the matrix is symmetric); only rows with a bound stick.

        Without a stick or slip row carrying a shear (mu = 0, or every row open) the system
        is the frictionless penalty's, assembled as it is.
        """
        setup, el = self.setup, self.setup.elasticity
        w, g0 = setup.w, setup.g
        rubs = self.free_t & (self.mu > 0.0)  # a row that can carry a shear
        if bound is None:
            stick = active & self.stick & rubs
            slip = active & ~self.stick & rubs
            fixed = np.zeros_like(w)
        else:
            stick = self.stick & rubs & (bound > 0.0)
            slip = np.zeros_like(stick)
            fixed = np.where(rubs & ~stick, bound * self.sign, 0.0)
        cn = np.where(active, self.eps_n / w, 0.0)
        ctt = np.where(stick, self.eps_t / w, 0.0)
        ctn = np.where(slip, -self.mu * self.sign * self.eps_n / w, 0.0)
        comm = setup.comm
        slips = comm.allreduce(bool(slip.any()), op=MPI.LOR)
        sheared = slips or comm.allreduce(bool(stick.any() or fixed.any()), op=MPI.LOR)
        Bn, Bt = setup.B, self.Bt
        BnT, BtT, An = self.BnT, self.BtT, scaled_rows(Bn, cn)
        A = add_product(None, BnT, An)
        rhs = el.f.copy()
        dn, tmp = Bn.createVecLeft(), rhs.duplicate()
        dn.array[:] = -cn * g0
        with released(comm, An, dn, tmp):
            BnT.mult(dn, tmp)
            rhs.axpy(1.0, tmp)
            if sheared:
                # Stick rows' lambda_t = a + (eps_t / w) B_t u; slip rows' = ctn (g0 + B_n u).
                a = self.shear_prev + self.eps_t * (self.shift_t - self.ut_prev) / w
                M, Mn = scaled_rows(Bt, ctt), scaled_rows(Bn, ctn)
                dt = Bt.createVecLeft()
                dt.array[:] = -np.where(stick, a, 0.0) - ctn * g0 - fixed
                with released(comm, M, Mn, dt):
                    M.axpy(1.0, Mn, structure=DIFFERENT)
                    A = add_product(A, BtT, M)
                    BtT.mult(dt, tmp)
                    rhs.axpy(1.0, tmp)
        A.axpy(1.0, el.K, structure=DIFFERENT)
        return A, rhs, slips

    def _tresca(self, active: np.ndarray) -> tuple[Point, float, dict[str, float], bool]:
        """One Newton step on Tresca's problem (the bound mu p fixed): Armijo on its energy.

        Returns the iterate, the step length, the solve's info and whether Tresca's set
        (contact, stick, direction) stayed: the inner problem is solved.
        """
        here, bound = self.point, self.bound
        assert here is not None and bound is not None
        e0, r0, t0 = self.energy(here.x, bound)
        self.stick, self.sign = t0.stick, t0.sign
        A, rhs, _ = self._system(active, bound)
        x, info = factor_solve(A, rhs, self.options)
        d = x - here.x
        D = r0.duplicate()
        D.array[:] = d
        slope = float(np.real(r0.dot(D)))
        with released(self.setup.comm, r0, D):
            t = 1.0
            for _ in range(MAX_HALVINGS_TRESCA):
                e, r, pt = self.energy(here.x + t * d, bound)
                r.destroy()
                same = bool(
                    self.setup.comm.allreduce(
                        bool(
                            np.array_equal(pt.contact, t0.contact)
                            and np.array_equal(pt.stick, t0.stick)
                            and np.array_equal(pt.sign[~pt.stick], t0.sign[~t0.stick])
                        ),
                        op=MPI.LAND,
                    )
                )
                if (t == 1.0 and same) or e <= e0 + ARMIJO * t * slope:
                    break
                t *= 0.5
        return self.at(here.x + t * d), t, info, t == 1.0 and same

    def solve(self, active: np.ndarray, it: int) -> Step:
        """One factorization on `active` and its friction sets; the next set by the return map.

        Full steps to the set's solution while no set comes back; then a Newton step on the
        Coulomb set with a line search on |R|; where none lowers |R|, the Tresca-Coulomb
        fixed point (module docstring).
        """
        done, t, stay, solved = False, 1.0, False, b""
        if self.bound is not None and not self.probe:
            pt, t, info, inner = self._tresca(active)
            self.probe = inner
            stay = True
        else:
            A, rhs, slips = self._system(active)
            x, info = factor_solve(A, rhs, self.lu if slips else self.options)
            if self.plain:
                solved = self._global_key(active)
                self.seen.add(solved)
                pt = self.at(x)
            elif self.probe:
                # The Tresca problem is solved: the Coulomb set's solution ends the step if
                # its set is its own; else the bound takes the iterate's mu p.
                assert self.point is not None
                full = self.at(x)
                if self._keeps(full, active):
                    pt, done = full, True
                else:
                    pt, stay = self.point, True
                    done = self.fixed(pt)
                    self.bound = self.mu * np.where(pt.contact, -self.eps_n * pt.gap, 0.0)
                    self.probe = False
            else:
                pt, t = self.search(x)
                if t == 0.0:
                    # No step lowers |R| (an iterate at a kink of |R|, a row at the cone's
                    # edge): the Tresca-Coulomb fixed point from this iterate.
                    self.bound = self.mu * np.where(pt.contact, -self.eps_n * pt.gap, 0.0)
                    stay = True
        step = self._step(active, pt, t, info, done, stay)
        after = self._global_key(step.new_active) if self.plain else b""
        if self.plain and after != solved and after in self.seen:
            # The next set was solved before: a cycle of full steps. From this iterate on,
            # the next set is its own (no reversal through stick) and steps are searched.
            self.plain = False
            self.stick = np.where(pt.contact, pt.stick, self.stick)
            self.sign = np.where(pt.contact & ~pt.stick, pt.sign, self.sign)
            step.changed = max(step.changed, 1)
        return step

    def _global_key(self, active: np.ndarray) -> bytes:
        """The whole set on every rank (cycle detection of the plain iteration)."""
        keys = self.setup.comm.allgather((self.setup.layout.mine, self.key(active)))
        out = np.zeros(self.setup.layout.size, dtype=np.int64)
        for idx, vals in keys:
            out[idx] = vals
        return out.tobytes()

    def _keeps(self, pt: Point, active: np.ndarray) -> bool:
        """Whether `pt`'s Coulomb set is the one solved (contact, stick, direction)."""
        same = (
            np.array_equal(pt.contact, active)
            and np.array_equal(pt.stick[active], self.stick[active])
            and np.array_equal((pt.sign * ~pt.stick)[active], (self.sign * ~self.stick)[active])
        )
        return bool(self.setup.comm.allreduce(bool(same), op=MPI.LAND))

    def _step(
        self,
        active: np.ndarray,
        pt: Point,
        t: float,
        info: dict[str, float],
        done: bool,
        stay: bool,
    ) -> Step:
        """Take the iterate `pt`: its Coulomb set is the next; the loop's Step."""
        setup, comm = self.setup, self.setup.comm
        self.point = pt
        self.u.x.petsc_vec.array[:] = pt.x
        self.u.x.scatter_forward()
        gap, contact, stick, sign = pt.gap, pt.contact, pt.stick, pt.sign
        if self.plain:
            # A row solved as slipping whose trial turns against its direction sticks next:
            # a reversal passes through stick (without it, the pull back of
            # tests/methods/test_penalty_friction.py's steps cycled).
            stick = stick | (active & ~self.stick & ~stick & (sign != self.sign) & (self.mu > 0))
        changed = contact & active & ((stick != self.stick) | (~stick & (sign != self.sign)))
        n_changed = 0 if done else comm.allreduce(int(changed.sum()))
        self.stick = np.where(contact, stick, self.stick)
        self.sign = np.where(contact & ~stick, sign, self.sign)
        self.lam_t, self.slip = pt.lam_t, pt.ut / setup.w
        self.status = np.where(contact, np.where(stick, Status.STICK, Status.SLIP), Status.OPEN)
        pen = max(comm.allreduce(float(np.max(-gap, initial=0.0)), op=MPI.MAX), 0.0)
        n_stick = comm.allreduce(int(np.sum(self.status == Status.STICK)))
        n_slip = comm.allreduce(int(np.sum(self.status == Status.SLIP)))
        record: dict[str, float] = {
            "stick": n_stick,
            "slip": n_slip,
            "friction_changed": n_changed,
            "penetration": pen,
            "penalty": self.eps_n,
            "step_length": t,
            "tresca": float(self.bound is not None),
            **info,
        }
        text = f"{n_stick} stick, {n_slip} slip, {n_changed} changed, max penetration {pen:.3e}, "
        text += "" if t == 1.0 else f"step {t:g}, "
        text += "tresca, " if self.bound is not None and not done else ""
        damped = (t < 1.0 or stay) and not done
        return Step(
            -self.eps_n * gap, gap, contact, 0.0, record, text, True, n_changed, True, damped
        )

    def next_set(self, active: np.ndarray, step: Step, entered: int) -> Proposal | None:
        """The return map's set."""
        return None


def solve_penalty_friction(
    scene: Scene, request: SolveRequest, timers: Timers, aso: ActiveSetOptions
) -> Solution:
    """Solve `scene` with regularized Coulomb friction by penalty, step by step.

    `refuse_friction` has passed (nts or mortar). eps_t = eps_n (the module's docstring).
    """
    return in_steps(scene, lambda s, before: _solve_step(s, request, timers, aso, before))


def _solve_step(
    scene: Scene,
    request: SolveRequest,
    timers: Timers,
    aso: ActiveSetOptions,
    before: PenaltyState | None,
) -> tuple[Solution, PenaltyState]:
    """One load step of `solve_penalty_friction`, from the state the step before left."""
    kernel = request.discretization.kernel
    try:
        setup = prepare_contact(scene, kernel, aso.penetration_tol, timers, frame=FRAME)
    except SingularSystemError as err:
        raise SingularSystemError(f"{err} (friction does not hold a body yet)") from None
    with released(scene.comm, setup):
        eps = default_penalty(setup.e_max, setup.h) if request.penalty is None else request.penalty
        with timers("contact"):
            Bt, shift_t, tangent, free_t, moving = tangent_constraint(
                scene, setup, request.basis, kernel
            )
        iteration = PenaltyFrictionIteration(
            scene, setup, (Bt, shift_t, free_t), eps, request.solver.petsc
        )
        with released(scene.comm, Bt, iteration):
            active = setup.initial_active(aso.penetration_tol * setup.h)
            if before is not None:
                if len(before.active) != len(active):
                    raise SolverError("the contact rows changed between load steps")
                active = active | before.active
                iteration.sign, iteration.ut_prev = before.sign.copy(), before.ut.copy()
                iteration.shear_prev = before.shear.copy()
            step, active, history = run_active_set(setup, iteration, active, aso, timers)
        sol = finish(
            setup, request.method, scene, iteration.u, step.lam, step.gap, active, history, timers
        )
        w = setup.w
    sol.penalty = PenaltyResult(eps, penetration(sol))
    comm = scene.comm
    status = np.where(active, iteration.status, Status.OPEN)
    shear = np.where(active, iteration.lam_t, 0.0)
    sol.friction = FrictionResult(
        mu=np.concatenate(comm.allgather(iteration.mu)),
        shear=np.concatenate(comm.allgather(shear)),
        slip=np.concatenate(comm.allgather(iteration.slip)),
        status=np.concatenate(comm.allgather(status)),
        tangent=tangent,
        tangent_motion=moving,
    )
    return sol, PenaltyState(active, iteration.sign, iteration.slip * w, shear)
