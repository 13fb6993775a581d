"""The linear solves of a frictional set: one LU of a fixed pattern, or the condensed path.

The direct path factors the saddle point
[[K, B_n^T, B_t^T], [B_n', C_nn, 0], [B_t', C_tn, C_tt]] (methods/friction.py). Its pattern
does not depend on the set: every row of B_n and B_t is stored in it, an open row with the
value 0 (C_nn = 1), a slipping tangential row too (C_tn = mu s, C_tt = 1). So one matrix is
assembled once (COO), each set only writes its values, and MUMPS' analysis (the ordering
and the symbolic factorization) is done once for the whole load history: each set costs a
numeric factorization (benchmarks/friction_cost.py). The condensed path eliminates the
multipliers node by node (linalg/condensed_friction.py).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..errors import SolverError
from ..linalg.condensed_friction import FrictionCondensedSolver, FrictionSolve
from ..linalg.petsc_options import PrefixedOptions
from ..linalg.row_update import KeptFactorization
from .solvers import with_ordering, with_sequential_analysis

# A column of the changed rows' block solve relative to one back-substitution (measured:
# benchmarks/README.md, friction_cost.py), and the most memory the kept columns (a dense
# vector each) may take.
COLUMN_COST = 0.4
KEPT_BYTES = 2**28
# A solve on the kept factorization is refined to the residual of the factorization's own
# back-substitution (times ROUNDOFF), or FLOOR_RTOL; else the set is factored: the loop's
# decisions then do not depend on which way a set was solved.
ROUNDOFF, FLOOR_RTOL = 10.0, 1e-15


@dataclass(frozen=True)
class FrictionSystem:
    """One set's law, owned rows: which rows are on, and the right-hand sides."""

    active: np.ndarray  # normal rows in contact
    stick: np.ndarray  # tangential rows sticking (of the active ones)
    slip_coef: np.ndarray  # mu s on a slipping row (mu_t + mu s mu_n = 0), else 0
    g_n: np.ndarray  # B_n u = -g_n on the active rows
    g_t: np.ndarray  # B_t u = -g_t on the sticking rows


@dataclass
class FrictionAnswer:
    """Owned u, mu_n, mu_t of one set's solve (K u + B_n^T mu_n + B_t^T mu_t = f)."""

    u: np.ndarray
    mu_n: np.ndarray
    mu_t: np.ndarray
    iterations: int = 1  # Krylov iterations (1: a direct solve)
    final: bool = True  # solved to the final tolerance (a condensed loose answer: False)


def _csr(A: PETSc.Mat) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A matrix's local rows as (row index of each entry, global column, value)."""
    indptr, cols, vals = A.getValuesCSR()
    rows = np.repeat(np.arange(len(indptr) - 1, dtype=np.int64), np.diff(indptr))
    return rows, np.asarray(cols, dtype=np.int64), np.asarray(vals, dtype=float)


