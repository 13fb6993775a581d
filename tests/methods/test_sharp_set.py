"""The condensed solver's first set from the coarse predictor: zone edges from the pressures.

Issue 33: the former rule (every fine node within half a coarse element of a coarse active
node) left the zone 1-2 rows too wide or narrow at each edge, a whole CG solve per row; the
sharp rule estimates each edge from the coarse pressures (docs/scale.md, "An exact first
set").
"""

from __future__ import annotations

import numpy as np
import pytest

from contactfx import solve
from contactfx.methods.multipliers import solve_contact
from contactfx.methods.predictor import coarse_initial_set, sharp_initial_set
from contactfx.options import SolverKind
from contactfx.request import SolveRequest
from contactfx.scenes import BLOCK_SCENES, HertzParams, build_scene, hertz

CONDENSED_COARSE_FACTOR = SolverKind.CONDENSED.traits.coarse_factor


def coarse_and_fine(scene, method: str, basis: str):
    """The coarse predictor's MUMPS solution and the condensed solve of `scene`."""
    coarse = scene.remeshed(CONDENSED_COARSE_FACTOR)
    request = SolveRequest.parse(method, basis=basis, solver="mumps")
    coarse_sol = solve_contact(coarse, request)
    fine = solve(scene, method, basis=basis, solver="condensed")
    return coarse_sol, fine


@pytest.mark.parametrize(("method", "basis"), [("mortar", "dual"), ("nts", "standard")])
def test_structured_hertz_first_set_is_the_converged_one(method: str, basis: str) -> None:
    """Structured Hertz, 140k DOFs: the former rule's set was 2 rows wide (35 for 33, three
    solves); the sharp one is the converged set, and the loop takes one solve."""
    scene = hertz(HertzParams(refine=0.045, h_far=0.45, mesh="structured"))
    coarse, fine = coarse_and_fine(scene, method, basis)
    x = fine.layout.x
    sharp = sharp_initial_set(coarse, CONDENSED_COARSE_FACTOR).active(x)
    former = coarse_initial_set(coarse, margin=0.5).active(x)
    assert np.array_equal(sharp, fine.active)
    assert int(former.sum()) == int(fine.active.sum()) + 2
    assert not (fine.active & ~former).any()  # a superset: rows to release
    assert fine.iterations == 1


@pytest.mark.parametrize(
    "params", [HertzParams(refine=0.031734, h_far=0.31734), HertzParams(refine=0.005)]
)
def test_exact_start_on_gmsh_hertz_does_not_cycle(params: HertzParams) -> None:
    """gmsh Hertz, 136k / 23k DOFs, dual basis: from the exact set a loose solve added a row
    whose penetration is within its error and the next removed it again (a cycle error; the
    23k one failed so from the former rule's set too); the final tolerance decides it: one solve,
    MUMPS' converged set (docs/scale.md, "An exact first set")."""
    scene = hertz(params)
    sol = solve(scene, "mortar", basis="dual", solver="condensed")
    ref = solve(scene, "mortar", basis="dual", solver="mumps")
    assert np.array_equal(sol.active, ref.active)
    assert sol.iterations == 1


def test_a_set_left_on_a_loose_answer_may_be_met_again() -> None:
    """gmsh Hertz with the benchmarks' edge refinement, nts: the first loose solve released
    a row of the (exact) predicted set and the next step's final answer took it back, which
    was a cycle error; only final answers settle a set, so the loop goes on to MUMPS' set
    (docs/scale.md, "One CG run per stationary set")."""
    scene = hertz(HertzParams(refine=0.005, refine_edge=0.00125))
    sol = solve(scene, "nts", solver="condensed")
    ref = solve(scene, "nts", solver="mumps")
    assert np.array_equal(sol.active, ref.active)


@pytest.mark.parametrize("name", ["S1", "S4"])
def test_corner_edges_keep_their_step_count(name: str) -> None:
    """Flat blocks, whose zone edges are corners (the pressure rises towards them): the
    former rule's reach is kept there, and the loop still takes one solve."""
    scene = build_scene("blocks", BLOCK_SCENES[name])
    sol = solve(scene, "mortar", basis="dual", solver="condensed")
    ref = solve(scene, "mortar", basis="dual", solver="mumps")
    assert np.array_equal(sol.active, ref.active)
    assert sol.iterations == 1
