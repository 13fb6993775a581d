"""PETSc's `-log_view` text parsed, and the 8-256-rank time model of the condensed solve.

No PETSc here (the parser reads text, the model is arithmetic): benchmarks/scaling.py writes
the logs and the measurements, tests/linalg/test_scaling_model.py checks both parts on a
captured log and a hand-computed case. The model and its assumptions: docs/scale.md,
"Scaling: measured and modelled".
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

# Events whose every call is one MPI_Allreduce on more than one rank (CG's dot products and
# norms). PETSc 3.25's "Reduct" column does not count them (a 500-iteration CG on 2 ranks
# logs 3 reductions for 1002 VecTDot and 501 VecNorm), so they are counted from the events.
REDUCING_EVENTS = ("VecTDot", "VecDot", "VecNorm", "VecMDot", "VecNormalize", "VecDotNorm2")

_NUM = r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?"


def _floats(text: str) -> list[float]:
    return [float(x) for x in re.findall(_NUM, text)]


def _all_numbers(words: list[str]) -> bool:
    return all(re.fullmatch(_NUM, w) for w in words)


def parse_log_view(text: str) -> dict[str, Any]:
    """The numbers of one `-log_view` (PETSc 3.25's ASCII format) as a dict.

    `global`: the header's Max / Avg / Total rows (time, flops, MPI messages, message
    bytes, reductions); `ranks`. `stages[name]`: time (average over ranks), flops, messages
    and message bytes summed over the ranks, reductions. `events[stage][event]`: count,
    time (max over ranks), flops (max over ranks and their max/min ratio), messages
    (summed over ranks), average message length and bytes (their product), reductions.
    """
    out: dict[str, Any] = {"global": {}, "stages": {}, "events": {}}
    m = re.search(r"with (\d+) process", text)
    out["ranks"] = int(m.group(1)) if m else 1
    rows = {
        "time": r"^Time \(sec\):(.*)$",
        "flops": r"^Flops?:(.*)$",
        "messages": r"^MPI Msg Count:(.*)$",
        "message_bytes": r"^MPI Msg Len \(bytes\):(.*)$",
        "reductions": r"^MPI Reductions:(.*)$",
    }
    for key, pattern in rows.items():
        m = re.search(pattern, text, re.MULTILINE)
        if m:
            v = _floats(m.group(1))
            out["global"][key] = dict(zip(("max", "ratio", "avg", "total"), v, strict=False))
    stage_row = re.compile(rf"^\s*\d+:\s+(.+?):\s+((?:{_NUM}%?\s*){{10}})$", re.MULTILINE)
    for name, numbers in stage_row.findall(text):
        v = _floats(numbers)
        out["stages"][name.strip()] = {
            "time": v[0],
            "flops": v[2],
            "messages": v[4],
            "avg_length": v[6],
            "message_bytes": v[4] * v[6],
            "reductions": v[8],
        }
    stage = None
    for line in text.splitlines():
        m = re.match(r"^--- Event Stage \d+: (.+)$", line)
        if m:
            stage = m.group(1).strip()
            if stage in out["events"]:  # the object table repeats the stage headers
                break
            out["events"][stage] = {}
            continue
        if stage is None:
            continue
        parts = line.split()
        # The name may hold spaces (GAMG's "PCGAMG Gal l00"): it ends before nine numbers.
        start = next((i for i in range(1, len(parts) - 8) if _all_numbers(parts[i : i + 9])), 0)
        if not start or not re.match(r"[A-Za-z_]", parts[0]):
            continue
        v = [float(x) for x in parts[start : start + 9]]
        out["events"][stage][" ".join(parts[:start])] = {
            "count": v[0],
            "time": v[2],
            "time_ratio": v[3],
            "flops": v[4],
            "flops_ratio": v[5],
            "messages": v[6],
            "avg_length": v[7],
            "message_bytes": v[6] * v[7],
            "reductions": v[8],
        }
    return out


def counted_reductions(events: dict[str, dict[str, float]]) -> float:
    """Allreduces of the dot-product events of one stage (each call is one on > 1 rank)."""
    return sum(events[e]["count"] for e in REDUCING_EVENTS if e in events)


@dataclass(frozen=True)
class Network:
    """A cluster's interconnect, as the model sees it (values: docs/scale.md)."""

    latency: float = 2e-6  # s per point-to-point message (InfiniBand HDR/EDR MPI, small)
    bandwidth: float = 5e9  # bytes/s per rank (HDR 25 GB/s per node shared by ~5 ranks' halos)
    allreduce_latency: float = 2e-6  # s per stage of a log2(P) tree allreduce


@dataclass(frozen=True)
class RankWork:
    """One rank's share of a phase: flops, messages sent, bytes sent, allreduces."""

    flops: float
    messages: float
    message_bytes: float
    reductions: float


