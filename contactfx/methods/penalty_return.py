"""Penalty friction's return map at a displacement, its residual and the line searches.

The regularized Coulomb law of penalty_friction.py makes the discrete problem a nonsmooth
equation in the displacement alone, R(u) = K u - f - B_n^T p(u) + B_t^T lambda_t(u) = 0, with
p and lambda_t the return map of u: piecewise linear, one piece per set. Newton's step on
the piece of u is the solve on u's set; `ReturnMap.search` damps it by Armijo's rule on |R|
(the damped Newton method for B-differentiable equations: Pang, Math. Oper. Res. 15 (1990)
311-341; for frictional contact Christensen, Klarbring, Pang and Stromberg, IJNME 42 (1998)
145-173). With the bound mu p fixed (Tresca's problem) R is the gradient of a convex energy,
`ReturnMap.energy`, whose decrease a line search can always get.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..discretize.setup import ContactSetup
from .cleanup import released
from .penalty import transposed

ARMIJO = 1e-4
"""Armijo's sufficient decrease of the residual norm per unit step length."""
MAX_HALVINGS = 12
"""Step halvings of the Coulomb step before the Tresca-Coulomb fixed point takes over."""
MAX_HALVINGS_TRESCA = 30
"""Step halvings of a Tresca step (its energy falls along it: round-off stops it)."""


@dataclass(frozen=True)
class Point:
    """An iterate (owned dofs) and the return map there (owned rows), with |R|."""

    x: np.ndarray
    gap: np.ndarray
    ut: np.ndarray
    contact: np.ndarray
    stick: np.ndarray
    sign: np.ndarray
    lam_t: np.ndarray
    norm: float
    trial: np.ndarray


