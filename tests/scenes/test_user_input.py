"""What a new user hit: a polyline walked the wrong way, a directory as a mesh path, the
Python API's `bodies=` of the wrong type, and advice that names the API's classes too."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, cli

from contactfx import Obstacle, SolveRequest, load_scene_file, run_scene, scene_from_gmsh
from contactfx.errors import GeometryError, InputError

SCENES = ROOT / "tests" / "scenes"
X0 = np.array([-0.6062177826491071, -0.35])  # a point of rigid_floor.geo's inclined floor
T = np.array([0.8660254037844386, 0.5])  # the floor's direction; the block lies on its left


def polyline_floor(tmp_path: Path, points: list[list[float]]) -> Path:
    """rigid_floor.toml with its plane replaced by a polyline through `points`."""
    toml = (SCENES / "rigid_floor.toml").read_text()
    head, _, tail = toml.partition("[[obstacle]]")
    _, _, rest = tail.partition("\n\n")
    pts = ", ".join(f"[{float(x)!r}, {float(y)!r}]" for x, y in points)
    obstacle = (
        f'[[obstacle]]\nname = "floor"\nshape = "polyline"\npoints = [{pts}]\n'
        'surface = "bottom"\n\n'
    )
    (tmp_path / "rigid_floor.geo").write_text((SCENES / "rigid_floor.geo").read_text())
    path = tmp_path / "floor.toml"
    path.write_text(head + obstacle + rest)
    return path


@pytest.mark.serial
def test_polyline_walked_the_wrong_way_says_to_reverse_it(tmp_path: Path) -> None:
    """The obstacle lies on the left of its points: walked along the floor's direction it is
    on the block's side. The refusal says so and how to fix it; reversed, the patch test."""
    ends = [X0 - 10 * T, X0 + 10 * T]
    wrong = polyline_floor(tmp_path, [list(p) for p in ends])
    with pytest.raises(GeometryError, match="reverse its points"):
        run_scene(load_scene_file(wrong), SolveRequest.parse("mortar"))
    right = polyline_floor(tmp_path, [list(p) for p in ends[::-1]])
    _, run = run_scene(load_scene_file(right), SolveRequest.parse("mortar"))
    assert run.patch is not None and run.patch.max < 1e-8


@pytest.mark.serial
def test_mesh_path_that_is_a_directory(tmp_path: Path) -> None:
    """A directory is not 'a file that does not exist': say what it is."""
    (tmp_path / "block.geo").mkdir()
    scene = tmp_path / "dir.toml"
    toml = (SCENES / "rigid_floor.toml").read_text()
    scene.write_text(toml.replace("rigid_floor.geo", "block.geo"))
    proc = cli("solve", str(scene))
    assert proc.returncode == 2, proc.stderr
    assert "is a directory" in proc.stderr and "does not exist" not in proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("bodies", "expected"),
    [
        (["block"], "bodies: expected a dict of body names"),
        ({}, "bodies: expected a dict of body names"),
        ({"block": 3500.0}, r"bodies\['block'\]: expected a Material or a dict"),
        ({"block": {"E": 1.0}}, "E and nu are required"),
    ],
)
def test_api_bodies_of_the_wrong_type_is_one_clear_error(bodies: object, expected: str) -> None:
    normal = (-0.5, 0.8660254037844386)
    floor = Obstacle("floor", "plane", "bottom", point=(float(X0[0]), float(X0[1])), normal=normal)
    with pytest.raises(InputError, match=expected):
        scene_from_gmsh(SCENES / "rigid_floor.geo", bodies=bodies, obstacles=[floor])


@pytest.mark.serial
def test_advice_names_the_python_classes_too() -> None:
    """A Python user has no [[dirichlet]] table: the advice names Dirichlet and Obstacle."""
    from contactfx.errors import SingularSystemError

    with pytest.raises(SingularSystemError) as err:
        run_scene(
            load_scene_file(SCENES / "disk_between_plates.toml"), SolveRequest.parse("mortar")
        )
    assert "[[dirichlet]]" in str(err.value) and "Dirichlet in Python" in str(err.value)


def scene_copy(tmp_path: Path, name: str, old: str = "", new: str = "") -> Path:
    """tests/scenes/NAME with its mesh path made absolute and `old` replaced by `new`."""
    text = (SCENES / name).read_text()
    geo = text.split('mesh = "')[1].split('"')[0]
    text = text.replace(f'mesh = "{geo}"', f'mesh = "{SCENES / geo}"')
    assert old in text, old
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1))
    return path


def one_line_refusal(*args: str) -> str:
    """The CLI's one stderr line for a refused input (exit 2, no traceback)."""
    proc = cli(*args)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr[-3000:]
    assert "Traceback" not in proc.stderr and lines[0].startswith("contactfx: error: ")
    return lines[0]


