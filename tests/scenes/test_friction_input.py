"""Coulomb friction's input: `mu` on a [[contact]] pair, `ContactPair(mu=...)`, `--mu`.

A pair with mu > 0 that a method cannot solve with friction is refused in one line (never
solved frictionless); mu = 0 (the default) is today's model.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, cli

from contactfx import ContactPair, SolveRequest, load_scene_file, run_scene
from contactfx.errors import InputError

SCENES = ROOT / "tests" / "scenes"


def stacked(tmp_path: Path, mu: str) -> Path:
    """stacked_blocks.toml with `mu = <mu>` on its first pair."""
    toml = (SCENES / "stacked_blocks.toml").read_text()
    (tmp_path / "stacked_blocks.geo").write_text((SCENES / "stacked_blocks.geo").read_text())
    head, sep, tail = toml.partition('passive = "b1_top"\n')
    path = tmp_path / "friction.toml"
    path.write_text(head + sep + f"mu = {mu}\n" + tail)
    return path


def test_contact_pair_mu() -> None:
    """mu defaults to 0 and is stored as a float; negative, NaN or non-numbers are refused."""
    assert ContactPair("a", "b").mu == 0.0
    assert ContactPair("a", "b", mu=1).mu == 1.0 and isinstance(
        ContactPair("a", "b", mu=1).mu, float
    )
    for bad in (-0.1, float("nan"), float("inf"), "0.3", True):
        with pytest.raises(InputError, match="mu must be a number >= 0"):
            ContactPair("a", "b", mu=bad)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("mu", "expected"),
    [
        ("-0.2", "contact 0.mu: must be a number >= 0"),
        ('"high"', "contact 0.mu: expected a number"),
        ("nan", "contact 0.mu: expected a finite number, got nan"),
    ],
)
def test_scene_file_bad_mu_is_one_line(tmp_path: Path, mu: str, expected: str) -> None:
    """A negative or non-numeric mu: one line, exit 2, before anything is meshed."""
    proc = cli("solve", str(stacked(tmp_path, mu)))
    assert proc.returncode == 2, proc.stderr
    assert expected in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


def test_frictional_pair_is_read_and_solved_or_refused(tmp_path: Path) -> None:
    """mu > 0 is read onto its pair; mortar and penalty solve it with friction, sts and
    Schwarz refuse it in one line."""
    scene = load_scene_file(stacked(tmp_path, "0.3"))
    assert [p.mu for p in scene.contacts] == [0.3, 0.0, 0.0]
    sol, _ = run_scene(scene, SolveRequest.parse("mortar"))
    assert sol.friction is not None
    np.testing.assert_array_equal(np.unique(sol.friction.mu), [0.0, 0.3])
    pen, _ = run_scene(scene, SolveRequest.parse("penalty"))
    assert pen.friction is not None and pen.penalty is not None
    frictionless = pen.friction.mu == 0.0
    assert frictionless.any() and np.all(pen.friction.shear[frictionless] == 0.0)
    for method in ("sts", "schwarz"):
        with pytest.raises(InputError, match=r"contact 0 \('b2_bottom' on 'b1_top'\) has mu = 0.3"):
            run_scene(scene, SolveRequest.parse(method))


def test_builtin_mu_option_reaches_the_pair() -> None:
    """--mu reaches the built-in scene's pair: with sts the CLI refuses friction, exit 2."""
    proc = cli("solve", "blocks", "--mu", "0.2", "--size1", "1", "--size2", "1", "--method", "sts")
    assert proc.returncode == 2, proc.stderr
    assert "has mu = 0.2: Coulomb friction is not solved with sts" in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("args", "refused"),
    [
        (("--method", "schwarz"), "the schwarz enforcement"),
        (("--solver", "fieldsplit"), "the fieldsplit solver"),
        (
            ("--method", "nts", "--solver", "condensed"),
            "the condensed solver on nts (standard basis), which needs dual mortar",
        ),
    ],
)
def test_friction_refused_by_enforcement_or_solver_is_one_line(
    args: tuple[str, ...], refused: str
) -> None:
    """Schwarz, an iterative solver, or the condensed solver on anything but dual mortar with
    friction: one line, exit 2,
    naming the pair and what does solve it."""
    proc = cli("solve", "blocks", "--mu", "0.2", "--size1", "1", "--size2", "1", *args)
    assert proc.returncode == 2, proc.stderr
    assert f"has mu = 0.2: Coulomb friction is not solved with {refused}; it is solved by nts" in (
        proc.stderr
    ), proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


