"""The goal estimates (contactfx/adapt/goal.py): a patch test, Hertz effectivity, refusals."""

from __future__ import annotations

import numpy as np
import pytest

import contactfx
from contactfx.adapt.curves import WINDOW, peak_exponent, singular_growth, window_peak
from contactfx.adapt.goal import (
    Goal,
    GoalUnbounded,
    goal_estimate,
    pressure_difference,
    refined_field,
    zone_halvings,
)
from contactfx.adapt.true_error import energy_error
from contactfx.results.references import hertz_summary
from contactfx.scenes import BlockParams, HertzParams, blocks, hertz


def test_patch_test_pressure_estimate_is_round_off() -> None:
    """Equal widths: mortar's pressure is the uniform one on both meshes, so they agree."""
    sol = contactfx.solve(blocks(BlockParams(l2=10.0, size1=0.5, size2=0.4)), "mortar")
    g = goal_estimate(sol, Goal.PRESSURE)
    assert g.goal is Goal.PRESSURE
    assert g.dofs > sol.dofs  # the refined mesh is another, finer one
    assert g.relative < 1e-10, g.parts


def test_pressure_difference_is_exact_for_piecewise_linear() -> None:
    """Two hat functions on different nodes: the L2 difference against a fine quadrature."""
    coarse = (np.array([0.0, 1.0, 2.0]), np.array([0.0, 1.0, 0.0]))
    fine = (np.array([0.0, 0.7, 1.3, 2.0]), np.array([0.0, 0.9, 0.8, 0.0]))
    d, n = pressure_difference(coarse, fine)
    s = np.linspace(0.0, 2.0, 400001)
    pc, pf = np.interp(s, *coarse), np.interp(s, *fine)
    assert d == pytest.approx(np.sqrt(np.trapezoid((pc - pf) ** 2, s)), rel=1e-8)
    assert n == pytest.approx(np.sqrt(np.trapezoid(pf**2, s)), rel=1e-8)


def test_radial_pressure_difference_is_the_revolved_l2_norm() -> None:
    """Axisymmetric: weighted by the radius x (linear along each segment), exactly."""
    coarse = (np.array([0.0, 1.0, 2.0]), np.array([2.0, 1.0, 0.0]), np.array([0.0, 1.0, 2.0]))
    fine = (
        np.array([0.0, 0.7, 1.3, 2.0]),
        np.array([2.1, 1.2, 0.8, 0.0]),
        np.array([0.0, 0.7, 1.3, 2.0]),
    )
    d, n = pressure_difference(coarse, fine, radial=True)
    s = np.linspace(0.0, 2.0, 400001)
    pc, pf = np.interp(s, *coarse[:2]), np.interp(s, *fine[:2])
    assert d == pytest.approx(np.sqrt(np.trapezoid((pc - pf) ** 2 * s, s)), rel=1e-8)
    assert n == pytest.approx(np.sqrt(np.trapezoid(pf**2 * s, s)), rel=1e-8)


def test_refined_field_halves_only_near_contact() -> None:
    """Pressure goal: the contact band at half size, the far field untouched."""
    sol = contactfx.solve(hertz(HertzParams(refine=0.2, h_far=10.0, refine_edge=0.0)), "mortar")
    field = refined_field(sol)
    uniform = refined_field(sol, near=1.0)
    ratio = field.sizes / uniform.sizes
    assert ratio.min() == pytest.approx(0.5, rel=1e-5)
    assert np.median(ratio) == pytest.approx(1.0)


def test_refined_field_refines_the_zone_edge_further() -> None:
    """`edge`: the cells around the segment the zone ends in get that factor, no others."""
    sol = contactfx.solve(hertz(HertzParams(refine=0.2, h_far=10.0, refine_edge=0.0)), "mortar")
    plain = refined_field(sol)
    field = refined_field(sol, edge=0.125)
    ratio = field.sizes / plain.sizes
    assert ratio.min() == pytest.approx(0.25, rel=1e-5)  # the edge's 0.125 over the band's 0.5
    # Where the sizes changed: around x = a (the zone's edge, Hertz's exact a below), within
    # EDGE_CELLS of the edge segment's length (0.2 here) of its ends, and a vertex more.
    changed = field.quads[np.any(np.abs(ratio - 1.0) > 1e-9, axis=1)].reshape(-1, 2)
    assert changed.size
    a = hertz_summary(sol).a_exact
    assert np.all(np.abs(changed[:, 0] - a) <= 0.2 * (1 + 2.0) + 2 * 0.2), changed[:, 0]


