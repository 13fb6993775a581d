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


@dataclass(frozen=True)
class SolverChoice:
    """Which solver `auto` ran and why (the JSON's `solver_choice`); memory in MB per node."""

    ran: str
    needed_mb: float | None  # MUMPS' estimate summed over the node's ranks (the tightest node)
    available_mb: float | None
    analysis_seconds: float | None
    safety: float = SAFETY

    @property
    def reason(self) -> str:
        """Why, in words: the numbers compared."""
        if self.needed_mb is None or self.available_mb is None:
            return "no MUMPS memory estimate: the direct default"
        verb = "needs" if self.ran != CONDENSED else "would need"
        return (
            f"MUMPS {verb} {self.needed_mb / 1e3:.2f} GB, {self.available_mb / 1e3:.2f} GB "
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
        }


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
