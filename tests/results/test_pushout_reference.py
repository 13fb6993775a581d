"""`[[reference]] type = "pushout"`: a press fit pushed out, computed for a scene's own pair.

On demos/scenes/press_fit_pushout.toml (a steel shaft b = 1 in a steel hub c = 2 of length 8,
delta = 0.001, mu = 0.2, the shaft pushed in 12 steps after the fit): the axial force grows
while part of the interface sticks, and from the first step where every node slips it is mu N
(N the pressure integrated over the revolved interface, a total over the turn like the axial
force: 2 pi times the radial resultant per radian), with |shear| = mu p at every slip node.
The fit's mean pressure against Lame: a frictionless fit of the same scene meets the
open-ended cylinder, a frictional one lies between it and plane strain. Then the JSON and
terminal plumbing, and the tables refused in one line.
"""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import pytest
from conftest import ROOT, cli

from contactfx import ContactPair, PushoutReference, SolveRequest, load_scene_file
from contactfx.api import run_scene
from contactfx.errors import InputError
from contactfx.results.reference_records import PushoutCheck
from contactfx.scenes import Dirichlet, Material, scene_from_gmsh

SCENE = ROOT / "demos" / "scenes" / "press_fit_pushout.toml"
GEO = ROOT / "meshes" / "press_fit_pushout.geo"
MESH_LINE = 'mesh = "../../meshes/press_fit_pushout.geo"'
STEPS = SCENE.read_text()[SCENE.read_text().index("[[step]]") : SCENE.read_text().index("[[ref")]


def variant(tmp_path: Path, *edits: tuple[str, str]) -> Path:
    """press_fit_pushout.toml with each `old` replaced by `new`, beside a copy of its mesh."""
    toml = SCENE.read_text().replace(MESH_LINE, 'mesh = "press_fit_pushout.geo"')
    for old, new in edits:
        assert old in toml, old
        toml = toml.replace(old, new, 1)
    (tmp_path / "press_fit_pushout.geo").write_text(GEO.read_text())
    path = tmp_path / "variant.toml"
    path.write_text(toml)
    return path


@pytest.mark.parametrize(
    ("method", "basis"), [("mortar", "standard"), ("mortar", "dual"), ("nts", "standard")]
)
def test_pushout_reaches_mu_n_in_full_slip(method: str, basis: str) -> None:
    """Stick with partial slip, then full slip at |axial| = mu N to round-off; N is the
    summary's axisymmetric convention (2 pi times the radial resultant per radian). The
    interface's nodes match: nts and both mortar bases give the same values."""
    _, run = run_scene(load_scene_file(SCENE), SolveRequest.parse(method, basis=basis))
    (po,) = run.pushout
    checks = po.steps
    assert len(checks) == len(run.steps) == 13
    full = [c.full_slip for c in checks]
    first = full.index(True)
    # Every step after the onset slips everywhere, every step before it has stick nodes.
    assert all(full[first:]) and not any(full[:first]) and first == 8
    for c, step in zip(checks, run.steps, strict=True):
        (contact,) = step.contacts
        assert c.normal == pytest.approx(2 * math.pi * abs(contact.radial_per_radian), rel=1e-9)
        assert c.axial == contact.axial_force
        assert c.stick + c.slip + c.open == contact.multipliers
    assert all(c.warning is None and c.taper < 1e-12 for c in checks)
    for c in checks[first:]:
        assert c.ratio == pytest.approx(1.0, abs=1e-9)
        assert c.slip_law is not None and c.slip_law < 1e-9
    ratios = [c.ratio for c in checks[:first]]
    assert all(b > a for a, b in itertools.pairwise(ratios)) and ratios[-1] < 0.99
    # Deterministic values of this mesh (1204 DOFs), pinned.
    assert ratios[0] == pytest.approx(0.03066, rel=1e-3)
    assert ratios[4] == pytest.approx(0.7778, rel=1e-3)
    assert checks[-1].normal == pytest.approx(4428.85, rel=1e-3)


def test_the_fit_against_lame(tmp_path: Path) -> None:
    """Without friction the fit's mean pressure is Lame's open-ended cylinder's (78.75) to
    0.67 % (the hub's ends); with mu = 0.2 stick holds the axial strains the open ends leave
    free, and the pressure (+8.1 %) lies between the open-ended and the plane-strain value."""
    _, run = run_scene(load_scene_file(SCENE), SolveRequest.parse("mortar"))
    fit = run.pushout[0].fit
    assert fit is not None
    assert fit.open_ended == pytest.approx(0.001 * 210000.0 * 3 / 8, rel=1e-12)
    assert fit.between and fit.error == pytest.approx(0.0813, rel=1e-2)
    plain = variant(
        tmp_path,
        ("mu = 0.2\n", ""),
        ("uy = -0.01\n", "uy = 0.0\n"),
        (STEPS, ""),
        ('type = "pushout"', 'type = "lame"'),
    )
    _, frictionless = run_scene(load_scene_file(plain), SolveRequest.parse("mortar"))
    (lame,) = frictionless.lame
    assert lame.p_exact == fit.open_ended
    assert lame.error < 0.01 and lame.p_mean < fit.p_mean < fit.plane_strain


