"""The saddle-point solve [[K, B^T], [B, C]] [u; mu] = [f; -g] through a PETSc MatNest.

`SaddleSolver` keeps its matrices, KSP and factorization (or multigrid hierarchy) across the
solves of an active-set loop: the active set only switches rows of the multiplier block on and
off, so every matrix keeps its nonzero pattern and PETSc redoes only the numeric setup (MUMPS
keeps its ordering and symbolic analysis). With a direct solver it goes further: a solve whose
active set differs from the factorized one in a few rows is a low-rank change, which GMRES
preconditioned by the old factorization solves in a few iterations; it refactors only when
that would cost more than a new numeric factorization. Multiplier responses (probes) come from
MUMPS' selected entries of the inverse (ICNTL(30), `mumps_inverse.py`) where that is
available: a few milliseconds for what costs one back-substitution per column as dense
right-hand sides.

Why one module of ~600 lines: the factorization-reuse policy (fresh, lagged, released rows
by a capacitance system, probes) is one state machine over one factorization; every path
reads and updates the same cached set, timings and PETSc objects, so split across modules
each part would need the whole solver passed in.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import cast

import numpy as np
import scipy.linalg
from mpi4py import MPI
from petsc4py import PETSc

from .errors import SolverError
from .mumps_inverse import inverse_entries, selected_inverse_available
from .solvers import PrefixedOptions, is_direct, petsc_error_message, reason_name

# Largest set of released rows solved by a capacitance system instead of a refactorization.
_MAX_RELEASED = 2000
# Entries per rank of one dense block of probe right-hand sides (8 bytes each).
_PROBE_ENTRIES = 64_000_000
# A fresh factorization's single back-substitution is accepted at this relative residual,
# as the reference solve (preonly) is accepted at any: MUMPS' own accuracy on these saddle
# points is 1e-11 to 4e-8 (every row active, nts, 600k dofs), where the solution agrees with
# GMRES's to 1e-11. Above it GMRES (rtol 1e-13) takes over from that solution.
_APPLY_RTOL = 1e-7
# A capacitance (released rows) solve is refined (at most twice) while its relative residual
# exceeds this or, if larger, that of the factorization's own back-substitution (MUMPS'
# accuracy, see _APPLY_RTOL), and refactored if it still does.
_RELEASED_RTOL = 1e-8


@dataclass
class SaddleResult:
    """Solution blocks (owned parts) and what the Krylov solver reported."""

    u: np.ndarray
    mu: np.ndarray
    iterations: int
    reason: int
    info: dict[str, object] = field(default_factory=dict)


def _diagonal_matrix(comm: PETSc.Comm, values: np.ndarray, offset: int) -> PETSc.Mat:
    """A square AIJ matrix with `values` on this rank's diagonal rows (global first row offset)."""
    m = len(values)
    csr = (
        np.arange(m + 1, dtype=PETSc.IntType),
        np.arange(offset, offset + m, dtype=PETSc.IntType),
        np.asarray(values, dtype=PETSc.ScalarType),
    )
    # The stub asks for Sequences; petsc4py takes (and converts) numpy arrays.
    C = PETSc.Mat().createAIJ(
        size=((m, PETSc.DETERMINE), (m, PETSc.DETERMINE)),
        csr=csr,  # type: ignore[arg-type]
        comm=comm,
    )
    C.assemble()
    return C


def schur_al_diagonal(active: np.ndarray, gamma: float, inactive: float = 1.0) -> np.ndarray:
    """Diagonal of the Schur preconditioner: -1/gamma on active rows, C's entry on the others.

    With A00 = K + gamma B^T B the exact identity S^-1 = -(gamma I + (B K^-1 B^T)^-1) holds on
    the active rows; gamma = E/h^2 bounds the second term by gamma times a constant of order
    one at every mesh size, so -I/gamma preconditions S with mesh-independent quality.
    """
    return np.where(active, -1.0 / gamma, inactive)


