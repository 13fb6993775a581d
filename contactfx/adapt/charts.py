"""The adaptive loop's two charts: estimate and error against DOFs, and against time."""

from __future__ import annotations

import itertools
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import FixedLocator, FuncFormatter, MaxNLocator, NullFormatter

from .records import AdaptLevel


def tick_values(lo: float, hi: float) -> list[float]:
    """At least three readable values in [lo, hi] (lo > 0) for a log axis.

    Decades: 1 x 10^k; a few decades: 1, 2, 5 x 10^k; about one: every integer times 10^k;
    shorter (h over one or two refinements): evenly spaced round numbers.
    """
    for mantissas in ((1,), (1, 2, 5), tuple(range(1, 10))):
        decades = range(int(np.floor(np.log10(lo))), int(np.ceil(np.log10(hi))) + 1)
        values = [m * 10.0**k for k in decades for m in mantissas]
        inside = _spaced(sorted({float(f"{v:.12g}") for v in values if lo <= v <= hi}), lo, hi)
        if len(inside) >= 3:
            return inside
    linear = MaxNLocator(nbins=4, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
    return [float(f"{v:.12g}") for v in linear if lo <= v <= hi]


def _spaced(values: list[float], lo: float, hi: float) -> list[float]:
    """`values` without those closer than 1/12 of the axis to a kept one (powers of ten first).

    9000 and 10000 at the end of a 9000..45000 axis print on top of each other.
    """
    gap = (np.log10(hi) - np.log10(lo)) / 12
    logs = {v: float(np.log10(v)) for v in values}
    keep = [v for v in values if abs(logs[v] - round(logs[v])) < 1e-9]
    for v in values:
        if v not in keep and all(abs(logs[v] - logs[k]) >= gap for k in keep):
            keep.append(v)
    return sorted(keep)


def readable_ticks(ax: plt.Axes) -> None:
    """Plain-number labels, at least three on each log axis however short its range.

    matplotlib's own labels on a range under a decade are minor ticks in 10^k notation that
    run into each other ("3x10^34x10^3").
    """
    for axis in (ax.xaxis, ax.yaxis):
        lo, hi = sorted(axis.get_view_interval())
        if not lo > 0:
            continue
        axis.set_major_locator(FixedLocator(tick_values(lo, hi)))
        axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        axis.set_minor_formatter(NullFormatter())


def reference_error(level: AdaptLevel) -> tuple[str, float] | None:
    """(label, value) of a level's error against the scene's exact solution, if it has one.

    With several Hertz pairs the worst one: a pair ten times worse than the first is what
    the mesh has to resolve.
    """
    run = level.summary
    if len(run.hertz) == 1:
        return "Hertz: relative L2 error of the pressure", float(run.hertz[0].l2_error)
    if run.hertz:
        worst = max(run.hertz, key=lambda h: h.l2_error)
        label = f"Hertz: relative L2 error of the pressure\n(worst of {len(run.hertz)} pairs)"
        return label, float(worst.l2_error)
    if run.patch is not None:
        return "patch test: max stress error", float(run.patch.max)
    return None


def _panels(levels: list[AdaptLevel]) -> list[tuple[tuple[str, ...], str]]:
    """(keys, y label) of the panels.

    The goal loop: its goal's estimate with the exact error beside it (where the scene has
    one), then the residual estimate. The residual loop: the estimate, then the exact error.
    """
    goal = levels[0].goal if levels else None
    ref = reference_error(levels[0]) if levels else None
    residual: tuple[tuple[str, ...], str] = (
        ("estimate",),
        "relative residual estimate (energy norm)",
    )
    if goal is not None:
        keys = ("goal", "reference") if ref is not None else ("goal",)
        return [(keys, f"relative {goal.goal.value} error: estimate and exact"), residual]
    exact: list[tuple[tuple[str, ...], str]] = [(("reference",), ref[0])] if ref else []
    return [residual, *exact]


# How each quantity is drawn and named in a panel that shows several.
SERIES = {"goal": ("-o", "estimate"), "estimate": ("-o", ""), "reference": ("--x", "exact")}


def _value(level: AdaptLevel, key: str) -> float | None:
    if key == "estimate":
        return float(level.est.relative)
    if key == "goal":
        return None if level.goal is None else float(level.goal.relative)
    ref = reference_error(level)
    return None if ref is None else ref[1]


def chart_points(
    levels: list[AdaptLevel], key: str, x: str, cumulative: bool
) -> list[tuple[float, float]]:
    """(x, value) of the levels: x the DOFs, or the time.

    With `cumulative` the time is summed over the levels so far: an adapted level costs
    every level before it.
    """
    times = list(itertools.accumulate(lv.time for lv in levels)) if cumulative else None
    pts = []
    for k, lv in enumerate(levels):
        v = _value(lv, key)
        if v is None or not v > 0:
            continue
        at = lv.dofs if x == "dofs" else (times[k] if times else lv.time)
        pts.append((float(at), v))
    return pts


def chart_title(scene: str, method: str, uniform: bool) -> str:
    """The charts' title: against uniform refinement only when its levels are drawn."""
    what = "adaptive against uniform refinement" if uniform else "adaptive refinement"
    return f"{scene}, {method}: {what}"


TIME_LABEL = "cumulative wall time (s): meshing, solve, estimate of the levels so far"
TIME_LABEL_UNIFORM = (
    "wall time (s): adaptive cumulative over its levels,\n"
    "uniform per mesh (meshing, solve, estimate)"
)


def plot_adapt(
    adaptive: list[AdaptLevel], uniform: list[AdaptLevel], path: Path, x: str, title: str
) -> Path:
    """One chart: each panel against `x` ("dofs" or "time"), adaptive and uniform levels.

    Against time an adapted level is charted at the cumulative time of the loop up to it (it
    needs every level before), a uniform one at its own: a uniform mesh needs no other.
    """
    panels = _panels(adaptive)
    fig, axes = plt.subplots(1, len(panels), figsize=(5.8 * len(panels), 4.8), squeeze=False)
    for ax, (keys, label) in zip(axes[0], panels, strict=True):
        for key in keys:
            style, what = SERIES[key]
            for name, levels, line, cumulative in (
                ("adaptive", adaptive, style, True),
                ("uniform", uniform, "--s", False),
            ):
                pts = chart_points(levels, key, x, cumulative)
                if pts:
                    tag = f"{name}, {what}" if len(keys) > 1 else name
                    ax.loglog(*zip(*pts, strict=True), line, label=tag, lw=1.8, ms=6)
        time_label = TIME_LABEL_UNIFORM if uniform else TIME_LABEL
        ax.set_xlabel("displacement DOFs" if x == "dofs" else time_label)
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        readable_ticks(ax)
        ax.legend()
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
