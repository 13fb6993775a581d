"""Solves with a kept factorization of P for a matrix A that differs from it in a few rows.

A = P + E_R D, E_R the unit columns of the changed rows R, D = (A - P)_R. Woodbury:

    x = y - Z (I + D Z)^-1 D y,    y = P^-1 b,  Z = P^-1 E_R,

one multi-right-hand-side solve for Z (|R| columns) and one back-substitution, exact as a
factorization of A up to the capacitance matrix's conditioning (r x r, dense); iterative
refinement on A's own residual follows, to a fresh factorization's residual. Z's columns
depend on P and R only: they are kept for the later sets on the same factorization, which
solve only for rows that are new. The
frictional saddle point changes only in the multiplier rows of nodes whose law changed
(methods/friction_linear.py).
"""

from __future__ import annotations

from typing import Any, cast

import numpy as np
from petsc4py import PETSc

# Steps of iterative refinement at most after the Woodbury solve (one back-substitution each).
# The residual's norm measures the displacement rows; the multipliers' own accuracy needs
# the refinement to go on to round-off: until a step reduces it by less than 1 / STALL.
REFINEMENTS = 4
STALL = 0.5


class KeptFactorization:
    """Woodbury solves on one factorization F of P, Z's columns kept by row."""

    def __init__(self, F: PETSc.Mat) -> None:
        self._F = F
        # Z's kept columns as the rows of one array (global row -> its index), so that a
        # set's columns are one gather rather than a stack of |R| arrays per solve.
        self._index: dict[int, int] = {}
        self._Zt = np.zeros((0, 0))
        self.columns_solved = 0

    def has(self, row: int) -> bool:
        """Whether Z's column of global row `row` is kept."""
        return row in self._index

    def _z(self, rows_all: np.ndarray, n_loc: int, comm: PETSc.Comm) -> np.ndarray:
        """This rank's rows of Z = P^-1 E_R (R = `rows_all`, every rank's, in order)."""
        new = [int(g) for g in rows_all if int(g) not in self._index]
        if new:
            r0, r1 = self._F.getOwnershipRange()
            E = PETSc.Mat().createDense(
                size=((n_loc, PETSc.DETERMINE), (PETSc.DECIDE, len(new))), comm=comm
            )
            E.setUp()
            for k, g in enumerate(new):
                if r0 <= g < r1:
                    E.setValue(g, k, 1.0)
            E.assemble()
            Z = E.duplicate()
            self._F.matSolve(E, Z)
            block = np.asarray(Z.getDenseArray()).reshape(n_loc, len(new))
            start = len(self._index)
            self._Zt = np.concatenate([self._Zt.reshape(start, n_loc), block.T])
            self._index.update((g, start + k) for k, g in enumerate(new))
            self.columns_solved += len(new)
            E.destroy()
            Z.destroy()
        if not len(rows_all):
            return np.zeros((n_loc, 0))
        return self._Zt[[self._index[int(g)] for g in rows_all]].T

    def solve(
        self,
        A: PETSc.Mat,
        P: PETSc.Mat,
        rows: np.ndarray,
        b: PETSc.Vec,
        x: PETSc.Vec,
        rtol: float,
    ) -> bool:
        """Solve A x = b to A's relative residual `rtol` (False: refinement did not reach it).

        `rows`: this rank's global rows where A != P (the same pattern).
        """
        comm = A.getComm()
        mpi = comm.tompi4py()
        r0, r1 = A.getOwnershipRange()
        n_loc = r1 - r0
        rows_all = np.concatenate(mpi.allgather(np.asarray(rows, dtype=np.int64)))
        r = len(rows_all)
        indptr, cols, vals = [0], [], []
        for g in rows:
            ca, va = A.getRow(int(g))
            _, vp = P.getRow(int(g))
            d = np.asarray(va) - np.asarray(vp)
            keep = d != 0.0
            cols.append(np.asarray(ca)[keep])
            vals.append(d[keep])
            indptr.append(indptr[-1] + int(keep.sum()))
        csr: Any = (
            np.asarray(indptr, dtype=PETSc.IntType),
            (np.concatenate(cols) if cols else np.zeros(0)).astype(PETSc.IntType),
            (np.concatenate(vals) if vals else np.zeros(0)).astype(PETSc.ScalarType),
        )
        size: Any = ((len(rows), r), (n_loc, PETSc.DETERMINE))
        D = PETSc.Mat().createAIJ(size=size, csr=csr, comm=comm)
        D.assemble()
        Zl = self._z(rows_all, n_loc, comm)
        # D Z, row by row of D: its columns' rows of Z may be another rank's (a vector each).
        Zv, w = A.createVecRight(), D.createVecLeft()
        DZ = np.zeros((r, r))
        for k in range(r):
            Zv.array[:] = Zl[:, k]
            D.mult(Zv, w)
            DZ[:, k] = np.concatenate(mpi.allgather(w.array_r.copy()))
        C = np.eye(r) + DZ
        res, y = b.duplicate(), b.duplicate()
        x.set(0.0)
        b.copy(res)
        b_norm = max(float(cast(Any, b.norm())), 1e-300)
        ok, last = False, float("inf")
        for _ in range(REFINEMENTS + 1):  # the solve, then refinement on A's own residual
            self._F.solve(res, y)
            D.mult(y, w)
            c = np.linalg.solve(C, np.concatenate(mpi.allgather(w.array_r.copy())))
            y.array[:] = y.array_r - np.asarray(Zl @ c, dtype=float)
            x.axpy(1.0, y)
            A.mult(x, res)
            res.aypx(-1.0, b)
            now = float(cast(Any, res.norm()))
            if now > last:  # the step made it worse: undo it (round-off reached)
                x.axpy(-1.0, y)
                break
            ok = now <= rtol * b_norm
            if now > STALL * last:  # round-off: more steps do not help
                break
            last = now
        for obj in (D, Zv, w, res, y):
            obj.destroy()
        return ok
