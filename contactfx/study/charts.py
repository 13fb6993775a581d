"""The two charts of a study: error against contact element size, and against time."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ..adapt.charts import readable_ticks as _ticks
from ..adapt.charts import tick_values as tick_values
from .core import Study, series
from .measures import ROUND_OFF, fit_rate
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
    """(x, error) of what the rate is fitted to (core.series): exactly the charted points.

    x "solve": the run's time after meshing, whose meshing may come from the mesh cache or
    from gmsh (seconds against milliseconds), which one axis cannot tell apart.
    """
    kind = "self" if study.reference["kind"] == "self" else "exact"
    if x != "solve":
        return series(study.runs, method, name, x, kind)
    pts = sorted(
        (r.level, r.after_mesh, e)
        for r in study.runs
        if r.method == method
        and r.ok
        and r.after_mesh
        and (e := (r.successive if kind == "self" else r.errors).get(name)) is not None
        and e > 0
    )
    return np.array([p[1] for p in pts]), np.array([p[2] for p in pts])


def _rate_text(rate: float | None, errors: np.ndarray, flag: str | None = None) -> str:
    if rate is not None:
        return f"rate {rate:.2f}" + (f" ({flag}!)" if flag else "")
    return "exact to round-off" if np.all(errors <= ROUND_OFF) else "no rate (< 2 levels)"


def _label(study: Study, name: str) -> str:
    """The y label: self-convergence charts the difference from the next finer level."""
    if study.reference["kind"] == "self":
        what = name.split("_pair")[0]
        return f"{what}: relative L2 difference\nfrom the next finer level (along s)"
    return LABELS.get(name, name)


def _figure(study: Study, x: str) -> tuple[plt.Figure, list[plt.Axes], list[str]]:
    names = main_errors(study)
    fig, axes = plt.subplots(
        1, len(names), figsize=(max(5.6 * len(names), 8.0), 5.0), squeeze=False
    )
    return fig, list(axes[0]), names


def _title(study: Study) -> str:
    ref = study.reference
    what = {
        "hertz": "exact Hertz solution",
        "uniform_stress": "exact uniform stress",
        "cattaneo": "Cattaneo-Mindlin",
    }.get(ref["type"], f"finest level of {ref.get('method')}")
    return f"{study.scene}, reference: {what}, {study.ranks} rank{'s' * (study.ranks > 1)}"


def _draw(ax: plt.Axes, study: Study, name: str, x: str, label: str | None = None) -> None:
    """Every method of `study` on one panel; an extra study (`label`) is drawn dashed."""
    for m in study.methods:
        xs, e = _series(study, m, name, x)
        if not len(xs):
            continue
        rate = study.rates[m].get(name) if x == "h" else fit_rate(xs, e)
        flag = study.flags.get(m, {}).get(name) if x == "h" else None
        text = _rate_text(rate, e, flag) if x == "h" or rate is None else f"error ~ t^{rate:.2f}"
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
        ax.set_ylabel(_label(study, name), fontsize=11)
        ax.grid(True, which="both", alpha=0.3)
        _ticks(ax)
        model = (
            "fitted: |u_k - u_k+1| ~ h_k^rate (successive levels)"
            if study.reference["kind"] == "self"
            else "fitted: error ~ h^rate"
        )
        ax.legend(fontsize=10, title=model, title_fontsize=10)
    return _finish(fig, path, f"Error against mesh size\n{_title(study)}")


def _adaptive_points(study: Study, method: str, name: str, x: str) -> np.ndarray:
    """(x, error) rows of a method's adaptive levels; x is "dofs" or "cumulative" (time)."""
    pts = [
        (float(getattr(r, x)), float(e))
        for r in study.adaptive
        if r.method == method and (e := r.errors.get(name)) is not None and e > 0
    ]
    return np.array(pts).reshape(-1, 2)


