"""MUMPS calls that petsc4py does not wrap, via ctypes: selected inverse entries, analysis.

The analysis alone gives MUMPS' memory estimate before any factorization. The active-set
loop's probes need a few hundred entries of the saddle-point inverse; MUMPS computes them
by pruning its elimination tree (ICNTL(30)), far cheaper than dense solves.
"""

from __future__ import annotations

import ctypes
import functools
import logging
import time
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from ..errors import SolverError
from .petsc_options import petsc_error_message

log = logging.getLogger("contactfx")


@functools.cache
def petsc_library() -> ctypes.CDLL | None:
    """The libpetsc that petsc4py loaded (for MUMPS calls petsc4py does not wrap), or None.

    Opened through petsc4py's own extension module: the dynamic loader resolves symbols in
    its dependencies, libpetsc among them, on Linux and macOS alike.
    """
    try:
        lib = ctypes.CDLL(PETSc.__file__)
        get_inverse, set_icntl = lib.MatMumpsGetInverse, lib.MatMumpsSetIcntl
    except (OSError, AttributeError) as err:
        log.info("no MUMPS selected inverse (%s): probes use dense solves", err)
        return None
    get_inverse.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    lib.MatMumpsGetIcntl.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.POINTER(ctypes.c_int)]
    set_icntl.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
    lib.MatCholeskyFactorSymbolic.argtypes = [ctypes.c_void_p] * 4
    lib.MatLUFactorSymbolic.argtypes = [ctypes.c_void_p] * 5
    lib.MatFactorInfoInitialize.argtypes = [ctypes.c_void_p]
    return lib


@dataclass(frozen=True)
class MumpsEstimate:
    """MUMPS' memory estimate after its analysis (MB): this rank's, the largest, the sum.

    In-core (INFO(15), INFOG(16), INFOG(17)) unless ICNTL(22) = 1 asks for out-of-core
    factors (INFO(17), INFOG(26), INFOG(27)); a rank's is ICNTL(23) where that caps it.
    MUMPS allocates this much at the numeric factorization (ICNTL(14)'s relaxation
    included; docs/scale.md, "The default solver").
    """

    rank_mb: float
    max_mb: float
    total_mb: float
    seconds: float  # of the analysis


def analyze_pc(pc: PETSc.PC, A: PETSc.Mat) -> MumpsEstimate | None:
    """MUMPS' analysis of A by a factorization PC before its first setup (`analyze`).

    None if the PC does not factorize with MUMPS or the analysis failed. The PC's options
    must be in PETSc's database.
    """
    if pc.getType() not in ("lu", "cholesky") or pc.getFactorSolverType() != "mumps":
        return None
    try:
        pc.setFactorSetUpSolverType()
        return analyze(pc.getFactorMatrix(), A, pc.getType() == "cholesky")
    except PETSc.Error as err:
        raise SolverError(petsc_error_message(err, "MUMPS analysis")) from None


def analyze(F: PETSc.Mat, A: PETSc.Mat, cholesky: bool) -> MumpsEstimate | None:
    """Run MUMPS' analysis of A into its factor F alone, and read its memory estimate.

    F is a PC's factor matrix before its first setup: PETSc's MUMPS interface then skips a
    second analysis of the same pattern, so the factorization reuses this one. The PETSc
    options of F's prefix must be in the database (MUMPS' ICNTLs are read here). None if
    the analysis failed (a log line says why), the same on every rank.
    """
    lib = petsc_library()
    if lib is None:
        return None
    info = (ctypes.c_double * 64)()  # a MatFactorInfo (about 20 reals); MUMPS ignores it
    lib.MatFactorInfoInitialize(ctypes.byref(info))
    mpi = F.getComm().tompi4py()
    t0 = time.perf_counter()
    if cholesky:
        err = lib.MatCholeskyFactorSymbolic(F.handle, A.handle, None, ctypes.byref(info))
    else:
        err = lib.MatLUFactorSymbolic(F.handle, A.handle, None, None, ctypes.byref(info))
    seconds = mpi.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    status = F.getMumpsInfog(1) if err == 0 else -1
    if mpi.allreduce(int(err != 0 or status < 0), op=MPI.MAX):
        if mpi.rank == 0:
            log.info("MUMPS analysis failed (PETSc error %d, INFOG(1) %d)", err, status)
        return None
    ooc = F.getMumpsIcntl(22) == 1
    mine, top, total = (17, 26, 27) if ooc else (15, 16, 17)
    cap = F.getMumpsIcntl(23)  # > 0: each rank allocates this much working memory instead
    return MumpsEstimate(
        float(cap if cap > 0 else F.getMumpsInfo(mine)),
        float(F.getMumpsInfog(top)),
        float(F.getMumpsInfog(total)),
        seconds,
    )


def _pattern(rows: np.ndarray, cols: np.ndarray, symmetric: bool) -> list[np.ndarray]:
    """The rows requested in each column: all of `rows`, or only half of the pairs in `cols`.

    With `symmetric` the other half follows from A^-1 = A^-T.
    """
    if not symmetric:
        return [rows] * len(cols)
    in_cols = np.isin(rows, cols)
    return [rows[~in_cols | (rows >= c)] for c in cols]


