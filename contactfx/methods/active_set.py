"""The active-set (semi-smooth Newton) loop shared by every method, and its helpers.

`run_active_set` is the one loop: visit a set (cycle detection), solve on it, count the nodes
that enter and leave, record and log the iteration, stop when the set is stationary (checking
the complementarity residual) or raise at the limit. What differs between the multiplier
methods and penalty is the `Iteration` they pass: how a set is solved and, for the multiplier
methods with a direct solver, which set to try next (probes and the small LCP predictor).

At the end of a passive surface (a hub's edge, a narrower block's corner) the loop decides
nothing of its own: it sees only the kernels' rows. The nodes whose support the passive
surface covers only partly (beyond its end, on it, or the last before it) have no row
(contact/operator.py, `end_rows`): their basis functions are merged into the first node
inside, whose multiplier is constant out to the end. That row is active or released by the
same test as every other (its multiplier's sign, its weighted gap's sign), so in a fit whose
interface is closed from end to end no row between two rows in contact is released unless
its own weighted gap is open. Before that merge the node beyond the end carried the corner's
load as a large multiplier and its neighbour inside turned tensile and was released with a
closed gap (docs/edges.md).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np
from mpi4py import MPI

from ..discretize.setup import ContactSetup
from ..errors import ActiveSetError
from ..timers import Timers
from .solution import History

log = logging.getLogger("contactfx")


@dataclass(frozen=True)
class ActiveSetOptions:
    """Controls of the primal-dual active-set iteration."""

    max_iterations: int = 50
    penetration_tol: float = 1e-6  # allowed initial penetration relative to the element size
    tolerance: float = 1e-6  # complementarity residual (relative) required at the end
    probes: bool = True  # probe candidate sets with multi-RHS solves (direct solvers)
    # Largest candidate set probed (its dense block: 8 c^2 bytes, 512 MB at 8000). Above it
    # the loop runs unprobed, which takes many more steps (docs/scale.md#measured-constants,
    # "Largest probed set").
    max_probes: int = 8000
    # With cheap probe responses (serial MUMPS: selected entries of the inverse), start from
    # every multiplier row in contact and probe them all: one factorization, the predicted
    # set by the small complementarity problem, then one solve that only releases rows.
    start_all: bool = True


@dataclass(frozen=True)
class InitialSet:
    """A first active set by position: `active(x)` in contact, `uncertain(x)` worth probing.

    Both map (n, 2) node coordinates to (n,) bools. A superset of the converged set makes the
    loop factorize once and then only release rows (solved without refactoring); probing only
    the uncertain band keeps the multi-right-hand-side solve small.
    """

    active: Callable[[np.ndarray], np.ndarray]
    uncertain: Callable[[np.ndarray], np.ndarray] | None = None


class SetHistory:
    """Bookkeeping of the active-set iteration: visited sets, probes, the small predictor."""

    def __init__(self, comm: MPI.Comm, mine: np.ndarray, size: int) -> None:
        self.comm, self.mine, self.size = comm, np.asarray(mine), size
        self.seen: set[bytes] = set()
        self.last = b""

    def to_global(self, local: np.ndarray) -> np.ndarray:
        """A per-row local array in the global multiplier order."""
        out = np.zeros((self.size, *local.shape[1:]), dtype=local.dtype)
        for idx, vals in self.comm.allgather((self.mine, local)):
            out[idx] = vals
        return out

    def visit(
        self,
        active: np.ndarray,
        it: int,
        n_active: int,
        probing: bool,
        full: np.ndarray | None = None,
    ) -> None:
        """A set about to be solved; raise if a final answer was given on it before (a cycle).

        `full` (owned rows): the whole set where a row has more states than in or out of
        contact (friction's stick, slip and slip direction); None: `active` is the set.
        """
        key = self.to_global(active if full is None else full).tobytes()
        repeat = probing and key == self.last  # the same set again, now with probes
        self.last = key
        if key in self.seen and not repeat:
            raise ActiveSetError(f"active set cycles at iteration {it} ({n_active} active nodes)")

    def settle(self) -> None:
        """The set visited last got a final answer: meeting it again is a cycle.

        A loose answer (an inexact solver's, `Step.final` False) does not settle its set:
        its signs may be wrong within its error, so the loop may come back to that set (a
        loose solve released a row of an exact predicted set; the next step's final answer
        took it back: docs/scale.md, "One CG run per stationary set").
        """
        self.seen.add(self.last)

    def global_indices(self, local_mask: np.ndarray) -> np.ndarray:
        """Global multiplier indices of a local row mask."""
        return np.flatnonzero(self.to_global(local_mask))

    def probe_rhs(self, probe: np.ndarray) -> np.ndarray:
        """Unit right-hand sides (local rows x candidates): open one weighted gap each."""
        rhs = np.zeros((len(self.mine), len(probe)))
        rows = np.flatnonzero(np.isin(self.mine, probe))
        rhs[rows, np.searchsorted(probe, self.mine[rows])] = 1.0
        return rhs

    def predict(
        self, probe: np.ndarray, lam: np.ndarray, dmu: np.ndarray, active: np.ndarray
    ) -> np.ndarray | None:
        """Active set (local mask) solving the complementarity problem restricted to `probe`.

        Rows of `active` (local mask) outside `probe` stay as they are.
        """
        lam0 = self.to_global(lam)[probe]
        # Column j: change of the tractions when the weighted gap of candidate j opens by 1.
        kq = -self.to_global(dmu)[probe]
        kq = 0.5 * (kq + kq.T)
        act = lcp_active_set(kq, lam0)
        if act is None:
            return None
        mask = self.to_global(np.asarray(active, dtype=bool))
        mask[probe] = False
        mask[probe[act]] = True
        return mask[self.mine]


def lcp_active_set(k: np.ndarray, lam0: np.ndarray, max_iterations: int = 100) -> np.ndarray | None:
    """Active set of lam = lam0 + k s >= 0, s >= 0, lam s = 0 by dense primal-dual steps.

    Starts from everything in contact (lam0 itself); returns None on cycling, on an empty
    set (the body would float: left to the full solve to report) or a singular block.
    """
    n = len(lam0)
    act = np.ones(n, dtype=bool)
    seen: set[bytes] = set()
    for _ in range(max_iterations):
        seen.add(act.tobytes())
        ina = ~act
        s = np.zeros(n)
        if ina.any():
            if not act.any():
                return None
            try:
                s[ina] = np.linalg.solve(k[np.ix_(ina, ina)], -lam0[ina])
            except np.linalg.LinAlgError:
                return None
        lam = lam0 + k @ s
        lam[ina] = 0.0
        new = np.where(act, lam > 0.0, s < 0.0)
        if np.array_equal(new, act):
            return act
        act = new
        if act.tobytes() in seen:
            return None
    return None


@dataclass
class Step:
    """One solve on a given set: owned-row tractions and gaps, the updated set, what it cost."""

    lam: np.ndarray  # contact traction per owned row (compression > 0)
    gap: np.ndarray  # normalized gap per owned row at the solution
    new_active: np.ndarray  # the semi-smooth Newton update of the set
    residual: float  # relative complementarity residual (0 where not defined)
    record: dict[str, float] = field(default_factory=dict)  # extra history columns
    text: str = ""  # extra words for the log line
    final: bool = True  # the solve reached the final tolerance (not a loop's loose answer)
    changed: int = 0  # rows (all ranks) whose other set changed: friction's stick/slip
    # The iteration guards against cycles itself (penalty friction: a set met again turns it
    # to steps searched along the Newton step, which come back to sets from other iterates):
    # the loop does not settle its sets. A damped step (a part of the Newton step, or the
    # iterate kept) is not the solved set's solution and does not end the loop.
    guarded: bool = False
    damped: bool = False


@dataclass(frozen=True)
class Proposal:
    """A next set other than the update's, and why (for the log line)."""

    active: np.ndarray  # owned rows
    why: str


class Iteration(Protocol):
    """What a method gives the loop: a solve on a set and, optionally, a better next set."""

    label: str

    @property
    def probing(self) -> bool:
        """Whether the next solve repeats the current set with probes (not a cycle)."""
        ...

    def solve(self, active: np.ndarray, it: int) -> Step:
        """Solve with `active` (owned rows) in contact."""
        ...

    def next_set(self, active: np.ndarray, step: Step, entered: int) -> Proposal | None:
        """The set to solve next instead of `step.new_active` (None: take the update)."""
        ...


@runtime_checkable
class KeyedIteration(Protocol):
    """An Iteration whose rows have more states than the contact set (friction)."""

    def key(self, active: np.ndarray) -> np.ndarray:
        """The whole set of the owned rows about to be solved (cycle detection)."""
        ...


def held_by_last(
    setup: ContactSetup, prev: tuple[np.ndarray, np.ndarray] | None, when: str
) -> None:
    """Before a loop gives up: a floating body (singular solves) is the error to report."""
    if prev is not None:
        setup.check_held_by(setup.loaded(*prev), f"in the last solve ({when})")


def run_active_set(
    setup: ContactSetup,
    iteration: Iteration,
    active: np.ndarray,
    aso: ActiveSetOptions,
    timers: Timers,
) -> tuple[Step, np.ndarray, History]:
    """Iterate until the active set is stationary; return the last step, set and history."""
    comm = setup.comm
    state = SetHistory(comm, setup.layout.mine, setup.layout.size)
    history: History = []
    entered = left = 0
    resid = np.nan
    prev: tuple[np.ndarray, np.ndarray] | None = None  # the last set solved, its tractions
    for it in range(1, aso.max_iterations + 1):
        n_active = comm.allreduce(int(active.sum()))
        setup.check_not_floating(n_active)
        # A set that leaves a body free makes the solve singular: name the bodies (and, by
        # the last solve's tractions, those held only by rows that carried nothing).
        carried = None if prev is None else ~prev[0] | setup.loaded(*prev)
        setup.check_held_by(active, f"in the active set of iteration {it}", carried)
        try:
            full = iteration.key(active) if isinstance(iteration, KeyedIteration) else None
            state.visit(active, it, n_active, iteration.probing, full)
        except ActiveSetError:
            held_by_last(setup, prev, "when the active set started to cycle")
            raise
        t0 = time.perf_counter()
        with timers("solve"):
            step = iteration.solve(active, it)
        if step.final and not step.guarded:
            state.settle()
        t_solve = time.perf_counter() - t0
        resid = step.residual
        entered = comm.allreduce(int(np.sum(step.new_active & ~active)))
        left = comm.allreduce(int(np.sum(active & ~step.new_active)))
        record: dict[str, float | None] = {
            "iteration": it,
            "active": n_active,
            "entered": entered,
            "left": left,
            "residual": resid,
            **step.record,
            "solve_time": t_solve,
        }
        history.append(record)
        stationary = entered == 0 and left == 0 and step.changed == 0 and not step.damped
        proposal = None if stationary else iteration.next_set(active, step, entered)
        after = ""
        if proposal is not None:
            # The next set is not the update's: say how it differs from this one, so that
            # the next line's count adds up.
            added = comm.allreduce(int(np.sum(proposal.active & ~active)))
            released = comm.allreduce(int(np.sum(active & ~proposal.active)))
            record["next_added"], record["next_released"] = added, released
            after = (
                f"; next set: {proposal.why}, +{added} -{released} -> "
                f"{n_active + added - released} active"
            )
        if comm.rank == 0:
            log.info(
                "%s %2d: %5d active, +%d -%d, %s%.3f s%s",
                iteration.label,
                it,
                n_active,
                entered,
                left,
                step.text,
                t_solve,
                after,
            )
        if stationary:
            if resid > aso.tolerance:
                raise ActiveSetError(
                    f"active set is stationary at iteration {it} but the "
                    f"complementarity residual {resid:.2e} exceeds "
                    f"{aso.tolerance:.1e}: the linear solves are too inexact"
                )
            setup.check_held_by(setup.loaded(active, step.lam), "at the converged solution")
            return step, active, history
        prev = (active, step.lam)
        active = step.new_active if proposal is None else proposal.active
    held_by_last(setup, prev, f"after {aso.max_iterations} iterations")
    raise ActiveSetError(
        f"active set did not converge in {aso.max_iterations} iterations "
        f"(last change: +{entered} -{left}, residual {resid:.2e})"
    )