@pytest.mark.parametrize("refine", [0.1, 0.05, 0.025])
def test_hertz_pressure_effectivity(refine: float) -> None:
    """Ungraded Hertz starts: estimate / exact L2 pressure error within [0.9, 2]."""
    scene = hertz(HertzParams(refine=refine, h_far=10.0, refine_edge=0.0, slope=0.3))
    sol = contactfx.solve(scene, "mortar")
    exact = hertz_summary(sol).l2_error
    g = goal_estimate(sol, "pressure")
    assert 0.9 <= g.relative / exact <= 2.0, (g.relative, exact)


def test_unresolved_zone_is_refined_until_resolved() -> None:
    """Two loaded segments (contact size 1): halving once left the error at 0.83 of the
    level's and the estimate at 2.06 x the error; the zone is quartered instead."""
    sol = contactfx.solve(hertz(HertzParams(refine=1.0, h_far=10.0, refine_edge=0.0)), "mortar")
    assert zone_halvings(sol) == 2
    g = goal_estimate(sol, Goal.PRESSURE)
    assert g.halvings == 2 and g.record().to_json()["goal_halvings"] == 2
    exact = hertz_summary(sol).l2_error
    assert 0.9 <= g.relative / exact <= 2.0, (g.relative, exact)
    assert hertz_summary(g.reference).l2_error < 0.5 * exact
    # A resolved zone is halved once, as before.
    fine = contactfx.solve(hertz(HertzParams(refine=0.1, h_far=10.0, refine_edge=0.0)), "mortar")
    assert zone_halvings(fine) == 1


def test_singular_pressure_is_refused() -> None:
    """A rigid flat punch: the peak grows like 1/sqrt, the L2 goal does not exist."""
    scene = contactfx.load_scene_file("demos/scenes/rigid_punch.toml")
    sol = contactfx.solve(scene, "nts")
    with pytest.raises(GoalUnbounded, match="--goal energy or --goal force"):
        goal_estimate(sol, Goal.PRESSURE, options={})


def test_hertz_energy_effectivity() -> None:
    """Coarse Hertz: estimate / energy error against an overkill solve within [1, 3]."""
    sol = contactfx.solve(hertz(HertzParams(refine=0.4, h_far=10.0, refine_edge=0.0)), "mortar")
    over = contactfx.solve(sol.scene.remeshed_to(refined_field(sol, far=0.25, near=0.25)), "mortar")
    true = energy_error(sol, over)
    assert true is not None
    g = goal_estimate(sol, Goal.ENERGY)
    assert 1.0 <= g.relative / true["relative"] <= 3.0, (g.relative, true)


def _sampled(profile, h: float) -> tuple[np.ndarray, np.ndarray]:
    """A pressure profile on [0, 1] sampled every h (the edge at s = 1)."""
    s = np.arange(0.0, 1.0 + h / 2, h)
    return s, profile(s)


def test_one_spiking_node_does_not_make_a_singularity() -> None:
    """Hertz-like sqrt(1 - s^2) with one node x 1000 on the middle mesh (a node beside the
    end of a passive surface): the node's peak jumps on one refinement and falls on the
    next; the windowed peak counts the spike 1/WINDOW; neither is a sustained growth."""
    nodal, windowed = [], []
    for k, h in enumerate([0.1, 0.05, 0.025]):
        s, p = _sampled(lambda s: np.sqrt(np.maximum(1.0 - s * s, 0.0)), h)
        if k == 1:
            p[len(p) // 2] *= 1000.0
        nodal.append((float(np.max(p)), h))
        windowed.append(window_peak(s, p))
    assert peak_exponent(nodal[0], nodal[1]) > 5  # one refinement alone would say singular
    assert singular_growth(nodal) is None and singular_growth(windowed) is None
    assert windowed[1][0] < 1000.0 / WINDOW + 1.0
    smooth = [window_peak(*_sampled(np.cos, h)) for h in (0.1, 0.05, 0.025)]
    assert singular_growth(smooth) is None


def test_growth_over_two_refinements_is_singular() -> None:
    """A flat punch's 1/sqrt edge: the windowed peak grows like h^-1/2 on both refinements,
    whatever the corner node itself carries."""
    edge = lambda s: 1.0 / np.sqrt(np.maximum(1.0 - s, 0.0) + 1e-300)  # noqa: E731
    peaks = []
    for h in (0.1, 0.05, 0.025):
        s, p = _sampled(edge, h)
        p[-1] = 2.0 / np.sqrt(h)  # the corner node: its share of the corner's load
        peaks.append(window_peak(s, p))
    exponents = singular_growth(peaks)
    assert exponents is not None and exponents == pytest.approx([0.5, 0.5], abs=0.05)
    # One refinement is not enough to judge.
    assert singular_growth(peaks[:2]) is None
    # Growth on one refinement, none on the next: bounded.
    assert singular_growth([peaks[0], peaks[1], (peaks[1][0], peaks[2][1])]) is None
