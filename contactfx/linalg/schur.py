"""One factorization per contact solve: MUMPS' Schur complement of every multiplier row (serial).

The saddle point of an active set A, [[K, B_A^T], [B_A, 0]], is rewritten with the candidate
rows' augmented multipliers w = mu - gamma B u (its part -gamma B u undoes the augmentation
exactly) as

    [[K + gamma B^T B, B^T], [B, D_A]] [u; w] = [f; r_A],

D_A = 0 and r = -g on active rows, D_A = 1/gamma and r = 0 on the others (there mu = 0, so
w = -gamma B u). Only D_A changes with the set: MUMPS factors K_gamma = K + gamma B^T B once
with every multiplier row as its Schur variables (ICNTL(19), PETSc's MatFactorSetSchurIS)
and returns the dense S0 = -B K_gamma^-1 B^T. K_gamma is nonsingular when the rows together
hold every body (a body held only by contact included). Each set is then a dense symmetric
solve (S0 + D_A) w = r_A + c, with c = -B K_gamma^-1 f from one solve, and u by one more
solve with the kept factor; on active rows mu = w - gamma g. The probe responses are columns
of (S0 + D_A)^-1 plus gamma on the diagonal: no selected inverse, no refactorization.

PETSc solves through the factor by condensation (ICNTL(26) = 1), a solve with its own copy
of the Schur matrix and expansion (ICNTL(26) = 2). That copy is replaced by -I, marked as
inverted: a solve with right-hand side [f; -w - c] then returns u of the set whose dense
solution is w. MatFactorSetSchurIS is not wrapped by petsc4py: ctypes, as `linalg/mumps.py`.
"""

from __future__ import annotations

import ctypes
import functools
import logging
import time
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
from petsc4py import PETSc

if TYPE_CHECKING:
    import scipy.linalg

from ..errors import SolverError
from .blocks import diagonal_matrix
from .petsc_options import PrefixedOptions, petsc_error_message
from .protocol import LoopTest, SaddleResult

log = logging.getLogger("contactfx")

# PETSc's MatFactorSchurStatus values (petscmat.h).
_SCHUR_INVERTED = 2


@functools.cache
def _library() -> ctypes.CDLL | None:
    """Libpetsc with the Schur-complement calls typed, or None (see mumps.petsc_library)."""
    try:
        lib = ctypes.CDLL(PETSc.__file__)
        calls = (
            lib.MatFactorSetSchurIS,
            lib.MatFactorGetSchurComplement,
            lib.MatFactorRestoreSchurComplement,
            lib.MatDenseGetArray,
            lib.MatDenseRestoreArray,
        )
    except (OSError, AttributeError) as err:
        log.info("no MUMPS Schur complement (%s)", err)
        return None
    vp, pp = ctypes.c_void_p, ctypes.POINTER(ctypes.c_void_p)
    calls[0].argtypes = [vp, vp]
    calls[1].argtypes = [vp, pp, ctypes.POINTER(ctypes.c_int)]
    calls[2].argtypes = [vp, pp, ctypes.c_int]
    calls[3].argtypes = [vp, ctypes.POINTER(ctypes.POINTER(ctypes.c_double))]
    calls[4].argtypes = [vp, ctypes.POINTER(ctypes.POINTER(ctypes.c_double))]
    return lib


def schur_available(comm: PETSc.Comm) -> bool:
    """Whether this path can run: one rank (PETSc's Schur interface is sequential), ctypes."""
    return comm.getSize() == 1 and _library() is not None and PETSc.ScalarType == np.float64


