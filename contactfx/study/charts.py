"""The two charts of a study: error against contact element size, and against time."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from .core import Study
from .measures import ROUND_OFF
from .report import main_errors

COLORS = {
    "nts": "tab:blue",
    "sts": "tab:orange",
    "mortar": "tab:green",
    "penalty": "tab:red",
    "schwarz": "tab:purple",
}
MARKERS = {"nts": "o", "sts": "s", "mortar": "^", "penalty": "v", "schwarz": "D"}
LABELS = {
    "l2": "relative L2 error of the pressure",
    "a": "|a - a_exact| / a_exact (half-width)",
    "p0": "|p0 - p0_exact| / p0_exact (peak pressure)",
    "stress": "max stress error / max |sigma_exact|",
    "pressure": "pressure: relative L2 difference\nfrom the reference (along s)",
    "displacement": "displacement: relative L2 difference\nfrom the reference (along s)",
}


def _series(study: Study, method: str, name: str, x: str) -> tuple[np.ndarray, np.ndarray]:
    """(x, error) of a method's finished runs with an error above round-off."""
    ref = study.reference
    # Self-convergence: on the reference's mesh a method differs from it by the methods only.
    last = ref["level"] if ref["kind"] == "self" and ref.get("level") is not None else None
    pts = [
        (r.h if x == "h" else r.after_mesh, r.errors.get(name))
        for r in study.runs
        if r.method == method and r.ok and (last is None or r.level < last)
    ]
    pts = [(a, e) for a, e in pts if a and e is not None and e > 0]
    return np.array([p[0] for p in pts]), np.array([p[1] for p in pts])


def _rate_text(rate: float | None, errors: np.ndarray) -> str:
    if rate is not None:
        return f"rate {rate:.2f}"
    return "exact to round-off" if np.all(errors <= ROUND_OFF) else "no rate (< 2 levels)"


def _figure(study: Study, x: str) -> tuple[plt.Figure, list[plt.Axes], list[str]]:
    names = main_errors(study)
    fig, axes = plt.subplots(
        1, len(names), figsize=(max(5.6 * len(names), 8.0), 5.0), squeeze=False
    )
    return fig, list(axes[0]), names


def _title(study: Study) -> str:
    ref = study.reference
    what = {"hertz": "exact Hertz solution", "uniform_stress": "exact uniform stress"}.get(
        ref["type"], f"finest level of {ref.get('method')}"
    )
    return f"{study.scene}, reference: {what}, {study.ranks} rank{'s' * (study.ranks > 1)}"


def _draw(ax: plt.Axes, study: Study, name: str, x: str, label: str | None = None) -> None:
    """Every method of `study` on one panel; an extra study (`label`) is drawn dashed."""
    rates = study.rates if x == "h" else study.time_rates
    for m in study.methods:
        xs, e = _series(study, m, name, x)
        if not len(xs):
            continue
        rate = rates[m].get(name)
        text = _rate_text(rate, e) if x == "h" or rate is None else f"error ~ t^{rate:.2f}"
        ax.loglog(
            xs,
            e,
            marker=MARKERS.get(m, "o") if label is None else "D",
            color=COLORS.get(m),
            lw=1.8,
            ms=7,
            ls="-" if label is None else "--",
            mfc=None if label is None else "none",
            label=f"{m}{'' if label is None else ', ' + label}: {text}",
        )


def _ticks(ax: plt.Axes) -> None:
    """Plain-number labels; at 1, 2, 5 x 10^k when the range is short (few decades)."""
    for axis in (ax.xaxis, ax.yaxis):
        lo, hi = sorted(axis.get_view_interval())
        short = lo > 0 and np.log10(hi / lo) <= 2.5
        axis.set_major_locator(
            LogLocator(base=10, subs=(1.0, 2.0, 5.0) if short else (1.0,), numticks=8)
        )
        axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        axis.set_minor_formatter(NullFormatter())


def _finish(fig: plt.Figure, path: Path, title: str) -> Path:
    fig.suptitle(title, fontsize=12)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_convergence(study: Study, path: Path, extra: Sequence[tuple[str, Study]] = ()) -> Path:
    """Error against the contact element size h, one panel per error, rates in the legend.

    `extra`: (label, study) pairs drawn dashed on the same panels (another mesh family).
    """
    fig, axes, names = _figure(study, "h")
    for ax, name in zip(axes, names, strict=True):
        _draw(ax, study, name, "h")
        for label, other in extra:
            _draw(ax, other, name, "h", label)
        ax.set_xlabel("contact element size h (median in the contact zone)", fontsize=11)
        ax.set_ylabel(LABELS.get(name, name), fontsize=11)
        ax.grid(True, which="both", alpha=0.3)
        _ticks(ax)
        model = (
            "fitted: difference ~ h^rate - h_ref^rate"
            if study.reference["kind"] == "self"
            else "fitted: error ~ h^rate"
        )
        ax.legend(fontsize=10, title=model, title_fontsize=10)
    return _finish(fig, path, f"Error against mesh size\n{_title(study)}")


def plot_time(study: Study, path: Path, extra: Sequence[tuple[str, Study]] = ()) -> Path:
    """Error against wall time after meshing, every method on each panel."""
    fig, axes, names = _figure(study, "time")
    for ax, name in zip(axes, names, strict=True):
        _draw(ax, study, name, "time")
        for label, other in extra:
            _draw(ax, other, name, "time", label)
        ax.set_xlabel("wall time after meshing (s): assembly, search, solves", fontsize=11)
        ax.set_ylabel(LABELS.get(name, name), fontsize=11)
        ax.grid(True, which="both", alpha=0.3)
        _ticks(ax)
        ax.legend(fontsize=10, title="lower left is better", title_fontsize=10)
    return _finish(fig, path, f"Accuracy against time\n{_title(study)}")
