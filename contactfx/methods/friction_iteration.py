"""One frictional set's solve and the three-set update: the friction loop's Iteration.

methods/friction.py runs it over the load steps; the linear solves are
methods/friction_linear.py's (a direct LU or the condensed path).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..contact.friction import Epochs, RowState, Status, classify, damped_length, ncp
from ..discretize.setup import ContactSetup
from ..scenes import Scene
from .active_set import Proposal, Step
from .friction_linear import CondensedFriction, DirectFriction, FrictionAnswer, FrictionSystem


def pair_mu(scene: Scene) -> list[float]:
    """Each pair's mu, by pair index: the contact pairs, then the obstacles."""
    return [pair.mu for pair in scene.contacts] + [ob.mu for ob in scene.obstacles]


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
        # The iterate the next Newton step starts from (None: the first solve of the step)
        # and the cycle key's epoch.
        self.state: RowState | None = None
        self.epochs = Epochs()

    def key(self, active: np.ndarray) -> np.ndarray:
        """The rows' full set: contact, stick, and the slip direction (for cycle detection)."""
        rows = np.where(active, np.where(self.stick, 1, 2 + (self.sign > 0)), 0)
        return rows + 4 * self.epochs.epoch

    def solve(self, active: np.ndarray, it: int) -> Step:
        """One solve of the frictional saddle point on `active` and the friction sets."""
        setup, comm = self.setup, self.setup.comm
        # A row without a free tangential dof neither sticks nor slips: lambda_t = 0.
        stick = active & self.stick & self.free_t
        slip = active & ~self.stick & self.free_t
        coef = np.where(slip, self.mu * self.sign, 0.0)
        system = FrictionSystem(active, stick, coef, setup.g, self.shift_t - self.ut_prev)
        if isinstance(self.linear, CondensedFriction):
            # The loose answer decides the next set, as the frictionless condensed loop's
            # does; a set it leaves unchanged is solved on to the final tolerance in the
            # same Krylov run (docs/friction.md, "How it is solved").
            def stationary(loose: FrictionAnswer) -> bool:
                saved = self._saved()
                try:
                    trial = self._step(loose, active)
                    moved = comm.allreduce(int(np.sum(trial.new_active != active)))
                    return moved == 0 and trial.changed == 0 and not trial.damped
                finally:
                    self._restore(saved)

            answer = self.linear.solve(system, stationary)
        else:
            answer = self.linear.solve(system)
        self.krylov += answer.iterations
        return self._step(answer, active)

    def _saved(self) -> tuple[Any, ...]:
        """What `_step` changes (it assigns new arrays; the epochs it updates in place)."""
        return (self.state, self.epochs.epoch, self.epochs.best, self.stick, self.sign,
                self.lam_t, self.slip, self.status)  # fmt: skip

    def _restore(self, saved: tuple[Any, ...]) -> None:
        """Back to `_saved`'s state (a trial step on a loose answer leaves no trace)."""
        (self.state, self.epochs.epoch, self.epochs.best, self.stick, self.sign,
         self.lam_t, self.slip, self.status) = saved  # fmt: skip

    def _step(self, answer: FrictionAnswer, active: np.ndarray) -> Step:
        """The loop's step from one set's answer: the damped iterate and the three sets."""
        setup, comm = self.setup, self.setup.comm
        u, mu_n, mu_t = answer.u, answer.mu_n, answer.mu_t
        lam_n, lam_t = np.where(active, -mu_n, 0.0), np.where(active, mu_t, 0.0)
        w = setup.w
        start = self.u.x.petsc_vec.array_r.copy()
        target = self._rows(u, lam_n, lam_t)
        alpha = 1.0
        if self.state is not None:
            # The solve is the full semismooth Newton step from the last iterate; shortened
            # where it does not lower the complementarity residual (docs/friction.md, "How
            # it is solved"); the key's epoch: contact/friction.py, Epochs.
            alpha, before, after = damped_length(
                self.state, target, self.mu, self.c, self.c, w, lambda x: comm.allreduce(x)
            )
            self.epochs.update(before, after)
            if alpha < 1.0:
                lam = self.state.toward(target, alpha)
                target = self._rows(start + alpha * (u - start), lam.lam_n, lam.lam_t)
        self.state = target
        lam_n, lam_t, gap, inc = target.arrays()
        # A row held along its tangent does not slip: its weighted slip is its neighbour's.
        ut = np.where(self.free_t, self._slip(), self.ut_prev)
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
        record: dict[str, float] = {
            "stick": n_stick,
            "slip": n_slip,
            "friction_changed": n_changed,
            "step_length": alpha,
        }
        damped = f", step {alpha:g}" if alpha < 1.0 else ""
        text = (
            f"{n_stick} stick, {n_slip} slip, {n_changed} changed{damped}, "
            f"complementarity {resid:.2e}, {answer.iterations} linear its, "
        )
        return Step(
            lam_n,
            gap,
            new_active,
            float(resid),
            record,
            text,
            answer.final,
            n_changed + (alpha < 1.0),
        )

    def _rows(self, u: np.ndarray, lam_n: np.ndarray, lam_t: np.ndarray) -> RowState:
        """The rows' state of a solution `u` with its multipliers."""
        self.u.x.petsc_vec.array[:] = u
        self.u.x.scatter_forward()
        gap = self.setup.normalized_gap(self.u)
        ut = self._slip()
        inc = np.where(self.free_t, (ut - self.ut_prev) / self.setup.w, 0.0)  # fixed: no slip
        return RowState(lam_n, lam_t, gap, inc)

    def _slip(self) -> np.ndarray:
        """The rows' weighted tangential displacement B_t u (+ prescribed) of the iterate."""
        y = self.Bt.createVecLeft()
        self.Bt.mult(self.u.x.petsc_vec, y)
        ut = y.array_r + self.shift_t
        y.destroy()
        return ut

    def next_set(self, active: np.ndarray, step: Step, entered: int) -> Proposal | None:
        """The update's set (no probes on the frictional path)."""
        return None
