"""The fixed-pattern blocks of the saddle point [[A00, B_A^T], [B_A, C]] as one PETSc MatNest.

An active set only scales B's rows (B_A = diag(active) B) and switches C's diagonal, so every
block keeps its nonzero pattern across the sets of a loop and `update` writes values only.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import cast

import numpy as np
from petsc4py import PETSc


def diagonal_matrix(comm: PETSc.Comm, values: np.ndarray, offset: int) -> PETSc.Mat:
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


def inactive_scale(K: PETSc.Mat, B: PETSc.Mat) -> float:
    """C's entry on inactive rows (which only say mu = 0): the scale of B K^-1 B^T, negative.

    Any nonzero value gives the same solution, but 1 next to Schur entries of order
    |B_j|^2 / K_jj (1e-8 and less) leaves eigenvalues that far apart, and GMRES on a lagged
    factorization then stagnates at the factorization's round-off.
    """
    comm = K.getComm().tompi4py()
    indptr, _, vals = B.getValuesCSR()
    rows = np.add.reduceat(vals**2, indptr[:-1]) if len(vals) else np.zeros(0)
    rows = rows[np.diff(indptr) > 0]
    diag = np.abs(K.getDiagonal().array_r)
    b2 = comm.allreduce(float(rows.sum())) / max(comm.allreduce(len(rows)), 1)
    kd = comm.allreduce(float(diag.sum())) / max(comm.allreduce(len(diag)), 1)
    return -b2 / kd if b2 > 0.0 and kd > 0.0 else 1.0


class SaddleBlocks:
    """The MatNest, its right-hand side and solution vectors, and their per-set values."""

    def __init__(
        self,
        K: PETSc.Mat,
        B: PETSc.Mat,
        f: PETSc.Vec,
        gamma: float,
        nullspace: PETSc.NullSpace | None,
        schur_user: bool,
    ) -> None:
        comm = K.getComm()
        self.comm = comm
        self.K, self.B, self.f, self.gamma = K, B, f, gamma
        m = B.getLocalSize()[0]
        r0 = B.getOwnershipRange()[0]
        self.act = PETSc.Vec().createMPI((m, PETSc.DETERMINE), comm=comm)
        self.act.set(1.0)
        self.BT = PETSc.Mat()
        B.transpose(self.BT)
        self.BA = B.copy()
        self.BAT = self.BT.copy()
        self.c_inactive = inactive_scale(K, B)
        self.C = diagonal_matrix(comm, np.full(m, self.c_inactive), r0)
        owned: list[PETSc.Object] = [self.act, self.BT, self.BA, self.BAT, self.C]
        self.A00 = K
        if gamma > 0.0:
            # The union pattern of K and B^T B, fixed once: later updates are value copies.
            self.P = self.BAT.matMult(self.BA)
            zero = self.P.duplicate(copy=False)
            self.Kx = K.duplicate(copy=True)
            different = cast(PETSc.Mat.Structure, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            self.Kx.axpy(1.0, zero, structure=different)
            zero.destroy()
            self.A00 = self.Kx.duplicate(copy=True)
            owned += [self.P, self.Kx, self.A00]
            if nullspace is not None:
                self.A00.setNearNullSpace(nullspace)
        self.A = PETSc.Mat().createNest([[self.A00, self.BAT], [self.BA, self.C]], comm=comm)
        self.is_u, self.is_l = self.A.getNestISs()[0]
        start = self.A.getOwnershipRange()[0]
        self.rows_u = self.is_u.getIndices() - start
        self.rows_l = self.is_l.getIndices() - start
        self.b = self.A.createVecRight()
        self.x = self.A.createVecRight()
        self.x.set(0.0)
        self.rhs_u = f.duplicate()
        owned += [self.A, self.b, self.x, self.rhs_u]
        self.Sp = diagonal_matrix(comm, np.ones(m), r0) if schur_user else None
        if self.Sp is not None:
            owned.append(self.Sp)
        if nullspace is not None:
            # PCFIELDSPLIT attaches a near-nullspace composed on the split's IS to its matrix.
            self.is_u.compose("nearnullspace", nullspace)
        self._owned = owned

    def destroy(self) -> None:
        """Free the blocks this object made (K, B and f belong to the caller)."""
        for obj in self._owned:
            obj.destroy()
        self._owned = []

    def update(self, g: np.ndarray, active: np.ndarray) -> None:
        """Write the values of the active set into the fixed-pattern blocks and the rhs."""
        # The stub types the Structure values as int but the parameters as Structure.
        same = cast(PETSc.Mat.Structure, PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        self.act.array[:] = active.astype(float)
        self.B.copy(self.BA, structure=same)
        self.BA.diagonalScale(L=self.act)
        self.BT.copy(self.BAT, structure=same)
        self.BAT.diagonalScale(R=self.act)
        diag = self.act.duplicate()
        diag.array[:] = np.where(active, 0.0, self.c_inactive)
        self.C.setDiagonal(diag)
        self.f.copy(self.rhs_u)
        if self.gamma > 0.0:
            # Augmented Lagrangian: adding gamma B^T (B u + g) = 0 makes A00 invertible when a
            # body is held only by contact, and leaves the solution unchanged.
            self.BAT.matMult(self.BA, result=self.P)
            self.Kx.copy(self.A00, structure=same)
            subset = cast(PETSc.Mat.Structure, PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            self.A00.axpy(self.gamma, self.P, structure=subset)
            diag.array[:] = -self.gamma * g * active
            tmp = self.rhs_u.duplicate()
            self.BAT.mult(diag, tmp)
            self.rhs_u.axpy(1.0, tmp)
            tmp.destroy()
        if self.Sp is not None:
            diag.array[:] = (
                schur_al_diagonal(active, self.gamma, self.c_inactive)
                if self.gamma > 0
                else self.c_inactive
            )
            self.Sp.setDiagonal(diag)
        diag.destroy()
        self.A.assemble()
        for iset, values in (
            (self.is_u, self.rhs_u.array_r),
            (self.is_l, np.where(active, -g, 0.0)),
        ):
            sub = self.b.getSubVector(iset)
            sub.array[:] = values
            self.b.restoreSubVector(iset, sub)

    def residual(self, x: PETSc.Vec) -> tuple[PETSc.Vec, float]:
        """The residual b - A x of the current operator and right-hand side, relative norm."""
        r = self.b.duplicate()
        self.A.mult(x, r)
        r.aypx(-1.0, self.b)
        # norm() of the default (2-) norm is a float; the stub also allows a pair.
        rel = cast(float, r.norm()) / max(cast(float, self.b.norm()), 1e-300)
        return r, float(rel) if np.isfinite(rel) else np.inf

    def split(self) -> tuple[np.ndarray, np.ndarray]:
        """Copies of the owned u and mu blocks of the solution vector."""
        u_sub, l_sub = self.x.getSubVector(self.is_u), self.x.getSubVector(self.is_l)
        u, mu = u_sub.array.copy(), l_sub.array.copy()
        self.x.restoreSubVector(self.is_u, u_sub)
        self.x.restoreSubVector(self.is_l, l_sub)
        return u, mu

    def augmented_rhs(self, gp: np.ndarray) -> np.ndarray:
        """Gamma B_A^T gp on the local displacement rows (all columns in one product)."""
        return self.dense_product(self.BAT, self.gamma * gp)

    def dense_product(self, A: PETSc.Mat, local: np.ndarray) -> np.ndarray:
        """Local rows of A @ X for a dense X given by its local rows (one sparse-dense product)."""
        size = ((local.shape[0], PETSc.DETERMINE), (PETSc.DECIDE, local.shape[1]))
        X = PETSc.Mat().createDense(size, comm=self.comm)
        X.setUp()
        X.getDenseArray()[:] = local
        X.assemble()
        Y = A.matMult(X)
        out = Y.getDenseArray().copy()
        X.destroy()
        Y.destroy()
        return out

    def apply_inverse(self, ksp: PETSc.KSP, direct: bool) -> Callable[[np.ndarray], np.ndarray]:
        """Solutions (local rows x columns) for dense right-hand sides, current operator."""

        def factored(rhs: np.ndarray) -> np.ndarray:
            # The factorization is exact here: one multi-right-hand-side MUMPS solve.
            size = ((rhs.shape[0], PETSc.DETERMINE), (PETSc.DECIDE, rhs.shape[1]))
            Bd = PETSc.Mat().createDense(size, comm=self.comm)
            Bd.setUp()
            Bd.getDenseArray()[:] = rhs
            Bd.assemble()
            Xd = Bd.duplicate()
            ksp.getPC().matApply(Bd, Xd)
            sol = Xd.getDenseArray().copy()
            Bd.destroy()
            Xd.destroy()
            return sol

        def krylov(rhs: np.ndarray) -> np.ndarray:
            sol = np.zeros_like(rhs)
            b, x = self.b.duplicate(), self.x.duplicate()
            for j in range(rhs.shape[1]):
                b.array[:] = rhs[:, j]
                x.set(0.0)
                ksp.solve(b, x)
                sol[:, j] = x.array_r
            b.destroy()
            x.destroy()
            return sol

        return factored if direct else krylov