class DirectFriction:
    """LU (MUMPS) of the frictional saddle point, its pattern and analysis kept across sets.

    `bind` takes a load step's K, B_n, B_t and f; a step with the same patterns keeps the
    matrix and the analysis (the load steps share the mesh and the contact rows).
    """

    def __init__(self, options: Mapping[str, object] | None = None) -> None:
        self._given = dict(options or {})
        self._options = PrefixedOptions({})
        self._A: PETSc.Mat | None = None
        self._P: PETSc.Mat | None = None
        self._ksp: PETSc.KSP | None = None
        self._key: tuple[np.ndarray, ...] = ()
        self._law: np.ndarray | None = None  # the factored set's law per row
        self._kept: KeptFactorization | None = None
        self.stats = {"analyses": 0, "factorizations": 0, "updated": 0, "assembly": 0.0}
        self.stats["factor"] = 0.0

    def bind(self, K: PETSc.Mat, Bn: PETSc.Mat, Bt: PETSc.Mat, f: PETSc.Vec) -> None:
        """The step's operators; the monolithic pattern is rebuilt only where it changed."""
        comm = K.getComm()
        mpi = comm.tompi4py()
        self._f = f
        k, n, t = _csr(K), _csr(Bn), _csr(Bt)
        old, self._parts = getattr(self, "_parts", ()), (k, n, t)
        nu, m = K.getLocalSize()[0], Bn.getLocalSize()[0]
        self._nu, self._m = nu, m
        key = (k[0], k[1], n[0], n[1], t[0], t[1])
        same = len(key) == len(self._key) and all(
            np.array_equal(a, b) for a, b in zip(key, self._key, strict=True)
        )
        if mpi.allreduce(same, op=MPI.LAND) and self._A is not None:
            values = all(np.array_equal(a[2], b[2]) for a, b in zip(old, self._parts, strict=True))
            if not mpi.allreduce(values, op=MPI.LAND):
                self._law, self._kept = None, None  # new values: not this factorization's
            return
        self.destroy()
        self._key = key
        sizes = np.array(mpi.allgather((nu, m)), dtype=np.int64)
        start = np.concatenate([[0], np.cumsum(sizes[:, 0] + 2 * sizes[:, 1])])
        u0 = np.concatenate([[0], np.cumsum(sizes[:, 0])])
        rank = mpi.rank

        def mapu(g: np.ndarray) -> np.ndarray:
            q = np.searchsorted(u0, g, side="right") - 1
            return start[q] + g - u0[q]

        base = start[rank]
        rows_u = base + np.arange(nu)
        rows_n = base + nu + np.arange(m)
        rows_t = rows_n + m
        self._rows_nt = (rows_n, rows_t)
        i = np.concatenate(
            [
                rows_u[k[0]],
                rows_n[n[0]],
                mapu(n[1]),
                rows_t[t[0]],
                mapu(t[1]),
                rows_n,
                rows_t,
                rows_t,
            ]
        )
        j = np.concatenate(
            [mapu(k[1]), mapu(n[1]), rows_n[n[0]], mapu(t[1]), rows_t[t[0]], rows_n, rows_n, rows_t]
        )
        size = nu + 2 * m
        ij = (i.astype(PETSc.IntType), j.astype(PETSc.IntType))
        mats = []
        for _ in range(2):  # the current set's matrix, and the one last factored
            M = PETSc.Mat().create(comm)
            M.setSizes(((size, PETSc.DETERMINE), (size, PETSc.DETERMINE)))
            M.setType(PETSc.Mat.Type.AIJ)
            # PETSc may reorder the index arrays in place: each matrix gets its own copy.
            M.setPreallocationCOO(cast(Any, ij[0].copy()), cast(Any, ij[1].copy()))
            mats.append(M)
        self._A, self._P = mats
        lu = {"ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}
        ordered = with_ordering(lu | self._given, K.getSize()[0])
        self._options = PrefixedOptions(with_sequential_analysis(ordered, mpi.size))
        ksp = PETSc.KSP().create(comm)
        ksp.setOptionsPrefix(self._options.prefix)
        self._ksp = ksp
        self._law, self._kept = None, None
        self._configured = False
        self._t_factor, self._t_bs = 0.0, 0.0  # a numeric factorization, a back-substitution
        self._res_bs = 0.0  # the relative residual of the last back-substitution

    def solve(self, s: FrictionSystem) -> FrictionAnswer:
        """Write the set's values and solve: by the kept factorization or a new one."""
        assert self._A is not None and self._P is not None and self._ksp is not None
        t0 = time.perf_counter()
        (_, _, kv), (nr, _, nv), (tr, _, tv) = self._parts
        on, stick = s.active.astype(float), s.stick.astype(float)
        v = np.concatenate(
            [kv, nv * on[nr], nv, tv * stick[tr], tv, 1.0 - on, s.slip_coef, 1.0 - stick]
        ).astype(PETSc.ScalarType)
        self._A.setValuesCOO(cast(Any, v), cast(Any, PETSc.InsertMode.INSERT_VALUES))
        self._A.assemble()
        law = np.concatenate([on, stick, s.slip_coef])
        mpi = self._A.getComm().tompi4py()
        b = self._A.createVecRight()
        b.array[:] = np.concatenate(
            [self._f.array_r, np.where(s.active, -s.g_n, 0.0), np.where(s.stick, -s.g_t, 0.0)]
        )
        x = b.duplicate()
        self.stats["assembly"] += time.perf_counter() - t0
        rows = np.zeros(0, dtype=np.int64)
        if self._law is not None:
            nodes = (law != self._law).reshape(3, -1).any(axis=0)
            rows = np.sort(np.concatenate([r[nodes] for r in self._rows_nt]))
        if self._refactor(rows, mpi):
            self._factor(v, law)
            rows = rows[:0]
        if mpi.allreduce(len(rows)) == 0:
            self._back_substitution(b, x)
        else:
            assert self._kept is not None
            rtol = max(ROUNDOFF * self._res_bs, FLOOR_RTOL)
            if self._kept.solve(self._A, self._P, rows, b, x, rtol):
                self.stats["updated"] += 1
            else:  # the kept factorization is too far from this set: a new one
                self._factor(v, law)
                self._back_substitution(b, x)
        nu, m = self._nu, self._m
        out = x.array_r.copy()
        b.destroy()
        x.destroy()
        return FrictionAnswer(out[:nu], out[nu : nu + m], out[nu + m :])

    def _refactor(self, rows: np.ndarray, mpi: MPI.Comm) -> bool:
        """Whether a new factorization costs less than a solve on the kept one.

        That solve costs two back-substitutions and a block solve with a column per row
        not met before on this factorization (each about COLUMN_COST of one); the kept
        columns are bounded by KEPT_BYTES.
        """
        if self._kept is None:
            return True
        new = mpi.allreduce(sum(1 for g in rows if not self._kept.has(int(g))))
        total = mpi.allreduce(len(rows))
        if total * 8 * max(self._nu + 2 * self._m, 1) > KEPT_BYTES:
            return True
        return (2.0 + COLUMN_COST * new) * self._t_bs > self._t_factor

    def _factor(self, v: np.ndarray, law: np.ndarray) -> None:
        """A numeric factorization of the set `v` (the analysis is the first one's)."""
        assert self._A is not None and self._P is not None and self._ksp is not None
        t0 = time.perf_counter()
        self._P.setValuesCOO(cast(Any, v), cast(Any, PETSc.InsertMode.INSERT_VALUES))
        self._P.assemble()
        ksp = self._ksp
        ksp.setOperators(self._P)
        with self._options.inserted():
            if not self._configured:
                ksp.setFromOptions()
                self._configured = True
                self.stats["analyses"] += 1
            ksp.setUp()
        self._law = law.copy()
        self._kept = KeptFactorization(ksp.getPC().getFactorMatrix())
        # Every rank must take the same branch of `_refactor` (a factorization is collective):
        # the slowest rank's time decides.
        self._t_factor = (
            self._P.getComm().tompi4py().allreduce(time.perf_counter() - t0, op=MPI.MAX)
        )
        self.stats["factorizations"] += 1
        self.stats["factor"] += self._t_factor

    def _back_substitution(self, b: PETSc.Vec, x: PETSc.Vec) -> None:
        """Solve on the factored set itself."""
        assert self._ksp is not None
        t0 = time.perf_counter()
        self._ksp.solve(b, x)
        self._t_bs = (
            b.getComm().tompi4py().allreduce(time.perf_counter() - t0, op=MPI.MAX)
        )  # as above
        assert self._A is not None
        r = b.duplicate()
        self._A.mult(x, r)
        r.aypx(-1.0, b)
        self._res_bs = float(cast(Any, r.norm())) / max(float(cast(Any, b.norm())), 1e-300)
        r.destroy()
        reason = cast(int, self._ksp.getConvergedReason())
        if reason < 0:
            raise SolverError(f"the frictional saddle point's LU failed ({reason})")

    def destroy(self) -> None:
        """Free the matrix and the factorization."""
        for obj in (self._ksp, self._A, self._P):
            if obj is not None:
                obj.destroy()
        self._ksp, self._A, self._P = None, None, None


class CondensedFriction:
    """The condensed path's solves of frictional sets (linalg/condensed_friction.py)."""

    def __init__(self, solver: FrictionCondensedSolver) -> None:
        self._solver = solver
        self.stats = solver.stats

    def solve(
        self, s: FrictionSystem, stationary: Callable[[FrictionAnswer], bool] | None = None
    ) -> FrictionAnswer:
        """Solve the set to the loop's loose tolerance, or on to the final one.

        The run goes on where the loose answer is `stationary` (asked inside the Krylov run);
        without `stationary` it solves to the final tolerance.
        """

        def ask(r: FrictionSolve) -> bool:
            assert stationary is not None
            return stationary(FrictionAnswer(r.u, r.mu_n, r.mu_t, r.iterations, False))

        r = self._solver.solve_sets(
            (s.g_n, s.g_t), s.active, s.stick, -s.slip_coef, None if stationary is None else ask
        )
        return FrictionAnswer(r.u, r.mu_n, r.mu_t, r.iterations, r.final)

    def destroy(self) -> None:
        """Free the solver."""
        self._solver.destroy()
