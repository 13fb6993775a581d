"""Figures of a run: the contact line charts (matplotlib) and the deformed fields (pyvista).

The deformed-field picture is like the paper's Fig. 3; the charts read the run's summary record.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..methods.solution import Solution
from .obstacles import outline
from .records import RunSummary
from .references import exact_pressure
from .stress import sigma_field

# A field whose spread is below this fraction of its scale is uniform to round-off: it is
# drawn as uniform (a band around its mean), not autoscaled onto its noise.
ROUND_OFF_SPREAD = 1e-6


def round_off_band(values: np.ndarray, scale: float = 0.0) -> tuple[float, float] | None:
    """Display limits for values uniform to round-off, or None if they vary for real.

    `scale`: the size the values are compared with (e.g. the largest traction of the chart;
    by default the values' own largest magnitude). A uniform field is shown as its mean
    +- 5 % of the scale, so its noise draws as the flat line it is.
    """
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return None
    ref = max(scale, float(np.abs(v).max()))
    if float(v.max() - v.min()) > ROUND_OFF_SPREAD * ref:
        return None
    half = 0.05 * ref if ref > 0 else 1.0
    mean = float(v.mean())
    return mean - half, mean + half


def deformed_fields(
    sol: Solution,
    path: Path,
    scale: float = 100.0,
    window: tuple[float, float, float, float] | None = None,
) -> Path | None:
    """Save u_y and sigma_yy on the mesh deformed `scale` times; serial runs only.

    Rigid obstacles are drawn as black outlines, displaced `scale` times their motion.
    `window` (xmin, xmax, ymin, ymax) zooms on a part of the plane (default: everything).
    """
    if sol.scene.mesh.comm.size > 1:
        return None
    import pyvista
    from dolfinx import plot

    pyvista.OFF_SCREEN = True
    if not os.environ.get("DISPLAY"):
        # Without an X server VTK tries X first and warns ("bad X server connection")
        # before it falls back to EGL: ask for EGL directly (unless the user chose).
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    V = sol.fields.V
    # vtk_mesh is a singledispatch function: mypy sees only its Mesh signature.
    topology, cell_types, x = plot.vtk_mesh(V)
    grid = pyvista.UnstructuredGrid(topology, cell_types, x)
    u = sol.u.x.array.reshape(-1, 2)
    grid.point_data["u_y"] = u[:, 1]
    grid.point_data["u"] = np.column_stack([u, np.zeros(len(u))])
    s = sigma_field(sol).x.array.reshape(-1, 4)
    # DG0 dofs follow the cell order of vtk_mesh(V) (both enumerate local cells).
    grid.cell_data["sigma_yy"] = s[: grid.n_cells, 3]
    warped = grid.warp_by_vector("u", factor=scale)
    # Rigid obstacles: their outlines moved by `scale` times their motion, like the mesh.
    outlines = [
        outline(ob, x[:, :2]) + scale * np.asarray(ob.displacement) for ob in sol.scene.obstacles
    ]
    # pyvista annotates window_size as list[int]; it takes any sequence (as BasePlotter says).
    plotter = pyvista.Plotter(shape=(1, 2), window_size=(1600, 700), off_screen=True)
    units = sol.scene.units
    for col, (name, label) in enumerate(
        (("u_y", f"u_y ({units.length})"), ("sigma_yy", f"sigma_yy ({units.stress})"))
    ):
        plotter.subplot(0, col)
        values = np.asarray(warped[name])
        band = round_off_band(values)
        if band is not None:
            label += f": uniform {float(values.mean()):.6g} (spread {np.ptp(values):.1e})"
        plotter.add_mesh(
            warped,
            scalars=name,
            cmap="turbo",
            clim=band,
            show_edges=False,
            # Below the field, not over it: the view leaves the bottom fifth for it.
            scalar_bar_args={
                "title": label,
                "vertical": False,
                "position_x": 0.15,
                "position_y": 0.06,
                "width": 0.7,
                "height": 0.1,
                "n_labels": 3 if band is not None else 4,
                "fmt": "%.4g",
                "title_font_size": 16,
                "label_font_size": 14,
            },
        )
        # The labels below the bar, the title above it (by default both sit above, overlapping).
        plotter.scalar_bars[label].SetTextPositionToPrecedeScalarBar()
        for xy in outlines:
            pts = np.column_stack([xy, np.zeros(len(xy))])
            plotter.add_mesh(pyvista.lines_from_points(pts), color="black", line_width=2)
        plotter.add_text(f"{label}, deformation x{scale:g}", font_size=10)
        plotter.view_xy()
        if window is not None:
            _zoom(plotter, window)
        _leave_room_below(plotter)
    path.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(path))
    plotter.close()
    return path


def _leave_room_below(plotter: Any) -> None:
    """Zoom out and lift the view so the field keeps clear of the colour bar at the bottom."""
    cam = plotter.camera
    cam.parallel_projection = True
    scale = cam.parallel_scale
    fx, fy, fz = cam.focal_point
    px, py, pz = cam.position
    shift = 0.25 * scale
    cam.focal_point = (fx, fy - shift, fz)
    cam.position = (px, py - shift, pz)
    cam.parallel_scale = 1.3 * scale


def _zoom(plotter: Any, window: tuple[float, float, float, float]) -> None:
    """Look at `window` (xmin, xmax, ymin, ymax) from above, in parallel projection."""
    x0, x1, y0, y1 = window
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    cam = plotter.camera
    cam.parallel_projection = True
    cam.focal_point = (cx, cy, 0.0)
    cam.position = (cx, cy, 10.0 * max(x1 - x0, y1 - y0))
    cam.up = (0.0, 1.0, 0.0)
    # Half the view's height; each subplot is 800 x 600 pixels.
    cam.parallel_scale = 0.5 * max(y1 - y0, 0.75 * (x1 - x0))


def contact_window(run: RunSummary) -> tuple[float, float, float, float] | None:
    """A window on the active nodes of the obstacle pairs (three times their extent)."""
    pts = []
    for c in run.contacts:
        itf = c.interface
        if c.obstacle is not None:
            pts += [(x, y) for x, y, a in zip(itf["x"], itf["y"], itf["active"], strict=True) if a]
    if not pts:
        return None
    xy = np.asarray(pts)
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    half = 1.5 * max(float(np.max(hi - lo)), 1e-12 * float(np.abs(xy).max() + 1.0))
    cx, cy = 0.5 * (lo + hi)
    return (cx - half, cx + half, cy - half, cy + half)


def contact_zoom(s: np.ndarray, active: np.ndarray) -> tuple[float, float] | None:
    """Limits around the active zone of a contact line (None if nothing is active).

    The zone plus half its length (at least three node spacings) on each side, within the
    line.
    """
    if not active.any():
        return None
    lo, hi = float(s[active].min()), float(s[active].max())
    spacing = float(np.median(np.diff(np.unique(s)))) if len(np.unique(s)) > 1 else 0.0
    margin = max(0.5 * (hi - lo), 3.0 * spacing)
    return max(float(np.nanmin(s)), lo - margin), min(float(np.nanmax(s)), hi + margin)


def plot_interface(run: RunSummary, path: Path, title: str = "") -> Path:
    """Chart sigma_yy of both bodies and the contact pressure along the contact line."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    itf = run.interface
    assert itf is not None, "the run has no paper_interface block"
    x = np.asarray(itf["x"])
    fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
    for key, style, label in (
        ("sigma_yy_1", "-", "sigma_yy body 1"),
        ("sigma_yy_2", "--", "sigma_yy body 2"),
    ):
        vals = np.array([np.nan if v is None else v for v in itf[key]], dtype=float)
        ax.plot(x, vals, style, label=label)
    ax.plot(x, -np.asarray(itf["pressure"]), ":", label="-pressure (multipliers)")
    if run.hertz:
        # Zoom on the contact zone and show the exact plane-strain Hertz profile.
        a, p0 = run.hertz[0].a_exact, run.hertz[0].p0_exact
        xs = np.linspace(0.0, 2.0 * a, 400)
        ax.plot(
            xs,
            -p0 * np.sqrt(np.clip(1 - (xs / a) ** 2, 0.0, None)),
            "k-",
            lw=0.8,
            alpha=0.6,
            label="-pressure, exact 2D Hertz",
        )
        ax.set_xlim(0.0, 2.0 * a)
    else:
        zoom = contact_zoom(x, np.asarray(itf["pressure"], dtype=float) > 0.0)
        if zoom is not None:
            ax.set_xlim(*zoom)
    ax.set_xlabel(f"x ({run.units.length})")
    ax.set_ylabel(run.units.stress)
    ax.ticklabel_format(axis="y", useOffset=False)
    ax.set_title(title or f"{run.scene} / {run.method.value}: contact line")
    ax.grid(alpha=0.3)
    ax.legend()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def stick_spans(s: np.ndarray, status: Sequence[str]) -> list[tuple[float, float]]:
    """The runs of consecutive `stick` nodes along s, each as (first s, last s).

    `s` sorted (the interface columns are); a lone stick node is a span of zero length.
    """
    spans: list[tuple[float, float]] = []
    start: float | None = None
    for i, st in enumerate(status):
        if st == "stick" and start is None:
            start = float(s[i])
        if st != "stick" and start is not None:
            spans.append((start, float(s[i - 1])))
            start = None
    if start is not None:
        spans.append((start, float(s[len(status) - 1])))
    return spans


def plot_pair(run: RunSummary, k: int, path: Path, mu: float = 0.0) -> Path:
    """Chart pair k along s: pressure, -sigma_nn and sigma_nt of both bodies (and Hertz).

    A frictional pair (`mu` > 0 and the interface's `shear` and `status` columns) also gets
    |shear| and mu p on the traction axes, with its stick zones shaded.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    c = run.contacts[k]
    itf = c.interface

    def arr(key: str) -> np.ndarray:
        return np.array([np.nan if v is None else v for v in itf[key]], dtype=float)

    s = arr("s")
    fig, (ax, bx) = plt.subplots(
        2, 1, figsize=(7, 5.5), sharex=True, layout="constrained", height_ratios=(3, 1.3)
    )
    ax.plot(s, arr("pressure"), "k.-", ms=3, lw=1, label="pressure (multipliers)")
    ax.plot(s, -arr("sigma_nn_active"), "-", label=f"-sigma_nn {c.active_body} (active)")
    bx.plot(s, arr("sigma_nt_active"), "-", label="active")
    if c.obstacle is None:  # a rigid obstacle has no stress to show
        ax.plot(s, -arr("sigma_nn_passive"), "--", label=f"-sigma_nn {c.passive_body} (passive)")
        bx.plot(s, arr("sigma_nt_passive"), "--", label="passive")
    hertz = [h for h in run.hertz if h.pair == k]
    if hertz:
        # The exact profile placed at the centre the L2 error is measured from (the peak node
        # is off it by up to a node spacing).
        a, p0, sc = hertz[0].a_exact, hertz[0].p0_exact, hertz[0].s_centre
        xs = np.linspace(-a, a, 400)
        ax.plot(
            sc + xs,
            p0 * np.sqrt(np.clip(1 - (xs / a) ** 2, 0, None)),
            "r-",
            lw=0.8,
            alpha=0.7,
            label="exact Hertz (at the pressure's centre)",
        )
        ax.set_xlim(sc - 2.0 * a, sc + 2.0 * a)
    active = np.asarray(itf["active"], dtype=bool)
    zoom = None if hertz else contact_zoom(s, active)
    if zoom is not None:
        # No reference to place: zoom on the contact zone, as the Hertz charts do.
        ax.set_xlim(*zoom)
    if active.any():
        ax.axvspan(s[active].min(), s[active].max(), color="0.9", zorder=0, label="active set")
    frictional = mu > 0.0 and "shear" in itf and "status" in itf
    if frictional:
        _draw_friction(ax, s, arr("pressure"), arr("shear"), itf["status"], mu)
    # Traction scale of the chart: a curve uniform to round-off against it is drawn flat.
    scale = float(np.nanmax(np.abs(arr("pressure")), initial=0.0))
    for a_ in (ax, bx):
        a_.ticklabel_format(axis="y", useOffset=False)
        band = round_off_band(np.concatenate([ln.get_ydata() for ln in a_.get_lines()]), scale)
        if band is not None:
            a_.set_ylim(*band)
    units = run.units
    what = "normal traction, |shear|" if frictional else "normal traction"
    ax.set_ylabel(f"{what} ({units.stress}, compression > 0)")
    bx.set_ylabel(f"sigma_nt ({units.stress})")
    bx.set_xlabel(f"s, arc length along the active surface ({units.length})")
    on = f"obstacle '{c.passive}'" if c.obstacle is not None else c.passive
    ax.set_title(f"{run.scene} / {run.method.value}: pair {k}, {c.active} on {on}")
    for a_ in (ax, bx):
        a_.grid(alpha=0.3)
    ax.legend(fontsize=8)
    bx.legend(fontsize=8)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _draw_friction(
    ax: Any, s: np.ndarray, p: np.ndarray, shear: np.ndarray, status: Sequence[str], mu: float
) -> None:
    """|shear| and the Coulomb bound mu p along s, the stick zones shaded (one legend entry)."""
    ax.plot(s, np.abs(shear), "b.-", ms=3, lw=1, label="|shear| (multipliers)")
    ax.plot(s, mu * p, "g--", lw=1, label=f"mu p (mu = {mu:g})")
    for i, (lo, hi) in enumerate(stick_spans(s, status)):
        span = ax.axvspan(lo, hi, color="tab:blue", alpha=0.15, zorder=0)
        span.set_gid("stick")
        if i == 0:
            span.set_label("stick")


def plot_hertz_profiles(runs: Sequence[tuple[str, RunSummary]], path: Path) -> Path:
    """Chart the contact pressure of labelled runs against Hertz, and each one's difference.

    Every run needs the paper's interface block (built-in scenes) and a Hertz reference; the
    exact profile is the first run's. A label containing "uniform" is drawn dashed.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    first = runs[0][1]
    assert first.hertz, "the runs have no Hertz reference"
    a, p0 = first.hertz[0].a_exact, first.hertz[0].p0_exact
    fig, (top, bottom) = plt.subplots(
        2, 1, figsize=(8, 7), sharex=True, height_ratios=[2, 1], layout="constrained"
    )
    xs = np.linspace(0.0, 1.5 * a, 600)
    top.plot(xs, exact_pressure(xs, a, p0), "k-", lw=2.5, alpha=0.4, label="exact (Hertz)")
    for label, run in runs:
        assert run.interface is not None, f"{label}: the run has no interface block"
        x = np.asarray(run.interface["x"], dtype=float)
        p = np.asarray(run.interface["pressure"], dtype=float)
        style = "--" if "uniform" in label else "-"
        top.plot(x, p, style, marker=".", ms=3, lw=1, label=label)
        bottom.plot(x, p - exact_pressure(x, a, p0), style, marker=".", ms=3, lw=1)
    for ax in (top, bottom):
        ax.axvline(a, color="gray", lw=0.8, ls=":")
        ax.grid(alpha=0.3)
    top.set_ylabel(f"contact pressure ({first.units.stress})")
    bottom.set_ylabel("p - p_exact")
    bottom.set_xlabel(f"x ({first.units.length})")
    bottom.set_xlim(0.0, 1.5 * a)
    bottom.set_ylim(-0.2 * p0, 0.2 * p0)
    top.legend(fontsize=8)
    top.set_title(f"Contact pressure against Hertz (a = {a:.4g} {first.units.length})")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
