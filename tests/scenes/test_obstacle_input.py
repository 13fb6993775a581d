"""Rigid obstacles at the edges of the tool: scene files, bad input, output files, solvers, MPI."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, cli

from contactfx import InputError, Obstacle, load_scene_file, scene_from_gmsh, solve
from contactfx.results.interface import u_at_points
from contactfx.scenes import Dirichlet, parse_scene_file

DEMO_SCENES = ROOT / "demos" / "scenes"
MESHES = ROOT / "meshes"
INDENTER = DEMO_SCENES / "rigid_indenter.toml"
HEAD = """mesh = "rigid_block.geo"
[bodies.block]
E = 7000.0
nu = 0.3
[[dirichlet]]
group = "symmetry"
ux = 0.0
[[dirichlet]]
group = "base"
uy = 0.0
[[obstacle]]
"""
CIRCLE = 'name = "ind"\nshape = "circle"\ncenter = [0.0, 20.0]\nradius = 20.0\nsurface = "top"\n'


def scene_file(tmp_path: Path, obstacle: str) -> Path:
    """A scene file next to a copy of rigid_block.geo with one [[obstacle]] table."""
    shutil.copy(MESHES / "rigid_block.geo", tmp_path / "rigid_block.geo")
    path = tmp_path / "s.toml"
    path.write_text(HEAD + obstacle)
    return path


@pytest.mark.parametrize(
    ("obstacle", "needle"),
    [
        ('shape = "sphere"\nsurface = "top"\n', "shape must be one of 'circle', 'plane'"),
        (CIRCLE.replace("20.0\nsurface", "-1.0\nsurface"), "radius must be > 0"),
        (CIRCLE.replace("radius = 20.0\n", ""), "missing key 'radius'"),
        (CIRCLE + "normal = [0.0, 1.0]\n", "unknown key 'normal'"),
        (CIRCLE.replace("[0.0, 20.0]", "[0.0]"), "expected a vector"),
        (CIRCLE + "displacement = [0.0, nan]\n", "finite"),
        ('shape = "plane"\npoint = [0.0, 0.0]\nnormal = [0.0, 0.0]\nsurface = "top"\n', "zero"),
        ('shape = "polyline"\npoints = [[0.0, 0.0]]\nsurface = "top"\n', "two or more"),
        ('shape = "polyline"\npoints = [[0, 0], [1, 0], [0.5, 0]]\nsurface = "top"\n', "folds"),
    ],
)
def test_bad_obstacle_tables(tmp_path: Path, obstacle: str, needle: str) -> None:
    """Each bad [[obstacle]] table is an InputError naming it, before any mesh is read."""
    with pytest.raises(InputError, match=needle):
        parse_scene_file(scene_file(tmp_path, obstacle))


def test_scene_file_and_python_api_agree(tmp_path: Path) -> None:
    """[[obstacle]] and Obstacle(...) through scene_from_gmsh make the same scene and answer."""
    parsed = parse_scene_file(INDENTER)[1].obstacles
    made = Obstacle("indenter", "circle", "top", center=(0, 20), radius=20, displacement=(0, -0.05))
    assert parsed == (made,)
    scene = scene_from_gmsh(
        MESHES / "rigid_block.geo",
        bodies={"block": {"E": 7000.0, "nu": 0.3}},
        dirichlet=[Dirichlet("symmetry", ux=0.0), Dirichlet("base", uy=0.0)],
        obstacles=[made],
    )
    sol_a = solve(scene, "nts")
    sol_b = solve(load_scene_file(INDENTER), "nts")
    np.testing.assert_array_equal(u_at_points(sol_a), u_at_points(sol_b))


@pytest.mark.parametrize(
    ("obstacle", "needle"),
    [
        ('shape = "cube"\nsurface = "top"\n', "shape must be one of"),
        (CIRCLE.replace("20.0\nsurface", "0.0\nsurface"), "radius must be > 0 (got 0.0)"),
        ('shape = "polyline"\npoints = [[0, 0], [0, 0]]\nsurface = "top"\n', "coincide"),
        (CIRCLE.replace('"top"', '"block"'), "'block' is a surface group, a curve group is"),
        (CIRCLE.replace("[0.0, 20.0]", "[0.0, 19.99]"), "obstacle 'ind' penetrates body"),
        (
            'shape = "plane"\npoint = [0.0, 1.0]\nnormal = [0.0, 1.0]\nsurface = "top"\n',
            "does not face obstacle 'obstacle0'",
        ),
    ],
    ids=["shape", "radius", "polyline", "not-a-curve", "penetration", "facing"],
)
def test_bad_obstacles_cli_one_line(tmp_path: Path, obstacle: str, needle: str) -> None:
    """Unknown shape, radius <= 0, degenerate polyline, a surface group that is not a curve,
    an initial penetration, a plane whose normal points away from the body: exit 2, one
    line, no traceback, no JSON."""
    out = tmp_path / "r.json"
    proc = cli("solve", str(scene_file(tmp_path, obstacle)), "--json", str(out))
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    assert not out.exists()


def test_out_writes_the_obstacle(tmp_path: Path) -> None:
    """--out: the obstacle's outline as its own VTK polyline (at its reference position, its
    motion as point data), the pair's surface, its chart and the fields picture."""
    import pyvista

    out, js = tmp_path / "out", tmp_path / "r.json"
    proc = cli("solve", str(INDENTER), "--method", "nts", "--json", str(js), "--out", str(out))
    assert proc.returncode == 0, proc.stderr
    data = json.loads(js.read_text())
    c = data["contacts"][0]
    assert (c["active"], c["passive"], c["active_body"]) == ("top", "indenter", "block")
    assert c["obstacle"] == {
        "shape": "circle",
        "center": [0.0, 20.0],
        "radius": 20.0,
        "displacement": [0.0, -0.05],
    }
    assert all(v is None for v in c["interface"]["sigma_nn_passive"])
    assert c["balance"] < 1e-12
    line = pyvista.read(out / "obstacle_indenter.vtp")
    r = np.linalg.norm(np.asarray(line.points)[:, :2] - [0.0, 20.0], axis=1)
    np.testing.assert_allclose(r, 20.0, rtol=1e-12)
    assert line.n_points > 700
    np.testing.assert_allclose(line.point_data["displacement"][:, :2], [[0.0, -0.05]] * len(r))
    for name in ("contact0_top.vtp", "interface_pair0.png", "fields.png"):
        assert (out / name).stat().st_size > 0, name


def test_solvers_and_methods_that_refuse_obstacles() -> None:
    """Schwarz refuses obstacles; the condensed solver takes NTS against a circle (its rows
    touch their own node only), dual mortar against it (the circle's normal turns within a
    segment: neighbouring pivots couple, linalg/pivots.py) and dual mortar against a straight
    polyline (the punch's face), each to MUMPS' answer."""
    scene = load_scene_file(INDENTER)
    with pytest.raises(InputError, match="schwarz does not take rigid obstacles"):
        solve(scene, "schwarz")
    punch = load_scene_file(DEMO_SCENES / "rigid_punch.toml")
    for s, options in ((scene, {}), (scene, {"basis": "dual"}), (punch, {"basis": "dual"})):
        method = "mortar" if options else "nts"
        direct = solve(s, method, **options)
        condensed = solve(s, method, solver="condensed", **options)
        ua, ub = u_at_points(direct), u_at_points(condensed)
        assert np.abs(ub[:, 2:] - ua[:, 2:]).max() < 1e-6 * np.abs(ua[:, 2:]).max()
