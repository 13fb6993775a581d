"""Write what a run produced: the JSON summary (atomically), XDMF fields, contact polylines."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from ..methods.solution import Solution
from .interface import INTERFACE_FIELDS
from .obstacles import from_summary, outline
from .stress import sigma_field


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
    for name, fn in (("displacement", sol.u), ("stress", s), ("E", sol.fields.E)):
        path = outdir / f"{name}.xdmf"
        with XDMFFile(msh.comm, path, "w") as xf:
            xf.write_mesh(msh)
            xf.write_function(fn)
        written.append(path)
    return written


def write_contact_surfaces(data: dict[str, Any], outdir: Path) -> list[Path]:
    """One VTK polyline per pair (open in ParaView): pressure, gap and the active flag.

    Each rigid obstacle also gets its outline, `obstacle_NAME.vtp`, at its reference
    position with its rigid motion as point data `displacement` (warp it like the body).
    """
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
        if "obstacle" in c:
            written.append(_write_outline(c, pts[:, :2], outdir))
    return written


def _write_outline(entry: dict[str, Any], near: np.ndarray, outdir: Path) -> Path:
    """The outline of the obstacle of a `contacts` entry as a VTK polyline."""
    import pyvista

    ob = from_summary(entry)
    xy = outline(ob, near)
    line = pyvista.lines_from_points(np.column_stack([xy, np.zeros(len(xy))]))
    line.point_data["displacement"] = np.tile([*ob.displacement, 0.0], (len(xy), 1))
    path = outdir / f"obstacle_{ob.name}.vtp"
    line.save(str(path))
    return path
