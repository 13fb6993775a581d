"""A body that floats never gets an answer: four stacked blocks with one pair written wrong.

tests/scenes/stacked_blocks.toml stacks four blocks under p = 10 (each block's only rigid
motion left by its supports is the translation along y). stacked_blocks_far_pair.toml writes
the third pair against the bottom block, two blocks away: the check before the solve sees
every body held (contact taken as bilateral), but b4 is pushed onto b1 and b2, b3 carry no
load. Before the fix this ended with exit 0 and a JSON, b2 and b3 at arbitrary positions;
later the loop found them from round-off multipliers (a verdict that changed with the BLAS
kernel). Now prepare_contact, which never solves, refuses from the statics of the rows.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, cli, run_cli

from contactfx import SolveRequest, load_scene_file, run_scene
from contactfx.discretize.load_programs import _carrying_lp, _one_mode, carrying_rows, pulled_away
from contactfx.discretize.setup import prepare_contact
from contactfx.errors import SingularSystemError
from contactfx.methods.active_set import ActiveSetOptions
from contactfx.options import Method
from contactfx.timers import Timers

SCENES = ROOT / "tests" / "scenes"
STACK = SCENES / "stacked_blocks.toml"
DISK = SCENES / "disk_between_plates.toml"
FAR = SCENES / "stacked_blocks_far_pair.toml"
P, L = 10.0, 2.0  # the pressure on b4's top and the blocks' width


def assert_names_the_floating_bodies(message: str) -> None:
    """The message names b2 and b3, the pairs 0 and 1 that lost contact, not the good pair."""
    assert "'b2'" in message and "'b3'" in message, message
    assert "'b1'" not in message and "'b4'" not in message, message
    assert "0 (b2_bottom on b1_top)" in message and "1 (b3_bottom on b2_top)" in message
    assert "b4_bottom on b1_top" not in message, message
    assert "[[contact]]" in message  # and what to check
    assert "before the first solve" in message, message


def refused_before_any_solve(path: Path, method: str) -> str:
    """The message of prepare_contact's refusal: it assembles and checks, it never solves."""
    kernel = Method(method).kernel
    with pytest.raises(SingularSystemError) as err:
        prepare_contact(load_scene_file(path), kernel, ActiveSetOptions().penetration_tol, Timers())
    return str(err.value)


@pytest.mark.parametrize(
    ("rows", "load", "carries"),
    [
        # One free mode (y of a block): a floor below (+1), a plate above (-1), no load: the
        # pair can squeeze the block, both carry.
        ([[1.0], [-1.0]], [0.0], [True, True]),
        # Both rows push up and nothing loads the block: no equilibrium with lam > 0.
        ([[1.0], [2.0]], [0.0], [False, False]),
        # The same rows under a downward load: both can carry it.
        ([[1.0], [2.0]], [-1.0], [True, True]),
        # The far pair's statics (modes b2_y, b3_y): pair 0 pushes b2 up, pair 1 pushes b2
        # down and b3 up, pair 2 acts on no free mode (b4 on the fixed b1: elastic, free).
        ([[1.0, 0.0], [-1.0, 1.0], [0.0, 0.0]], [0.0, 0.0], [False, False, True]),
        # The correct stack (modes b2_y, b3_y, b4_y), p on b4: every pair carries it.
        ([[1.0, 0.0, 0.0], [-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]], [0.0, 0.0, -1.0], [True] * 3),
    ],
)
def test_rows_that_can_carry_load_by_statics(
    rows: list[list[float]], load: list[float], carries: list[bool]
) -> None:
    """Which rows are positive in some lam >= 0 with rows^T lam + load = 0 (hand statics)."""
    got = carrying_rows(np.array(rows), np.array(load))
    assert got is not None and got.tolist() == carries


@pytest.mark.parametrize("load", [-2.0, 0.0, 3.0])
def test_one_free_mode_in_closed_form_agrees_with_the_program(load: float) -> None:
    """Every sign pattern of four rows on one mode: the closed form is the LP's verdict."""
    for signs in np.ndindex(3, 3, 3, 3):
        a = (np.array(signs, dtype=float) - 1.0) * np.array([1.0, 2.5, 0.3, 7.0])
        j = np.flatnonzero(a)
        if not j.size:
            continue
        lp = _carrying_lp(a[:, None], np.array([load]), j, np.ones(4, dtype=bool))
        closed = _one_mode(a, load, np.ones(4, dtype=bool))
        assert (lp is None) == (closed is None), (a, load)
        if lp is not None and closed is not None:
            assert lp.tolist() == closed.tolist(), (a, load)


@pytest.mark.parametrize(("q", "held"), [(0.0, True), (2.9, True), (-2.9, True), (3.1, False)])
def test_friction_holds_a_block_sideways_within_its_cone(q: float, held: bool) -> None:
    """A block (modes x, y) on two floor rows (normal along y, tangent along x, mu = 0.3)
    pressed by 10 and pulled by q along x: an equilibrium inside Coulomb's cone exists iff
    |q| <= mu * 10; a frictionless pair never holds a pull (hand statics)."""
    a = np.array([[0.0, 1.0], [0.0, 2.0]])  # unequal rows: the bound is per row
    at = np.array([[1.0, 0.0], [2.0, 0.0]])
    load = np.array([q, -10.0])
    got = carrying_rows(a, load, at, np.array([0.3, 0.3]))
    assert (got is not None) == held
    if got is not None:
        assert got.tolist() == [True, True]
    frictionless = carrying_rows(a, load, at, np.zeros(2))
    assert (frictionless is not None) == (q == 0.0)