@pytest.mark.serial
def test_a_modulus_no_units_allow_is_refused_at_input(tmp_path: Path) -> None:
    """E = 1e308 ended in a traceback from scipy's linprog (load_paths): now refused when
    the scene is read, naming the body, the value and the range, nothing written."""
    path = scene_copy(tmp_path, "stacked_blocks.toml", "E = 7000.0", "E = 1e308")
    out = tmp_path / "r.json"
    line = one_line_refusal("solve", str(path), "--json", str(out))
    assert "Young's modulus E = 1e+308 is outside 1e-10 to 1e+15" in line and "units" in line
    assert not out.exists()
    assert "body 1: Young's modulus E = 1e+300" in one_line_refusal(
        "solve", "blocks", "--E1", "1e300"
    )


@pytest.mark.serial
def test_load_paths_refuses_an_overflowed_system_in_one_line() -> None:
    """Past the input check (a Material made in Python and put into a scene as it is): the
    assembled load is not finite; load_paths says so instead of HiGHS's ValueError."""
    from dataclasses import replace

    from contactfx import Material

    scene = load_scene_file(SCENES / "stacked_blocks.toml")
    first = replace(scene.bodies[0], material=Material(1e308, 0.3))
    scene = replace(scene, bodies=(first, *scene.bodies[1:]))
    with pytest.raises(InputError, match="overflows double precision"):
        run_scene(scene, SolveRequest.parse("mortar"))


@pytest.mark.serial
@pytest.mark.parametrize(
    ("line", "said"),
    [
        ("model = 3", "model: expected one of plane_strain, plane_stress, axisymmetric (a string)"),
        ("units = { length = 5 }", "units.length: expected a unit name (a string), got 5"),
        ("name = 3", "name: expected a name (a string), got 3"),
        ("mesh = 3", "mesh: expected a mesh file path (a string), got 3"),
    ],
)
def test_a_top_level_key_of_the_wrong_type_says_what_it_wanted(
    tmp_path: Path, line: str, said: str
) -> None:
    """These said "expected a group name (a string)", which none of them is."""
    path = scene_copy(tmp_path, "stacked_blocks.toml")
    text = path.read_text()
    if line.startswith("mesh"):
        text = "\n".join(ln for ln in text.splitlines() if not ln.startswith("mesh ="))
    path.write_text(f"{line}\n{text}")
    refusal = one_line_refusal("solve", str(path))
    assert said in refusal and "group name" not in refusal


def test_the_scene_file_reference_says_what_each_top_level_key_wants() -> None:
    """The generated reference repeated "a group name" for mesh, name and model."""
    from contactfx.scenes.schema import reference_markdown

    rows = {ln.split("|")[1].strip(): ln for ln in reference_markdown().splitlines() if "| `" in ln}
    assert "mesh file path" in rows["`mesh`"] and "expected a name" in rows["`name`"]
    assert "plane_strain, plane_stress, axisymmetric (a string)" in rows["`model`"]
    for key in ("`mesh`", "`name`", "`model`"):
        assert "group name" not in rows[key]
    assert "group name" in rows["`active`"]


@pytest.mark.serial
def test_a_load_that_would_overflow_is_refused_naming_the_load(tmp_path: Path) -> None:
    """p = 1e300 ended in "linear solve (gmres) did not converge ... DIVERGED_NANORINF" and
    --P 1e300 in a mesher's message naming no option: each now names its load, before
    anything is meshed or solved."""
    path = scene_copy(tmp_path, "stacked_blocks.toml", "p = 10.0", "p = 1e300")
    line = one_line_refusal("solve", str(path))
    assert "load on 'b4_top': p = 1e+300 exceeds the largest Young's modulus" in line
    line = one_line_refusal("solve", "hertz", "--P", "1e300")
    assert "P = 1e+300 gives a Hertz contact half-width a = 1.44e+149 beyond the radius" in line
    line = one_line_refusal("solve", "blocks", "--p", "1e300")
    assert "p = 1e+300 exceeds the larger Young's modulus 70000" in line


@pytest.mark.serial
def test_an_interference_beyond_the_models_size_is_refused(tmp_path: Path) -> None:
    """interference = 1e6 on rings of outer radius 3 was solved without a word."""
    path = scene_copy(
        tmp_path, "shrink_fit_touching.toml", "interference = 0.002", "interference = 1e6"
    )
    line = one_line_refusal("solve", str(path))
    assert "interference = 1e+06 is more than 0.1 of the model's size 3" in line, line


@pytest.mark.serial
def test_a_cooled_body_between_walls_blames_its_thermal_strain(tmp_path: Path) -> None:
    """heated_block.toml cooled (dT = -100) shrinks off its walls: refused as "the load
    pulls the bodies apart", where the scene applies no load."""
    path = scene_copy(tmp_path, "heated_block.toml", "dT = 100.0", "dT = -100.0")
    line = one_line_refusal("solve", str(path))
    assert "the thermal strain (alpha dT = -0.001 in 'block': it shrinks) pulls" in line, line
    assert "(no load is applied)" in line and "the load pulls" not in line
