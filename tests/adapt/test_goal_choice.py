"""`adapt SCENE --tol X` decides its goal: the pressure where it is bounded, else the energy.

A flat punch's edge (1/sqrt) and a press fit's hub edge make the pressure's peak grow with
every refinement of the contact cells (adapt/goal.py judges that over two refinements, not
one node); the loop then stops on the energy estimate and says so in the log and adapt.json.
"""

from __future__ import annotations

import json
from pathlib import Path

from conftest import ROOT, cli

PUNCH = ROOT / "demos" / "scenes" / "rigid_punch.toml"
PRESS_FIT = ROOT / "tests" / "scenes" / "press_fit_chamfer.toml"


def _adapt(tmp: Path, scene: Path, *args: str) -> tuple[dict, str]:
    proc = cli("adapt", str(scene), *args, "--out", str(tmp))
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return json.loads((tmp / "adapt.json").read_text()), proc.stdout


def test_flat_punch_stops_on_the_energy(tmp_path: Path) -> None:
    """Defaults and --tol only: the punch's pressure is singular, the energy goal is chosen,
    said in the log and the JSON, and the loop stops on its estimate."""
    data, stdout = _adapt(tmp_path, PUNCH, "--tol", "0.1")
    assert data["settings"]["goal"] == "pressure" and data["goal"] == "energy"
    assert "pressure goal is unbounded" in data["goal_note"]
    assert "over two refinements" in data["goal_note"]
    assert "goal: energy (" in stdout
    assert data["stop"].startswith("energy estimate") and "<= tol 10 %" in data["stop"]
    assert all(lv["goal"] == "energy" for lv in data["levels"])


def test_chamfered_press_fit_stops_on_its_estimate(tmp_path: Path) -> None:
    """An axisymmetric shaft-hub press fit, the hub's edge chamfered: defaults and --tol only
    run and stop on the chosen goal's estimate (not on the budget or the levels)."""
    data, stdout = _adapt(tmp_path, PRESS_FIT, "--tol", "0.1")
    assert "<= tol 10 %" in data["stop"], data["stop"]
    assert data["stop"].startswith(data["goal"] + " estimate")
    assert f"goal: {data['goal']}" in stdout
