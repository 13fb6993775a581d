"""Multiplier responses of a factorized saddle point: selected entries of A^-1, or dense solves.

The probe step asks: if the weighted gap of candidate j opened by 1, how would the
multipliers of the other candidates change? For unit columns on active rows the answer is
the entries (i, j) of A^-1 over the active multiplier rows i. MUMPS computes such entries by
pruning its elimination tree (ICNTL(30)): 60 x 60 entries took 0.14 s at 1M DOFs, against
9.7 s as dense columns (docs/scale.md). Elsewhere the responses are solves with dense
right-hand sides.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from .mumps import inverse_entries

# Entries per rank of one dense block of probe right-hand sides (8 bytes each).
PROBE_ENTRIES = 64_000_000


def unit_columns(
    probes: np.ndarray, active: np.ndarray, positions: np.ndarray, comm: MPI.Comm
) -> np.ndarray | None:
    """The system row of each column if every column of `probes` is e_j on an active row j.

    `positions`: each local multiplier row's (global) row in the whole system. None if a
    column is not such a unit vector (the answer is the same on every rank).
    """
    nz = probes != 0.0
    ok = bool(np.all(probes[nz] == 1.0)) and bool(np.all(active[np.nonzero(nz)[0]]))
    count = comm.allreduce(nz.sum(axis=0))
    if not comm.allreduce(ok, op=MPI.LAND) or not np.all(count == 1):
        return None
    here = nz.any(axis=0)
    pos = np.full(probes.shape[1], -1, dtype=np.int64)
    if here.any():  # a rank may own no multiplier row, or none of the probed ones
        pos[here] = positions[np.argmax(nz[:, here], axis=0)]
    comm.Allreduce(MPI.IN_PLACE, pos, op=MPI.MAX)
    return pos


def selected_responses(
    factor: PETSc.Mat,
    positions: np.ndarray,
    n: int,
    probes: np.ndarray,
    active: np.ndarray,
    comm: MPI.Comm,
    symmetric: bool = False,
    wanted: np.ndarray | None = None,
) -> np.ndarray | None:
    """Responses (local rows x k) as selected entries of A^-1 from the MUMPS factor, or None.

    `positions`: each local multiplier row's global row in the whole system A (n x n). The
    requested entries are the (wanted rows) x (probe rows) block, gathered on every rank;
    `wanted` (a local mask within `active`, default `active`): the other rows stay zero.
    None if a column is not a unit vector on an active row, or MUMPS refuses. `symmetric`:
    A is symmetric (half of the pairs within the columns are asked for).
    """
    col_pos = unit_columns(probes, active, positions, comm)
    if col_pos is None:
        return None
    wanted = active if wanted is None else np.asarray(wanted, dtype=bool) & active
    req = np.sort(np.concatenate(comm.allgather(positions[wanted])))
    cols, where = np.unique(col_pos, return_inverse=True)
    entries = inverse_entries(factor, req, cols, n, symmetric)
    if entries is None:
        return None
    mine = np.flatnonzero(wanted)
    out = np.zeros((len(active), probes.shape[1]))
    out[mine, :] = entries[where][:, np.searchsorted(req, positions[mine])].T
    return out


def dense_responses(
    apply_inverse: Callable[[np.ndarray], np.ndarray],
    probes: np.ndarray,
    active: np.ndarray,
    rows_u: np.ndarray,
    rows_l: np.ndarray,
    comm: MPI.Comm,
    augment: Callable[[np.ndarray], np.ndarray] | None = None,
) -> np.ndarray:
    """Responses (local rows x k) by solves with dense right-hand sides, in blocks.

    `rows_u`, `rows_l`: local positions of the displacement and multiplier rows in the whole
    vector. `augment(gp)`, if given, is the displacement block's right-hand side of the gap
    columns gp (gamma B^T gp for an augmented A00).
    """
    k = probes.shape[1]
    out = np.zeros((len(active), k))
    gp = np.where(active[:, None], probes, 0.0)
    n_local = len(rows_u) + len(rows_l)
    # Right-hand sides and solutions are (dofs x columns): gigabytes for a million DOFs and
    # 400 probes at once, so at most PROBE_ENTRIES per rank in one block.
    chunk = max(1, min(k, PROBE_ENTRIES // max(comm.allreduce(n_local, op=MPI.MAX), 1)))
    for lo in range(0, k, chunk):
        cols = slice(lo, min(lo + chunk, k))
        rhs = np.zeros((n_local, cols.stop - lo))
        rhs[rows_l] = gp[:, cols]
        if augment is not None:
            rhs[rows_u] = augment(gp[:, cols])
        out[:, cols] = apply_inverse(rhs)[rows_l]
    return out


@dataclass
class ResponseCache:
    """The last responses computed on a factorization, by global multiplier row.

    A later subset of that set (rows released) is solved by a capacitance system on the
    released rows, whose matrix is these responses: kept, it costs no solve at all.
    """

    factorization: int = -1
    rows: np.ndarray | None = None  # sorted global rows of the columns
    values: np.ndarray | None = None  # (local rows x len(rows))
    wanted: np.ndarray | None = None  # local mask of the rows computed (others are zero)

    def store(
        self,
        factorization: int,
        probes: np.ndarray,
        active: np.ndarray,
        values: np.ndarray,
        first_row: int,
        comm: MPI.Comm,
        wanted: np.ndarray | None = None,
    ) -> None:
        """Keep `values`, the responses to `probes` (local rows x k) on `factorization`.

        `wanted`: the local rows they hold (None: every row); a lookup needs its rows there.
        """
        k = values.shape[1]
        gp = np.where(active[:, None], probes, 0.0)
        nz = gp != 0.0
        # A rank may own no multiplier row: argmax of an empty axis is undefined there.
        first = np.argmax(nz, axis=0) if nz.shape[0] else np.zeros(k, dtype=np.int64)
        col_row = np.where(nz.any(axis=0), first_row + first, -1).astype(np.int64)
        comm.Allreduce(MPI.IN_PLACE, col_row, op=MPI.MAX)
        order = np.argsort(col_row)
        self.factorization, self.rows, self.values = factorization, col_row[order], values[:, order]
        self.wanted = None if wanted is None else np.asarray(wanted, dtype=bool).copy()

    def lookup(
        self, factorization: int, rows: np.ndarray, local: np.ndarray, comm: MPI.Comm
    ) -> np.ndarray | None:
        """The kept responses to the global `rows` (sorted), if all are kept for it.

        `local`: the same rows as a local mask; their own responses must have been computed
        (collective: the answer is the same on every rank).
        """
        if self.factorization != factorization or self.rows is None or self.values is None:
            return None
        if not len(self.rows):
            return None
        pos = np.minimum(np.searchsorted(self.rows, rows), len(self.rows) - 1)
        held = self.wanted is None or bool(np.all(self.wanted[np.asarray(local, dtype=bool)]))
        if not comm.allreduce(held, op=MPI.LAND):
            return None
        return self.values[:, pos] if np.array_equal(self.rows[pos], rows) else None


def local_slice(comm: MPI.Comm, mask: np.ndarray) -> slice:
    """This rank's part of the rank-ordered concatenation of the local `mask` rows."""
    counts = comm.allgather(int(np.count_nonzero(mask)))
    lo = sum(counts[: comm.rank])
    return slice(lo, lo + counts[comm.rank])
