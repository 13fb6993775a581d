"""A Hertz reference without a known load: `[[reference]] type = "hertz"` with P omitted takes
the pair's computed contact force, which is what a displacement-controlled scene knows.

References: the applied load where there is one (two_cylinders.toml: pressure 100/120 on a
radius of 60 gives the half model P/2 = 50), plane-strain Hertz otherwise (the rotated,
displacement-controlled scene: a, p0 and L2 against Hertz with its own computed P; measured
a -0.25 %, p0 +0.76 %, L2 2.2 %).
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from conftest import ROOT

from contactfx import SolveRequest, load_scene_file, run_scene
from contactfx.errors import InputError

SCENES = ROOT / "tests" / "scenes"


def without_p(tmp: Path, name: str) -> Path:
    """Scene file `name` (and its .geo) in `tmp`, with its reference's P removed."""
    text = (SCENES / f"{name}.toml").read_text()
    (tmp / f"{name}.geo").write_text((SCENES / f"{name}.geo").read_text())
    lines = [ln for ln in text.splitlines() if not ln.replace(" ", "").startswith("P=")]
    path = tmp / f"{name}.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.serial
def test_rotated_displacement_controlled_hertz_against_its_computed_load() -> None:
    """P omitted: P is the pair's normal force; a, p0 and L2 match Hertz for that load."""
    scene = load_scene_file(SCENES / "rotated_hertz.toml")
    assert scene.references[0].P is None
    _, data = run_scene(scene, SolveRequest.parse("mortar"))
    data = data.to_json()
    hz, force = data["hertz"], data["contacts"][0]["force"]
    # Full model, frictionless on a 30-degree flat block: the force is the rotated normal's.
    assert math.degrees(math.atan2(-force[0], force[1])) == pytest.approx(30.0, abs=0.05)
    assert hz["P"] == pytest.approx(math.hypot(*force), rel=1e-6)
    assert hz["P_source"].startswith("computed")
    e_star = 7000.0 / (2 * (1 - 0.3**2))
    assert hz["a_exact"] == pytest.approx(math.sqrt(4 * hz["P"] * 10.0 / (math.pi * e_star)))
    assert abs(hz["a"] / hz["a_exact"] - 1) < 0.01
    assert abs(hz["p0"] / hz["p0_exact"] - 1) < 0.02
    assert hz["l2_error"] < 0.04


@pytest.mark.serial
def test_half_model_without_p_takes_twice_its_force(tmp_path: Path) -> None:
    """Symmetric: P = 2 x the half model's force along the centre's normal = the applied 100
    to 1e-5 (the centre's nodal normal is its end segment's, tilted by h/(2R) = 2e-4 rad:
    measured 99.99975), so the reference is the one with P = 100 given."""
    given = run_scene(load_scene_file(SCENES / "two_cylinders.toml"), SolveRequest.parse("mortar"))[
        1
    ].hertz[0]
    computed = run_scene(
        load_scene_file(without_p(tmp_path, "two_cylinders")), SolveRequest.parse("mortar")
    )[1]
    hz = computed.hertz[0]
    assert hz.P == pytest.approx(100.0, rel=1e-5) and hz.P_source.startswith("computed")
    assert given.P == 100.0 and given.P_source == "given"
    for key in ("a_exact", "p0_exact"):
        assert getattr(hz, key) == pytest.approx(getattr(given, key), rel=1e-5), key
    for key in ("a", "p0"):  # read off the pressure: the same solve, the same values
        assert getattr(hz, key) == pytest.approx(getattr(given, key), rel=1e-12), key
    assert hz.l2_error == pytest.approx(given.l2_error, abs=1e-5)


@pytest.mark.serial
def test_a_given_p_must_still_be_positive(tmp_path: Path) -> None:
    """P may be omitted, not zero."""
    path = without_p(tmp_path, "two_cylinders")
    path.write_text(path.read_text().replace("R = 24.0", "R = 24.0\nP = 0.0"))
    with pytest.raises(InputError, match="R and P must be positive"):
        load_scene_file(path)