def _draw_adaptive(ax: plt.Axes, study: Study, name: str, x: str) -> None:
    """Every method's adaptive levels (study --adaptive), dotted with star markers."""
    for m in dict.fromkeys(r.method for r in study.adaptive):
        pts = _adaptive_points(study, m, name, x)
        if not len(pts):
            continue
        rate = fit_rate(pts[:, 0], pts[:, 1])
        what = "cumulative time, remeshing included" if x == "cumulative" else "DOFs N"
        text = "" if rate is None else f": error ~ {'t' if x == 'cumulative' else 'N'}^{rate:.2f}"
        ax.loglog(
            pts[:, 0],
            pts[:, 1],
            marker="*",
            color=COLORS.get(m),
            lw=1.8,
            ms=10,
            ls=":",
            label=f"{m}, adaptive ({what}){text}",
        )


def _draw_dofs(ax: plt.Axes, study: Study, name: str) -> None:
    """Every method's uniform levels against DOFs, with the slope in N."""
    for m in study.methods:
        pts = [
            (float(r.dofs), float(e))
            for r in study.runs
            if r.method == m and r.ok and r.dofs and (e := r.errors.get(name)) is not None
        ]
        pts = [p for p in pts if p[1] > 0]
        if not pts:
            continue
        xs, e = np.array(pts).T
        rate = fit_rate(xs, e)
        ax.loglog(
            xs,
            e,
            marker=MARKERS.get(m, "o"),
            color=COLORS.get(m),
            lw=1.8,
            ms=7,
            label=f"{m}, uniform" + ("" if rate is None else f": error ~ N^{rate:.2f}"),
        )


def plot_dofs(study: Study, path: Path) -> Path:
    """Error against displacement DOFs: uniform and adaptive levels (study --adaptive).

    Without an exact solution both are the difference from the study's reference (the
    finest uniform level of the most accurate method), not from the next finer level.
    """
    fig, axes, names = _figure(study, "dofs")
    for ax, name in zip(axes, names, strict=True):
        _draw_dofs(ax, study, name)
        _draw_adaptive(ax, study, name, "dofs")
        ax.set_xlabel("displacement DOFs N", fontsize=11)
        label = LABELS.get(name, name)
        if study.reference["kind"] == "self":
            label = f"{name}: relative L2 difference\nfrom the reference (along s)"
        ax.set_ylabel(label, fontsize=11)
        ax.grid(True, which="both", alpha=0.3)
        _ticks(ax)
        ax.legend(fontsize=9, title="lower left is better", title_fontsize=10)
    return _finish(fig, path, f"Accuracy against DOFs\n{_title(study)}")


def plot_time(study: Study, path: Path, extra: Sequence[tuple[str, Study]] = ()) -> Path:
    """Error against each run's wall time after meshing, every method on each panel.

    Meshing is left out: a level's mesh comes from the mesh cache or from gmsh, seconds
    apart, and one axis mixing both would compare the cache, not the methods (the meshing
    times are in study.json and study.csv). With study --adaptive also the adaptive levels,
    at their cumulative time (solves, estimates and gmsh's remeshing of all levels up to
    each: labelled so); without an exact solution those are differences from the
    reference, the uniform runs' from the next finer level.
    """
    fig, axes, names = _figure(study, "time")
    for ax, name in zip(axes, names, strict=True):
        _draw(ax, study, name, "solve")
        for label, other in extra:
            _draw(ax, other, name, "solve", label)
        _draw_adaptive(ax, study, name, "cumulative")
        ax.set_xlabel(
            "wall time after meshing (s): assembly, search, solves\n(uniform levels; "
            "meshing, from the cache or gmsh, left out)",
            fontsize=11,
        )
        ax.set_ylabel(_label(study, name), fontsize=11)
        ax.grid(True, which="both", alpha=0.3)
        _ticks(ax)
        ax.legend(fontsize=10, title="lower left is better", title_fontsize=10)
    return _finish(fig, path, f"Accuracy against time\n{_title(study)}")
