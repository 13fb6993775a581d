"""Every file `solve --out` writes opens with the installed pyvista, in a fresh process.

pyvista's XDMF reader (VTK's XDMF2) crashed (SIGSEGV) on the XDMF files written before; the
reader runs in a child process here so that a crash is a failed test, not a dead pytest.
The fields are checked against the exact solution of the stacked-blocks scene: under p = 10
on top, ux = 0 on the left edges and frictionless flat interfaces, every block is in
uniaxial plane-strain compression, sigma_yy = -p and sigma_xx = sigma_xy = 0, and
u = (-nu (1 + nu) sigma_yy x / E, u_y piecewise linear in y) is exact for Q1 and mortar.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import ENV, ROOT, cli, run_cli

STACK = ROOT / "tests" / "scenes" / "stacked_blocks.toml"
P, H = 10.0, 1.0
MATERIALS = [(7000.0, 0.3), (3500.0, 0.25), (7000.0, 0.3), (3500.0, 0.25)]  # b1 .. b4

READER = """
import sys
import numpy as np
import pyvista
for path, dump in zip(sys.argv[1::2], sys.argv[2::2]):
    print(path, flush=True)  # the last line printed names the file a crash happened on
    data = pyvista.read(path)
    if isinstance(data, pyvista.MultiBlock):
        data = data.combine()
    out = {"n_points": data.n_points, "n_cells": data.n_cells}
    if isinstance(data, pyvista.UnstructuredGrid) and data.n_cells:
        out["points"] = np.asarray(data.points)
        out["centres"] = np.asarray(data.cell_centers().points)
        # Each point's cell centre: bodies share no point, so it tells the point's body.
        conn = np.asarray(data.cells).reshape(-1, 5)[:, 1:]
        owner = np.full(data.n_points, np.nan)
        owner[conn.ravel()] = np.repeat(out["centres"][:, 1], 4)
        out["point_cell_y"] = owner
    for where, arrays in (("point", data.point_data), ("cell", data.cell_data)):
        for name in arrays.keys():
            out[f"{where}:{name}"] = np.asarray(arrays[name])
    np.savez(dump, **out)
