"""PETSc objects freed on the way out of a solve, except while an error unwinds under mpirun.

Destroying a factored solver is collective (MUMPS frees its communicators). An error raised on
one rank only would otherwise wait there for the other ranks, which wait in another
collective of the solve, and mpirun would hang; left alone, the objects are freed with the
error's traceback, and the CLI ends every rank (cli/failure.py). In serial, and on success,
they are destroyed as usual.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Protocol

from mpi4py import MPI


class Destroyable(Protocol):
    """Anything with a collective destroy() (a PETSc object, a solver, a contact setup)."""

    def destroy(self) -> object:
        """Free it (collective)."""


@contextmanager
def released(comm: MPI.Comm, *objs: Destroyable) -> Iterator[None]:
    """Destroy `objs` when the block ends; under mpirun not if it ends by an exception."""
    try:
        yield
    except BaseException:
        dropped(comm, *objs)
        raise
    for obj in objs:
        obj.destroy()


def dropped(comm: MPI.Comm, *objs: Destroyable) -> None:
    """Destroy `objs` on an error's way out: in serial only (mpirun: see the module's note)."""
    if comm.size == 1:
        for obj in objs:
            obj.destroy()