# Right-hand sides per block of the selected inverse, by the system's size: larger blocks
# pay once the factors are large (PORD's sizes); measured in
# docs/scale.md#measured-constants ("Selected-inverse block").
SMALL_BLOCK, LARGE_BLOCK, LARGE_FROM = 64, 256, 300_000


def inverse_block(n: int) -> int:
    """ICNTL(27) for the selected inverse of an n x n system (restored afterwards).

    benchmarks/inverse_block.py replaces this rule for its A/B.
    """
    return LARGE_BLOCK if n >= LARGE_FROM else SMALL_BLOCK


def inverse_entries(
    F: PETSc.Mat, rows: np.ndarray, cols: np.ndarray, n: int, symmetric: bool = False
) -> np.ndarray | None:
    """Entries (rows x cols, as (len(cols), len(rows))) of A^-1 from its MUMPS factor F.

    `rows`, `cols`: sorted global row numbers of the whole system (n x n), the same on every
    rank. `symmetric`: A is symmetric, so of the pairs within `cols` only one half is asked
    for (MUMPS' work per column shrinks with the rows requested: about a third less when
    every row is a column). MUMPS takes the pattern centralized on its host: on several
    ranks it is rank 0's diagonal block of an MPI matrix with every row there (PETSc reads
    that block), and the entries are broadcast. ICNTL(20), (21), (27) and (30) are restored
    afterwards, for the next ordinary solve. None on failure (a log line says why), the
    same on every rank.
    """
    lib = petsc_library()
    if lib is None:
        return None
    comm = F.getComm()
    mpi = comm.tompi4py()
    host = mpi.rank == 0
    asked = _pattern(rows, cols, symmetric) if host else []
    # Row c of the transposed pattern asks for the entries (asked rows, c) of A^-1.
    count = np.zeros(n if host else 0, dtype=np.int64)
    if host:
        count[cols] = [len(a) for a in asked]
    indptr = np.concatenate([[0], np.cumsum(count)]).astype(PETSc.IntType)
    indices = (np.concatenate(asked) if asked else np.zeros(0)).astype(PETSc.IntType)
    values = np.zeros(len(indices), dtype=PETSc.ScalarType)
    local = n if host else 0
    spT = PETSc.Mat().createAIJ(
        ((local, n), (local, n)),
        csr=(indptr, indices, values),  # type: ignore[arg-type]
        comm=comm if mpi.size > 1 else PETSc.COMM_SELF,
    )
    spT.assemble()
    sp = PETSc.Mat().createTranspose(spT)
    saved = {i: ctypes.c_int() for i in (20, 21, 27, 30)}
    for i, v in saved.items():
        lib.MatMumpsGetIcntl(F.handle, i, ctypes.byref(v))
    lib.MatMumpsSetIcntl(F.handle, 27, inverse_block(n))
    err = lib.MatMumpsGetInverse(F.handle, sp.handle)
    for i, v in saved.items():  # back to ordinary solves
        lib.MatMumpsSetIcntl(F.handle, i, v.value)
    entries = None
    if host:
        block = spT.getDiagonalBlock() if mpi.size > 1 else spT
        entries = _unpack(block.getValuesCSR()[2], asked, rows, cols)
    entries = mpi.bcast(entries, root=0)
    sp.destroy()
    spT.destroy()
    err = mpi.allreduce(int(err), op=MPI.MAX)
    if err != 0 or entries is None or not np.all(np.isfinite(entries)):
        if host:
            log.info("MUMPS selected inverse failed (error %d): dense probe solves", err)
        return None
    return entries


def _unpack(
    values: np.ndarray, asked: list[np.ndarray], rows: np.ndarray, cols: np.ndarray
) -> np.ndarray:
    """(len(cols), len(rows)) entries from the CSR values of the asked pattern.

    The half of the pairs within `cols` that was not asked for is filled by symmetry.
    """
    out = np.full((len(cols), len(rows)), np.nan)
    if asked:
        flat = np.concatenate(asked)
        ks = np.repeat(np.arange(len(asked)), [len(a) for a in asked])
        out[ks, np.searchsorted(rows, flat)] = values[: len(flat)]
    missing = np.isnan(out)
    idx = np.searchsorted(rows, cols)
    if missing.any() and np.array_equal(rows[np.minimum(idx, len(rows) - 1)], cols):
        # Every column is a row too: the unasked half is the transpose of the asked one in
        # the (cols x cols) block, entry (cols[j], cols[k]) = (cols[k], cols[j]).
        block = out[:, idx]
        out[:, idx] = np.where(np.isnan(block), block.T, block)
    elif missing.any():
        ks, ii = np.nonzero(missing)
        # Entry (rows[i], cols[k]) = entry (cols[k], rows[i]) = column rows[i], row cols[k].
        out[ks, ii] = out[np.searchsorted(cols, rows[ii]), np.searchsorted(rows, cols[ks])]
    return out
