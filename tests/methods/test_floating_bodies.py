"""A body that floats never gets an answer: four stacked blocks with one pair written wrong.

tests/scenes/stacked_blocks.toml stacks four blocks under p = 10 (each block's only rigid
motion left by its supports is the translation along y). stacked_blocks_far_pair.toml writes
the third pair against the bottom block, two blocks away: the check before the solve sees
every body held (contact taken as bilateral), but b4 is pushed onto b1 and b2, b3 carry no
load. Before the fix this ended with exit 0 and a JSON, b2 and b3 at arbitrary positions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, cli, run_cli

from contactfx import load_scene_file, run_scene
from contactfx.errors import SingularSystemError

SCENES = ROOT / "tests" / "scenes"
STACK = SCENES / "stacked_blocks.toml"
FAR = SCENES / "stacked_blocks_far_pair.toml"
P, L = 10.0, 2.0  # the pressure on b4's top and the blocks' width


def assert_names_the_floating_bodies(message: str) -> None:
    """The message names b2 and b3, the pairs 0 and 1 that lost contact, not the good pair."""
    assert "'b2'" in message and "'b3'" in message, message
    assert "'b1'" not in message and "'b4'" not in message, message
    assert "0 (b2_bottom on b1_top)" in message and "1 (b3_bottom on b2_top)" in message
    assert "b4_bottom on b1_top" not in message, message
    assert "[[contact]]" in message  # and what to check


@pytest.mark.serial
def test_stacked_blocks_carry_the_load_through_every_pair() -> None:
    """The correct stack: every pair carries p L = 20 along y (statics), balanced."""
    _, data = run_scene(load_scene_file(STACK), "mortar")
    data = data.to_json()
    assert len(data["contacts"]) == 3
    for c in data["contacts"]:
        np.testing.assert_allclose(c["force"], [0.0, P * L], atol=1e-9 * P * L)
        assert c["balance"] < 1e-12


@pytest.mark.serial
@pytest.mark.parametrize("method", ["mortar", "nts", "penalty"])
def test_far_pair_leaves_two_bodies_floating_and_is_refused(method: str) -> None:
    """Every method that runs the active-set loop stops on the floating bodies."""
    scene = load_scene_file(FAR)
    with pytest.raises(SingularSystemError) as err:
        run_scene(scene, method)
    assert_names_the_floating_bodies(str(err.value))


@pytest.mark.serial
def test_far_pair_cli_exit_2_one_line_no_json(tmp_path: Path) -> None:
    """The CLI: exit 2, one error line naming the bodies and pairs, no JSON, no files."""
    out = tmp_path / "r.json"
    proc = cli("solve", str(FAR), "--json", str(out), "--out", str(tmp_path / "out"))
    assert proc.returncode == 2, proc.stdout[-2000:] + proc.stderr[-2000:]
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("contactfx: error: "), proc.stderr
    assert_names_the_floating_bodies(lines[0])
    assert not out.exists() and not (tmp_path / "out").exists()
    assert "Traceback" not in proc.stderr


@pytest.mark.mpi
def test_far_pair_refused_on_two_ranks(tmp_path: Path) -> None:
    """mpirun -n 2: the same one line, exit 2, no JSON (the check is collective)."""
    out = tmp_path / "r.json"
    proc = run_cli("solve", str(FAR), "--json", str(out), ranks=2)
    assert proc.returncode == 2, proc.stdout[-2000:] + proc.stderr[-2000:]
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert_names_the_floating_bodies(lines[0])
    assert not out.exists()


@pytest.mark.serial
def test_loop_that_gives_up_on_a_floating_body_names_it() -> None:
    """An iteration limit reached with bodies floating reports them, not the limit (their
    singular solves are why the set wanders)."""
    with pytest.raises(SingularSystemError) as err:
        run_scene(load_scene_file(FAR), "mortar", max_iterations=2)
    assert_names_the_floating_bodies(str(err.value))
    assert "in the last solve (after 2 iterations)" in str(err.value)