class _SchurFactor:
    """The MUMPS factor of [[K_gamma, B^T], [B, 0]] with the multiplier rows as Schur set."""

    def __init__(
        self, A: PETSc.Mat, schur_is: PETSc.IS, size: int, options: Mapping[str, object]
    ) -> None:
        lib = _library()
        assert lib is not None
        self._lib, self._size = lib, size
        self._options = PrefixedOptions(options)
        self.pc = PETSc.PC().create(A.getComm())
        self.pc.setOptionsPrefix(self._options.prefix)
        with self._options.inserted():
            self.pc.setFromOptions()
            self.pc.setOperators(A)
            self.pc.setFactorSetUpSolverType()
            F = self.pc.getFactorMatrix()
            if lib.MatFactorSetSchurIS(F.handle, schur_is.handle) != 0:
                raise SolverError("MUMPS refused the Schur set (MatFactorSetSchurIS)")
            self.pc.setUp()
        self.F = self.pc.getFactorMatrix()
        self.S0 = self._swap_schur()

    def _swap_schur(self) -> np.ndarray:
        """A copy of the Schur complement; PETSc's own copy becomes -I, marked as inverted."""
        lib, F = self._lib, self.F
        S, status = ctypes.c_void_p(), ctypes.c_int()
        if lib.MatFactorGetSchurComplement(F.handle, ctypes.byref(S), ctypes.byref(status)):
            raise SolverError("no Schur complement from MUMPS (MatFactorGetSchurComplement)")
        ptr = ctypes.POINTER(ctypes.c_double)()
        lib.MatDenseGetArray(S, ctypes.byref(ptr))
        size = self._size
        view = np.ctypeslib.as_array(ptr, shape=(size, size))
        # Column-major storage; the Schur complement of a symmetric matrix is symmetric,
        # but MUMPS' LDL^T may give one triangle only: take the lower one by columns.
        S0 = np.array(view.T, copy=True)
        if not np.allclose(S0, S0.T, rtol=1e-8, atol=0.0):
            low = np.tril(S0)
            S0 = low + np.tril(low, -1).T
        view[:] = 0.0
        view[np.diag_indices(size)] = -1.0
        lib.MatDenseRestoreArray(S, ctypes.byref(ptr))
        lib.MatFactorRestoreSchurComplement(F.handle, ctypes.byref(S), _SCHUR_INVERTED)
        return S0

    def solve(self, b: PETSc.Vec, x: PETSc.Vec) -> None:
        """Condense, apply -I to the reduced right-hand side, expand."""
        self.F.solve(b, x)

    def destroy(self) -> None:
        self.pc.destroy()