def phase_time(work: RankWork, rate: float, ranks: int, net: Network) -> dict[str, float]:
    """time = flops / rate + messages * latency + bytes / bandwidth + reductions * allreduce(P).

    allreduce(P) = log2(P) * allreduce_latency; `rate` is the flop rate of one core in this
    phase (flop/s). Returns each term and their sum (`total`).
    """
    terms = {
        "compute": work.flops / rate,
        "latency": work.messages * net.latency,
        "bandwidth": work.message_bytes / net.bandwidth,
        "allreduce": work.reductions * math.log2(ranks) * net.allreduce_latency
        if ranks > 1
        else 0.0,
    }
    terms["total"] = sum(terms.values())
    return terms


def neighbours(ranks: int) -> float:
    """Subdomains a rank exchanges halos with in a 2D partition: 1 on 2 ranks, at most 6."""
    return float(min(ranks - 1, 6))


def halo_factor(ranks: int) -> float:
    """A rank's halo length on `ranks` square-ish subdomains over the 2-rank cut, same mesh.

    Two ranks: one cut across the domain (length L). P square subdomains of a square domain:
    a rank's perimeter is 4 L / sqrt(P). So 4 / sqrt(P) from 4 ranks (1 at P = 16).
    """
    return 1.0 if ranks <= 2 else 4.0 / math.sqrt(ranks)


def power_fit(xs: list[float], ys: list[float]) -> tuple[float, float]:
    """(c, g) of y = c x^g by least squares in log-log; g = 0 for a single point."""
    if len(xs) == 1:
        return ys[0], 0.0
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    sxx = sum((a - mx) ** 2 for a in lx)
    g = sum((a - mx) * (b - my) for a, b in zip(lx, ly, strict=True)) / sxx if sxx else 0.0
    return math.exp(my - g * mx), g


# Allreduces per iteration of PETSc's CG with the unpreconditioned norm (KSPSolve_CG: the
# residual norm and two dot products).
CG_REDUCTIONS = 3


@dataclass(frozen=True)
class Part:
    """One part of the solve stage as measured on 2 ranks (one neighbour), per rank.

    flops_per_dof: flops summed over the ranks per DOF (per DOF and CG iteration where
    `per_iteration`); rate: flop/s of one rank in it; messages, message_bytes, reductions:
    one rank's (per iteration where `per_iteration`), bytes at the measured size.
    """

    name: str
    flops_per_dof: float
    rate: float
    messages: float
    message_bytes: float
    reductions: float
    per_iteration: bool


@dataclass(frozen=True)
class Measured:
    """The model's inputs: the parts at `dofs` and iterations(N) = its_c N^its_g."""

    dofs: float
    parts: tuple[Part, ...]
    its_c: float
    its_g: float


def scale_work(part: Part, m: Measured, dofs: float, ranks: int) -> RankWork:
    """One rank's work of `part` at `dofs` on `ranks`.

    Flops: per DOF as measured, times dofs / ranks (and the iterations); messages: as on 2
    ranks (one neighbour) times neighbours(P); bytes: the halo, sqrt(dofs / measured dofs)
    times halo_factor(P); reductions as measured; everything per iteration times the
    iterations for a per-iteration part. One rank: no messages, no reductions.
    """
    k = m.its_c * dofs**m.its_g if part.per_iteration else 1.0
    par = float(ranks > 1)
    return RankWork(
        flops=part.flops_per_dof * dofs * k / ranks,
        messages=part.messages * neighbours(ranks) * k * par,
        message_bytes=part.message_bytes * math.sqrt(dofs / m.dofs) * halo_factor(ranks) * k * par,
        reductions=part.reductions * k * par,
    )


def predict(m: Measured, dofs: float, ranks: int, net: Network) -> dict[str, float]:
    """Modelled seconds of the solve stage at `dofs` on `ranks`: per part, and their sums."""
    out = {"iterations": m.its_c * dofs**m.its_g, "compute": 0.0, "total": 0.0}
    for part in m.parts:
        t = phase_time(scale_work(part, m, dofs, ranks), part.rate, ranks, net)
        out[part.name] = t["total"]
        out["compute"] += t["compute"]
        out["total"] += t["total"]
    out["communication"] = out["total"] - out["compute"]
    return out


@dataclass(frozen=True)
class Phases:
    """The run's other phases, seconds per DOF as measured on 2 ranks.

    mesh and predictor are held per DOF and not divided by the ranks (the structured grid is
    generated on rank 0; the coarse predictor is a direct solve of N/16 DOFs); assembly is
    divided by the ranks (`assemble_rank`: seconds x ranks / DOFs).
    """

    mesh: float
    assemble_rank: float
    predictor: float


def whole_run(m: Measured, ph: Phases, dofs: float, ranks: int, net: Network) -> float:
    """Modelled seconds of the whole run: mesh + assembly + predictor + the solve stage."""
    other = ph.mesh * dofs + ph.assemble_rank * dofs / ranks + ph.predictor * dofs
    return other + predict(m, dofs, ranks, net)["total"]
