"""Coulomb friction on the condensed path: GMRES on W^T K T, the multigrid of T^T K T.

linalg/node_blocks.py eliminates the active multipliers node by node (dual basis: D
diagonal): T from the constraint rows (normal where in contact, tangential where sticking),
W from the force rows (on a slipping node the normal row plus the tangential one times -mu s).
The displacement system W^T K T v = W^T (f - K t) is unsymmetric where nodes slip; GMRES
solves it, applied matrix-free, right-preconditioned by the condensed solver's multigrid
built on the symmetric T^T K T (the two differ by a term of the slipping nodes' rank).
The multipliers are recovered from the residual at the pivots, as the frictionless
condensed solver does.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from petsc4py import PETSc

from ..errors import SolverError
from .condensed import CondensedSolver
from .elimination import (
    CondensedOperator,
    LocalRows,
    elimination_matrix,
    t_mult,
    t_mult_transpose,
)
from .node_blocks import NodeBlocks, node_blocks
from .petsc_options import petsc_error_message

# GMRES keeps every direction of a solve: the preconditioned operator differs from the
# identity by the slipping nodes' rank, and a restart would lose what CG's recurrence keeps.
RESTART = 300


@dataclass(frozen=True)
class FrictionSolve:
    """One frictional condensed solve: owned u, mu_n, mu_t, and what it cost."""

    u: np.ndarray
    mu_n: np.ndarray
    mu_t: np.ndarray
    iterations: int
    setup: float
    solve: float
    final: bool = True  # solved to the final tolerance (else the loop's loose answer)


class _Cycle:
    """A petsc4py Python PC: one application of an inner (preonly) KSP."""

    def __init__(self, inner: PETSc.KSP) -> None:
        self._inner = inner

    def apply(self, pc: PETSc.PC, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """Apply the inner preconditioner to x, into y."""
        self._inner.solve(x, y)


class FrictionCondensedSolver(CondensedSolver):
    """The condensed solver with tangential rows `Bt` beside B's normal ones (same layout).

    A set keeps the multigrid of an earlier one while its pivots have moved in few places
    (`CondensedSolver._keeps_multigrid`: each change costs GMRES about one iteration, a
    new setup several); W is applied matrix-free and never enters the multigrid.
    """

    def __init__(self, *args: Any, Bt: PETSc.Mat, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._t_rows = LocalRows.of(Bt, self._rows.node_dofs)
        # GMRES outside; the multigrid (one cycle: the inherited KSP, preonly) on S inside.
        outer = PETSc.KSP().create(self._comm)
        outer.setType(PETSc.KSP.Type.GMRES)
        outer.setGMRESRestart(RESTART)
        outer.setPCSide(cast(Any, PETSc.PC.Side.RIGHT))
        outer.setNormType(cast(Any, PETSc.KSP.NormType.UNPRECONDITIONED))
        outer.setTolerances(rtol=self._rtol, max_it=5000)
        pc = outer.getPC()
        pc.setType(PETSc.PC.Type.PYTHON)
        pc.setPythonContext(_Cycle(self._ksp))
        outer.addConvergenceTest(cast(Any, self._check.test), prepend=True)
        self._outer = outer

    def destroy(self) -> None:
        """Free the PETSc objects."""
        self._outer.destroy()
        super().destroy()

    def solve_sets(
        self,
        g: tuple[np.ndarray, np.ndarray],
        active: np.ndarray,
        stick: np.ndarray,
        coef: np.ndarray,
        stationary: Callable[[FrictionSolve], bool] | None = None,
    ) -> FrictionSolve:
        """Solve on a frictional set (owned rows), to the final tolerance or the loop's.

        `g` = (g_n, g_t): B_n u = -g_n on `active`, B_t u = -g_t on `stick`; `coef`: a
        slipping row's mu_t = coef mu_n. With `stationary` the loose answer is asked inside
        the GMRES run (as the frictionless loop's is inside CG's): where it says True the
        run goes on to the final tolerance, else it stops there (`final` False).
        """
        t0 = time.perf_counter()
        nb = node_blocks(self._rows, self._t_rows, active, stick, coef, g, self._mpi, self._r0)
        nglob = self._K.getSize()[0]
        ip: Any = nb.dofs.astype(PETSc.IntType)
        EC = elimination_matrix(nb.c_rows, self._r0, self._r1, nglob, self._comm, identity=False)
        EG = elimination_matrix(nb.g_rows, self._r0, self._r1, nglob, self._comm, identity=False)
        d, t, r, b = (self._f.duplicate() for _ in range(4))
        d.set(0.0)
        d.setValues(ip, cast(Any, self._diag.getValues(ip)))
        d.assemble()
        t.set(0.0)
        t.setValues(ip, cast(Any, nb.shift_values))
        t.assemble()
        self._K.mult(t, r)
        r.aypx(-1.0, self._f)  # f - K t
        t_mult_transpose(EG, r, b)
        v = self._u.copy()  # warm start: the last displacement, pivots free
        v.setValues(ip, cast(Any, np.zeros(len(nb.dofs))))
        v.assemble()
        A = PETSc.Mat().createPython(
            cast(Any, self._K.getSizes()), CondensedOperator(self._K, EC, d, EG), comm=self._comm
        )
        A.setUp()
        ksp, check = self._outer, self._check
        reuse = self._keeps_multigrid(nb.dofs)
        check.stopped, check.error = False, None
        try:
            with self._options.inserted():
                if not reuse:
                    self._preconditioner(nb)
            ksp.setOperators(A)
            ksp.setInitialGuessNonzero(True)
            target = self._relative_to_b(A, v, b, self._loose_rtol)
            if stationary is not None and target > self._rtol:

                def ask(w: PETSc.Vec, its: int) -> bool:
                    mu_n, mu_t = self._recover(EC, w, t, r, nb)
                    loose = FrictionSolve(self._u.array.copy(), mu_n, mu_t, its, 0.0, 0.0, False)
                    return stationary(loose)

                check.at, check.ask = target * float(cast(Any, b.norm())), ask
            ksp.setTolerances(rtol=self._rtol)  # the run's own end; the checkpoint may stop it
            ksp.setUp()
            t1 = time.perf_counter()
            ksp.solve(b, v)
        except PETSc.Error as err:
            raise check.error or SolverError(
                petsc_error_message(err, "frictional condensed solve")
            ) from None
        finally:
            check.ask = None
        its = self._iterations(ksp, v, "frictional condensed solve")
        mu_n, mu_t = self._recover(EC, v, t, r, nb)
        t2 = time.perf_counter()
        for obj in (EC, EG, d, t, r, b, v, A):
            obj.destroy()
        self.stats["reused" if reuse else "factorizations"] += 1
        self.stats["setup_time"] += t1 - t0
        return FrictionSolve(
            self._u.array.copy(), mu_n, mu_t, its, t1 - t0, t2 - t1, not check.stopped
        )

    def _preconditioner(self, nb: NodeBlocks) -> None:
        """One multigrid cycle on T^T K T + P (symmetric positive definite), set up."""
        self._multigrid(nb.c_rows, nb.dofs)
        self._ksp.setType(PETSc.KSP.Type.PREONLY)
        self._ksp.setUp()

    def _recover(
        self, EC: PETSc.Mat, v: PETSc.Vec, t: PETSc.Vec, r: PETSc.Vec, nb: NodeBlocks
    ) -> tuple[np.ndarray, np.ndarray]:
        """(mu_n, mu_t) from f - K u at the pivots; u = T v + t is kept (the warm start)."""
        t_mult(EC, v, self._u)
        self._u.axpy(1.0, t)
        self._K.mult(self._u, r)
        r.aypx(-1.0, self._f)
        return nb.multipliers(r.getValues(cast(Any, nb.dofs.astype(PETSc.IntType))))