"""


def read_in_child(paths: list[Path], tmp: Path) -> dict[str, dict[str, np.ndarray]]:
    """pyvista.read of every path in one fresh python: their arrays (a crash fails the test)."""
    dumps = [tmp / f"read{k}.npz" for k in range(len(paths))]
    args = [str(a) for pair in zip(paths, dumps, strict=True) for a in pair]
    proc = subprocess.run(
        [sys.executable, "-c", READER, *args], env=ENV, capture_output=True, text=True, timeout=300
    )
    last = proc.stdout.strip().splitlines()[-1:] or ["(none)"]
    assert proc.returncode == 0, (
        f"pyvista.read exit {proc.returncode} on {last[0]}: {proc.stderr[-1500:]}"
    )
    out = {}
    for path, dump in zip(paths, dumps, strict=True):
        with np.load(dump) as z:
            out[path.name] = dict(z)
    return out


def exact_u(x: np.ndarray, cell_y: np.ndarray) -> np.ndarray:
    """The exact displacement (n, 2) at points x, each of the block of its cell (centre y)."""
    eyy = [(1 - nu**2) * -P / E for E, nu in MATERIALS]
    exx = [-nu * (1 + nu) * -P / E for E, nu in MATERIALS]
    k = np.clip(np.floor(cell_y / H).astype(int), 0, 3)
    base = np.concatenate([[0.0], np.cumsum(np.array(eyy) * H)])
    uy = base[k] + np.array(eyy)[k] * (x[:, 1] - k * H)
    return np.column_stack([np.array(exx)[k] * x[:, 0], uy])


def solve_with_out(tmp: Path, ranks: int) -> tuple[Path, dict]:
    out, js = tmp / "out", tmp / "r.json"
    args = ("solve", str(STACK), "--out", str(out), "--json", str(js))
    proc = cli(*args) if ranks == 1 else run_cli(*args, ranks=ranks)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return out, json.loads(js.read_text())


def check_fields(f: dict[str, np.ndarray], data: dict) -> None:
    """fields.pvtu: every cell once, u at the points, sigma and E per cell, all exact."""
    assert f["n_cells"] == data["elements"]
    u, sig, E = f["point:u"], f["cell:sigma"], f["cell:E"]
    assert u.shape == (f["n_points"], 3) and sig.shape == (f["n_cells"], 9)
    assert E.shape == (f["n_cells"],)
    block = np.clip(np.floor(f["centres"][:, 1] / H).astype(int), 0, 3)
    np.testing.assert_array_equal(E, np.array([m[0] for m in MATERIALS])[block])
    tensor = sig.reshape(-1, 3, 3)
    np.testing.assert_allclose(tensor[:, 1, 1], -P, atol=1e-8 * P)
    np.testing.assert_allclose(tensor[:, :2, :2].reshape(-1, 4)[:, :3], 0.0, atol=1e-8 * P)
    # Plane strain: sigma_zz = nu (sxx + syy) = -nu P (it was written 0 before).
    nus = np.array([m[1] for m in MATERIALS])[block]
    np.testing.assert_allclose(tensor[:, 2, 2], -nus * P, atol=1e-8 * P)
    np.testing.assert_array_equal(tensor[:, 2, :2], 0.0)
    used = np.isfinite(f["point_cell_y"])  # (a piece may hold a ghost point no cell uses)
    assert used.sum() >= f["n_points"] - 200
    ue = exact_u(f["points"][used, :2], f["point_cell_y"][used])
    np.testing.assert_allclose(u[used, :2], ue, atol=1e-8 * np.abs(ue).max())
    np.testing.assert_array_equal(u[:, 2], 0.0)


def open_every_file(out: Path, tmp: Path) -> dict[str, dict[str, np.ndarray]]:
    """pyvista.read opens every file in `out` (the charts too) in a fresh process."""
    got = read_in_child(sorted(out.iterdir()), tmp)
    for name, arrays in got.items():
        assert arrays["n_points"] > 0, name
    return got


@pytest.mark.serial
def test_every_out_file_opens_with_pyvista_and_holds_u_sigma_e(tmp_path: Path) -> None:
    """Serial: fields.pvtu (one piece), one .vtp per pair and the charts; all open."""
    out, data = solve_with_out(tmp_path, 1)
    got = open_every_file(out, tmp_path)
    assert "fields.pvtu" in got and "fields_p0.vtu" in got
    assert not [n for n in got if n.endswith((".xdmf", ".h5"))]
    assert sum(n.endswith(".vtp") for n in got) == len(data["contacts"]) == 3
    assert sum(n.endswith(".png") for n in got) == 3  # one chart per pair
    check_fields(got["fields.pvtu"], data)
    assert "point:contact_status" not in got["fields.pvtu"]  # frictionless: no status field
    vtp = got["contact0_b2_bottom.vtp"]
    np.testing.assert_allclose(vtp["point:pressure"][vtp["point:active"] == 1], P, rtol=1e-8)


@pytest.mark.mpi
def test_two_ranks_write_one_piece_each_and_the_same_fields(tmp_path: Path) -> None:
    """mpirun -n 2: a piece per rank under fields.pvtu; every cell once, values exact."""
    out, data = solve_with_out(tmp_path, 2)
    got = open_every_file(out, tmp_path)
    assert {"fields.pvtu", "fields_p0.vtu", "fields_p1.vtu"} <= set(got)
    check_fields(got["fields.pvtu"], data)


@pytest.mark.parametrize("umask", [0o022, 0o077])
def test_the_json_gets_the_mode_of_any_new_file(tmp_path: Path, umask: int) -> None:
    """JSON files were 0600 (the temporary file's mode) where every other file is 0644."""
    import os

    from contactfx.results.files import write_json

    saved = os.umask(umask)
    try:
        write_json(tmp_path / "r.json", {"a": 1})
        (tmp_path / "other.txt").write_text("x")
    finally:
        os.umask(saved)
    mode = (tmp_path / "r.json").stat().st_mode & 0o777
    assert mode == 0o666 & ~umask == (tmp_path / "other.txt").stat().st_mode & 0o777
    assert json.loads((tmp_path / "r.json").read_text()) == {"a": 1}


@pytest.mark.serial
def test_a_frictional_solve_writes_each_contact_nodes_status_and_shear(tmp_path: Path) -> None:
    """fields.pvtu of a pushed block (mortar, mu = 0.3): `contact_status` is -1 off the
    contact surface and each multiplier node's Status (0 open, 1 stick, 2 slip) on it,
    `shear` its tangential multiplier; the push leaves both stick and slip nodes."""
    from contactfx import ContactPair, scene_from_gmsh, solve
    from contactfx.contact.friction import Status
    from contactfx.results.files import write_fields
    from contactfx.scenes import Dirichlet, Material, Pressure

    scene = scene_from_gmsh(
        ROOT / "tests" / "scenes" / "friction_blocks.geo",
        bodies={"base": Material(1000.0, 0.3), "block": Material(1000.0, 0.3)},
        contacts=[ContactPair("block_bottom", "base_top", mu=0.3)],
        dirichlet=[Dirichlet("base_bottom", ux=0.0, uy=0.0), Dirichlet("block_top", ux=0.002)],
        loads=[Pressure("block_top", P)],
    )
    sol = solve(scene, "mortar")
    fr = sol.friction
    assert fr is not None
    assert (fr.status == Status.STICK).any() and (fr.status == Status.SLIP).any()
    write_fields(sol, tmp_path / "out")
    f = read_in_child([tmp_path / "out" / "fields.pvtu"], tmp_path)["fields.pvtu"]
    status, shear = f["point:contact_status"], f["point:shear"]
    on = status >= 0
    assert on.sum() == len(fr.status)  # one point per multiplier node, every other -1
    assert set(np.unique(status[~on])) == {-1} and np.isnan(shear[~on]).all()
    for k in (Status.OPEN, Status.STICK, Status.SLIP):
        assert (status == k).sum() == (fr.status == k).sum()
    for xy, st, q in zip(sol.layout.x, fr.status, fr.shear, strict=True):
        here = on & (np.abs(f["points"][:, :2] - xy).max(axis=1) < 1e-12)
        assert here.sum() == 1 and status[here][0] == st
        assert shear[here][0] == pytest.approx(q, abs=1e-12 * P)
