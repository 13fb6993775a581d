"""Write what a run produced: the JSON summary (atomically), the fields, contact polylines."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from dolfinx import fem

from ..methods.solution import Solution
from ..scenes import Obstacle
from .interface import INTERFACE_FIELDS
from .obstacles import outline
from .records import RunSummary
from .stress import sigma_field, sigma_zz_field


def write_json(path: Path, data: dict[str, Any]) -> None:
    """Write JSON through a temporary file so a failed run never leaves half a file.

    The file gets the mode any new file gets (0666 less the umask: 0644 as a rule), not the
    temporary file's private 0600.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        json.dump(data, fh, indent=1, allow_nan=False)
        os.fchmod(fh.fileno(), 0o666 & ~_umask())
    os.replace(tmp, path)


def _umask() -> int:
    """The process's umask (read by setting it: there is no other way to read it)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def field_grid(sol: Solution, cell_fields: tuple[fem.Function, ...] = ()) -> Any:
    """This rank's owned cells as a pyvista grid: u (points), sigma and E (cells).

    `cell_fields`: more scalar DG0 functions written as cell data under their names (the
    error indicators `eta`).

    u is padded to 3 components and sigma to the 3 x 3 tensor (9 components; sigma_zz is
    nu (sxx + syy) in plane strain, 0 in plane stress, sigma_theta in axisymmetric),
    which is how ParaView reads vectors and tensors. The points are this rank's dofs (Q1:
    the vertices), ghosts included where an owned cell needs them.
    """
    import pyvista
    from dolfinx import plot

    V = sol.fields.V
    msh = V.mesh
    ncells = msh.topology.index_map(msh.topology.dim).size_local
    # vtk_mesh is a singledispatch function: mypy sees only its Mesh signature.
    topology, cell_types, x = plot.vtk_mesh(V)
    width = 5  # VTK_QUAD: a count and four points per cell
    grid = pyvista.UnstructuredGrid(topology[: width * ncells], cell_types[:ncells], x)
    u = sol.u.x.array.reshape(-1, 2)
    grid.point_data["u"] = np.column_stack([u, np.zeros(len(u))])
    sig = sigma_field(sol)
    # DG0 values by each cell's own dof (not assumed to equal the cell index).
    s = sig.x.array.reshape(-1, 4)[sig.function_space.dofmap.list[:ncells, 0]]
    tensor = np.zeros((ncells, 9))
    tensor[:, [0, 1, 3, 4]] = s
    szz = sigma_zz_field(sol)
    tensor[:, 8] = szz.x.array[szz.function_space.dofmap.list[:ncells, 0]]
    grid.cell_data["sigma"] = tensor
    E = sol.fields.E
    grid.cell_data["E"] = E.x.array[E.function_space.dofmap.list[:ncells, 0]]
    for f in cell_fields:
        grid.cell_data[f.name] = f.x.array[f.function_space.dofmap.list[:ncells, 0]]
    if sol.friction is not None:
        status, shear = contact_point_fields(sol)
        grid.point_data["contact_status"] = status
        grid.point_data["shear"] = shear
    return grid


# contact_status off the contact surfaces (docs/usage.md): the multiplier nodes carry
# contact/friction.Status (0 open, 1 stick, 2 slip).
NOT_CONTACT = -1


def contact_point_fields(sol: Solution) -> tuple[np.ndarray, np.ndarray]:
    """Each of this rank's points: its friction status and shear (frictional solves only).

    The points are V's local dof blocks (those of `field_grid`). A point that carries no
    multiplier gets status NOT_CONTACT and shear NaN; a node of two pairs shows the last.
    """
    fr = sol.friction
    assert fr is not None, "contact_point_fields needs a frictional solution"
    imap = sol.fields.V.dofmap.index_map
    gblocks = imap.local_to_global(np.arange(imap.size_local + imap.num_ghosts, dtype=np.int32))
    status = np.full(len(gblocks), NOT_CONTACT, dtype=np.int32)
    shear = np.full(len(gblocks), np.nan)
    order = np.argsort(gblocks)
    for pv in sol.pairs:
        at = np.searchsorted(gblocks, pv.gblock, sorter=order).clip(max=len(order) - 1)
        here = gblocks[order[at]] == pv.gblock  # the pair's nodes this rank holds
        status[order[at[here]]] = fr.status[pv.rows[here]]
        shear[order[at[here]]] = fr.shear[pv.rows[here]]
    return status, shear


def write_fields(
    sol: Solution, outdir: Path, cell_fields: tuple[fem.Function, ...] = ()
) -> list[Path]:
    """Write u, the DG0 stress tensor and E as fields.pvtu: one binary .vtu piece per rank.

    pyvista (pyvista.read) and ParaView open it. Measured at 400k DOFs (serial): 0.5 s,
    25 MB; DOLFINx's XDMF took 0.35 s but pyvista's XDMF reader crashes on it, its VTKFile
    (ASCII) 7.6 s, its VTKHDF names every array "u" and its VTX (.bp) pyvista cannot read.
    """
    comm = sol.scene.comm
    if comm.rank == 0:
        outdir.mkdir(parents=True, exist_ok=True)
    comm.Barrier()
    grid = field_grid(sol, cell_fields)
    piece = outdir / f"fields_p{comm.rank}.vtu"
    # lz4: faster than zlib for somewhat larger files (docs/scale.md#measured-constants).
    grid.save(str(piece), binary=True, compression="lz4")
    pieces = comm.gather(piece.name)
    main = outdir / "fields.pvtu"
    if comm.rank == 0:
        assert pieces is not None
        main.write_text(_pvtu(grid, pieces))
    comm.Barrier()
    return [main]


def _pvtu(grid: Any, pieces: list[str]) -> str:
    """The parallel file that names every piece and declares their arrays."""

    def arrays(data: Any) -> str:
        return "".join(
            f'<PDataArray type="{_vtk_type(data[k])}" Name="{k}" '
            f'NumberOfComponents="{1 if data[k].ndim == 1 else data[k].shape[1]}"/>'
            for k in data
        )

    return (
        '<?xml version="1.0"?>\n<VTKFile type="PUnstructuredGrid" version="1.0" '
        'byte_order="LittleEndian" header_type="UInt64">\n<PUnstructuredGrid GhostLevel="0">\n'
        f"<PPointData>{arrays(grid.point_data)}</PPointData>\n"
        f"<PCellData>{arrays(grid.cell_data)}</PCellData>\n"
        f'<PPoints><PDataArray type="{_vtk_type(grid.points)}" NumberOfComponents="3"/>'
        "</PPoints>\n"
        + "".join(f'<Piece Source="{p}"/>\n' for p in pieces)
        + "</PUnstructuredGrid>\n</VTKFile>\n"
    )


def _vtk_type(a: np.ndarray) -> str:
    """VTK's name of a numpy dtype (the pieces' arrays are float64 here)."""
    return {"float64": "Float64", "float32": "Float32", "int64": "Int64", "int32": "Int32"}[
        str(np.asarray(a).dtype)
    ]


def write_contact_surfaces(run: RunSummary, outdir: Path) -> list[Path]:
    """One VTK polyline per pair (open in ParaView): pressure, gap and the active flag.

    Each rigid obstacle also gets its outline, `obstacle_NAME.vtp`, at its reference
    position with its rigid motion as point data `displacement` (warp it like the body).
    """
    import pyvista

    written = []
    for k, c in enumerate(run.contacts):
        itf = c.interface
        pts = np.column_stack([itf["x"], itf["y"], np.zeros(len(itf["x"]))])
        line = pyvista.lines_from_points(pts) if len(pts) > 1 else pyvista.PolyData(pts)
        for key in INTERFACE_FIELDS[2:]:  # all but the coordinates
            line.point_data[key] = np.array([np.nan if v is None else v for v in itf[key]])
        line.point_data["active"] = np.asarray(itf["active"], dtype=np.int8)
        path = outdir / f"contact{k}_{c.active}.vtp"
        line.save(str(path))
        written.append(path)
        if c.obstacle is not None:
            written.append(_write_outline(c.obstacle, pts[:, :2], outdir))
    return written


def _write_outline(ob: Obstacle, near: np.ndarray, outdir: Path) -> Path:
    """The outline of an obstacle as a VTK polyline."""
    import pyvista

    xy = outline(ob, near)
    line = pyvista.lines_from_points(np.column_stack([xy, np.zeros(len(xy))]))
    line.point_data["displacement"] = np.tile([*ob.displacement, 0.0], (len(xy), 1))
    path = outdir / f"obstacle_{ob.name}.vtp"
    line.save(str(path))
    return path
