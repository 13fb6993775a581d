"""The adaptive loop's records (contactfx/adapt/records.py): options validated on
construction, `tol` the goal's relative error or None (the budget decides), one weight rule,
adapt.json named by the request. No solve: these are cheap."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from contactfx.adapt.goal import GOAL_MEANING, Goal
from contactfx.adapt.planned import BUDGET_FILL, MIN_LEVELS, plan_growth
from contactfx.adapt.records import (
    RESIDUAL_GROWTH,
    RESIDUAL_WEIGHT,
    AdaptOptions,
    AdaptResult,
    default_tol,
)
from contactfx.errors import InputError
from contactfx.request import SolveRequest


@pytest.mark.parametrize(
    ("kwargs", "option"),
    [
        ({"tol": 0.0}, "--tol"),
        ({"tol": -1.0}, "--tol"),
        ({"growth": 1.0}, "--growth"),
        ({"max_dofs": 5}, "--max-dofs"),
        ({"contact_weight": 0.5}, "--weight-contact"),
        ({"max_levels": 0}, "--max-levels"),
        ({"goal": Goal.RESIDUAL, "pressure_tol": 0.0}, "--pressure-tol"),
        ({"pressure_tol": 0.01}, "--pressure-tol"),  # the pressure goal sizes itself
        ({"fallback": Goal.PRESSURE}, "fallback"),
    ],
)
def test_options_are_validated_on_construction(kwargs: dict, option: str) -> None:
    """One InputError naming the option, from the constructor (no check() to forget)."""
    with pytest.raises(InputError, match=option):
        AdaptOptions(**kwargs)


def test_tol_is_the_goals_relative_error_or_none() -> None:
    """tol None: no tolerance, the budget decides (the residual goal never stops on it; the
    goal estimates spread the budget as far as a tolerance of 1e-12 did)."""
    assert default_tol(Goal.PRESSURE) == default_tol(Goal.ENERGY) == 0.01
    assert default_tol(Goal.RESIDUAL) == 0.05
    est = SimpleNamespace(relative=1e-12, pressure=None)
    assert AdaptOptions(Goal.RESIDUAL, None).met(est) is None  # type: ignore[arg-type]
    assert AdaptOptions(Goal.RESIDUAL, 1e-9).met(est) is not None  # type: ignore[arg-type]
    room = BUDGET_FILL * 60_000 / 1000
    free = plan_growth([(1000, 0.3)], None, 60_000, Goal.PRESSURE)
    assert free == pytest.approx(room ** (1 / (MIN_LEVELS - 1)))
    assert free == plan_growth([(1000, 0.3)], 1e-12, 60_000, Goal.PRESSURE)


def test_one_weight_rule() -> None:
    """The residual goal weights the contact terms (unless the pressure sizing is on); the
    goal estimates do not; a given weight wins."""
    assert AdaptOptions(Goal.RESIDUAL, 0.05).weight == RESIDUAL_WEIGHT
    assert AdaptOptions(Goal.RESIDUAL, 0.05, pressure_tol=0.01).weight == 1.0
    assert AdaptOptions(Goal.PRESSURE).weight == AdaptOptions(Goal.ENERGY).weight == 1.0
    assert AdaptOptions(Goal.ENERGY, contact_weight=3.0).rule.contact_weight == 3.0


def test_adapt_json_names_the_request_and_the_goal_stopped_on() -> None:
    """The method and solver as the request resolved them (not the user's strings); the goal
    the loop stopped on beside the one asked for, and why."""
    request = SolveRequest.parse("nts", enforcement="penalty")
    result = AdaptResult([], "stop", Goal.ENERGY, "the pressure goal is unbounded")
    data = result.to_json("punch.toml", request, AdaptOptions())
    assert data["method"] == "penalty-nts" == request.label
    assert data["settings"]["solver"] == request.solver.name
    assert data["settings"]["goal"] == "pressure" and data["settings"]["fallback"] == "energy"
    assert data["goal"] == "energy" and data["goal_meaning"] == GOAL_MEANING[Goal.ENERGY]
    assert data["goal_note"] == "the pressure goal is unbounded"


def test_one_home_for_the_growth() -> None:
    """`growth` on the options: given, x 4 for the residual goal, planned (None) otherwise;
    adapt.json records the one the loop uses."""
    assert AdaptOptions(Goal.RESIDUAL, 0.05).level_growth == RESIDUAL_GROWTH
    assert AdaptOptions(Goal.RESIDUAL, 0.05, growth=2.0).level_growth == 2.0
    assert AdaptOptions(Goal.PRESSURE).level_growth is None
    assert AdaptOptions(Goal.ENERGY, growth=3.0).settings()["growth"] == 3.0
