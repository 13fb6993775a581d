"""`[[reference]] type = "spence"`: a rigid cylinder pressed with friction, against Spence's c/a.

Spence's stick ratio itself (spence_stick_ratio, 0.689 for mu = nu = 0.3) is checked against an
independent half-plane BEM in test_friction_references.py. Here the solver against it on
demos/scenes/spence_indenter.toml (R = 200, a/R <= 0.0035, a 100 x 100 block: the theory's
regime), coarsened for speed (size factor 2: a/h up to ~23 over 8 steps growing a by ~1.15
each): the stick half-width from the statuses within 1.5 contact cells of Spence's at every
step after the first,
no active-set cycle (nts, mortar, dual mortar); step 1, a single step from zero, is not Spence's
(docs/friction_verification.md: measured c/a = 0.33 and 0.24); and the scene-file plumbing
and its refusals.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest
from conftest import ROOT, cli

from contactfx import (
    InputError,
    Obstacle,
    SolveRequest,
    SpenceReference,
    load_scene_file,
    scene_from_gmsh,
)
from contactfx.api import run_scene
from contactfx.results.friction_references import spence_stick_ratio
from contactfx.scenes import Dirichlet, Material

SCENE = ROOT / "demos" / "scenes" / "spence_indenter.toml"
MESH = ROOT / "meshes" / "spence_block.geo"
# 8 steps, the contact growing by ~1.15 per step (the approach ~ a^2).
STEPS = tuple({"indenter": 1.15 ** (2 * (k - 7))} for k in range(8))
CELLS = 1.5  # the done-when's tolerance on the stick edge, in contact cells


METHODS = [("nts", "standard"), ("mortar", "standard"), ("mortar", "dual")]


@pytest.mark.parametrize(("method", "basis"), METHODS)
def test_spence_stick_ratio_at_every_step(method: str, basis: str) -> None:
    """c within 1.5 cells of Spence's (c/a) a from step 2 on, at a/h up to 23; step 1 (the
    whole contact at once) sticks far less than Spence's; every step converges (no cycle:
    with the symmetry node's tangential row kept (discretize/tangents.held_rows off), dual
    mortar cycled here)."""
    scene = replace(load_scene_file(SCENE, size_factor=2.0), steps=STEPS)
    _, run = run_scene(scene, SolveRequest.parse(method, basis=basis))
    checks = [s.spence[0] for s in run.steps]
    assert len(checks) == 8 and run.spence == (checks[-1],)
    ratio = spence_stick_ratio(0.3, 0.3)
    for k, c in enumerate(checks[1:], start=2):
        assert c.ratio_exact == pytest.approx(ratio, rel=1e-12)
        assert abs(c.offset_cells) < CELLS, (k, c.text())
        assert c.warning is None and c.a / c.R < 0.005
    assert checks[-1].a / checks[-1].h > 20
    first = checks[0]
    assert first.ratio < 0.4 and first.offset_cells < -2.0 and "step 1" in (first.warning or "")
    assert all(s.iterations < 20 for s in run.steps)


def test_spence_on_a_full_model() -> None:
    """An unmirrored block (the contact's centre read from the pressure, both edges of each
    zone): the stick edge within 1.5 cells of Spence's from step 2 on (mortar)."""
    scene = load_scene_file(ROOT / "tests" / "scenes" / "spence_full.toml")
    _, run = run_scene(scene, SolveRequest.parse("mortar"))
    checks = [s.spence[0] for s in run.steps]
    assert len(checks) == 8 and checks[-1].a / checks[-1].h > 20
    for k, c in enumerate(checks[1:], start=2):
        assert abs(c.offset_cells) < CELLS, (k, c.text())
    assert checks[0].ratio < 0.4


def small(tmp_path: Path, old: str = "", new: str = "") -> Path:
    """spence_indenter.toml with 3 steps (and `old` replaced by `new`), its mesh path absolute."""
    toml = SCENE.read_text().replace('"../../meshes/spence_block.geo"', f'"{MESH}"')
    head, _, _ = toml.partition("[[step]]")
    toml = head + "[[step]]\nindenter = 0.6\n[[step]]\nindenter = 0.8\n[[step]]\nindenter = 1.0\n"
    toml += '\n[[reference]]\ntype = "spence"\npair = 0\nsymmetric = true\n'
    assert old in toml
    path = tmp_path / "spence.toml"
    path.write_text(toml.replace(old, new, 1))
    return path


