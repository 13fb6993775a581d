"""The condensed solver: the active multipliers eliminated, CG + multigrid on the displacements.

The elimination itself is `linalg/elimination.py`. The first set builds T^T K T and GAMG on
it, with the rigid modes of all bodies (zero on the pivots) as near-nullspace. Later sets
differ from it by a few pivots, a low-rank change: CG keeps that multigrid and applies the
new operator matrix-free, from the last displacement, until the pivots have moved too far.
Given the prolongations of coarser grids (a structured grid's own, or a remeshed scene's),
PCMG on them with Galerkin coarse operators replaces GAMG, kept across sets by the same rule
(its Galerkin products and smoother factorizations cost several CG iterations from a
million DOFs: docs/condensed.md, "One multigrid per loop").
The loop's solves stop at a loose tolerance (only signs decide the set): there the loop's
`stationary` test reads the loose answer inside the CG run (a convergence test), and on a
stationary set the same run goes on to the final tolerance, so the answer does not depend on
the loose one and CG keeps its Krylov space (a restarted polish lost it: docs/scale.md,
"One CG run per stationary set").
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from petsc4py import PETSc

from ..errors import SolverError
from .elimination import (
    CondensedOperator,
    LocalRows,
    PivotRows,
    condensed_matrix,
    elimination_matrix,
    t_mult,
    t_mult_transpose,
)
from .nullspace import orthonormalize
from .petsc_options import PrefixedOptions, global_options, petsc_error_message, reason_name
from .pivots import Pivots, pivots
from .protocol import LoopTest, SaddleResult

# Pivot changes since the multigrid was built (summed over ranks) below which it is reused,
# or below this fraction of the pivots. Each changed pivot costs the kept cycle about one
# CG iteration, while a fresh ICC-smoothed cycle needs few, so a few dozen changes already
# cost more than a new setup (measured: docs/scale.md, "GAMG on stretched cells").
REBUILD_CHANGES = 8
REBUILD_FRACTION = 0.05
# A loose solve from a warm start reduces its own initial residual at least this much, and
# stops at loose_rtol ||b|| (`_relative_to_b`): fewest iterations with the same sets and
# final accuracy among 1e-4 (the former rule) / 1e-2 / 1e-1 (docs/scale.md, "Release steps").
WARM_REDUCTION = 0.1


@dataclass
class _Checkpoint:
    """The loop's question inside a CG run: asked once, when the residual norm reaches `at`."""

    at: float = 0.0
    ask: Callable[[PETSc.Vec, int], bool] | None = None  # (iterate, its) -> go on; None: asked
    stopped: bool = False  # the answer was no: the run ended at the loose tolerance
    error: BaseException | None = None

    def test(self, ksp: PETSc.KSP, its: int, rnorm: float) -> int:
        """A KSP convergence test run before PETSc's default one (0: the default decides)."""
        ask = self.ask
        if ask is None or rnorm > self.at:
            return 0
        self.ask = None
        try:
            # buildSolution: GMRES forms its iterate only on request (CG's is its vector).
            self.stopped = not ask(ksp.buildSolution(), its)
        except BaseException as err:  # raised again after KSPSolve, on every rank alike
            self.error = err
            return int(PETSc.KSP.ConvergedReason.DIVERGED_BREAKDOWN)
        return int(PETSc.KSP.ConvergedReason.CONVERGED_RTOL) if self.stopped else 0


