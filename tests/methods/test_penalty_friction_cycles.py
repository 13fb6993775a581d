"""Penalty friction on coarse blocks (methods/penalty_friction.py, penalty_return.py): no cycle.

On the built-in blocks with one to three cm elements the plain set iteration of the
regularized Coulomb law met a set twice (`contactfx solve blocks --mu 0.2 --size1 1 --size2 1
--method penalty`) until the rows on a held edge stopped carrying shear
(discretize/tangents.held_rows); it still does on the heated block with nts rows. From a set met
again the iteration takes searched Newton steps (Armijo
on |R|) and, where no step lowers |R|, the Tresca-Coulomb fixed point. Each case is checked
against the law itself and against the multipliers on the same mesh (the displacement and
the pressure within the penalty's O(1 / eps) error; the statuses where a row is not at the
edge of the cone).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import cli

from contactfx import SolveRequest, load_scene_file, solve
from contactfx.contact.friction import Status
from contactfx.methods.solution import Solution
from contactfx.scenes.builtin import BlockParams, blocks

ROOT = Path(__file__).resolve().parents[2]

# (method, size1, size2, mu): the command's case first, then other sizes and mus.
CASES = [
    ("mortar", 1.0, 1.0, 0.2),
    ("nts", 1.0, 1.0, 0.2),
    ("mortar", 2.0, 1.0, 0.1),
    ("mortar", 1.0, 3.0, 0.1),
    ("nts", 3.0, 1.0, 0.1),
    ("mortar", 3.0, 2.0, 0.3),
    ("mortar", 3.0, 3.0, 0.2),
    ("nts", 2.0, 2.0, 0.5),
    ("mortar", 2.0, 3.0, 0.5),
]


def coulomb(sol: Solution, mu: float) -> None:
    """The regularized Coulomb law at every node: open rows carry nothing, |shear| < mu p
    where a row sticks and = mu p (to round-off) where it slips."""
    fr = sol.friction
    assert fr is not None and sol.penalty is not None
    p, q, status = sol.pressure, fr.shear, fr.status
    scale = p.max()
    slip, stick, open_ = (status == s for s in (Status.SLIP, Status.STICK, Status.OPEN))
    assert np.all(p[open_] == 0.0) and np.all(q[open_] == 0.0)
    assert np.all(p[~open_] > 0.0)
    assert np.all(np.abs(q[stick]) < mu * p[stick])
    assert np.abs(np.abs(q[slip]) - mu * p[slip]).max(initial=0.0) < 1e-12 * scale


@pytest.mark.parametrize(("method", "size1", "size2", "mu"), CASES)
def test_coarse_blocks_converge_to_the_multipliers_within_the_penalty_error(
    method: str, size1: float, size2: float, mu: float
) -> None:
    """No cycle; Coulomb's law at every node; against the multipliers on the same mesh the
    displacement and the pressure differ by the penalty's error, which falls like 1 / eps
    (at ten times eps a tenth: 7 to 13 times less); the statuses are the multipliers' except
    at a row the multipliers hold at the cone's edge (mu p - |shear| within 1e-3 of the
    largest pressure: the penalty's error there picks a side). For nts the shear is the
    multipliers' within the same error; mortar's stick rows on these meshes leave the
    multipliers' shear undetermined (several shears, one displacement), so its shear is
    checked through the displacement only."""
    scene = blocks(BlockParams(size1=size1, size2=size2, mu=mu))
    pen = solve(scene, SolveRequest.parse(method, enforcement="penalty"))
    ref = solve(scene, method)
    coulomb(pen, mu)
    assert pen.penalty is not None and pen.friction is not None and ref.friction is not None
    scale, umax = ref.pressure.max(), np.abs(ref.u.x.array).max()
    du = np.abs(pen.u.x.array - ref.u.x.array).max() / umax
    dp = np.abs(pen.pressure - ref.pressure).max() / scale
    assert du < 1e-3 and dp < 1e-3
    stiff = solve(
        scene, SolveRequest.parse(method, enforcement="penalty", penalty=10 * pen.penalty.eps)
    )
    assert stiff.friction is not None
    du10 = np.abs(stiff.u.x.array - ref.u.x.array).max() / umax
    assert 7.0 < du / du10 < 13.0, (du, du10)
    differ = pen.friction.status != ref.friction.status
    edge = np.abs(mu * ref.pressure - np.abs(ref.friction.shear)) <= 1e-3 * scale
    assert np.all(edge[differ])
    np.testing.assert_array_equal(stiff.friction.status, pen.friction.status)
    if method == "nts":
        assert not differ.any()
        assert np.abs(pen.friction.shear - ref.friction.shear).max() < 1e-3 * scale


def test_the_first_try_converges_as_the_multipliers() -> None:
    """The command's case (blocks, 1 cm elements, mu = 0.2, the penalty on mortar rows), which
    cycled before the held rows and the searched steps: it converges, holds Coulomb's law,
    and its statuses are the mortar multipliers' (the row on the held edge carries no shear)."""
    scene = blocks(BlockParams(size1=1.0, size2=1.0, mu=0.2))
    sol = solve(scene, "penalty")
    ref = solve(scene, "mortar")
    coulomb(sol, 0.2)
    assert sol.friction is not None and ref.friction is not None
    np.testing.assert_array_equal(sol.friction.status, ref.friction.status)


