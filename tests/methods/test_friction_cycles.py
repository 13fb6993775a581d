"""Coulomb friction on scenes whose active set cycled or carried a spurious shear
(methods/friction_iteration.py, docs/friction.md "How it is solved").

With mu = 0.2 on their pairs: the heated block between rigid walls (its walls' slip turns
against the slip direction each set assumes: the undamped update cycled), the quarter shrink
fit (its end rows lie on the symmetry lines: their stick multipliers duplicated the
supports' reactions and came out as mu p, alternating along the rows) and the axisymmetric
long hub (the same on its mid-plane row: 17.4, -4.8, 1.3, -0.35 along the first rows where
the penalty gives about 0). Each solves without a cycle, Coulomb's law holds at every node
(slip: |shear| = mu p with the shear's sign the slip's), and the answers are checked against
an independent one: the frictionless solve where friction has nothing to do (the shrink
fit's shear is zero exactly), the penalty's regularized law within its documented error,
another discretization's total force.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from conftest import ROOT

import contactfx.methods.friction_iteration as friction_method
from contactfx import load_scene_file, solve
from contactfx.contact.friction import Status
from contactfx.errors import ActiveSetError
from contactfx.methods.solution import Solution
from contactfx.scenes import Scene

MU = 0.2
SCENES = ROOT / "tests" / "scenes"
# The penalty's distance from the multipliers at its default stiffness: 1.28e-3 of the
# largest pressure on the pushed block (docs/friction.md, "The penalty baseline").
PENALTY_ERROR = 2e-3
CASES = [("mortar", "standard"), ("mortar", "dual"), ("nts", "standard")]


def frictional(name: str, mu: float = MU) -> Scene:
    """The scene file `name` with `mu` on every contact pair and obstacle."""
    scene = load_scene_file(SCENES / f"{name}.toml")
    return replace(
        scene,
        contacts=tuple(replace(c, mu=mu) for c in scene.contacts),
        obstacles=tuple(replace(o, mu=mu) for o in scene.obstacles),
    )


def check_law(sol: Solution, mu: float = MU) -> None:
    """Coulomb's law at every node of a one-step solve, to round-off of the largest pressure."""
    fr = sol.friction
    assert fr is not None
    p, q, slip, status = sol.pressure, fr.shear, fr.slip, fr.status
    scale = p.max()
    sliding, sticking = status == Status.SLIP, status == Status.STICK
    assert np.all(p[status != Status.OPEN] > 0.0)
    assert np.all(np.abs(q) <= mu * p + 1e-12 * scale)
    assert np.abs(np.abs(q[sliding]) - mu * p[sliding]).max(initial=0.0) < 1e-9 * scale
    # The traction on the active body, -shear t, opposes the slip along t.
    assert np.all(np.sign(q[sliding]) == np.sign(slip[sliding]))
    assert np.all(slip[sliding] != 0.0)
    # A stick node does not slip: to round-off of the displacement with multipliers, by the
    # elastic slip shear / eps with the penalty (one step from rest).
    elastic = 0.0 if sol.penalty is None else np.abs(q[sticking]) / sol.penalty.eps
    excess = np.abs(slip[sticking]) - elastic * (1.0 + 1e-6)
    assert excess.max(initial=0.0) < 1e-10 * np.abs(sol.u.x.array).max()


def wall_forces(sol: Solution) -> np.ndarray:
    """The normal force (sum of w p) on each wall of the heated block (x = 0, x = 2)."""
    x, w = sol.layout.x[:, 0], sol.layout.weights
    return np.array([w[side] @ sol.pressure[side] for side in (x < 1.0, x > 1.0)])


@pytest.mark.parametrize(
    ("method", "basis"), [("mortar", "standard"), ("mortar", "dual"), ("nts", "standard")]
)
def test_heated_block_between_frictional_walls(method: str, basis: str) -> None:
    """The heated block pressing on two frictional walls: no cycle, Coulomb at every node,
    and each wall's normal force the same as nts's (the dual basis and nts coincide on a
    flat rigid wall; the standard basis's corner pressures differ by 30 % of the largest,
    its total force by 1e-4)."""
    sol = solve(frictional("heated_block"), method, basis=basis)
    check_law(sol)
    fr = sol.friction
    assert fr is not None
    assert np.any(fr.status == Status.STICK) and np.any(fr.status == Status.SLIP)
    reference = solve(frictional("heated_block"), "nts")
    np.testing.assert_allclose(wall_forces(sol), wall_forces(reference), rtol=1e-3)
    # Friction adds to the frictionless walls' force E alpha dT / (1 - nu) H = 1.4286.
    assert np.all(wall_forces(sol) > 1.01 * 1.4285714285714286)


