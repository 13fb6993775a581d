"""The rule of the default solver `auto`: MUMPS' memory estimate against the memory available.

Pure apart from reading /proc/meminfo and one collective (`node_budget`); the run that
applies it is methods/autosolve.py, the rule and its measurements docs/scale.md, "The
default solver".
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Any

from mpi4py import MPI

# The direct path runs if SAFETY x MUMPS' estimate fits in the memory available after the
# analysis: the margin covers the resident memory the factorization adds beyond MUMPS' own
# count and the loop after it (probes, GMRES); measured in docs/scale.md, "The default solver".
SAFETY = 1.25
CONDENSED = "condensed"  # the preset `auto` falls back to
# Where the fine analysis would be long, `auto` first analyses the same scene meshed this
# much coarser (a quarter of the DOFs): MUMPS' estimate per DOF grows with the DOFs on this
# family from COARSE_BOUND_DOFS up (1 and 2 ranks), so the coarse estimate scaled to the
# fine DOFs is a lower bound of the fine one (`scaled_bound`); below that size a rank's
# fixed share can make the per-DOF figure fall. A quarter, not the predictor's 1/16: the
# bound from 1/16 falls further short of the fine estimate and did not decide where the
# fine analysis is the long one (measured: docs/scale.md, "The default solver").
COARSE_BOUND_FACTOR = 2.0
COARSE_BOUND_DOFS = 400_000
# The coarse check runs only where it could decide: where SAFETY x this much per DOF (above
# every estimate per DOF measured in docs/scale.md, "The default solver") would not fit;
# elsewhere the fine analysis decides at once (its first factorization reuses it).
CHECK_KB_PER_DOF = 2.0


class Choice(StrEnum):
    """What `auto` runs."""

    DIRECT = "direct"
    CONDENSED = "condensed"
    REFUSE = "refuse"  # the direct path would not fit and the multipliers cannot be eliminated


def choose(
    needed_mb: float | None, available_mb: float | None, condensable: bool, safety: float = SAFETY
) -> Choice:
    """The path for MUMPS' estimate `needed_mb` against `available_mb` (both per node).

    Direct when it fits with the safety factor, or when either number is unknown (the
    direct path is the default); otherwise condensed if `condensable`, else refuse.
    """
    if needed_mb is None or available_mb is None or needed_mb * safety <= available_mb:
        return Choice.DIRECT
    return Choice.CONDENSED if condensable else Choice.REFUSE


def scaled_bound(coarse_mb: float, coarse_dofs: int, dofs: int) -> float:
    """A lower bound of MUMPS' estimate for `dofs` DOFs from its estimate for `coarse_dofs`.

    Valid where the estimate per DOF does not fall with the DOFs (from COARSE_BOUND_DOFS):
    est(dofs) >= est(coarse) x dofs / coarse_dofs.
    """
    return coarse_mb * dofs / coarse_dofs


@dataclass(frozen=True)
class SolverChoice:
    """Which solver `auto` ran and why (the JSON's `solver_choice`); memory in MB per node."""

    ran: str
    needed_mb: float | None  # MUMPS' estimate summed over the node's ranks (the tightest node)
    available_mb: float | None
    analysis_seconds: float | None
    safety: float = SAFETY
    # DOFs of the coarse system whose analysis, scaled, bounds the estimate from below (None:
    # the estimate is the fine system's own).
    coarse_dofs: int | None = None
    # The estimate is the graph model's lower bound (methods/mumps_model.py): no analysis ran.
    model: bool = False

    @property
    def reason(self) -> str:
        """Why, in words: the numbers compared."""
        if self.needed_mb is None or self.available_mb is None:
            return "no MUMPS memory estimate: the direct default"
        verb = "needs" if self.ran != CONDENSED else "would need"
        amount = f"{self.needed_mb / 1e3:.2f} GB"
        if self.coarse_dofs is not None:
            amount = f">= {amount} (analysis of the {self.coarse_dofs:,}-DOF coarse system, scaled)"
        elif self.model:
            amount = f">= {amount} (the model of its estimate from the graph, a lower bound)"
        return (
            f"MUMPS {verb} {amount}, {self.available_mb / 1e3:.2f} GB "
            f"available; margin x{self.safety:g}"
        )

    def to_json(self) -> dict[str, Any]:
        """The `solver_choice` block of the JSON summary."""
        return {
            "requested": "auto",
            "ran": self.ran,
            "reason": self.reason,
            "mumps_estimate_mb": self.needed_mb,
            "available_mb": self.available_mb,
            "safety": self.safety,
            "analysis_seconds": self.analysis_seconds,
            "estimate_of": self._estimate_of,
            "coarse_dofs": self.coarse_dofs,
        }

    @property
    def _estimate_of(self) -> str:
        """Which system's estimate was compared (the JSON's `estimate_of`)."""
        if self.coarse_dofs is not None:
            return "coarse, scaled (a lower bound)"
        return "graph model (a lower bound)" if self.model else "fine"


def mem_available_mb() -> float | None:
    """MemAvailable of /proc/meminfo (MB: 1e6 bytes, MUMPS' unit), or None where there is none."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024 / 1e6  # kB (KiB) -> MB, as MUMPS
    except OSError:
        pass
    return None


def node_budget(
    comm: MPI.Comm, rank_mb: float | None, override_mb: float | None
) -> tuple[float | None, float | None]:
    """(needed, available) MB on the node with the least room; the ranks of a node share it.

    `rank_mb`: this rank's estimate (None on any rank: unknown); `override_mb`: the
    available memory per node instead of MemAvailable. Collective; the same on every rank.
    """
    node = comm.Split_type(MPI.COMM_TYPE_SHARED)
    try:
        unknown = comm.allreduce(rank_mb is None, op=MPI.LOR)
        needed = node.allreduce(0.0 if rank_mb is None else rank_mb)
        avail = override_mb if override_mb is not None else mem_available_mb()
        avail = node.bcast(avail if node.rank == 0 else None, root=0)
        leader = node.rank == 0
    finally:
        node.Free()
    nodes = [p for p in comm.allgather((needed, avail) if leader else None) if p is not None]
    if unknown or any(a is None for _, a in nodes):
        return None, None
    return min(nodes, key=lambda p: p[1] - SAFETY * p[0])
