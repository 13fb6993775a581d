"""The adaptive loop's two charts: estimate and error against DOFs, and against time."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from .loop import AdaptLevel


def reference_error(level: AdaptLevel) -> tuple[str, float] | None:
    """(label, value) of a level's error against the scene's exact solution, if it has one."""
    run = level.summary
    if run.hertz:
        return "Hertz: relative L2 error of the pressure", float(run.hertz[0].l2_error)
    if run.patch is not None:
        return "patch test: max stress error", float(run.patch.max)
    return None


def _panels(levels: list[AdaptLevel]) -> list[tuple[str, str]]:
    """(key, y label) of the panels: the estimate, and the exact error where there is one."""
    out = [("estimate", "relative estimate (energy norm)")]
    ref = reference_error(levels[0]) if levels else None
    if ref is not None:
        out.append(("reference", ref[0]))
    return out


def _value(level: AdaptLevel, key: str) -> float | None:
    if key == "estimate":
        return float(level.est.relative)
    ref = reference_error(level)
    return None if ref is None else ref[1]


def plot_adapt(
    adaptive: list[AdaptLevel], uniform: list[AdaptLevel], path: Path, x: str, title: str
) -> Path:
    """One chart: each panel against `x` ("dofs" or "time"), adaptive and uniform levels."""
    panels = _panels(adaptive)
    fig, axes = plt.subplots(1, len(panels), figsize=(5.8 * len(panels), 4.8), squeeze=False)
    for ax, (key, label) in zip(axes[0], panels, strict=True):
        for name, levels, style in (("adaptive", adaptive, "-o"), ("uniform", uniform, "--s")):
            pts = [(lv.dofs if x == "dofs" else lv.time, _value(lv, key)) for lv in levels]
            pts = [(a, b) for a, b in pts if b is not None and b > 0]
            if pts:
                ax.loglog(*zip(*pts, strict=True), style, label=name, lw=1.8, ms=6)
        ax.set_xlabel("displacement DOFs" if x == "dofs" else "wall time per level (s)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