class ReturnMap:
    """The return map, R and Tresca's energy at a displacement (owned dofs and rows)."""

    def __init__(
        self,
        setup: ContactSetup,
        tangential: tuple[PETSc.Mat, np.ndarray, np.ndarray],
        eps: float,
        mu: np.ndarray,
    ) -> None:
        self.setup, self.eps_n, self.eps_t, self.mu = setup, eps, eps, mu
        self.Bt, self.shift_t, self.free_t = tangential
        # B_n^T and B_t^T: the same in every solve of the step (freed by `destroy`).
        self.BnT, self.BtT = transposed(setup.B), transposed(self.Bt)
        m = len(setup.layout.mine)
        self.ut_prev = np.zeros(m)
        self.shear_prev = np.zeros(m)
        self.point: Point | None = None  # the current iterate (None before the first solve)
        self.bound: np.ndarray | None = None  # Tresca's fixed mu p (None: Newton on Coulomb)

    def destroy(self) -> None:
        """Free the transposes."""
        self.BnT.destroy()
        self.BtT.destroy()

    def residual(self, X: PETSc.Vec, contact: np.ndarray, lam_t: np.ndarray) -> PETSc.Vec:
        """R = K x - f + B_n^T (eps_n g on the rows in contact) + B_t^T lam_t at X.

        It is the set's A x - rhs where the set is x's own (penalty_friction.py's docstring).
        """
        setup, el = self.setup, self.setup.elasticity
        r, tmp = el.K.createVecLeft(), el.K.createVecLeft()
        yn, yt = setup.B.createVecLeft(), self.Bt.createVecLeft()
        with released(setup.comm, tmp, yn, yt):
            el.K.mult(X, r)
            r.axpy(-1.0, el.f)
            setup.B.mult(X, yn)
            yn.array[:] = np.where(contact, self.eps_n * (setup.g + yn.array_r) / setup.w, 0.0)
            self.BnT.mult(yn, tmp)
            r.axpy(1.0, tmp)
            yt.array[:] = np.where(self.mu > 0.0, lam_t, 0.0)
            self.BtT.mult(yt, tmp)
            r.axpy(1.0, tmp)
        return r

    def at(self, x: np.ndarray) -> Point:
        """The return map at the displacement `x` (owned dofs) and the residual R(x)'s norm."""
        setup, w = self.setup, self.setup.w
        X = setup.elasticity.K.createVecRight()
        X.array[:] = x
        yn, yt = setup.B.createVecLeft(), self.Bt.createVecLeft()
        with released(setup.comm, X, yn, yt):
            setup.B.mult(X, yn)
            self.Bt.mult(X, yt)
            gap = (setup.g + yn.array_r) / w
            # A row held along its tangent does not slip (discretize/tangents.held_rows).
            ut = np.where(self.free_t, yt.array_r + self.shift_t, self.ut_prev)
            p = -self.eps_n * gap
            contact = gap < 0.0
            trial = np.where(
                self.free_t, self.shear_prev + self.eps_t * (ut - self.ut_prev) / w, 0.0
            )
            stick = np.abs(trial) < self.mu * p
            sign = np.where(trial >= 0.0, 1.0, -1.0)
            lam_t = np.where(contact, np.where(stick, trial, self.mu * p * sign), 0.0)
            r = self.residual(X, contact, lam_t)
            norm = float(np.real(r.norm()))
            r.destroy()
        return Point(x, gap, ut, contact, stick, sign, lam_t, norm, trial)

    def search(self, x: np.ndarray) -> tuple[Point, float]:
        """The iterate along the Newton step to the set's solution `x`, and its length.

        Armijo's rule on the residual: the first of t = 1, 1/2, ... 1/2^MAX_HALVINGS with
        |R(u + t d)| <= (1 - 1e-4 t) |R(u)|; 0 (the iterate stays) where none is.
        """
        full = self.at(x)
        here = self.point
        assert here is not None
        if full.norm <= (1.0 - ARMIJO) * here.norm:
            return full, 1.0
        d, t = x - here.x, 1.0
        for _ in range(MAX_HALVINGS):
            t *= 0.5
            cut = self.at(here.x + t * d)
            if cut.norm <= (1.0 - ARMIJO * t) * here.norm:
                return cut, t
        return here, 0.0

    def energy(self, x: np.ndarray, bound: np.ndarray) -> tuple[float, PETSc.Vec, Point]:
        """Tresca's energy at `x` with the fixed bound, its gradient R_T, and the point.

        The point's stick and sign are Tresca's set (by the bound, not by mu p).
        """
        setup, el, w = self.setup, self.setup.elasticity, self.setup.w
        pt = self.at(x)
        z = pt.trial
        stick = np.abs(z) < bound
        sign = np.where(z >= 0.0, 1.0, -1.0)
        lam = np.where(stick, z, bound * sign)
        huber = np.where(stick, 0.5 * z * z, bound * np.abs(z) - 0.5 * bound * bound)
        X, Kx = el.K.createVecRight(), el.K.createVecLeft()
        X.array[:] = x
        with released(setup.comm, X, Kx):
            el.K.mult(X, Kx)
            r = self.residual(X, pt.contact, lam)
            local = 0.5 * float(Kx.array_r @ x) - float(el.f.array_r @ x)
        gn = np.minimum(pt.gap, 0.0)
        local += float(np.sum(0.5 * self.eps_n * w * gn * gn + (w / self.eps_t) * huber))
        energy = setup.comm.allreduce(local)
        tset = replace(pt, stick=stick, sign=sign)
        return energy, r, tset

    def fixed(self, pt: Point) -> bool:
        """Whether the bound is the iterate's mu p to round-off: the fixed point."""
        assert self.bound is not None
        mup = self.mu * np.where(pt.contact, -self.eps_n * pt.gap, 0.0)
        comm = self.setup.comm
        diff = comm.allreduce(float(np.max(np.abs(mup - self.bound), initial=0.0)), op=MPI.MAX)
        scale = comm.allreduce(float(np.max(mup, initial=0.0)), op=MPI.MAX)
        return diff <= 1e-12 * scale
