"""The saddle-point solve [[K, B^T], [B, C]] [u; mu] = [f; -g] through a PETSc MatNest.

`SaddleSolver` keeps its matrices, KSP and factorization (or multigrid hierarchy) across the
solves of an active-set loop: the active set only switches rows of the multiplier block on and
off, so every matrix keeps its nonzero pattern and PETSc redoes only the numeric setup (MUMPS
keeps its ordering and symbolic analysis). With a direct solver it reuses the factorization
of an earlier set where that is cheaper (`linalg/policy.py`): released rows by a capacitance
system (`linalg/capacitance.py`), other small changes by GMRES on the old factorization.
Multiplier responses for the probe step come from `linalg/responses.py`.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Mapping
from typing import cast

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..errors import SolverError
from .blocks import SaddleBlocks
from .capacitance import released_solve
from .mumps import MumpsEstimate, analyze_pc, petsc_library
from .petsc_options import PrefixedOptions, petsc_error_message, reason_name
from .policy import Decision, Factored, FactorizationPolicy
from .protocol import LoopTest, SaddleResult
from .responses import ResponseCache, dense_responses, local_slice, selected_responses

log = logging.getLogger("contactfx")

# A fresh factorization's single back-substitution is accepted at this relative residual,
# as the reference solve (preonly) is accepted at any: it is MUMPS' own accuracy on these
# saddle points (docs/scale.md#measured-constants, "Back-substitution acceptance"). Above it
# GMRES (rtol 1e-13) takes over from that solution.
_APPLY_RTOL = 1e-7
# GMRES around the factorization: one iteration with a fresh one, a few with a lagged one
# (the change is low-rank); right preconditioning tests the true residual, modified
# Gram-Schmidt keeps the basis orthogonal down to round-off.
_MAX_IT = 120
_REUSE_KSP: Mapping[str, object] = {
    "ksp_type": "gmres",
    "ksp_pc_side": "right",
    "ksp_rtol": 1e-13,
    "ksp_atol": 0.0,
    "ksp_max_it": _MAX_IT,
    "ksp_gmres_restart": _MAX_IT,
    "ksp_gmres_modifiedgramschmidt": True,
}


def _reuse_options(options: Mapping[str, object], reuse: bool, say: bool) -> dict[str, object]:
    """The options with the reused factorization's GMRES keys; say which ones it overrides.

    A direct preset's own ksp_type=preonly is replaced by design (not worth a line); any
    other option the reuse overrides was the user's.
    """
    if not reuse:
        return dict(options)
    replaced = sorted(
        f"{k}={v}"
        for k, v in options.items()
        if k in _REUSE_KSP and (k, v) != ("ksp_type", "preonly")
    )
    if replaced and say:
        log.info(
            "saddle solver: %s ignored (the reused factorization runs its own GMRES)",
            ", ".join(replaced),
        )
    return {**options, **_REUSE_KSP}


class SaddleSolver:
    """A persistent saddle-point solver for one (K, B, f): call `solve(g, active)` repeatedly.

    `direct`: the options factorize the whole saddle point (responses are then exact);
    `gamma` > 0 augments A00 = K + gamma B^T B (a fieldsplit's A00 must be invertible);
    `policy`: when to reuse the factorization (None: a throwaway solver, no reuse);
    `fieldsplit`: split the KSP's PC by the u and lambda blocks; `schur_user`: supply the
    Schur preconditioning matrix (-I/gamma on active rows) that PETSc then asks for.
    """

    def __init__(
        self,
        K: PETSc.Mat,
        B: PETSc.Mat,
        f: PETSc.Vec,
        options: Mapping[str, object],
        *,
        direct: bool,
        gamma: float = 0.0,
        nullspace: PETSc.NullSpace | None = None,
        policy: FactorizationPolicy | None = None,
        fieldsplit: bool = False,
        schur_user: bool = False,
    ) -> None:
        self.direct = direct
        self.gamma = gamma
        self.policy = policy if policy is not None and direct else FactorizationPolicy(False)
        self.stats = {"reused": 0, "setup_time": 0.0}
        self._mpi = K.getComm().tompi4py()
        self._m = SaddleBlocks(K, B, f, gamma, nullspace, schur_user)
        keys = _reuse_options(options, self.policy.reuse, self._mpi.rank == 0)
        self._options = PrefixedOptions(keys)
        self._ksp = PETSc.KSP().create(K.getComm())
        self._ksp.setOptionsPrefix(self._options.prefix)
        self._fieldsplit = fieldsplit
        self.factored = Factored()
        self._cache = ResponseCache()
        self._configured = False

    exact = True  # every solve is final: exact, or a fieldsplit Krylov solve to its rtol

    @property
    def can_probe(self) -> bool:
        """Responses need the exact inverse: a factorization of the whole saddle point."""
        return self.direct

    @property
    def cheap_responses(self) -> bool:
        """Whether responses are MUMPS' selected inverse entries (linalg/mumps.py; plain K)."""
        if not (self.direct and self.gamma == 0.0):
            return False
        self._configure()
        solver_type = self._ksp.getPC().getFactorSolverType()
        return solver_type == "mumps" and petsc_library() is not None

    def __enter__(self) -> SaddleSolver:
        return self

    def __exit__(self, *exc: object) -> None:
        self.destroy()

    def destroy(self) -> None:
        """Free the PETSc objects."""
        self._ksp.destroy()
        self._m.destroy()

    def _configure(self) -> None:
        """First use: build the KSP from the options (collective)."""
        if self._configured:
            return
        ksp, m = self._ksp, self._m
        ksp.setOperators(m.A)
        pc = ksp.getPC()
        if self._fieldsplit:
            pc.setType("fieldsplit")
            pc.setFieldSplitIS(("u", m.is_u), ("lambda", m.is_l))
        try:
            with self._options.inserted():
                ksp.setFromOptions()
        except PETSc.Error as err:  # e.g. a misspelt --petsc-option value
            raise SolverError(petsc_error_message(err, "saddle-point solve")) from None
        if m.Sp is not None:
            user = cast(PETSc.PC.FieldSplitSchurPreType, PETSc.PC.FieldSplitSchurPreType.USER)
            pc.setFieldSplitSchurPreType(user, m.Sp)
        if not self.policy.reuse:
            ksp.setInitialGuessNonzero(not self.direct)
        self._configured = True

    def solve(
        self, g: np.ndarray, active: np.ndarray, *, fresh: bool = False, stationary: LoopTest = None
    ) -> SaddleResult:
        """Solve with the rows of `active` enforced as equalities and mu = 0 elsewhere.

        `fresh`: factorize this very set (the probe step's responses need it). Exact: it
        never asks `stationary`.
        """
        active = np.asarray(active, dtype=bool)
        self._m.update(g, active)
        self._configure()
        changed, subset = self.factored.changed(active, self._mpi)
        decision = self.policy.decide(changed, subset, fresh, release=self.gamma == 0.0)
        if decision is Decision.RELEASED:
            released = self._solve_released(g, active, changed)
            if released is not None:
                return released
            decision = self.policy.decide(changed, subset, fresh, release=False)
        result = self._solve_factored(g, active, decision is Decision.REFACTOR, changed)
        if result is None:  # the lagged factorization was not good enough
            log.info("saddle solver: GMRES on the factorization failed: refactoring")
            self.factored.active = None
            result = self._solve_factored(g, active, True, -1)
            assert result is not None  # a fresh factorization raises instead
        return result

    def _solve_factored(
        self, g: np.ndarray, active: np.ndarray, refactor: bool, changed: int
    ) -> SaddleResult | None:
        """Solve with a new factorization or the kept one; None if a lagged one failed."""
        ksp, pc, m = self._ksp, self._ksp.getPC(), self._m
        # PETSc reads options lazily during setup and solve (MUMPS' ICNTLs, a fieldsplit's
        # inner solvers, GAMG's smoothers at every rebuild): they are in place for both.
        try:
            with self._options.inserted():
                t0 = time.perf_counter()
                pc.setReusePreconditioner(not refactor)
                ksp.setOperators(m.A)
                if refactor:
                    ksp.setUp()
                    self.factored.factorized(active)
                else:
                    self.stats["reused"] += 1
                t1 = time.perf_counter()
                if self.direct:
                    m.x.set(0.0)
                # A fresh factorization is applied once, as preonly would (GMRES's two
                # iterations cost three back-substitutions); GMRES only if that is inexact.
                warm = refactor and self.policy.reuse
                single = warm and self._apply_once()
                if not single:
                    ksp.setInitialGuessNonzero(warm)
                    ksp.solve(m.b, m.x)
                    ksp.setInitialGuessNonzero(False)
                t2 = time.perf_counter()
        except PETSc.Error as err:
            raise SolverError(petsc_error_message(err, "saddle-point solve")) from None
        if single:
            reason, its = int(PETSc.KSP.ConvergedReason.CONVERGED_ITS), 1
        else:
            reason = cast(int, ksp.getConvergedReason())  # an int; the stub: the enum class
            its = ksp.getIterationNumber()
        if refactor:
            count = self.factored.count
            self.policy.factorized(t1 - t0, numeric_only=changed >= 0 or count > 1)
            self.policy.applied(t2 - t1, its)
        self.stats["setup_time"] += t1 - t0
        if not (reason > 0 and np.isfinite(m.x.norm())):
            if self.policy.reuse and not refactor:
                return None
            raise SolverError(
                f"linear solve ({ksp.getType()}) did not converge: PETSc reason "
                f"{reason} ({reason_name(reason)}) after {its} iterations"
            )
        if self.direct:
            self.factored.keep(active, g, m.x.array_r)
        u, mu = m.split()
        return SaddleResult(u, mu, its, reason, refactor, changed, 0, t1 - t0, t2 - t1)

    def _solve_released(
        self, g: np.ndarray, active: np.ndarray, changed: int
    ) -> SaddleResult | None:
        """A subset of the factorized set, exactly, by a capacitance system; None: refactor."""
        t0 = time.perf_counter()
        pc, m = self._ksp.getPC(), self._m
        pc.setReusePreconditioner(True)
        factored = self.factored.active
        assert factored is not None  # the policy releases rows only from a factorized set
        count = self.factored.count

        def responses(rows: np.ndarray, local: np.ndarray) -> np.ndarray:
            kept = self._cache.lookup(count, rows, local, self._mpi)
            if kept is not None:
                return kept
            unit = np.zeros((len(local), len(rows)))
            unit[np.flatnonzero(local), np.arange(len(rows))[local_slice(self._mpi, local)]] = 1.0
            return self.responses(unit, factored, local)

        done = released_solve(
            pc.apply,
            m.residual,
            m.b,
            m.x,
            m.rows_l,
            factored,
            active,
            g,
            responses,
            self._mpi,
            self.factored.solution_for(g),
            self.factored.own_residual,
        )
        if done is None:
            return None
        applies, res, n_released = done
        self.stats["reused"] += 1
        u, mu = m.split()
        return SaddleResult(
            u, mu, applies, 1, False, changed, n_released, 0.0, time.perf_counter() - t0, res
        )

    def responses(
        self, probes: np.ndarray, active: np.ndarray, rows: np.ndarray | None = None
    ) -> np.ndarray:
        """Multiplier responses (local rows x k) to `probes`, on the set factorized last.

        Selected entries are computed on `rows` only (a local mask; None: every active row).
        """
        probes, active = np.asarray(probes, dtype=float), np.asarray(active, dtype=bool)
        k = self._mpi.allreduce(probes.shape[1] if probes.ndim == 2 else 0, op=MPI.MAX)
        if k == 0:
            return np.zeros((len(active), 0))
        probes = probes.reshape(len(active), k)
        m = self._m
        out = None
        if self.cheap_responses:
            F = self._ksp.getPC().getFactorMatrix()
            start = m.A.getOwnershipRange()[0]
            n = m.A.getSize()[0]
            # The saddle point is symmetric whichever way it is factorized (LU or LDL^T).
            out = selected_responses(F, m.rows_l + start, n, probes, active, self._mpi, True, rows)
            if out is None and self._mpi.rank == 0:
                log.info("saddle solver: no selected inverse entries: dense probe solves")
        if out is None:
            augment = m.augmented_rhs if self.gamma > 0.0 else None
            solve = m.apply_inverse(self._ksp, self.direct)
            out = dense_responses(solve, probes, active, m.rows_u, m.rows_l, self._mpi, augment)
        if self.direct:
            r0 = m.B.getOwnershipRange()[0]
            self._cache.store(self.factored.count, probes, active, out, r0, self._mpi, rows)
        return out

    def _apply_once(self) -> bool:
        """One back-substitution with the fresh factorization into x; True if accurate."""
        m = self._m
        self._ksp.getPC().apply(m.b, m.x)
        r, rel = m.residual(m.x)
        r.destroy()
        self.factored.own_residual = rel
        return rel <= _APPLY_RTOL

    def mumps_estimate(self) -> MumpsEstimate | None:
        """MUMPS' analysis of the saddle point alone, before any factorization.

        Its memory estimate, or None (not a MUMPS factorization, or the analysis failed); the
        first factorization reuses the analysis (linalg/mumps.py: `analyze_pc`).
        """
        if not self.direct:
            return None
        self._configure()
        with self._options.inserted():
            return analyze_pc(self._ksp.getPC(), self._m.A)
