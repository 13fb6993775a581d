"""MUMPS' block low-rank (BLR) factorization: approximate factors, full-rank answers.

The factors are compressed at a relative threshold, so no single back-substitution with them
is an answer: every accepted solve must reach the full-rank path's answer. The mesh is the
smallest structured Hertz mesh of the 10H family on which MUMPS compresses (a 2D front must
be a few hundred variables wide): a loose threshold there needs many GMRES iterations.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from contactfx import solve
from contactfx.linalg.saddle import SaddleSolver
from contactfx.methods.multipliers import floor_spec
from contactfx.methods.solvers import BLR_KEYS, with_low_rank
from contactfx.options import SOLVERS, LowRank
from contactfx.scenes import HertzParams, build_scene

H = 0.031734  # 266,768 DOFs (docs/scale.md, "Block low-rank factorization")


@pytest.fixture(scope="module")
def scene():
    """The structured Hertz mesh of the 10H family at H."""
    return build_scene("hertz", HertzParams(mesh="structured", refine=H, h_far=10 * H))


@pytest.fixture(scope="module")
def full(scene):
    """The full-rank default's answer: the reference."""
    return solve(scene, "mortar", solver="mumps")


def _same_answer(sol, ref) -> None:
    """The same active set; pressures and displacements within 1e-8 of their maxima."""
    assert np.array_equal(sol.active, ref.active)
    dp = np.abs(sol.pressure - ref.pressure).max() / np.abs(ref.pressure).max()
    du = np.abs(sol.u.x.array - ref.u.x.array).max() / np.abs(ref.u.x.array).max()
    assert dp <= 1e-8 and du <= 1e-8, (dp, du)


def _first_step_iterations(sol) -> int:
    return int(sol.history[0]["linear_iterations"])


@pytest.mark.parametrize("tolerance", [1e-8, 1e-2])
def test_low_rank_gives_the_full_rank_answer(scene, full, tolerance, caplog) -> None:
    """BLR at the preset's threshold and at a deliberately loose one: the full-rank answer.

    At 1e-8 no single back-substitution with the compressed factors is accepted (the
    full-rank step takes one): GMRES runs (its count depends on the compression, so only
    "more than one" is asserted). At 1e-2 GMRES does not converge on
    them: the solver refactors at full rank, and says so.
    """
    spec = replace(SOLVERS["mumps-blr"], low_rank=LowRank(0, tolerance))
    with caplog.at_level("INFO", logger="contactfx"):
        sol = solve(scene, "mortar", solver=spec)
    _same_answer(sol, full)
    assert _first_step_iterations(full) == 1
    fell_back = "GMRES on the factorization failed" in caplog.text
    assert fell_back is (tolerance == 1e-2)
    if not fell_back:
        assert _first_step_iterations(sol) > 1


def test_low_rank_by_petsc_options_is_refined_too(scene, full) -> None:
    """BLR asked for by PETSc options on the default (the lead's run): read from the factor."""
    spec = SOLVERS["mumps"].with_petsc(["mat_mumps_icntl_35=2", "mat_mumps_cntl_7=1e-6"])
    sol = solve(scene, "mortar", solver=spec)
    _same_answer(sol, full)
    assert _first_step_iterations(sol) > 1  # GMRES, not one back-substitution


def test_a_throwaway_solver_on_compressed_factors_runs_gmres(scene) -> None:
    """A solver without reuse (preonly) on BLR factors switches to GMRES.

    Its true residual reaches the full-rank back-substitution's (round-off: eps |A| |x|,
    far above GMRES's own estimate of 1e-13), where the compressed factors alone leave one
    far above it.
    """
    from contactfx.contact import Kernel
    from contactfx.discretize.setup import prepare_contact
    from contactfx.methods.active_set import ActiveSetOptions
    from contactfx.timers import Timers

    setup = prepare_contact(scene, Kernel.MORTAR, ActiveSetOptions().penetration_tol, Timers())
    el, every = setup.elasticity, np.ones(len(setup.g), dtype=bool)
    results, residual = {}, {}
    for name, extra in (("full", {}), ("blr", {BLR_KEYS[0]: 2, BLR_KEYS[1]: 1e-6})):
        options = {**SOLVERS["mumps"].petsc, **extra}
        with SaddleSolver(el.K, setup.B, el.f, options, direct=True) as solver:
            results[name] = solver.solve(setup.g, every)
            assert solver.approximate is (name == "blr")
            assert solver._ksp.getType() == ("gmres" if name == "blr" else "preonly")
            m = solver._m
            residual[name] = m.residual(m.x)[1]
            if name == "blr":  # one back-substitution with the compressed factors
                solver._ksp.getPC().apply(m.b, m.x)
                residual["single"] = m.residual(m.x)[1]
    # Round-off class, with room for another BLAS; one compressed back-substitution is
    # orders of magnitude above it (docs/scale.md, "Block low-rank factorization").
    assert residual["blr"] <= 10.0 * residual["full"]
    assert residual["single"] >= 1e4 * residual["blr"]
    assert results["blr"].iterations > 1
    dmu = np.abs(results["blr"].mu - results["full"].mu).max()
    assert dmu <= 1e-8 * np.abs(results["full"].mu).max()
    setup.destroy()


def test_low_rank_rule_and_full_rank_floors() -> None:
    """BLR keys from `from_dofs` on, MUMPS only, never over given keys; floors full rank."""
    mumps = SOLVERS["mumps"].petsc
    low = LowRank(from_dofs=1000, tolerance=1e-7, variant=3)
    assert not any(k in with_low_rank(mumps, low, 999) for k in BLR_KEYS)
    on = with_low_rank(mumps, low, 1000)
    assert (on[BLR_KEYS[0]], on[BLR_KEYS[1]]) == (3, 1e-7)
    given = {**mumps, BLR_KEYS[1]: 0.0}
    assert with_low_rank(given, low, 1000) == given
    assert with_low_rank(SOLVERS["condensed"].petsc, low, 1000) == SOLVERS["condensed"].petsc
    by_hand = SOLVERS["mumps"].with_petsc(["mat_mumps_icntl_35=2", "mat_mumps_cntl_7=1e-8"])
    for spec in (SOLVERS["mumps-blr"], by_hand):
        floor = floor_spec(spec, "lu")
        assert floor.low_rank is None and not any(k in floor.petsc for k in BLR_KEYS)
        assert floor.petsc["pc_type"] == "lu"