def test_load_that_pulls_a_block_off_has_no_equilibrium() -> None:
    """Rows push up only, the load pulls up: no lam >= 0 balances it; the motion that
    proves it opens every gap (rows . y >= 0) and the load does work on it."""
    a, load = np.array([[1.0, 0.0], [2.0, 1.0]]), np.array([1.0, 0.0])
    assert carrying_rows(a, load) is None
    y = pulled_away(a, load)
    assert np.all(a @ y >= -1e-9) and load @ y == pytest.approx(1.0)


@pytest.mark.serial
def test_stacked_blocks_carry_the_load_through_every_pair() -> None:
    """The correct stack: every pair carries p L = 20 along y (statics), balanced."""
    _, data = run_scene(load_scene_file(STACK), SolveRequest.parse("mortar"))
    data = data.to_json()
    assert len(data["contacts"]) == 3
    for c in data["contacts"]:
        np.testing.assert_allclose(c["force"], [0.0, P * L], atol=1e-9 * P * L)
        assert c["balance"] < 1e-12


@pytest.mark.serial
@pytest.mark.parametrize("method", ["mortar", "nts", "penalty"])
def test_far_pair_leaves_two_bodies_floating_and_is_refused(method: str) -> None:
    """Every method refuses before its first solve (no round-off of a singular one decides)."""
    message = refused_before_any_solve(FAR, method)
    assert_names_the_floating_bodies(message)
    with pytest.raises(SingularSystemError) as err:
        run_scene(load_scene_file(FAR), SolveRequest.parse(method))
    assert str(err.value) == message


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
@pytest.mark.parametrize("max_iterations", [1, 2, 50])
def test_refusal_comes_before_the_loop_whatever_max_iterations(
    max_iterations: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The loop is never entered: its iteration limit cannot change the verdict."""
    import contactfx.methods.multipliers as multipliers

    entered: list[int] = []

    def no_loop(*args: object, **kwargs: object) -> None:
        entered.append(1)
        raise AssertionError("the active-set loop ran")

    monkeypatch.setattr(multipliers, "run_active_set", no_loop)
    with pytest.raises(SingularSystemError) as err:
        run_scene(load_scene_file(FAR), SolveRequest.parse("mortar", max_iterations=max_iterations))
    assert not entered
    assert_names_the_floating_bodies(str(err.value))


@pytest.mark.serial
def test_loop_safety_net_names_bodies_left_free_by_a_set() -> None:
    """The check inside the loop (kept as a safety net) on the correct stack: a set without
    pair 1's rows leaves b3 and b4 (which rests on b3) free, and it says so."""
    setup = prepare_contact(
        load_scene_file(STACK), Method.MORTAR.kernel, ActiveSetOptions().penetration_tol, Timers()
    )
    pair = setup.layout.pair[setup.layout.mine]
    setup.check_held_by(pair >= 0, "in a set with every row")
    with pytest.raises(SingularSystemError) as err:
        setup.check_held_by(pair != 1, "in a set without pair 1")
    message = str(err.value)
    assert "'b3'" in message and "'b4'" in message, message
    assert "'b1'" not in message and "'b2'" not in message, message
    assert "1 (b3_bottom on b2_top)" in message and "in a set without pair 1" in message
    setup.destroy()


@pytest.mark.serial
@pytest.mark.parametrize("method", ["nts", "mortar", "penalty"])
def test_disk_between_rigid_plates_is_refused_along_the_plates_normal(method: str) -> None:
    """The plates push along y only (their normal, not the rim's radial normals): nothing
    holds the disk along x. Refused before any solve, naming that motion; the advice fits a
    scene of obstacles (no [[contact]] pair to check)."""
    message = refused_before_any_solve(DISK, method)
    assert "body 'disk'" in message and "translation along x" in message, message
    assert "translation along y" not in message, message
    assert "before the first solve" in message, message
    assert "[[dirichlet]]" in message and "[[obstacle]]" in message, message
    assert "[[contact]]" not in message, message


def test_body_blocks_are_the_sorted_unique_blocks() -> None:
    """The mask in body_blocks gives np.unique's blocks: sorted, each once, per body."""
    from dolfinx import fem
    from mpi4py import MPI

    from contactfx.discretize.supports import body_blocks
    from contactfx.scenes import HertzParams, hertz

    scene = hertz(HertzParams(refine=0.3, h_far=3.0, mesh="structured"), comm=MPI.COMM_SELF)
    V = fem.functionspace(scene.mesh, ("Lagrange", 1, (2,)))
    for body in scene.bodies:
        cells = scene.body_cells(body)
        expected = np.unique(V.dofmap.list[cells].ravel())
        assert np.array_equal(body_blocks(V, cells), expected)
    assert body_blocks(V, np.zeros(0, dtype=np.int32)).size == 0


def test_a_program_that_refuses_its_input_is_an_error_on_every_rank() -> None:
    """HiGHS's ValueError on rank 0 (a nan in the program) was raised there alone while the
    other ranks waited in the broadcast of its verdict: now it is broadcast and raised as a
    SingularSystemError on each rank."""
    from mpi4py import MPI

    from contactfx.discretize.load_paths import _verdict

    a = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    with pytest.raises(ValueError, match="linprog"):
        carrying_rows(a, np.array([np.nan, 1.0]))
    with pytest.raises(SingularSystemError, match=r"the check of which contacts .* failed"):
        _verdict(MPI.COMM_SELF, a, np.array([np.nan, 1.0]))
