"""Block scenes S1-S4: equilibrium, the contact patch test, and the methods' known errors."""

from dataclasses import replace

import numpy as np
import pytest
from conftest import MULTIPLIER_METHODS

from contactfx import SolveRequest
from contactfx.api import run_case
from contactfx.results.paper import patch_errors
from contactfx.results.stress import body_stress_deviation
from contactfx.scenes import BLOCK_SCENES

METHODS = [m.value for m in MULTIPLIER_METHODS]
S4 = BLOCK_SCENES["S4"]
P = S4.p


@pytest.mark.parametrize("active", [1, 2])
def test_patch_test_matching_meshes(multiplier_method: str, active: int) -> None:
    """Equal widths and matching uniform meshes: every method gives sigma_yy = -p exactly."""
    params = replace(S4, size1=0.125, size2=0.125, grading1=1.0, grading2=1.0)
    sol, data = run_case("blocks", params, SolveRequest.parse(multiplier_method), active=active)
    data = data.to_json()
    dev = body_stress_deviation(sol, -P)
    assert dev["body1"] < 1e-8 and dev["body2"] < 1e-8
    assert patch_errors(data["interface"], P)["pressure"] < 1e-8


@pytest.mark.parametrize("scene", list(BLOCK_SCENES))
def test_contact_force_equals_load(scene: str, multiplier_method: str) -> None:
    """The top block is held only by contact, so the contact force is the whole load p*l2/2."""
    params = BLOCK_SCENES[scene]
    _, data = run_case("blocks", params, SolveRequest.parse(multiplier_method))
    data = data.to_json()
    assert data["contact_force"] == pytest.approx(params.p * params.l2 / 2, rel=1e-10)
    assert data["iterations"] == 1


@pytest.mark.parametrize("active", [1, 2])
@pytest.mark.parametrize("graded", [False, True])
def test_mortar_passes_patch_test_on_nonmatching_meshes(active: int, graded: bool) -> None:
    """Segment-based mortar reproduces the uniform state to round-off (SPEC S4 bar: 1e-8)."""
    params = S4 if graded else replace(S4, grading1=1.0, grading2=1.0)
    sol, data = run_case("blocks", params, SolveRequest.parse("mortar"), active=active)
    data = data.to_json()
    dev = body_stress_deviation(sol, -P)
    assert max(dev.values()) < 1e-8
    assert patch_errors(data["interface"], P)["pressure"] < 1e-8


# Measured on the paper's S4 meshes (0.12 / 0.15 cm, graded): the failures are physics, not bugs.
# NTS collocates nodal forces, so the fine passive mesh gets point loads; STS integrates across
# passive nodes with a smooth-integrand rule. The mesh is fixed, so these numbers are
# deterministic: they are checked to rel 1e-3, and any change of behaviour shows.
KNOWN_S4_ERRORS = {
    # (method, active): (body 1, body 2, pressure), max relative deviations from the exact state
    ("nts", 2): (8.3503e-1, 3.0379e-2, 2.3586e-2),
    ("nts", 1): (1.7569e-1, 1.6193e-2, 1.4879e-1),
    ("sts", 2): (4.8847e-2, 1.1686e-3, 2.0912e-3),
    ("sts", 1): (2.0107e-2, 2.0964e-3, 3.3745e-2),
}


@pytest.mark.parametrize(("method", "active"), list(KNOWN_S4_ERRORS))
def test_nts_and_sts_fail_patch_test_by_known_amount(method: str, active: int) -> None:
    """NTS and STS do not pass the non-matching patch test; their errors keep a known size."""
    sol, data = run_case("blocks", S4, SolveRequest.parse(method), active=active)
    data = data.to_json()
    dev = body_stress_deviation(sol, -P)
    measured = (dev["body1"], dev["body2"], patch_errors(data["interface"], P)["pressure"])
    for got, known in zip(measured, KNOWN_S4_ERRORS[(method, active)], strict=True):
        assert got == pytest.approx(known, rel=1e-3)


def test_s1_methods_agree_away_from_corner() -> None:
    """S1 (matching meshes): the methods agree to 0.1 % away from the corner (paper: ~5th digit).

    The stresses agree to round-off on the outer 90 % of the line. NTS's pressure is a lumped
    nodal force per tributary length while STS and mortar interpolate a traction field; the two
    differ by O(h^2 p''), which the corner singularity makes large on its last few elements, so
    the pressure is compared on the inner two thirds.
    """
    params = BLOCK_SCENES["S1"]
    results = {
        m: run_case("blocks", params, SolveRequest.parse(m))[1].to_json()["interface"]
        for m in METHODS
    }
    x = np.asarray(results["nts"]["x"])
    corner = params.l2 / 2
    for key, zone in (("sigma_yy_1", 0.9), ("sigma_yy_2", 0.9), ("pressure", 2 / 3)):
        far = x < zone * corner
        ref = np.asarray(results["mortar"][key], dtype=float)[far]
        for m in ("nts", "sts"):
            other = np.asarray(results[m][key], dtype=float)[far]
            assert np.max(np.abs(other / ref - 1)) < 1e-3, (key, m)