class SchurSolver:
    """LinearSolver: one Schur factorization, every active set a dense solve (serial MUMPS).

    `options`: the MUMPS factorization's PETSc options (pc_type cholesky or lu, ordering,
    CNTL(1)); `gamma` > 0 the augmentation of K by gamma B^T B over every multiplier row.
    """

    exact = True
    can_probe = True
    cheap_responses = True

    def __init__(
        self,
        K: PETSc.Mat,
        B: PETSc.Mat,
        f: PETSc.Vec,
        options: Mapping[str, object],
        gamma: float,
    ) -> None:
        if gamma <= 0.0:
            raise SolverError("the Schur-complement solver needs gamma > 0")
        self.gamma = gamma
        self.stats = {"reused": 0, "setup_time": 0.0}
        comm = K.getComm()
        self._m = m = B.getSize()[0]
        self._B = B
        self._BT = B.transpose(PETSc.Mat())
        self._Kg = K.duplicate(copy=True)
        BtB = self._BT.matMult(B)
        different = PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN
        self._Kg.axpy(gamma, BtB, structure=different)  # type: ignore[arg-type]
        BtB.destroy()
        self._Z = diagonal_matrix(comm, np.zeros(m), 0)
        self._A = PETSc.Mat().createNest([[self._Kg, self._BT], [B, self._Z]], comm=comm)
        is_u, is_l = self._A.getNestISs()[0]
        self._rows_u, self._rows_l = is_u.getIndices(), is_l.getIndices()
        self._is_l = is_l
        self._options = {k: v for k, v in options.items() if k != "ksp_type"}
        self._b = self._A.createVecRight()
        self._x = self._A.createVecRight()
        self._b.array[self._rows_u] = f.array_r
        self._factor: _SchurFactor | None = None
        self._c: np.ndarray | None = None
        self._last: tuple[np.ndarray, scipy.linalg.LinAlgError | None, object] | None = None
        self._solved: tuple[np.ndarray, tuple[np.ndarray, np.ndarray]] | None = None

    @property
    def schur_size(self) -> int:
        """Rows of the dense block (every multiplier row)."""
        return self._m

    def _setup(self) -> float:
        """Factor once (the first solve); the seconds it took."""
        if self._factor is not None:
            return 0.0
        t0 = time.perf_counter()
        try:
            self._factor = _SchurFactor(self._A, self._is_l, self._m, self._options)
        except PETSc.Error as err:
            raise SolverError(petsc_error_message(err, "Schur factorization")) from None
        # c = -B K_gamma^-1 f: with PETSc's Schur operator -I, the solve of [f; 0] returns
        # w = -(0 + c).
        self._b.array[self._rows_l] = 0.0
        self._factor.solve(self._b, self._x)
        self._c = -self._x.array_r[self._rows_l].copy()
        seconds = time.perf_counter() - t0
        self.stats["setup_time"] += seconds
        return seconds

    def _dense(self, g: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, object]:
        """The set's w and the factorization of S0 + D_A (kept for responses)."""
        import scipy.linalg  # only where used (first-answer time: docs/scale.md)

        assert self._factor is not None and self._c is not None
        key = active.tobytes()
        if self._last is not None and self._last[0].tobytes() == key:
            lu = self._last[2]
        else:
            S = self._factor.S0.copy()
            S[np.diag_indices(self._m)] += np.where(active, 0.0, 1.0 / self.gamma)
            try:
                lu = scipy.linalg.lu_factor(S, check_finite=True)
            except (ValueError, np.linalg.LinAlgError) as err:
                raise SolverError(f"the contact rows' Schur block is singular ({err})") from None
            self._last = (active.copy(), None, lu)
        r = np.where(active, -g, 0.0)
        w = scipy.linalg.lu_solve(lu, r + self._c)
        return w, lu

    def solve(
        self, g: np.ndarray, active: np.ndarray, *, fresh: bool = False, stationary: LoopTest = None
    ) -> SaddleResult:
        """The set's solution: a dense solve on the Schur block, u by one solve with the factor."""
        active = np.asarray(active, dtype=bool)
        setup = self._setup()
        refactored = setup > 0.0
        if not refactored:
            self.stats["reused"] += 1
        t0 = time.perf_counter()
        assert self._factor is not None and self._c is not None
        w, _ = self._dense(g, active)
        if not np.all(np.isfinite(w)):
            raise SolverError("the contact rows' Schur block is singular (non-finite solution)")
        self._b.array[self._rows_l] = -w - self._c
        try:
            self._factor.solve(self._b, self._x)
        except PETSc.Error as err:
            raise SolverError(petsc_error_message(err, "Schur expansion")) from None
        u = self._x.array_r[self._rows_u].copy()
        # On active rows mu = w + gamma B u = w - gamma g; elsewhere mu = 0.
        mu = np.where(active, w - self.gamma * g, 0.0)
        return SaddleResult(
            u, mu, 1, 1, refactored, -1 if refactored else 0, 0, setup, time.perf_counter() - t0
        )

    def responses(
        self, probes: np.ndarray, active: np.ndarray, rows: np.ndarray | None = None
    ) -> np.ndarray:
        """Multiplier responses to multiplier-block right-hand sides on the last set.

        Every active row's, whatever `rows` asks (the dense block holds them all).

        A right-hand side e_j on an active row j moves w by (S0 + D_A)^-1 e_j and B_A u by
        e_j, so mu_A = w_A + gamma B_A u by that column plus gamma e_j.
        """
        active = np.asarray(active, dtype=bool)
        probes = np.asarray(probes, dtype=float).reshape(len(active), -1)
        if self._last is None or not np.array_equal(self._last[0], active):
            raise SolverError("Schur responses asked for a set that was not solved last")
        lu = self._last[2]
        rhs = np.where(active[:, None], probes, 0.0)
        import scipy.linalg  # imported by _dense already: a dict look-up

        dw = scipy.linalg.lu_solve(lu, rhs)
        return np.where(active[:, None], dw + self.gamma * rhs, 0.0)

    def destroy(self) -> None:
        """Free the PETSc objects."""
        if self._factor is not None:
            self._factor.destroy()
        for obj in (self._A, self._Kg, self._BT, self._Z, self._b, self._x):
            obj.destroy()