def test_a_body_held_sideways_by_stick_alone_from_the_cli(tmp_path: Path) -> None:
    """friction_held_sideways.toml solves (the shear carries the pull, the middle sticks);
    with mu = 0 the block is free along x: one line, exit 2, before any solve."""
    out = tmp_path / "run.json"
    scene = SCENES / "friction_held_sideways.toml"
    proc = cli("solve", str(scene), "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    (pair,) = json.loads(out.read_text())["contacts"]
    assert (
        pair["force"][0] == pytest.approx(-1.0, rel=1e-9) and "stick" in pair["interface"]["status"]
    )
    (tmp_path / "friction_blocks.geo").write_text((SCENES / "friction_blocks.geo").read_text())
    plain = tmp_path / "plain.toml"
    plain.write_text(scene.read_text().replace("mu = 0.3", "mu = 0.0"))
    proc = cli("solve", str(plain))
    assert proc.returncode == 2 and "can still move freely" in proc.stderr, proc.stderr
    assert "translation along x" in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


def test_load_steps_in_the_json_and_on_the_terminal(tmp_path: Path) -> None:
    """[[step]] tables: one JSON entry per step (the press alone carries no shear, the last
    push slides the block: Q = mu P), the top-level keys are the last step's, and the
    terminal prints each step's forces, stick/slip counts and iterations."""
    out = tmp_path / "run.json"
    proc = cli("solve", str(SCENES / "friction_push.toml"), "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    steps = data["steps"]
    assert len(steps) == 3
    forces = [s["contacts"][0]["force"] for s in steps]
    assert all(f[1] == pytest.approx(10.0, rel=1e-10) for f in forces)
    assert abs(forces[0][0]) < 1e-9
    assert -0.3 * 10.0 < forces[1][0] < 0.0
    assert forces[2][0] == pytest.approx(-0.3 * 10.0, rel=1e-10)
    assert data["contacts"][0]["force"] == forces[2]
    assert data["contacts"][0]["interface"] == steps[2]["contacts"][0]["interface"]
    assert "stick" in steps[1]["contacts"][0]["interface"]["status"]
    lines = [line for line in proc.stdout.splitlines() if "step 3, pair 0" in line]
    assert len(lines) == 1 and "0 stick" in lines[0] and "iterations" in lines[0]


@pytest.mark.parametrize(
    ("step", "expected"),
    [
        ("[[step]]\npull = 1.0\n", "step 0: no load is named 'pull' (named loads: press, push)"),
        ('[[step]]\npush = "full"\n', "step 0.push: expected a number (a factor), got 'full'"),
        ("step = [1.0]\n", "step 0: expected a table of load names and factors (got 1.0)"),
        ("[[step]]\npush = inf\n", "step 0.push: expected a finite number, got inf"),
    ],
)
def test_bad_step_is_one_line(tmp_path: Path, step: str, expected: str) -> None:
    """A step naming an unknown load, or not a table of numbers: one line, exit 2."""
    toml = (SCENES / "friction_push.toml").read_text()
    head = toml.partition("[[step]]")[0]
    if not step.startswith("[[step]]"):  # a top-level key must come before the tables
        head = step + head
        step = ""
    (tmp_path / "friction_blocks.geo").write_text((SCENES / "friction_blocks.geo").read_text())
    path = tmp_path / "bad.toml"
    path.write_text(head + step)
    proc = cli("solve", str(path))
    assert proc.returncode == 2, proc.stderr
    assert expected in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1


def test_mu_zero_is_the_frictionless_scene_bit_for_bit(tmp_path: Path) -> None:
    """`mu = 0` written out is the scene without the key: same pressures and displacement."""
    plain = run_scene(
        load_scene_file(SCENES / "stacked_blocks.toml"), SolveRequest.parse("mortar")
    )[0]
    zero = run_scene(load_scene_file(stacked(tmp_path, "0.0")), SolveRequest.parse("mortar"))[0]
    assert zero.friction is None
    np.testing.assert_array_equal(zero.pressure, plain.pressure)
    np.testing.assert_array_equal(zero.u.x.array, plain.u.x.array)
