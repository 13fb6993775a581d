"""How a failed command ends: one message, exit code 2, every rank stopped.

An error a check raises on every rank alike (contactfx's checks are collective) ends each rank
with exit code 2 and rank 0's line. An error on some ranks only (an exception no check
foresaw, a file a rank cannot write) would leave the other ranks waiting in a collective
forever: the failing rank says so once, with its rank, and aborts the job with code 2.
Which case it is, the ranks find out by a non-blocking barrier on a communicator of their
own, which every failing rank enters and the others do not while they wait elsewhere.

For the failing rank to get here, nothing on its way up may call a collective: the solvers'
PETSc objects, whose destroy is one (MUMPS), are not destroyed while an exception unwinds
under mpirun (methods/cleanup.py).
"""

from __future__ import annotations

import os
import sys
import time
import traceback

from mpi4py import MPI

from ..errors import ContactFxError

# How long a failing rank waits for the others to fail too before it aborts the job. A
# collective check raises on every rank within milliseconds of each other (after the same
# broadcast or reduction); a rank that is still computing is not failing.
AGREE_SECONDS = 3.0


def is_bug(err: BaseException) -> bool:
    """Whether `err` is a bug of contactfx.

    Not a bug: a ContactFxError (every input contactfx refuses raises one), or a file the
    system refused (an OSError naming its file).
    """
    return not isinstance(err, ContactFxError) and not (
        isinstance(err, OSError) and err.filename is not None
    )


def message(err: BaseException) -> str:
    """The line the user reads: a contactfx error's text, or an internal error's type and text.

    A bug's traceback is printed before the line.
    """
    if isinstance(err, ContactFxError):
        return f"contactfx: error: {err}"
    if not is_bug(err):
        assert isinstance(err, OSError)
        return f"contactfx: error: {err.filename}: {err.strerror}"
    return (
        f"contactfx: internal error: {type(err).__name__}: {err} (a bug in contactfx, not "
        "in the input: please report it with the traceback above)"
    )


def everyone_failed(errors: MPI.Comm, wait: float) -> bool:
    """Whether every rank of `errors` entered this call within `wait` seconds."""
    request = errors.Ibarrier()
    deadline = time.monotonic() + wait
    while not request.Test():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.005)
    return True


def fail(err: Exception, errors: MPI.Comm | None, wait: float = AGREE_SECONDS) -> int:
    """Report `err` once and return the exit code 2, or abort every rank with code 2.

    `errors`: a communicator of all ranks used for nothing else (None in serial). If every
    rank fails (a collective check), rank 0 prints and all return 2; if this rank fails
    alone, it prints with its rank and calls MPI_Abort, which ends the ranks that wait.
    """
    line = message(err)
    internal = is_bug(err)
    if errors is None or errors.size == 1:
        if internal:
            traceback.print_exception(err)
        print(line, file=sys.stderr, flush=True)
        return 2
    if everyone_failed(errors, wait):
        if errors.rank == 0:
            if internal:
                traceback.print_exception(err)
            print(line, file=sys.stderr, flush=True)
        return 2
    abort(err, errors)
    return 2  # not reached: MPI_Abort ends the process


def abort(err: BaseException, errors: MPI.Comm) -> None:
    """Print `err` once, with this rank, and end every rank of the job with code 2."""
    if is_bug(err):
        traceback.print_exception(err)
    print(
        f"{message(err)} (on rank {errors.rank} of {errors.size} only: every rank is stopped)",
        file=sys.stderr,
        flush=True,
    )
    sys.stdout.flush()
    # MPICH prints a line of its own on MPI_Abort ("application called MPI_Abort ..."): the
    # user's one line is the one above.
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    errors.Abort(2)
