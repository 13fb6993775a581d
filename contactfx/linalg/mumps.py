"""MUMPS calls that petsc4py does not wrap (selected entries of the inverse), via ctypes.

The active-set loop's probes need a few hundred entries of the saddle-point inverse; MUMPS
computes them by pruning its elimination tree (ICNTL(30)), far cheaper than dense solves.
"""

from __future__ import annotations

import ctypes
import functools
import logging

import numpy as np
from petsc4py import PETSc

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
    return lib


def inverse_entries(F: PETSc.Mat, rows: np.ndarray, cols: np.ndarray, n: int) -> np.ndarray | None:
    """Entries (rows x cols, as (len(cols), len(rows))) of A^-1 from its MUMPS factor F.

    Serial only: on several ranks the call succeeds but leaves MUMPS' centralized
    right-hand-side pointer set, and the next solve fails (INFOG(1) = -22). None on failure.
    """
    lib = petsc_library()
    if lib is None:
        return None
    # Row c of the transposed pattern asks for the entries (rows, c) of A^-1.
    count = np.zeros(n, dtype=np.int64)
    count[cols] = len(rows)
    indptr = np.concatenate([[0], np.cumsum(count)]).astype(PETSc.IntType)
    indices = np.tile(rows, len(cols)).astype(PETSc.IntType)
    values = np.zeros(len(indices), dtype=PETSc.ScalarType)
    spT = PETSc.Mat().createAIJ(
        (n, n),
        csr=(indptr, indices, values),  # type: ignore[arg-type]
        comm=PETSc.COMM_SELF,
    )
    spT.assemble()
    sp = PETSc.Mat().createTranspose(spT)
    saved = {i: ctypes.c_int() for i in (20, 30)}
    for i, v in saved.items():
        lib.MatMumpsGetIcntl(F.handle, i, ctypes.byref(v))
    err = lib.MatMumpsGetInverse(F.handle, sp.handle)
    for i, v in saved.items():  # back to ordinary solves
        lib.MatMumpsSetIcntl(F.handle, i, v.value)
    entries = spT.getValuesCSR()[2].reshape(len(cols), len(rows)).copy()
    sp.destroy()
    spT.destroy()
    if err != 0 or not np.all(np.isfinite(entries)):
        return None
    return entries
