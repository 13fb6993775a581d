"""Solves with a kept factorization of P for a matrix A that differs from it in a few rows.

A = P + E_R D, E_R the unit columns of the changed rows R, D = (A - P)_R. Woodbury:

    x = y - Z (I + D Z)^-1 D y,    y = P^-1 b,  Z = P^-1 E_R,

one multi-right-hand-side solve for Z (|R| columns) and one back-substitution, exact as a
factorization of A (the r x r capacitance matrix is dense and small); one step of iterative
refinement on A's own residual follows. The frictional saddle point changes only in the
multiplier rows of nodes whose law changed (methods/friction_linear.py).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from petsc4py import PETSc


def changed_row_solve(
    F: PETSc.Mat, A: PETSc.Mat, P: PETSc.Mat, rows: np.ndarray, b: PETSc.Vec, x: PETSc.Vec
) -> None:
    """Solve A x = b with F = the factorization of P; `rows`: owned global rows where A != P."""
    comm = A.getComm()
    mpi = comm.tompi4py()
    r0, r1 = A.getOwnershipRange()
    counts = mpi.allgather(len(rows))
    r, off = sum(counts), sum(counts[: mpi.rank])
    indptr, cols, vals = [0], [], []
    for g in rows:
        ca, va = A.getRow(int(g))
        cp, vp = P.getRow(int(g))
        assert np.array_equal(ca, cp)  # one pattern
        d = np.asarray(va) - np.asarray(vp)
        keep = d != 0.0
        cols.append(np.asarray(ca)[keep])
        vals.append(d[keep])
        indptr.append(indptr[-1] + int(keep.sum()))
    n_loc = r1 - r0
    csr: Any = (
        np.asarray(indptr, dtype=PETSc.IntType),
        (np.concatenate(cols) if cols else np.zeros(0)).astype(PETSc.IntType),
        (np.concatenate(vals) if vals else np.zeros(0)).astype(PETSc.ScalarType),
    )
    D = PETSc.Mat().createAIJ(size=((len(rows), r), (n_loc, PETSc.DETERMINE)), csr=csr, comm=comm)
    D.assemble()
    # The right-hand sides E_R: column off + k is the unit vector of this rank's row k.
    E = PETSc.Mat().createDense(size=((n_loc, PETSc.DETERMINE), (PETSc.DECIDE, r)), comm=comm)
    E.setUp()
    for k, g in enumerate(rows):
        E.setValue(int(g), off + k, 1.0)
    E.assemble()
    Z = E.duplicate()
    F.matSolve(E, Z)
    DZ = D.matMult(Z)
    C = np.eye(r) + np.vstack(mpi.allgather(np.asarray(DZ.getDenseArray()).reshape(-1, r)))
    Zl = np.asarray(Z.getDenseArray()).reshape(-1, r)
    w = D.createVecLeft()
    res = b.duplicate()
    x.set(0.0)
    res.set(0.0)
    res.axpy(1.0, b)
    for _ in range(2):  # the solve, then one refinement on A's residual
        y = b.duplicate()
        F.solve(res, y)
        D.mult(y, w)
        c = np.linalg.solve(C, np.concatenate(mpi.allgather(w.array_r.copy())))
        y.array[:] = y.array_r - np.asarray(Zl @ c, dtype=float)
        x.axpy(1.0, y)
        y.destroy()
        A.mult(x, res)
        res.aypx(-1.0, b)
    for obj in (D, E, Z, DZ, w, res):
        obj.destroy()
