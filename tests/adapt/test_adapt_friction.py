"""adapt on a frictional scene: what it bounds, the residual's shear term, the effectivities.

tests/scenes/cattaneo_mirrored.toml at size factor 4 (a/h = 50, 2,484 DOFs; pressed, then
pushed to Q / mu P = 0.62), mortar, one level of the pressure goal (its refined solve
included, about 5 s). The truth: Hertz's pressure under the pair's force (Cattaneo-Mindlin's)
and Cattaneo-Mindlin's closed-form shear. Measured (`python benchmarks/adapt_friction.py
--factors 4 --levels 3`, benchmarks/adapt_friction_f4.json; docs/adapt.md, "With friction"):

| level | DOFs | pressure est. / true | eff. | shear est. / true | eff. |
|---|---|---|---|---|---|
| 0 | 2,484 | 12.6 / 2.61 % | 4.83 | 22.8 / 5.00 % | 4.56 |
| 1 | 20,624 | 0.945 / 0.602 % | 1.57 | 2.32 / 1.60 % | 1.46 |
| 2 | 163,924 | 0.359 / 0.393 % | 0.91 | 0.817 / 0.87 % | 0.94 |

(at level 2 the true errors flatten on the half-space theory's own distance from the finite
cylinders). Level 0 is asserted here: both effectivities in [4.4, 5.2], the band that holds
the two measured values 4.56 and 4.83 with a 4-8 % margin for the mesh generator's
round-off; the estimates are deterministic for a given gmsh, the band is not a pin.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

from contactfx.adapt.estimate import estimate
from contactfx.adapt.goal import FRICTION_MEANING
from contactfx.adapt.loop import adapt
from contactfx.adapt.records import AdaptOptions, AdaptResult
from contactfx.request import SolveRequest
from contactfx.scenes.scene_file import load_scene_file

SCENE = ROOT / "tests" / "scenes" / "cattaneo_mirrored.toml"
BAND = (4.4, 5.2)


@pytest.fixture(scope="module")
def run() -> tuple[AdaptResult, list[str]]:
    lines: list[str] = []
    scene = load_scene_file(SCENE, size_factor=4.0)
    opts = AdaptOptions(tol=None, max_levels=1)
    return adapt(scene, SolveRequest.parse("mortar"), opts, say=lines.append), lines


def test_it_says_what_it_bounds(run: tuple[AdaptResult, list[str]]) -> None:
    result, lines = run
    assert f"friction: {FRICTION_MEANING}" in lines
    assert "the shear is not bounded" in FRICTION_MEANING
    data = result.to_json("cattaneo_mirrored", SolveRequest.parse("mortar"), AdaptOptions())
    assert data["friction"] == FRICTION_MEANING and data["goal"] == "pressure"
    level = data["levels"][0]
    assert level["shear_estimate"] > 0 and level["exact_shear_error"] > 0
    assert "shear estimate" in lines[-2] and "not bounded" in lines[-2]


def test_effectivities_lie_in_the_measured_band(run: tuple[AdaptResult, list[str]]) -> None:
    (level,) = run[0].levels
    assert level.goal is not None and level.dofs == 2484
    p_true, s_true = level.exact_error, level.exact_shear_error
    assert p_true is not None and s_true is not None
    shear = level.goal.shear_estimate
    assert shear is not None
    assert BAND[0] < level.goal.relative / p_true < BAND[1]
    assert BAND[0] < shear / s_true < BAND[1]


def test_the_residual_reads_the_shear(run: tuple[AdaptResult, list[str]]) -> None:
    """The tangential term compares sigma_nt with the shear multiplier: with the shear's sign
    flipped (the multipliers' traction on each body turned the wrong way) it grows, and it
    is smaller than with the shear ignored (the frictionless estimator)."""
    (level,) = run[0].levels
    sol = level.solution
    assert sol.friction is not None and sol.steps[-1] is sol
    shear = sol.friction.shear.copy()
    term = {}
    for name, s in (("right", shear), ("ignored", 0.0 * shear), ("flipped", -shear)):
        sol.friction.shear[:] = s
        term[name] = estimate(sol).terms["tangential"]
    sol.friction.shear[:] = shear
    assert term["right"] == pytest.approx(level.est.terms["tangential"], rel=1e-12)
    assert term["right"] < term["ignored"] < term["flipped"]
    # The squared term is X + 2 (sigma_nt, s) + |s|^2 (weighted): the shear's own part |s|^2
    # and -(sigma_nt, s) agree where sigma_nt ~ -s (measured: 0.95 of it).
    r2, i2, f2 = (term[k] ** 2 for k in ("right", "ignored", "flipped"))
    own, cross = 0.5 * (r2 + f2) - i2, 0.25 * (f2 - r2)
    assert np.isclose(cross, own, rtol=0.1)