class CondensedSolver:
    """Solve K u + B^T mu = f, B_A u = -g_A by elimination: a LinearSolver without probes.

    `node_dofs` (m, 2): global dofs of each owned row's active node. `rtol`: the final
    tolerance; `loose_rtol`: the relative reduction of the loop's solves.
    `reuse` False: a throwaway solver (a new preconditioner for every set).
    `free_products`: the preconditioner's setup frees its matrix products' intermediate data
    (PETSc's unprefixed mat_product_clear: GAMG's products carry no prefix).
    `interpolations`: a PCMG's prolongations, finest first (owned); None: GAMG's own.
    """

    def __init__(
        self,
        K: PETSc.Mat,
        B: PETSc.Mat,
        f: PETSc.Vec,
        options: Mapping[str, object],
        node_dofs: np.ndarray,
        modes: list[PETSc.Vec],
        *,
        rtol: float,
        loose_rtol: float | None = None,
        reuse: bool = True,
        free_products: bool = False,
        interpolations: list[PETSc.Mat] | None = None,
    ) -> None:
        self._K, self._f = K, f
        self._comm = K.getComm()
        self._mpi = self._comm.tompi4py()
        self._rows = LocalRows.of(B, node_dofs)
        self._modes = modes
        self._options = PrefixedOptions(options)
        self._rtol = rtol
        self._loose_rtol = max(rtol, loose_rtol if loose_rtol is not None else rtol)
        self._A: PETSc.Mat | None = None  # the operator the multigrid was built from
        self._ksp = PETSc.KSP().create(self._comm)
        self._ksp.setOptionsPrefix(self._options.prefix)
        self._u = f.duplicate()
        self._u.set(0.0)
        self._diag = K.getDiagonal()
        self._r0, self._r1 = K.getOwnershipRange()
        self.stats = {"factorizations": 0.0, "reused": 0.0, "setup_time": 0.0}
        self._built_for: np.ndarray | None = None  # the pivots the multigrid was built with
        self.reuse = reuse
        self._setup_options: dict[str, object] = (
            {"mat_product_clear": True} if free_products else {}
        )
        self._check = _Checkpoint()  # the loop's question during a solve
        self._interp = interpolations or []  # a geometric multigrid's, finest first
        self._tested = False  # its convergence test is in the KSP (petsc4py adds one)

    exact = False  # the loop's solves stop at loose_rtol, a stationary set's go on
    can_probe = False  # no factorization: no exact responses
    cheap_responses = False

    def destroy(self) -> None:
        """Free the PETSc objects."""
        for obj in (self._ksp, self._u, self._diag, self._A, *self._interp):
            if obj is not None:
                obj.destroy()

    def solve(
        self, g: np.ndarray, active: np.ndarray, *, fresh: bool = False, stationary: LoopTest = None
    ) -> SaddleResult:
        """Displacements and multipliers (owned parts), at the loose tolerance of the loop.

        With `stationary` the loose answer is asked inside the CG run; where it says True
        the run goes on to the final tolerance (`final`). A throwaway solver (`reuse`
        False: a reference solve) solves to the final one.
        """
        if not self.reuse:
            return self._solve(g, active, self._rtol)
        return self._solve(g, active, self._loose_rtol, stationary)

    def responses(
        self, rhs: np.ndarray, active: np.ndarray, rows: np.ndarray | None = None
    ) -> np.ndarray:
        """Not available: the condensed solver has no factorization (can_probe is False)."""
        raise SolverError("the condensed solver has no probe responses (it is not a factorization)")

    def _solve(
        self,
        g: np.ndarray,
        active: np.ndarray,
        rtol: float,
        stationary: LoopTest = None,
    ) -> SaddleResult:
        t0 = time.perf_counter()
        nglob = self._K.getSize()[0]
        mask = np.asarray(active, dtype=bool)
        pv = pivots(self._rows, mask, self._mpi, self._r0, nglob)
        piv, prows = pv.dofs, pv.e_rows
        # petsc4py's stubs type indices and values as Sequences; numpy arrays work as well.
        ip: Any = piv.astype(PETSc.IntType)
        # E = T - I: the pivot rows only (T itself would hold a row per dof).
        E = elimination_matrix(prows, self._r0, self._r1, nglob, self._comm, identity=False)
        d, t, r, b = (self._f.duplicate() for _ in range(4))
        d.set(0.0)
        d.setValues(ip, cast(Any, self._diag.getValues(ip)))
        d.assemble()
        t.set(0.0)
        t.setValues(ip, cast(Any, pv.shift(g)))
        t.assemble()
        self._K.mult(t, r)
        r.aypx(-1.0, self._f)  # f - K t
        t_mult_transpose(E, r, b)
        v = self._u.copy()  # warm start: the last displacement, pivots free
        v.setValues(ip, cast(Any, np.zeros(len(piv))))
        v.assemble()
        reuse = self._keeps_multigrid(piv)
        ksp, check = self._ksp, self._check
        check.stopped, check.error = False, None
        try:
            with self._options.inserted():  # read lazily at setup and solve (GAMG levels)
                A = self._operator(reuse, E, d, pv)
                ksp.getPC().setReusePreconditioner(reuse)
                ksp.setInitialGuessNonzero(True)
                target = self._relative_to_b(A, v, b, rtol)
                if stationary is not None and target > self._rtol:

                    def ask(w: PETSc.Vec, its: int) -> bool:
                        u, mu = self._answer(E, w, t, r, pv, len(active))
                        return stationary(SaddleResult(u, mu, its, 0, not reuse, final=False))

                    check.at, check.ask = target * float(cast(Any, b.norm())), ask
                    target = self._rtol  # the run's own end; the checkpoint may stop it first
                ksp.setTolerances(rtol=target)
                with global_options({} if reuse else self._setup_options):
                    ksp.setUp()
                t1 = time.perf_counter()
                ksp.solve(b, v)
        except PETSc.Error as err:
            raise check.error or SolverError(petsc_error_message(err, "condensed solve")) from None
        finally:
            check.ask = None
        its = self._iterations(ksp, v, "condensed solve")
        final = target <= self._rtol and not check.stopped
        u, mu = self._answer(E, v, t, r, pv, len(active))
        t2 = time.perf_counter()
        for obj in (E, d, t, r, b, v):
            obj.destroy()
        if reuse:
            A.destroy()
        self.stats["reused" if reuse else "factorizations"] += 1
        self.stats["setup_time"] += t1 - t0
        reason = cast(int, ksp.getConvergedReason())
        return SaddleResult(u, mu, its, reason, not reuse, -1, 0, t1 - t0, t2 - t1, final=final)

    def _iterations(self, ksp: PETSc.KSP, v: PETSc.Vec, what: str) -> int:
        """The run's iterations; the checkpoint's error, or SolverError where it diverged."""
        reason, its = cast(int, ksp.getConvergedReason()), ksp.getIterationNumber()
        if self._check.error is not None:
            raise self._check.error
        if reason <= 0 or not np.isfinite(v.norm()):
            raise SolverError(
                f"{what} ({ksp.getType()}) did not converge: PETSc "
                f"reason {reason} ({reason_name(reason)}) after {its} iterations"
            )
        return its

    def _answer(
        self, E: PETSc.Mat, v: PETSc.Vec, t: PETSc.Vec, r: PETSc.Vec, pv: Pivots, n: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """(u, mu) of the condensed iterate v: u = T v + t, mu from f - K u on the pivots."""
        t_mult(E, v, self._u)
        self._u.axpy(1.0, t)
        self._K.mult(self._u, r)
        r.aypx(-1.0, self._f)  # f - K u: the contact force on the pivots
        mu = np.zeros(n)
        mu[pv.rows] = pv.multipliers(r.getValues(cast(Any, pv.dofs.astype(PETSc.IntType))))
        return self._u.array.copy(), mu

    def _keeps_multigrid(self, piv: np.ndarray) -> bool:
        """Whether the multigrid of an earlier set still preconditions this one.

        A few pivots more or less change T^T K T by a term of their rank, which costs CG at
        most that many extra iterations: the multigrid is kept until the pivots have moved
        in more than max(REBUILD_FRACTION of the set, REBUILD_CHANGES) places.
        """
        prev = self._built_for
        if not self.reuse or prev is None:
            return False
        changed = self._mpi.allreduce(int(np.setxor1d(prev, piv).size))
        n_piv = self._mpi.allreduce(len(piv))
        return changed <= max(REBUILD_FRACTION * n_piv, REBUILD_CHANGES)

    def _operator(self, reuse: bool, E: PETSc.Mat, d: PETSc.Vec, pv: Pivots) -> PETSc.Mat:
        """The KSP's operator: matrix-free on the kept multigrid, or a new matrix and setup."""
        ksp = self._ksp
        if reuse:
            A = PETSc.Mat().createPython(
                cast(Any, self._K.getSizes()), CondensedOperator(self._K, E, d), comm=self._comm
            )
            A.setUp()
            assert self._A is not None
            ksp.setOperators(A, self._A)
            return A
        A = self._multigrid(pv.e_rows, pv.dofs)
        if not self._tested:  # before PETSc's default test, once (after the type is set)
            ksp.addConvergenceTest(cast(Any, self._check.test), prepend=True)
            self._tested = True
        return A

    def _multigrid(self, prows: PivotRows, piv: np.ndarray) -> PETSc.Mat:
        """T^T K T + P of these pivot rows as the inner KSP's operator (not yet set up).

        The multigrid's levels are given and the matrix kept: the multigrid is built from it.
        """
        ksp = self._ksp
        A = condensed_matrix(self._K, prows, self._r0, piv, self._diag)
        if self._modes:
            A.setNearNullSpace(self._near_nullspace(piv))
        if self._interp:  # before the operators: a rebuild resets the PC
            _geometric_levels(ksp.getPC(), self._interp, piv)
        ksp.setOperators(A)
        ksp.setFromOptions()
        if self._A is not None:
            self._A.destroy()
        self._A = A
        self._built_for = piv.copy()
        return A

    def _relative_to_b(self, A: PETSc.Mat, v: PETSc.Vec, b: PETSc.Vec, rtol: float) -> float:
        """The rtol (PETSc's, relative to ||b||) of a loop's solve from the warm start v.

        The loose solves stop at rtol ||b||, the accuracy the first set's solve (from zero)
        had, but reduce their own initial residual by at least WARM_REDUCTION: from a warm
        start already within rtol ||b|| a solve that did not iterate would judge the set on
        the previous set's displacements (the default Hertz scene then cycled), while
        reducing it by rtol itself solved each release step 1e4 times more accurately than
        the first step (docs/scale.md, "Release steps"). The final tolerance stays
        relative to ||b||.
        """
        if rtol <= self._rtol:
            return rtol
        res0 = b.duplicate()
        A.mult(v, res0)
        res0.aypx(-1.0, b)
        r0, b0 = float(cast(Any, res0.norm())), float(cast(Any, b.norm()))
        res0.destroy()
        return max(self._rtol, min(rtol, WARM_REDUCTION * r0 / max(b0, 1e-300)))

    def _near_nullspace(self, piv: np.ndarray) -> PETSc.NullSpace:
        """The rigid-body modes with the (decoupled) pivot entries removed, orthonormal."""
        modes = []
        for m in self._modes:
            w = m.copy()
            w.setValues(cast(Any, piv.astype(PETSc.IntType)), cast(Any, np.zeros(len(piv))))
            w.assemble()
            modes.append(w)
        orthonormalize(modes)
        nsp = PETSc.NullSpace().create(vectors=modes, comm=self._comm)
        for w in modes:
            w.destroy()
        return nsp


def _geometric_levels(pc: PETSc.PC, interp: list[PETSc.Mat], piv: np.ndarray) -> None:
    """PCMG on the given prolongations (finest first), the pivots' rows of the finest zero.

    The pivots are decoupled rows of T^T K T + P: the coarse grids must not correct them.
    """
    fine = interp[0].copy()
    keep = fine.createVecLeft()
    keep.set(1.0)
    keep.setValues(cast(Any, piv.astype(PETSc.IntType)), cast(Any, np.zeros(len(piv))))
    keep.assemble()
    fine.diagonalScale(L=keep)
    keep.destroy()
    n = len(interp) + 1
    if pc.getType() == PETSc.PC.Type.MG:
        # A rebuild: the Galerkin products start afresh (their data was freed: free_products).
        pc.reset()
    else:
        pc.setType(PETSc.PC.Type.MG)
    if pc.getMGLevels() != n:
        pc.setMGLevels(n)
    for level, P in enumerate([fine, *interp[1:]]):
        pc.setMGInterpolation(n - 1 - level, P)  # PETSc's level 0 is the coarsest
    fine.destroy()
