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
