"""Write what a run produced: the JSON summary (atomically), XDMF fields and interface figures."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from .postprocess import INTERFACE_FIELDS, sigma_field
from .solution import Solution


def write_json(path: Path, data: dict[str, Any]) -> None:
    """Write JSON through a temporary file so a failed run never leaves half a file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump(data, fh, indent=1, allow_nan=False)
    os.replace(tmp, path)


def write_fields(sol: Solution, outdir: Path) -> list[Path]:
    """Write u, the DG0 stress tensor and E as XDMF (open in ParaView)."""
    from dolfinx.io import XDMFFile

    outdir.mkdir(parents=True, exist_ok=True)
    msh = sol.scene.mesh
    s = sigma_field(sol)
    written = []
    for name, fn in (("displacement", sol.u), ("stress", s), ("E", sol.elasticity.E)):
        path = outdir / f"{name}.xdmf"
        with XDMFFile(msh.comm, path, "w") as xf:
            xf.write_mesh(msh)
            xf.write_function(fn)
        written.append(path)
    return written


def plot_interface(data: dict[str, Any], path: Path, title: str = "") -> Path:
    """Chart sigma_yy of both bodies and the contact pressure along the contact line."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    itf = data["interface"]
    x = np.asarray(itf["x"])
    fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
    for key, style, label in (
        ("sigma_yy_1", "-", "sigma_yy body 1"),
        ("sigma_yy_2", "--", "sigma_yy body 2"),
    ):
        vals = np.array([np.nan if v is None else v for v in itf[key]], dtype=float)
        ax.plot(x, vals, style, label=label)
    ax.plot(x, -np.asarray(itf["pressure"]), ":", label="-pressure (multipliers)")
    if "hertz" in data:
        # Zoom on the contact zone and show the exact plane-strain Hertz profile.
        a, p0 = data["hertz"]["a_exact"], data["hertz"]["p0_exact"]
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
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("MPa")
    ax.set_title(title or f"{data['scene']} / {data['method']}: contact line")
    ax.grid(alpha=0.3)
    ax.legend()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def write_contact_surfaces(data: dict[str, Any], outdir: Path) -> list[Path]:
    """One VTK polyline per pair (open in ParaView): pressure, gap and the active flag."""
    import pyvista

    written = []
    for k, c in enumerate(data["contacts"]):
        itf = c["interface"]
        pts = np.column_stack([itf["x"], itf["y"], np.zeros(len(itf["x"]))])
        line = pyvista.lines_from_points(pts) if len(pts) > 1 else pyvista.PolyData(pts)
        for key in INTERFACE_FIELDS[2:]:  # all but the coordinates
            line.point_data[key] = np.array([np.nan if v is None else v for v in itf[key]])
        line.point_data["active"] = np.asarray(itf["active"], dtype=np.int8)
        path = outdir / f"contact{k}_{c['active']}.vtp"
        line.save(str(path))
        written.append(path)
    return written


def plot_pair(data: dict[str, Any], k: int, path: Path) -> Path:
    """Chart pair k along s: pressure, -sigma_nn and sigma_nt of both bodies (and Hertz)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    c = data["contacts"][k]
    itf = c["interface"]

    def arr(key: str) -> np.ndarray:
        return np.array([np.nan if v is None else v for v in itf[key]], dtype=float)

    s = arr("s")
    fig, (ax, bx) = plt.subplots(
        2, 1, figsize=(7, 5.5), sharex=True, layout="constrained", height_ratios=(3, 1.3)
    )
    ax.plot(s, arr("pressure"), "k.-", ms=3, lw=1, label="pressure (multipliers)")
    ax.plot(s, -arr("sigma_nn_active"), "-", label=f"-sigma_nn {c['active_body']} (active)")
    ax.plot(s, -arr("sigma_nn_passive"), "--", label=f"-sigma_nn {c['passive_body']} (passive)")
    bx.plot(s, arr("sigma_nt_active"), "-", label="active")
    bx.plot(s, arr("sigma_nt_passive"), "--", label="passive")
    hertz = [
        h
        for h in data.get("hertz_pairs", [data["hertz"]] if "hertz" in data else [])
        if h.get("pair") == k
    ]
    if hertz:
        # The exact profile against the distance from the centre, placed at the computed peak.
        h = hertz[0]
        a, p0 = h["a_exact"], h["p0_exact"]
        sc = float(s[int(np.nanargmax(arr("pressure")))])
        xs = np.linspace(-a, a, 400)
        ax.plot(
            sc + xs,
            p0 * np.sqrt(np.clip(1 - (xs / a) ** 2, 0, None)),
            "r-",
            lw=0.8,
            alpha=0.7,
            label="exact Hertz (placed at the peak)",
        )
        ax.set_xlim(sc - 2.0 * a, sc + 2.0 * a)
    active = np.asarray(itf["active"], dtype=bool)
    if active.any():
        ax.axvspan(s[active].min(), s[active].max(), color="0.9", zorder=0, label="active set")
    ax.set_ylabel("normal traction (compression > 0)")
    bx.set_ylabel("sigma_nt")
    bx.set_xlabel("s, arc length along the active surface")
    ax.set_title(f"{data['scene']} / {data['method']}: pair {k}, {c['active']} on {c['passive']}")
    for a_ in (ax, bx):
        a_.grid(alpha=0.3)
    ax.legend(fontsize=8)
    bx.legend(fontsize=8)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