def test_heated_block_penalty_converges_to_the_multipliers() -> None:
    """The penalty's regularized law (damped as the multipliers) on the heated block: the
    multipliers' statuses, and pressures and shears that approach theirs like 1 / eps
    (2.1e-3 of the largest pressure at the default eps, 2.1e-4 at ten times it)."""
    scene = frictional("heated_block")
    sol = solve(scene, "mortar")
    assert sol.friction is not None
    scale = sol.pressure.max()
    default = solve(scene, "penalty")
    assert default.penalty is not None
    stiff = solve(scene, "penalty", penalty=10.0 * default.penalty.eps)
    gaps = []
    for pen in (default, stiff):
        assert pen.friction is not None
        np.testing.assert_array_equal(pen.friction.status, sol.friction.status)
        gaps.append(np.abs(pen.pressure - sol.pressure).max() / scale)
        assert np.abs(pen.friction.shear - sol.friction.shear).max() < gaps[-1]
    assert gaps[0] < 3e-3 and gaps[1] < gaps[0] / 5.0


def test_heated_block_cycled_with_the_undamped_update(monkeypatch: pytest.MonkeyPatch) -> None:
    """What the damped step is for: with every step taken in full the sets cycle."""
    monkeypatch.setattr(friction_method, "damped_length", lambda *args, **kw: (1.0, 0.0, 0.0))
    with pytest.raises(ActiveSetError, match="cycles"):
        solve(frictional("heated_block"), "mortar")


@pytest.mark.parametrize("method", ["mortar", "penalty"])
def test_shrink_fit_has_no_shear(method: str) -> None:
    """Lame's shrink fit has no tangential motion: with friction every contact node sticks,
    the shear is zero up to the discretization (4e-5 of mu p measured) and the pressures
    are the frictionless ones. Before, the rows on the two symmetry lines slipped with
    |shear| = mu p."""
    sol = solve(frictional("shrink_fit"), method)
    check_law(sol)
    fr = sol.friction
    assert fr is not None
    plain = solve(frictional("shrink_fit", 0.0), method)
    scale = plain.pressure.max()
    assert np.all(fr.status == Status.STICK)
    assert np.abs(fr.shear).max() < 1e-3 * MU * scale
    np.testing.assert_allclose(sol.pressure, plain.pressure, rtol=0, atol=1e-5 * scale)


@pytest.mark.parametrize(
    ("method", "basis"), [("mortar", "standard"), ("mortar", "dual"), ("nts", "standard")]
)
def test_long_hub_mid_plane_carries_no_shear(method: str, basis: str) -> None:
    """The axisymmetric long hub: the ends slip outwards, the middle sticks; the rows near the
    mid-plane (z < 1), where symmetry rules a shear out, carry less than 1 % of mu p (3e-4
    measured; the row on the mid-plane none), and the penalty's answer is the same to its
    known error, status for status."""
    scene = frictional("long_hub_axi")
    sol = solve(scene, method, basis=basis)
    check_law(sol)
    fr = sol.friction
    assert fr is not None
    z = sol.layout.x[:, 1]
    near = z < 1.0
    assert np.all(np.abs(fr.shear[near]) < 1e-2 * MU * sol.pressure[near])
    assert fr.shear[np.argmin(z)] == 0.0
    assert np.all(fr.status[near] == Status.STICK)
    assert fr.status[np.argmax(z)] == Status.SLIP
    penalty = solve(scene, method, enforcement="penalty")  # the standard basis
    assert penalty.friction is not None
    np.testing.assert_array_equal(fr.status, penalty.friction.status)
    scale = sol.pressure.max()
    if basis == "standard":  # the penalty takes the standard basis
        assert np.abs(sol.pressure - penalty.pressure).max() < PENALTY_ERROR * scale
        assert np.abs(fr.shear - penalty.friction.shear).max() < PENALTY_ERROR * scale
