"""`[[reference]] type = "cattaneo"`: Cattaneo-Mindlin computed for a scene file's own pair.

The closed form and its error measures are tested in test_friction_references.py and against
the solver in tests/methods/test_friction.py (the shear's L2 error pinned at 3.258 % on the
mirrored cylinders); here the plumbing: the scene file's table, the JSON's `cattaneo` keys at
the top level and in every step, the terminal lines, the warning where the approach slipped or
the load path is one step, and the tables refused in one line.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import ROOT, cli

from contactfx import CattaneoReference, ContactPair, scene_from_gmsh
from contactfx.errors import InputError
from contactfx.scenes import Dirichlet, Material

SCENES = ROOT / "tests" / "scenes"
SCENE = SCENES / "cattaneo_cylinders.toml"
KEYS = {"a_exact", "c_exact", "c", "c_error_cells", "shear_l2", "slip_law", "P", "Q", "mu"}


def variant(tmp_path: Path, old: str, new: str) -> Path:
    """cattaneo_cylinders.toml with `old` replaced by `new` (beside a copy of its mesh)."""
    toml = SCENE.read_text()
    assert old in toml
    (tmp_path / "cattaneo_cylinders.geo").write_text(
        (SCENES / "cattaneo_cylinders.geo").read_text()
    )
    path = tmp_path / "variant.toml"
    path.write_text(toml.replace(old, new, 1))
    return path


def test_cattaneo_reference_in_the_json_and_on_the_terminal(tmp_path: Path) -> None:
    """The mirrored cylinders pressed, then pushed: the JSON's `cattaneo` is the last step's
    (the shear's L2 error the solver test pins, c within 1.5 cells, |shear| = mu p on slip
    nodes), every step has one, the pressed step carries no push and a shear under 5 % of
    mu p (no warning), and the terminal prints each step's line and the last one's."""
    out = tmp_path / "run.json"
    proc = cli("solve", str(SCENE), "--method", "mortar", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    (top,) = data["cattaneo"]
    assert KEYS <= set(top)
    assert top["shear_l2"] == pytest.approx(0.03258, rel=1e-3)
    assert top["c_error_cells"] < 1.5 and top["slip_law"] < 1e-6
    assert 0.3 < top["Q"] / (top["mu"] * top["P"]) < 0.9 and top["mu"] == 0.3
    assert top["warning"] is None and top["approach_shear"] < 0.05
    steps = [s["cattaneo"][0] for s in data["steps"]]
    assert len(steps) == 2 and steps[1] == top
    assert steps[0]["Q"] < 0.01 * 0.3 * steps[0]["P"]
    assert steps[0]["shear_ratio"] == top["approach_shear"]
    lines = proc.stdout.splitlines()
    assert any(line.startswith("step 1, Cattaneo-Mindlin, pair 0: no push yet") for line in lines)
    assert any(line.startswith("step 2, Cattaneo-Mindlin, pair 0: c = ") for line in lines)
    assert sum(line.startswith("Cattaneo-Mindlin, pair 0: c = ") for line in lines) == 1
    assert "warning" not in proc.stdout


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        # Dissimilar Poisson's ratios: the pressed bodies expand apart and friction locks in a
        # shear (measured 48 % of mu p): the push starts from a state the theory does not have.
        ("nu = 0.3\n\n[[contact]]", "nu = 0.0\n\n[[contact]]", "warning: the approach slipped"),
        ("[[step]]\npress = 1.0\n[[step]]\npush = 1.0\n", "", "warning: one load step"),
    ],
)
def test_cattaneo_warns_where_it_does_not_hold(
    tmp_path: Path, old: str, new: str, expected: str
) -> None:
    """A slipping approach, or one step for press and push: the terminal and the JSON say so."""
    out = tmp_path / "run.json"
    proc = cli("solve", str(variant(tmp_path, old, new)), "--method", "mortar", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    assert expected in proc.stdout
    warning = json.loads(out.read_text())["cattaneo"][0]["warning"]
    assert warning is not None and warning in proc.stdout


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ("mu = 0.3\n", "", "cattaneo reference (pair 0): the pair is frictionless"),
        ("R = 0.5\n", "R = 0.5\nsymmetric = true\n", "symmetric"),
        ("R = 0.5\n", "R = -0.5\n", "reference 0 (cattaneo): R and mu must be positive"),
        ("R = 0.5\n", "R = 0.5\nmu = 0.0\n", "reference 0 (cattaneo): R and mu must be positive"),
        ("pair = 0\n", "pair = 1\n", "cattaneo reference (pair 1): pair 1 is not one of"),
    ],
)
def test_bad_cattaneo_table_is_one_line(tmp_path: Path, old: str, new: str, expected: str) -> None:
    """A frictionless pair, an unknown key, R or mu <= 0, a missing pair: one line, exit 2."""
    proc = cli("solve", str(variant(tmp_path, old, new)))
    assert proc.returncode == 2, proc.stderr
    assert expected in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("ref", "mu", "expected"),
    [
        (CattaneoReference(0, -0.5), 0.3, "R and mu must be positive"),
        (CattaneoReference(0, 0.5, mu=0.0), 0.3, "R and mu must be positive"),
        (CattaneoReference(0, 0.5), 0.0, "the pair is frictionless"),
    ],
)
def test_bad_cattaneo_reference_in_python(ref: CattaneoReference, mu: float, expected: str) -> None:
    """The Python API refuses what the scene file refuses (InputError, one line)."""
    with pytest.raises(InputError, match=expected):
        scene_from_gmsh(
            SCENES / "cattaneo_cylinders.geo",
            bodies={"upper": Material(1000.0, 0.3), "lower": Material(1000.0, 0.3)},
            contacts=[ContactPair("upper_arc", "lower_arc", mu=mu)],
            dirichlet=[Dirichlet("lower_flat", ux=0.0, uy=0.0), Dirichlet("upper_flat", uy=-0.03)],
            references=[ref],
        )
