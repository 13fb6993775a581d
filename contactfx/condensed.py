"""The condensed solver: the active multipliers eliminated, CG + GAMG on the displacements.

With a diagonal D (NTS, or mortar with the dual basis) each active row j of B touches one
active node's own dofs only, so one of them, the pivot p(j) (the component with the largest
coefficient c_j), is given by the constraint: u_p = -(g_j + sum_{k != p} B_jk u_k) / c_j.
Writing u = T v + t (T the identity except on pivot rows, t = -g_j / c_j there) turns the
saddle point into the symmetric positive definite displacement system

    (T^T K T + P) v = T^T (f - K t),    P = diag(K_pp) on the pivots (v_p is free: set 0),

and the multipliers follow from the pivot rows of equilibrium, mu_j = (f - K u)_p / c_j.

The first set builds T^T K T = K + E^T K + K E + E^T K E (E = T - I: a few rows) and GAMG on
it, with the rigid modes of all bodies (zero on the pivots) as near-nullspace. Later sets
differ from it by a few pivots, a low-rank change: CG keeps that multigrid and applies the new
operator matrix-free, from the last displacement, until the pivots have moved too far. The
loop's solves stop at a loose tolerance (only signs decide the set); the stationary set is
polished to the final one (`polish`), so the answer does not depend on the loose one.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from typing import Any, cast

import numpy as np
from petsc4py import PETSc

from .errors import InputError, SolverError
from .nullspace import orthonormalize
from .saddle import SaddleResult
from .solvers import PrefixedOptions, petsc_error_message, reason_name

_ADD = cast(Any, PETSc.InsertMode.ADD_VALUES)
# Entries of B on another active node's dofs larger than this (relative to the row's pivot)
# mean D is not diagonal: the elimination would couple the pivots.
_DIAGONAL_TOL = 1e-10
# Pivot changes since the multigrid was built (summed over ranks) below which it is reused.
_REBUILD_CHANGES = 64


def is_condensed(options: Mapping[str, object]) -> bool:
    """True for the options of the condensed solver."""
    return bool(options.get("contactfx_condensed", False))


class CondensedSolver:
    """Solve K u + B^T mu = f, B_A u = -g_A by elimination; same interface as SaddleSolver."""

    def __init__(
        self,
        K: PETSc.Mat,
        B: PETSc.Mat,
        f: PETSc.Vec,
        options: Mapping[str, object],
        node_dofs: np.ndarray,
        modes: list[PETSc.Vec] | None = None,
    ) -> None:
        """`node_dofs` (m, 2): global dofs of each owned row's active node."""
        self._K, self._B, self._f = K, B, f
        self._comm = K.getComm()
        self._mpi = self._comm.tompi4py()
        self._node_dofs = np.asarray(node_dofs, dtype=np.int64).reshape(-1, 2)
        self._indptr, self._cols, self._vals = B.getValuesCSR()
        self._modes = modes or []
        self._options = PrefixedOptions(
            {k: v for k, v in options.items() if not k.startswith("contactfx_")}
        )
        # The loop's solves stop early (the set only needs signs); the one on the set that
        # turned out stationary is polished to ksp_rtol (`polish`).
        self._rtol = float(cast(Any, options.get("ksp_rtol", 1e-9)))
        self._loose_rtol = max(
            self._rtol, float(cast(Any, options.get("contactfx_loose_rtol", self._rtol)))
        )
        self._A: PETSc.Mat | None = None  # the operator the multigrid was built from
        self._ksp = PETSc.KSP().create(self._comm)
        self._ksp.setOptionsPrefix(self._options.prefix)
        self._u = f.duplicate()
        self._u.set(0.0)
        self._diag = K.getDiagonal()
        self._r0, self._r1 = K.getOwnershipRange()
        self.stats = {"factorizations": 0.0, "reused": 0.0, "setup_time": 0.0}
        self._built_for: np.ndarray | None = None  # the pivots the multigrid was built with
        self.reuse = True

    @property
    def cheap_responses(self) -> bool:
        """No probe responses: the condensed solver has no factorization to reuse."""
        return False

    def destroy(self) -> None:
        """Free the PETSc objects and remove this solver's options."""
        self._options.remove()
        for obj in (self._ksp, self._u, self._diag, self._A):
            if obj is not None:
                obj.destroy()

    def _pivots(self, active: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(owned active rows, their pivot dofs, the pivot coefficients)."""
        rows = np.flatnonzero(active)
        piv = np.zeros(len(rows), dtype=np.int64)
        coef = np.zeros(len(rows))
        for i, j in enumerate(rows):
            lo, hi = self._indptr[j], self._indptr[j + 1]
            cols, vals = self._cols[lo:hi], self._vals[lo:hi]
            own = np.isin(cols, self._node_dofs[j])
            if not own.any() or np.abs(vals[own]).max() == 0.0:
                raise InputError(
                    "the condensed solver cannot eliminate a contact row whose "
                    "active node is fully prescribed: use --solver mumps"
                )
            k = np.flatnonzero(own)[int(np.argmax(np.abs(vals[own])))]
            piv[i], coef[i] = cols[k], vals[k]
        # Every active node's dofs, from all ranks: a row touching another one means that D
        # is not diagonal.
        others = np.concatenate(self._mpi.allgather(self._node_dofs[rows].ravel()))
        for i, j in enumerate(rows):
            lo, hi = self._indptr[j], self._indptr[j + 1]
            cols, vals = self._cols[lo:hi], self._vals[lo:hi]
            foreign = np.isin(cols, others) & ~np.isin(cols, self._node_dofs[j])
            if foreign.any() and np.abs(vals[foreign]).max() > _DIAGONAL_TOL * abs(coef[i]):
                raise InputError(
                    "the condensed solver needs a diagonal D (one active node per "
                    "constraint row): use --method nts, or mortar with --basis "
                    "dual (on a flat passive surface), or --solver mumps"
                )
        return rows, piv, coef

    def _pivot_rows(
        self, rows: np.ndarray, piv: np.ndarray, coef: np.ndarray
    ) -> dict[int, tuple[np.ndarray, np.ndarray]]:
        """Row p(j) of E = T - I per pivot (by local row): -B_j / c_j, -1 on the pivot, sorted."""
        out: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        for i, j in enumerate(rows):
            lo, hi = self._indptr[j], self._indptr[j + 1]
            cols, vals = self._cols[lo:hi], self._vals[lo:hi]
            keep = (cols != piv[i]) & (vals != 0.0)
            c = np.append(cols[keep], piv[i])
            v = np.append(-vals[keep] / coef[i], -1.0)
            order = np.argsort(c)
            out[int(piv[i] - self._r0)] = (c[order], v[order])
        return out

    def _matrix(self, prows: dict[int, tuple[np.ndarray, np.ndarray]], identity: bool) -> PETSc.Mat:
        """T (identity=True: I off the pivot rows, 0 on the pivot itself) or E = T - I."""
        n = self._r1 - self._r0
        counts = np.full(n, 1 if identity else 0, dtype=np.int64)
        for r, (c, _) in prows.items():
            counts[r] = len(c)
        indptr = np.concatenate([[0], np.cumsum(counts)])
        cols = np.arange(self._r0, self._r1, dtype=np.int64).repeat(counts)
        vals = np.ones(indptr[-1])
        for r, (c, v) in prows.items():
            seg = slice(indptr[r], indptr[r + 1])
            cols[seg] = c
            vals[seg] = v + (c == self._r0 + r) if identity else v
        csr: Any = (
            indptr.astype(PETSc.IntType),
            cols.astype(PETSc.IntType),
            vals.astype(PETSc.ScalarType),
        )
        nglob = self._K.getSize()[0]
        M = PETSc.Mat().createAIJ(size=((n, nglob), (n, nglob)), csr=csr, comm=self._comm)
        M.assemble()
        return M

    def solve(
        self, g: np.ndarray, active: np.ndarray, probes: np.ndarray | None = None
    ) -> SaddleResult:
        """Displacements and multipliers (owned parts), at the loose tolerance of the loop."""
        if probes is not None:
            raise InputError("the condensed solver has no probes (it is not a factorization)")
        return self._solve(g, active, self._loose_rtol)

    def polish(self, g: np.ndarray, active: np.ndarray) -> SaddleResult:
        """The same set solved to the final tolerance, from the last (loose) solution."""
        return self._solve(g, active, self._rtol)

    def _solve(self, g: np.ndarray, active: np.ndarray, rtol: float) -> SaddleResult:
        t0 = time.perf_counter()
        rows, piv, coef = self._pivots(np.asarray(active, dtype=bool))
        # petsc4py's stubs type indices and values as Sequences; numpy arrays work as well.
        ip: Any = piv.astype(PETSc.IntType)
        prows = self._pivot_rows(rows, piv, coef)
        T = self._matrix(prows, identity=True)
        d = self._f.duplicate()
        d.set(0.0)
        d.setValues(ip, cast(Any, self._diag.getValues(ip)))
        d.assemble()
        t = self._f.duplicate()
        t.set(0.0)
        t.setValues(ip, cast(Any, -np.asarray(g)[rows] / coef))
        t.assemble()
        r = self._f.duplicate()
        self._K.mult(t, r)
        r.aypx(-1.0, self._f)  # f - K t
        b = self._f.duplicate()
        T.multTranspose(r, b)
        v = self._u.copy()  # warm start: the last displacement, pivots free
        v.setValues(ip, cast(Any, np.zeros(len(piv))))
        v.assemble()
        # A few pivots more or less change T^T K T by a term of their rank, which costs CG
        # at most that many extra iterations: the multigrid built for an earlier set keeps
        # preconditioning it (the new operator applied matrix-free) until the pivots have
        # moved in more than max(a fifth of the set, `_REBUILD_CHANGES`) places, when a new
        # setup pays off.
        prev = self._built_for
        changed = self._mpi.allreduce(int(np.setxor1d(prev, piv).size)) if prev is not None else 0
        n_piv = self._mpi.allreduce(len(piv))
        reuse = self.reuse and prev is not None and changed <= max(0.2 * n_piv, _REBUILD_CHANGES)
        ksp = self._ksp
        try:
            if reuse:
                op = _CondensedOperator(self._K, T, d)
                A = PETSc.Mat().createPython(cast(Any, self._K.getSizes()), op, comm=self._comm)
                A.setUp()
                assert self._A is not None
                ksp.setOperators(A, self._A)
            else:
                A = self._condensed_matrix(prows, ip)
                if self._modes:
                    A.setNearNullSpace(self._near_nullspace(piv))
                ksp.setOperators(A)
                ksp.setFromOptions()
                if self._A is not None:
                    self._A.destroy()
                self._A = A
                self._built_for = piv.copy()
            ksp.getPC().setReusePreconditioner(reuse)
            ksp.setInitialGuessNonzero(True)
            if rtol > self._rtol:
                # A loose solve reduces its own initial residual (PETSc measures against
                # ||b||): from a warm start that is already within rtol it would not
                # iterate at all, and the set would be judged on the previous set's
                # displacements (which made the default Hertz scene cycle).
                res0 = b.duplicate()
                A.mult(v, res0)
                res0.aypx(-1.0, b)
                r0, b0 = float(cast(Any, res0.norm())), float(cast(Any, b.norm()))
                rtol = max(self._rtol, rtol * r0 / max(b0, 1e-300))
                res0.destroy()
            ksp.setTolerances(rtol=rtol)
            ksp.setUp()
            t1 = time.perf_counter()
            ksp.solve(b, v)
        except PETSc.Error as err:
            raise SolverError(petsc_error_message(err, "condensed solve")) from None
        reason, its = cast(int, ksp.getConvergedReason()), ksp.getIterationNumber()
        if reason <= 0 or not np.isfinite(v.norm()):
            raise SolverError(
                f"condensed solve ({ksp.getType()}) did not converge: PETSc "
                f"reason {reason} ({reason_name(reason)}) after {its} iterations"
            )
        T.mult(v, self._u)
        self._u.axpy(1.0, t)
        self._K.mult(self._u, r)
        r.aypx(-1.0, self._f)  # f - K u: the contact force on the pivots
        mu = np.zeros(len(active))
        mu[rows] = r.getValues(ip) / coef
        u = self._u.array.copy()
        t2 = time.perf_counter()
        for obj in (T, d, t, r, b, v):
            obj.destroy()
        if reuse:
            A.destroy()
        self.stats["reused" if reuse else "factorizations"] += 1
        self.stats["setup_time"] += t1 - t0
        return SaddleResult(
            u, mu, its, reason, {"refactored": not reuse, "setup": t1 - t0, "solve": t2 - t1}
        )

    def _condensed_matrix(
        self, prows: dict[int, tuple[np.ndarray, np.ndarray]], ip: Any
    ) -> PETSc.Mat:
        """T^T K T + P = K + E^T K + K E + E^T K E (E = T - I, nonzero on pivot rows only).

        A general PtAP costs several passes over K and leaves the pivot rows without a
        diagonal (inserting one reallocates the matrix, once per row). Here E^T K is a few
        rows of K (the pivots' neighbourhoods); only the final sum passes over K once.
        """
        diff = cast(Any, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
        E = self._matrix(prows, identity=False)
        Et = E.transpose(PETSc.Mat())  # without `out` petsc4py transposes in place
        EtK = Et.matMult(self._K)
        C = EtK.transpose(PETSc.Mat())  # K E (K is symmetric)
        C.axpy(1.0, EtK, structure=diff)
        EtKE = EtK.matMult(E)
        C.axpy(1.0, EtKE, structure=diff)
        A = self._K.copy()
        A.axpy(1.0, C, structure=diff)
        # Round-off leaves ~1e-16 on the pivot rows and columns: zero them, with K_pp on
        # the diagonal (the decoupled v_p = 0).
        A.zeroRowsColumns(ip, diag=1.0)
        diag = A.getDiagonal()
        diag.setValues(ip, cast(Any, self._diag.getValues(ip)))
        diag.assemble()
        A.setDiagonal(diag)
        A.setBlockSize(2)
        for obj in (E, Et, EtK, C, EtKE, diag):
            obj.destroy()
        return A

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


class _CondensedOperator:
    """y = (T^T K T + P) x applied matrix-free (a petsc4py Python matrix context)."""

    def __init__(self, K: PETSc.Mat, T: PETSc.Mat, d: PETSc.Vec) -> None:
        self._K, self._T, self._d = K, T, d
        self._w1, self._w2 = K.createVecRight(), K.createVecLeft()

    def mult(self, mat: PETSc.Mat, x: PETSc.Vec, y: PETSc.Vec) -> None:
        """The product with x (the pivots' own diagonal added: they are decoupled)."""
        self._T.mult(x, self._w1)
        self._K.mult(self._w1, self._w2)
        self._T.multTranspose(self._w2, y)
        self._w1.pointwiseMult(self._d, x)
        y.axpy(1.0, self._w1)


def owned_node_dofs(layout_gblock: np.ndarray, mine: np.ndarray) -> np.ndarray:
    """(m, 2) global dofs (x, y) of the active node of each owned multiplier row."""
    g = np.asarray(layout_gblock)[mine].astype(np.int64)
    return np.column_stack([2 * g, 2 * g + 1])