def test_searched_steps_and_tresca_end_the_heated_block() -> None:
    """The heated block between frictional walls (mu = 0.2) with the penalty on nts rows: the
    plain iteration meets a set again, the searched steps (and, where none lowers |R|, the
    Tresca-Coulomb fixed point) take over, and it ends on the multipliers' statuses with
    Coulomb's law at every node (the plain iteration cycled here)."""
    scene = load_scene_file(ROOT / "tests" / "scenes" / "heated_block.toml")
    scene = replace(
        scene,
        contacts=tuple(replace(c, mu=0.2) for c in scene.contacts),
        obstacles=tuple(replace(o, mu=0.2) for o in scene.obstacles),
    )
    sol = solve(scene, SolveRequest.parse("nts", enforcement="penalty"))
    # The plain iteration's rows all flip together here (the walls' shear moves them back by
    # more than the expansion): not a tie of round-off, so a searched step is always taken.
    assert any(r["step_length"] < 1.0 for r in sol.history)
    coulomb(sol, 0.2)
    ref = solve(scene, "nts")
    assert sol.friction is not None and ref.friction is not None
    np.testing.assert_array_equal(sol.friction.status, ref.friction.status)


def test_cli_first_try_of_mu_with_the_penalty() -> None:
    """`contactfx solve blocks --mu 0.2 --size1 1 --size2 1 --method penalty` succeeds."""
    proc = cli(
        "solve", "blocks", "--mu", "0.2", "--size1", "1", "--size2", "1", "--method", "penalty"
    )
    assert proc.returncode == 0, proc.stderr
    assert "3 stick, 1 slip" in proc.stdout


def test_the_penalty_converges_like_one_over_eps() -> None:
    """Blocks with 2 cm elements, mu = 0.2, mortar rows (both enforcements cycled here before
    the held rows): the penalty holds Coulomb's law at every node, and ten
    times eps keeps its statuses and moves its displacement ten times less than the step
    from eps / 10 to eps (7 to 13): a limit exists and the default is within O(1 / eps) of it."""
    scene = blocks(BlockParams(size1=2.0, size2=2.0, mu=0.2))
    sol = solve(scene, "penalty")
    assert sol.penalty is not None and sol.friction is not None
    coulomb(sol, 0.2)
    eps = sol.penalty.eps
    soft, stiff = (solve(scene, "penalty", penalty=f * eps) for f in (0.1, 10.0))
    assert soft.friction is not None and stiff.friction is not None
    np.testing.assert_array_equal(stiff.friction.status, sol.friction.status)
    np.testing.assert_array_equal(soft.friction.status, sol.friction.status)
    coulomb(stiff, 0.2)
    far = np.abs(sol.u.x.array - soft.u.x.array).max()
    near = np.abs(stiff.u.x.array - sol.u.x.array).max()
    assert 7.0 < far / near < 13.0, (far, near)