def test_spence_reference_in_the_json_and_on_the_terminal(tmp_path: Path) -> None:
    """The JSON's `spence` is the last step's and every step has one; the terminal prints
    each step's line and the last one's, and the first step's warning."""
    out = tmp_path / "run.json"
    proc = cli("solve", str(small(tmp_path)), "--method", "nts", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    (top,) = data["spence"]
    assert {"ratio", "ratio_exact", "a", "c", "h", "offset_cells", "warning"} <= set(top)
    steps = [s["spence"][0] for s in data["steps"]]
    assert len(steps) == 3 and steps[-1] == top and top["warning"] is None
    assert top["ratio_exact"] == pytest.approx(0.689, abs=5e-4)
    assert top["ratio"] == pytest.approx(top["c"] / top["a"], rel=1e-12)
    assert steps[0]["warning"].startswith("step 1 loads from zero")
    lines = proc.stdout.splitlines()
    for n in (1, 2, 3):
        assert any(line.startswith(f"step {n}, Spence, pair 0: c/a = ") for line in lines)
    assert sum(line.startswith("Spence, pair 0: c/a = ") for line in lines) == 1


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ("mu = 0.3\n", "", "spence reference (pair 0): obstacle 'indenter' is frictionless"),
        ("pair = 0\n", "pair = 1\n", "spence reference (pair 1): pair 1 is not one of the 1"),
        ('mesh = "', 'model = "plane_stress"\nmesh = "', "use plane_strain"),
        ("symmetric = true\n", "symmetric = 1\n", "symmetric: expected true or false"),
        ("symmetric = true\n", "mu = -0.1\n", "reference 0 (spence): mu must be positive"),
        ("symmetric = true\n", "R = 2.0\n", "unknown key 'R'"),
        ('type = "spence"', 'type = "spense"', "or 'spence' (got 'spense')"),
    ],
)
def test_bad_spence_table_is_one_line(tmp_path: Path, old: str, new: str, expected: str) -> None:
    """A frictionless obstacle, a pair that is no obstacle, a model other than plane strain, a
    wrong type, mu <= 0, an unknown key, a misspelt type: one line, exit 2."""
    proc = cli("solve", str(small(tmp_path, old, new)))
    assert proc.returncode == 2, proc.stderr
    assert expected in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("obstacle", "expected"),
    [
        (Obstacle("indenter", "circle", "top", center=(0.0, 200.0), radius=200.0), "frictionless"),
        (
            Obstacle("indenter", "plane", "top", point=(0.0, 0.0), normal=(0.0, 1.0), mu=0.3),
            "give it shape = 'circle'",
        ),
    ],
)
def test_bad_spence_reference_in_python(obstacle: Obstacle, expected: str) -> None:
    """The Python API refuses what the scene file refuses (InputError, one line)."""
    with pytest.raises(InputError, match=expected):
        scene_from_gmsh(
            MESH,
            bodies={"block": Material(7000.0, 0.3)},
            obstacles=[obstacle],
            dirichlet=[Dirichlet("symmetry", ux=0.0), Dirichlet("base", uy=0.0)],
            references=[SpenceReference(0, symmetric=True)],
        )


def test_spence_check_warns_outside_the_theory() -> None:
    """Step 1 (a single step from zero) and a/R above 0.02 carry a warning; the offset is
    signed, in cells."""
    from contactfx.results.reference_records import SpenceCheck

    base = {"pair": 0, "mu": 0.3, "nu": 0.3, "R": 20.0, "ratio_exact": 0.689, "h": 0.015}
    inside = SpenceCheck(**base, a=0.3, c=0.21, step=2)
    assert inside.warning is None
    assert inside.offset_cells == pytest.approx((0.21 - 0.689 * 0.3) / 0.015, rel=1e-12)
    wide = SpenceCheck(**base, a=0.6, c=0.45, step=5)
    assert wide.warning is not None and "a/R = 0.03" in wide.warning
    assert "step 1" in (SpenceCheck(**base, a=0.1, c=0.03, step=1).warning or "")
