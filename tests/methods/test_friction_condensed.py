"""Coulomb friction on both solver paths: the direct LU and the condensed dual path agree.

The condensed path (linalg/condensed_friction.py) eliminates the dual-mortar multipliers
node by node and solves an unsymmetric displacement system by GMRES to rtol 1e-9; the direct
path factors the saddle point (methods/friction_linear.py). Independent linear algebra on
the same sets: the statuses must be identical and the pressures and shears equal to the
iterative solve's tolerance. Scenes of tests/methods/test_friction.py.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from test_friction import MU, P, check_coulomb, forces, patch, pushed, stepped

from contactfx import solve
from contactfx.contact.friction import Status
from contactfx.methods.solution import Solution
from contactfx.scenes import Scene

# GMRES stops at rtol 1e-9 of ||b||: pressures and shears agree with the LU's to 1e-7 P.
AGREE = 1e-7 * P

SCENES: dict[str, Callable[[], Scene]] = {
    "patch-stick": lambda: patch(2.0, 0.0),
    "patch-slip": lambda: patch(MU * P, 0.01),
    # Pressed, pushed a little (the middle sticks), then far (every contact node slips).
    "pushed-stick-then-slip": lambda: stepped(MU, [0.04, 1.0]),
}


def steps_of(sol: Solution) -> list[Solution]:
    """The load steps' solutions (the solution itself without steps)."""
    return sol.steps or [sol]


@pytest.mark.parametrize("name", sorted(SCENES))
def test_condensed_friction_equals_the_direct_solve(name: str) -> None:
    """Same statuses in every step, pressures and shears to the GMRES tolerance; Coulomb's
    law holds on the condensed answer itself."""
    direct = solve(SCENES[name](), "mortar", basis="dual", solver="mumps")
    condensed = solve(SCENES[name](), "mortar", basis="dual", solver="condensed")
    assert len(steps_of(direct)) == len(steps_of(condensed))
    before = None
    for a, b in zip(steps_of(direct), steps_of(condensed), strict=True):
        assert a.friction is not None and b.friction is not None
        np.testing.assert_array_equal(b.friction.status, a.friction.status)
        np.testing.assert_allclose(b.pressure, a.pressure, rtol=0, atol=AGREE)
        np.testing.assert_allclose(b.friction.shear, a.friction.shear, rtol=0, atol=AGREE)
        check_coulomb(b, MU, before)
        before = b
    if name.startswith("patch"):
        # The uniform state, exact in Q1: the patch test's 1e-8 at every node (as the LU).
        tau = 2.0 if name == "patch-stick" else MU * P
        assert condensed.friction is not None
        np.testing.assert_allclose(condensed.pressure, P, rtol=1e-8)
        np.testing.assert_allclose(condensed.friction.shear, tau, rtol=1e-8)
    else:
        stick, slip = steps_of(condensed)[1:]
        assert stick.friction is not None and slip.friction is not None
        assert np.sum(stick.friction.status == Status.STICK) >= 3
        assert np.all(slip.friction.status[slip.active] == Status.SLIP)
        assert forces(slip)[1] == pytest.approx(MU * forces(slip)[0], rel=1e-8)


def test_vanishing_mu_on_condensed_gives_the_frictionless_condensed_solve() -> None:
    """mu = 1e-12 runs the frictional condensed path (GMRES, node blocks); its set and
    pressures are the frictionless condensed solver's (CG on its own elimination)."""
    frictionless = solve(pushed(0.0, 0.002), "mortar", basis="dual", solver="condensed")
    assert frictionless.friction is None
    tiny = solve(pushed(1e-12, 0.002), "mortar", basis="dual", solver="condensed")
    assert tiny.friction is not None
    np.testing.assert_array_equal(tiny.active, frictionless.active)
    np.testing.assert_allclose(tiny.pressure, frictionless.pressure, rtol=0, atol=AGREE)
    assert np.abs(tiny.friction.shear).max() < 1e-9 * P


def test_condensed_sets_are_solved_loosely_until_stationary(monkeypatch) -> None:
    """Each load step's last set is solved to the final tolerance, the sets before it only
    to the loop's loose one (their answers only decide the next set); the answers above
    equal the LU's all the same."""
    from contactfx.linalg.condensed_friction import FrictionCondensedSolver

    runs: list[tuple[bool, int]] = []
    solve_sets = FrictionCondensedSolver.solve_sets

    def spy(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        r = solve_sets(self, *args, **kwargs)
        runs.append((r.final, r.iterations))
        return r

    monkeypatch.setattr(FrictionCondensedSolver, "solve_sets", spy)
    sol = solve(SCENES["pushed-stick-then-slip"](), "mortar", basis="dual", solver="condensed")
    iterations = [len(s.history) for s in steps_of(sol)]
    assert len(runs) == sum(iterations)
    ends = np.cumsum(iterations) - 1
    finals = np.array([f for f, _ in runs])
    assert finals[ends].all()  # every step ends on a final answer
    loose = np.delete(finals, ends)
    assert loose.size > 0 and not loose.any()  # and solved every set before it loosely