def test_pushout_in_the_json_and_on_the_terminal(tmp_path: Path) -> None:
    """The JSON's `pushout` is the last step's with the ratios and the fit; every step has
    its entry; the terminal prints each step's line, the fit and the ratios."""
    out = tmp_path / "run.json"
    proc = cli("solve", str(SCENE), "--method", "mortar", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    (top,) = data["pushout"]
    assert top["warning"] is None
    assert top["full_slip"] and top["first_full_slip_step"] == 9 and len(top["ratios"]) == 13
    assert top["fit"]["between"] and top["fit"]["lame_open_ended"] == pytest.approx(78.75)
    steps = [s["pushout"][0] for s in data["steps"]]
    assert [s["ratio"] for s in steps] == top["ratios"]
    assert steps[-1]["axial_force"] == data["contacts"][0]["axial_force"]
    lines = proc.stdout.splitlines()
    assert any(
        line.startswith("step 1, push-out, pair 0: axial / (mu N) = 0.0307") for line in lines
    )
    assert any(line.startswith("push-out fit (step 1): mean pressure 85.15") for line in lines)
    assert any(line.startswith("  axial / (mu N) by step: 0.031") for line in lines)


@pytest.mark.parametrize(
    ("edits", "expected"),
    [
        ((("mu = 0.2\n", ""),), "pushout reference (pair 0): the pair is frictionless"),
        (
            (('model = "axisymmetric"\n', ""),),
            "pushout reference (pair 0): a shaft pushed out of a hub is an axisymmetric scene",
        ),
        (((STEPS, ""),), "pushout reference (pair 0): give [[step]] tables, the fit first"),
        ((('type = "pushout"', 'type = "pushout"\npair = 1'),), "pair 1 is not one of the 1"),
        ((("c = 2.0\n", ""),), "Lame's rings need a, b and c: missing key 'c'"),
        ((("a = 0.0\n", "a = 1.5\n"),), "the rings' radii must satisfy 0 <= a < b < c"),
        ((('type = "pushout"', 'type = "pushout"\nmu = 0.0'),), "mu must be a number > 0"),
        ((('type = "pushout"', 'type = "pushout"\nR = 1.0'),), "unknown key 'R'"),
        (
            (("a = 0.0\nb = 1.0\nc = 2.0\n", "delta = 0.001\n"),),
            "delta is Lame's: give the rings' a, b and c with it",
        ),
        (
            (("interference = 0.001", "interference = true"),),
            "give delta for Lame's rings (the pair has no interference = D",
        ),
    ],
)
def test_bad_pushout_table_is_one_line(
    tmp_path: Path, edits: tuple[tuple[str, str], ...], expected: str
) -> None:
    """A frictionless pair, a plane model, no steps, a missing pair, bad rings, mu <= 0, an
    unknown key, delta without rings or Lame without delta: one line, exit 2."""
    proc = cli("solve", str(variant(tmp_path, *edits)))
    assert proc.returncode == 2, proc.stderr
    assert expected in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


def test_pushout_warns_off_a_cylinder_or_where_coulomb_fails() -> None:
    """A tapered interface (the pressure has an axial part) or a full slip whose ratio or slip
    law is off: the record's warning says which, on its terminal line and in its JSON."""
    base = {"pair": 0, "mu": 0.2, "axial": 100.0, "normal": 500.0, "open": 0}
    good = PushoutCheck(**base, stick=0, slip=9, slip_law=1e-16)
    assert good.full_slip and good.ratio == 1.0 and good.warning is None
    tapered = PushoutCheck(**base, stick=3, slip=6, slip_law=1e-16, taper=0.05)
    assert "not a cylinder" in str(tapered.warning) and "warning:" in tapered.text()
    off = PushoutCheck(**{**base, "axial": 99.0}, stick=0, slip=9, slip_law=1e-16)
    assert "axial / (mu N) = 0.99" in str(off.warning)
    assert off.to_json()["warning"] == off.warning
    loose = PushoutCheck(**base, stick=0, slip=9, slip_law=1e-3)
    assert "slip law's largest violation is 0.001" in str(loose.warning)


def test_bad_pushout_reference_in_python() -> None:
    """The Python API refuses what the scene file refuses (InputError, one line)."""
    with pytest.raises(InputError, match="rings' radii must satisfy"):
        PushoutReference(0, rings=(0.0, 2.0, 1.0))
    with pytest.raises(InputError, match="give \\[\\[step\\]\\] tables"):
        scene_from_gmsh(
            GEO,
            bodies={"shaft": Material(210000.0, 0.3), "hub": Material(210000.0, 0.3)},
            contacts=[ContactPair("shaft_contact", "hub_contact", interference=0.001, mu=0.2)],
            dirichlet=[Dirichlet("axis", ux=0.0), Dirichlet("hub_bottom", uy=0.0)],
            references=[PushoutReference(0)],
            model="axisymmetric",
        )