class SaddleSolver:
    """A persistent saddle-point solver for one (K, B, f): call `solve(g, active)` repeatedly."""

    def __init__(
        self,
        K: PETSc.Mat,
        B: PETSc.Mat,
        f: PETSc.Vec,
        options: Mapping[str, object],
        gamma: float = 0.0,
        nullspace: PETSc.NullSpace | None = None,
        reuse_factorization: bool = True,
    ) -> None:
        self.options = dict(options)
        self.gamma = gamma
        self.direct = is_direct(self.options)
        self.reuse = reuse_factorization and self.direct
        self.stats = {"factorizations": 0, "reused": 0, "setup_time": 0.0}
        comm = K.getComm()
        self._comm = comm
        self._mpi = comm.tompi4py()
        self._K, self._B, self._f = K, B, f
        m = B.getLocalSize()[0]
        r0 = B.getOwnershipRange()[0]
        self._act = PETSc.Vec().createMPI((m, PETSc.DETERMINE), comm=comm)
        self._act.set(1.0)
        self._BT = PETSc.Mat()
        B.transpose(self._BT)
        self._BA = B.copy()
        self._BAT = self._BT.copy()
        self._c_inactive = _inactive_scale(K, B)
        self._C = _diagonal_matrix(comm, np.full(m, self._c_inactive), r0)
        self._owned: list[PETSc.Object] = [self._act, self._BT, self._BA, self._BAT, self._C]
        self._A00 = K
        if gamma > 0.0:
            # The union pattern of K and B^T B, fixed once: later updates are value copies.
            self._P = self._BAT.matMult(self._BA)
            zero = self._P.duplicate(copy=False)
            self._Kx = K.duplicate(copy=True)
            different = cast(PETSc.Mat.Structure, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            self._Kx.axpy(1.0, zero, structure=different)
            zero.destroy()
            self._A00 = self._Kx.duplicate(copy=True)
            self._owned += [self._P, self._Kx, self._A00]
            if nullspace is not None:
                self._A00.setNearNullSpace(nullspace)
        self._A = PETSc.Mat().createNest([[self._A00, self._BAT], [self._BA, self._C]], comm=comm)
        self._is_u, self._is_l = self._A.getNestISs()[0]
        self._b = self._A.createVecRight()
        self._x = self._A.createVecRight()
        self._x.set(0.0)
        self._rhs_u = f.duplicate()
        self._owned += [self._A, self._b, self._x, self._rhs_u]
        self._Sp = None
        if self.options.get("pc_fieldsplit_schur_precondition") == "user":
            self._Sp = _diagonal_matrix(comm, np.ones(m), r0)
            self._owned.append(self._Sp)
        if nullspace is not None and self._is_u is not None:
            # PCFIELDSPLIT attaches a near-nullspace composed on the split's IS to its matrix.
            self._is_u.compose("nearnullspace", nullspace)
        keys = dict(self.options)
        if self.reuse:
            # GMRES around the LU: one iteration with a fresh factorization, a few with a
            # lagged one (the change is low-rank); right preconditioning tests the true
            # residual, modified Gram-Schmidt keeps the basis orthogonal down to round-off.
            keys.update(
                {
                    "ksp_type": "gmres",
                    "ksp_pc_side": "right",
                    "ksp_rtol": 1e-13,
                    "ksp_atol": 0.0,
                    "ksp_max_it": 120,
                    "ksp_gmres_restart": 120,
                    "ksp_gmres_modifiedgramschmidt": True,
                }
            )
        self._options = PrefixedOptions(keys)
        self._ksp = PETSc.KSP().create(comm)
        self._ksp.setOptionsPrefix(self._options.prefix)
        self._factored: np.ndarray | None = None
        # (factorization count, g, solution) of the last direct solve on the factorized set:
        # the capacitance path's first back-substitution when nothing changed since.
        self._last: tuple[float, np.ndarray, np.ndarray] | None = None
        # (factorization count, sorted global rows, responses) of the last direct probe solve.
        self._cache: tuple[float, np.ndarray, np.ndarray] | None = None
        self._t_numeric = np.inf
        # Relative residual of the last fresh factorization's own single back-substitution:
        # what a capacitance solve on it must reach (see _solve_released).
        self._own_residual = 0.0
        self._t_apply = 0.0
        self._ready = False
        # "auto" weighs a lagged factorization against a new one by their measured costs;
        # "reuse" and "refactor" force one side (tests, benchmarks).
        self.policy = "auto"

    @property
    def cheap_responses(self) -> bool:
        """Whether probe responses come from MUMPS' selected inverse entries (serial MUMPS LU).

        petsc4py does not wrap MatMumpsGetInverse; it is called through ctypes. On several
        ranks it leaves MUMPS' centralized right-hand-side pointer set, and the next solve
        fails (INFOG(1) = -22): there the probes stay dense multi-right-hand-side solves.
        """
        return self.gamma == 0.0 and selected_inverse_available(self.options, self._mpi.size)

    def __enter__(self) -> SaddleSolver:
        return self

    def __exit__(self, *exc: object) -> None:
        self.destroy()

    def destroy(self) -> None:
        """Free the PETSc objects and remove this solver's options from the database."""
        self._options.remove()
        self._ksp.destroy()
        for obj in self._owned:
            obj.destroy()
        self._owned = []

    def _update(self, g: np.ndarray, active: np.ndarray) -> None:
        """Write the values of the active set into the fixed-pattern blocks and the rhs."""
        # The stub types the Structure values as int but the parameters as Structure.
        same = cast(PETSc.Mat.Structure, PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        self._act.array[:] = active.astype(float)
        self._B.copy(self._BA, structure=same)
        self._BA.diagonalScale(L=self._act)
        self._BT.copy(self._BAT, structure=same)
        self._BAT.diagonalScale(R=self._act)
        diag = self._act.duplicate()
        diag.array[:] = np.where(active, 0.0, self._c_inactive)
        self._C.setDiagonal(diag)
        self._f.copy(self._rhs_u)
        if self.gamma > 0.0:
            # Augmented Lagrangian: adding gamma B^T (B u + g) = 0 makes A00 invertible when a
            # body is held only by contact, and leaves the solution unchanged.
            self._BAT.matMult(self._BA, result=self._P)
            self._Kx.copy(self._A00, structure=same)
            subset = cast(PETSc.Mat.Structure, PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            self._A00.axpy(self.gamma, self._P, structure=subset)
            diag.array[:] = -self.gamma * g * active
            tmp = self._rhs_u.duplicate()
            self._BAT.mult(diag, tmp)
            self._rhs_u.axpy(1.0, tmp)
            tmp.destroy()
        if self._Sp is not None:
            diag.array[:] = (
                schur_al_diagonal(active, self.gamma, self._c_inactive)
                if self.gamma > 0
                else self._c_inactive
            )
            self._Sp.setDiagonal(diag)
        diag.destroy()
        self._A.assemble()
        for iset, values in (
            (self._is_u, self._rhs_u.array_r),
            (self._is_l, np.where(active, -g, 0.0)),
        ):
            sub = self._b.getSubVector(iset)
            sub.array[:] = values
            self._b.restoreSubVector(iset, sub)

    def _configure(self) -> None:
        """First use: build the KSP from the options (collective)."""
        ksp = self._ksp
        ksp.setOperators(self._A)
        pc = ksp.getPC()
        if self.options.get("pc_type") == "fieldsplit":
            pc.setType("fieldsplit")
            pc.setFieldSplitIS(("u", self._is_u), ("lambda", self._is_l))
        ksp.setFromOptions()
        if self._Sp is not None:
            user = cast(PETSc.PC.FieldSplitSchurPreType, PETSc.PC.FieldSplitSchurPreType.USER)
            pc.setFieldSplitSchurPreType(user, self._Sp)
        if not self.reuse:
            ksp.setInitialGuessNonzero(not self.direct)
        self._ready = True

    def _changed(self, active: np.ndarray) -> int:
        """Number of multiplier rows whose active flag differs from the factorized set."""
        if self._factored is None:
            return -1
        return self._mpi.allreduce(int(np.count_nonzero(active != self._factored)))

    def solve(
        self, g: np.ndarray, active: np.ndarray, probes: np.ndarray | None = None
    ) -> SaddleResult:
        """Solve with the rows of `active` enforced as equalities and mu = 0 elsewhere.

        `probes` (local rows x k), if given, are extra right-hand sides of the multiplier block
        (a column e_j closes the weighted gap of row j by 1) solved with zero load by the same
        operator; their multiplier blocks are returned in `info["probes"]`.
        """
        active = np.asarray(active, dtype=bool)
        self._update(g, active)
        if not self._ready:
            try:
                self._configure()
            except PETSc.Error as err:  # e.g. a misspelt --petsc-option value
                raise SolverError(petsc_error_message(err, "saddle-point solve")) from None
        ksp, pc = self._ksp, self._ksp.getPC()
        changed = self._changed(active)
        if probes is not None and self.direct:
            changed = -1  # the multi-RHS probes need the exact factorization of this set
        if (
            self.reuse
            and self.gamma == 0.0
            and probes is None
            and self.policy != "refactor"
            and 0 < changed <= _MAX_RELEASED
            and self._factored is not None
            and not self._mpi.allreduce(bool(np.any(active & ~self._factored)), op=MPI.LOR)
        ):
            released = self._solve_released(g, active)
            if released is not None:
                return released
        # A lagged factorization costs about one solve per changed row and side (the change is
        # a rank-2 update per row): refactor when that exceeds a numeric factorization.
        refactor = (
            not self.reuse
            or changed < 0
            or self.policy == "refactor"
            or (self.policy == "auto" and (2 * changed + 1) * self._t_apply > self._t_numeric)
            or 2 * changed + 1 > 100
        )
        try:
            t0 = time.perf_counter()
            if refactor:
                pc.setReusePreconditioner(False)
                ksp.setOperators(self._A)
                ksp.setUp()
                self._own_residual = 0.0
                self._factored = active.copy()
                self.stats["factorizations"] += 1
            else:
                pc.setReusePreconditioner(True)
                ksp.setOperators(self._A)
                self.stats["reused"] += 1
            t1 = time.perf_counter()
            if self.direct:
                self._x.set(0.0)
            # A fresh factorization is applied once, as preonly would (GMRES's two
            # iterations cost three back-substitutions' time); GMRES only if that is inexact.
            single = refactor and self.reuse and self._apply_once()
            if not single:
                ksp.setInitialGuessNonzero(refactor and self.reuse)
                ksp.solve(self._b, self._x)
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
            if changed >= 0 or self.stats["factorizations"] > 1:
                self._t_numeric = t1 - t0
            elif not np.isfinite(self._t_numeric):
                self._t_numeric = t1 - t0  # includes the analysis: an overestimate at first
            self._t_apply = (t2 - t1) / max(its, 1)
        self.stats["setup_time"] += t1 - t0
        ok = reason > 0 and np.isfinite(self._x.norm())
        if not ok and self.reuse and not refactor:
            # The lagged factorization was not good enough: refactor and solve again.
            self._factored = None
            return self.solve(g, active)
        if not ok:
            raise SolverError(
                f"linear solve ({ksp.getType()}) did not converge: PETSc reason "
                f"{reason} ({reason_name(reason)}) after {its} iterations"
            )
        if self.direct and self._factored is not None and np.array_equal(active, self._factored):
            self._last = (
                self.stats["factorizations"],
                np.array(g, copy=True),
                self._x.array_r.copy(),
            )
        u_sub, l_sub = self._x.getSubVector(self._is_u), self._x.getSubVector(self._is_l)
        u, mu = u_sub.array.copy(), l_sub.array.copy()
        self._x.restoreSubVector(self._is_u, u_sub)
        self._x.restoreSubVector(self._is_l, l_sub)
        info: dict[str, object] = {
            "refactored": refactor,
            "changed_rows": changed,
            "setup": t1 - t0,
            "solve": t2 - t1,
        }
        if probes is not None:
            info["probes"] = self._solve_probes(np.asarray(probes, dtype=float), active)
        return SaddleResult(u, mu, its, reason, info)

    def _residual(self, x: PETSc.Vec) -> tuple[PETSc.Vec, float]:
        """The residual b - A x of the current operator and right-hand side, relative norm."""
        r = self._b.duplicate()
        self._A.mult(x, r)
        r.aypx(-1.0, self._b)
        # norm() of the default (2-) norm is a float; the stub also allows a pair.
        rel = cast(float, r.norm()) / max(cast(float, self._b.norm()), 1e-300)
        return r, float(rel) if np.isfinite(rel) else np.inf

    def _apply_once(self) -> bool:
        """One back-substitution with the fresh factorization into x; True if accurate."""
        self._ksp.getPC().apply(self._b, self._x)
        r, rel = self._residual(self._x)
        r.destroy()
        self._own_residual = rel
        return rel <= _APPLY_RTOL

    def _solve_released(self, g: np.ndarray, active: np.ndarray) -> SaddleResult | None:
        """Exact solve for a subset of the factorized set by a capacitance system (no refactor).

        The factorized system with its gap right-hand sides shifted by s on the released rows R
        has the same u as the new one as soon as mu_R = 0, and mu_R = mu_R(0) + M s with M the
        multiplier responses of R to unit shifts (cached from probes, else one multi-RHS solve).
        The first back-substitution is the factorized set's own solution when it is kept.
        Starting from every row, mu_R(0) is large (far rows pulled shut) and the shift that
        cancels it can leave a relative residual of ~1e-7 (600k dofs, 4e-8 for the factorized
        set's own solve): up to two steps of iterative refinement, each the same capacitance
        solve (two back-substitutions) on the residual, bring it to 1e-8 or the factorized
        set's own level (_RELEASED_RTOL); if not, the caller refactors.
        """
        t0 = time.perf_counter()
        pc = self._ksp.getPC()
        pc.setReusePreconditioner(True)
        factored = self._factored
        assert factored is not None  # solve() comes here only with a factorized set
        rel = factored & ~active
        rel_global = np.flatnonzero(np.concatenate(self._mpi.allgather(rel)))
        start = self._A.getOwnershipRange()[0]
        rows_l = self._is_l.getIndices() - start
        rows_r = rows_l[rel]
        mine = self._local_slice(rel)
        b = self._b.duplicate()
        self._b.copy(b)
        b.array[rows_l] = np.where(factored, -g, 0.0)
        last = self._last
        applies = 1
        try:
            if (
                last is not None
                and last[0] == self.stats["factorizations"]
                and np.array_equal(last[1], g)
            ):
                self._x.array[:] = last[2]  # the factorized set's own solution, kept
            else:
                pc.apply(b, self._x)
                applies += 1
            mu0 = np.concatenate(self._mpi.allgather(self._x.array_r[rows_r]))
            resp = self._responses(rel_global, rel, factored)
            lu = scipy.linalg.lu_factor(
                np.concatenate(self._mpi.allgather(resp[rel])), check_finite=True
            )
            shift = scipy.linalg.lu_solve(lu, -mu0)
            b.array[rows_r] += shift[mine]
            pc.apply(b, self._x)
            self._x.array[rows_r] = 0.0
            r, res = self._residual(self._x)
            target = max(_RELEASED_RTOL, self._own_residual)
            for _ in range(2):
                if res <= target:
                    break
                # The correction solves the new system with the residual as right-hand side:
                # the factorized one with mu_R = 0 imposed by the same capacitance matrix.
                r.array[rows_r] = 0.0
                dx = r.duplicate()
                pc.apply(r, dx)
                d0 = np.concatenate(self._mpi.allgather(dx.array_r[rows_r]))
                r.array[rows_r] = scipy.linalg.lu_solve(lu, -d0)[mine]
                pc.apply(r, dx)
                dx.array[rows_r] = 0.0
                self._x.axpy(1.0, dx)
                dx.destroy()
                r.destroy()
                applies += 2
                r, res = self._residual(self._x)
            r.destroy()
        except (PETSc.Error, np.linalg.LinAlgError, ValueError):
            return None
        finally:
            b.destroy()
        if res > target:
            return None  # an ill-conditioned capacitance system: refactor instead
        t1 = time.perf_counter()
        self.stats["reused"] += 1
        u_sub, l_sub = self._x.getSubVector(self._is_u), self._x.getSubVector(self._is_l)
        u, mu = u_sub.array.copy(), l_sub.array.copy()
        self._x.restoreSubVector(self._is_u, u_sub)
        self._x.restoreSubVector(self._is_l, l_sub)
        info: dict[str, object] = {
            "refactored": False,
            "changed_rows": len(rel_global),
            "released": len(rel_global),
            "setup": 0.0,
            "solve": t1 - t0,
            "residual": res,
        }
        return SaddleResult(u, mu, applies, 1, info)

    def _responses(self, rows: np.ndarray, local: np.ndarray, factored: np.ndarray) -> np.ndarray:
        """Multiplier responses (local rows x len(rows)) to unit shifts of the global `rows`."""
        cache = self._cache
        if cache is not None and cache[0] == self.stats["factorizations"]:
            pos = np.searchsorted(cache[1], rows)
            pos = np.minimum(pos, len(cache[1]) - 1)
            if len(cache[1]) and np.array_equal(cache[1][pos], rows):
                return cache[2][:, pos]
        unit = np.zeros((len(local), len(rows)))
        unit[np.flatnonzero(local), np.arange(len(rows))[self._local_slice(local)]] = 1.0
        return self._solve_probes(unit, factored)

    def _local_slice(self, mask: np.ndarray) -> slice:
        """This rank's part of the rank-ordered concatenation of the local `mask` rows."""
        counts = self._mpi.allgather(int(np.count_nonzero(mask)))
        lo = sum(counts[: self._mpi.rank])
        return slice(lo, lo + counts[self._mpi.rank])

    def _solve_probes(self, probes: np.ndarray, active: np.ndarray) -> np.ndarray:
        """Multiplier responses (local rows x k) to multiplier-block right-hand sides `probes`."""
        k = probes.shape[1] if probes.ndim == 2 else 0
        k = self._mpi.allreduce(k, op=MPI.MAX)
        out = np.zeros((len(active), k))
        if k == 0:
            return out
        selected = self._selected_responses(probes.reshape(len(active), k), active)
        if selected is not None:
            out = selected
        else:
            self._dense_responses(probes, active, out)
        if self.direct:
            # Keep the responses: a later subset of this set is then solved without refactoring.
            gp = np.where(active[:, None], probes.reshape(len(active), k), 0.0)
            r0 = self._B.getOwnershipRange()[0]
            nz = gp != 0.0
            # A rank may own no multiplier row: argmax of an empty axis is undefined there.
            first = np.argmax(nz, axis=0) if nz.shape[0] else np.zeros(k, dtype=np.int64)
            col_row = np.where(nz.any(axis=0), r0 + first, -1)
            col_row = col_row.astype(np.int64)
            self._mpi.Allreduce(MPI.IN_PLACE, col_row, op=MPI.MAX)
            order = np.argsort(col_row)
            self._cache = (self.stats["factorizations"], col_row[order], out[:, order])
        return out

    def _selected_responses(self, probes: np.ndarray, active: np.ndarray) -> np.ndarray | None:
        """The probe responses as selected entries of A^-1 (MUMPS ICNTL(30)), or None.

        Only for unit columns on active rows (what the active-set loop probes): column j's
        responses are then the entries (i, j) of A^-1 over the active multiplier rows i
        (inactive rows respond with mu = 0). MUMPS prunes its elimination tree to the paths
        of these rows: 60 x 60 entries took 0.14 s at 1M dofs, 9.7 s as dense columns.
        """
        if not self.cheap_responses:
            return None
        nz = probes != 0.0
        if not (np.all(nz.sum(axis=0) == 1) and np.all(probes[nz] == 1.0)):
            return None
        col_rows = np.argmax(nz, axis=0)
        if not np.all(active[col_rows]):
            return None
        req = np.flatnonzero(active)
        rows_l = self._is_l.getIndices() - self._A.getOwnershipRange()[0]
        n = self._A.getSize()[0]
        cols, where = np.unique(rows_l[col_rows], return_inverse=True)
        wanted = np.sort(rows_l[req])
        order = np.argsort(rows_l[req])
        F = self._ksp.getPC().getFactorMatrix()
        entries = inverse_entries(F, wanted, cols, n)
        if entries is None:
            return None
        out = np.zeros((len(active), probes.shape[1]))
        out[req[order], :] = entries[where].T
        return out

    def _dense_responses(self, probes: np.ndarray, active: np.ndarray, out: np.ndarray) -> None:
        """Probe responses by multi-right-hand-side solves with the whole operator, into out."""
        k = out.shape[1]
        gp = np.where(active[:, None], probes.reshape(len(active), k), 0.0)
        start = self._A.getOwnershipRange()[0]
        rows_u = self._is_u.getIndices() - start
        rows_l = self._is_l.getIndices() - start
        nloc = self._b.getLocalSize()
        # Dense blocks of at most ~_PROBE_ENTRIES entries per rank: the right-hand sides and
        # solutions are (dofs x columns), gigabytes for a million dofs and 400 probes at once.
        chunk = max(1, min(k, _PROBE_ENTRIES // max(self._mpi.allreduce(nloc, op=MPI.MAX), 1)))
        for lo in range(0, k, chunk):
            cols = slice(lo, min(lo + chunk, k))
            rhs = np.zeros((nloc, cols.stop - lo))
            rhs[rows_l] = gp[:, cols]
            if self.gamma > 0.0:
                # The augmented block's right-hand side gamma B^T g, all columns in one product.
                rhs[rows_u] = self._dense_product(self._BAT, self.gamma * gp[:, cols])
            out[:, cols] = self._apply_inverse(rhs)[rows_l]

    def _dense_product(self, A: PETSc.Mat, local: np.ndarray) -> np.ndarray:
        """Local rows of A @ X for a dense X given by its local rows (one sparse-dense product)."""
        size = ((local.shape[0], PETSc.DETERMINE), (PETSc.DECIDE, local.shape[1]))
        X = PETSc.Mat().createDense(size, comm=self._comm)
        X.setUp()
        X.getDenseArray()[:] = local
        X.assemble()
        Y = A.matMult(X)
        out = Y.getDenseArray().copy()
        X.destroy()
        Y.destroy()
        return out

    def _apply_inverse(self, rhs: np.ndarray) -> np.ndarray:
        """Solutions (local rows x columns) for dense right-hand sides, current operator."""
        if self.direct:
            # The factorization is exact here: one multi-right-hand-side MUMPS solve.
            size = ((rhs.shape[0], PETSc.DETERMINE), (PETSc.DECIDE, rhs.shape[1]))
            Bd = PETSc.Mat().createDense(size, comm=self._comm)
            Bd.setUp()
            Bd.getDenseArray()[:] = rhs
            Bd.assemble()
            Xd = Bd.duplicate()
            self._ksp.getPC().matApply(Bd, Xd)
            sol = Xd.getDenseArray().copy()
            Bd.destroy()
            Xd.destroy()
            return sol
        sol = np.zeros_like(rhs)
        b, x = self._b.duplicate(), self._x.duplicate()
        for j in range(rhs.shape[1]):
            b.array[:] = rhs[:, j]
            x.set(0.0)
            self._ksp.solve(b, x)
            sol[:, j] = x.array_r
        b.destroy()
        x.destroy()
        return sol


def _inactive_scale(K: PETSc.Mat, B: PETSc.Mat) -> float:
    """C's entry on inactive rows (which only say mu = 0): the scale of B K^-1 B^T, negative.

    Any nonzero value gives the same solution, but 1 next to Schur entries of order
    |B_j|^2 / K_jj (1e-8 and less) leaves eigenvalues that far apart, and GMRES on a lagged
    factorization then stagnates at the factorization's round-off.
    """
    comm = K.getComm().tompi4py()
    _, _, vals = B.getValuesCSR()
    indptr = B.getValuesCSR()[0]
    rows = np.add.reduceat(vals**2, indptr[:-1]) if len(vals) else np.zeros(0)
    rows = rows[np.diff(indptr) > 0]
    diag = np.abs(K.getDiagonal().array_r)
    b2 = comm.allreduce(float(rows.sum())) / max(comm.allreduce(len(rows)), 1)
    kd = comm.allreduce(float(diag.sum())) / max(comm.allreduce(len(diag)), 1)
    return -b2 / kd if b2 > 0.0 and kd > 0.0 else 1.0


def solve_saddle(
    K: PETSc.Mat,
    B: PETSc.Mat,
    f: PETSc.Vec,
    g: np.ndarray,
    active: np.ndarray,
    options: Mapping[str, object],
    gamma: float = 0.0,
    nullspace: PETSc.NullSpace | None = None,
    probes: np.ndarray | None = None,
) -> SaddleResult:
    """One fresh solve (setup, factorization or preconditioner set-up, solve), nothing kept."""
    with SaddleSolver(K, B, f, options, gamma, nullspace, reuse_factorization=False) as solver:
        return solver.solve(g, active, probes)


def reference_solve(
    K: PETSc.Mat,
    B: PETSc.Mat,
    f: PETSc.Vec,
    g: np.ndarray,
    active: np.ndarray,
    options: Mapping[str, object],
    gamma: float = 0.0,
    nullspace: PETSc.NullSpace | None = None,
) -> tuple[SaddleResult, float]:
    """A fresh solve with the active set fixed, and its wall-clock seconds (the cost floor)."""
    K.getComm().tompi4py().Barrier()
    t0 = time.perf_counter()
    res = solve_saddle(K, B, f, g, active, options, gamma, nullspace)
    return res, time.perf_counter() - t0
