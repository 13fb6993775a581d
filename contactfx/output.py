"""Write what a run produced: the JSON summary (atomically), XDMF fields and interface figures."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from .postprocess import sigma_field
from .problem import Solution


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
    for key, style, label in (("sigma_yy_1", "-", "sigma_yy body 1"),
                              ("sigma_yy_2", "--", "sigma_yy body 2")):
        vals = np.array([np.nan if v is None else v for v in itf[key]], dtype=float)
        ax.plot(x, vals, style, label=label)
    ax.plot(x, -np.asarray(itf["pressure"]), ":", label="-pressure (multipliers)")
    if "hertz" in data:
        # Zoom on the contact zone and show the exact plane-strain Hertz profile.
        a, p0 = data["hertz"]["a_exact"], data["hertz"]["p0_exact"]
        xs = np.linspace(0.0, 2.0 * a, 400)
        ax.plot(xs, -p0 * np.sqrt(np.clip(1 - (xs / a) ** 2, 0.0, None)), "k-", lw=0.8,
                alpha=0.6, label="-pressure, exact 2D Hertz")
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
