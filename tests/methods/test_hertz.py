"""Hertz scene (S5) against the exact plane-strain solution; the active-set loop's behaviour."""

import dolfinx_solver  # noqa: F401 - orders MPI ahead of the dolfinx bindings
import numpy as np
import pytest
from mpi4py import MPI

from contactfx.api import run_case
from contactfx.errors import InputError, SingularSystemError
from contactfx.methods.active_set import lcp_active_set
from contactfx.request import SolveRequest
from contactfx.results.references import exact_pressure, fit_half_width, l2_error
from contactfx.scenes import BlockParams, HertzParams, hertz_exact


def _graded(h: float, slope: float) -> HertzParams:
    """A coarse graded Hertz mesh: contact-edge size h, zone 4h, slope ~ sqrt(h)."""
    return HertzParams(refine=4 * h, refine_edge=h, slope=slope)


@pytest.fixture(scope="module")
def mortar_finest() -> dict:
    """Mortar's summary on the finest of the study's cheap levels (h_e = 0.01, 1933 cells).

    The rates over the three levels are asserted per method in tests/study/test_study.py.
    """
    return run_case(
        "hertz", _graded(0.01, 0.141), SolveRequest.parse("mortar"), comm=MPI.COMM_SELF
    )[1].to_json()


def test_exact_formulas_against_johnson() -> None:
    # SPEC: E* = 3695.49 MPa, a = 1.4378 cm, p0 = 44.28 MPa for the paper's parameters.
    ex = hertz_exact(HertzParams())
    assert ex["E_star"] == pytest.approx(3695.49, abs=0.01)
    assert ex["a"] == pytest.approx(1.4378, abs=1e-4)
    assert ex["p0"] == pytest.approx(44.28, abs=0.01)


def test_postprocessing_measures_on_the_exact_profile() -> None:
    a, p0 = 1.5, 40.0
    x = np.linspace(0.0, 1.4, 50)
    assert fit_half_width(x, exact_pressure(x, a, p0)) == pytest.approx(a, rel=1e-12)
    # Piecewise-linear interpolation of a sqrt edge: O(h) in L2, small but nonzero.
    xs = np.arange(0.0, 3.0, 0.01)
    err = l2_error(xs, exact_pressure(xs, a, p0), a, p0)
    assert 1e-4 < err < 3e-3
    assert l2_error(xs, 1.1 * exact_pressure(xs, a, p0), a, p0) == pytest.approx(0.1, rel=0.02)


def test_profile_matches_exact_on_coarse_graded_mesh(mortar_finest: dict) -> None:
    # 1933 elements: pointwise within 1.5 % of p0 away from the edge, edge bracket around a.
    data = mortar_finest
    assert data["elements"] < 2500
    hz = data["hertz"]
    x = np.array(data["interface"]["x"])
    p = np.array(data["interface"]["pressure"])
    inner = x < 0.9 * hz["a_exact"]
    pe = exact_pressure(x, hz["a_exact"], hz["p0_exact"])
    assert np.abs(p - pe)[inner].max() < 0.015 * hz["p0_exact"]
    lo, hi = hz["a_bracket"]
    assert lo - 0.02 < hz["a_exact"] < hi + 0.02
    assert abs(hz["a"] / hz["a_exact"] - 1) < 0.004
    assert abs(hz["p0"] / hz["p0_exact"] - 1) < 0.004
    assert hz["l2_error"] < 0.007
    # Equilibrium: the contact carries the whole load P/2 of the half model.
    assert data["contact_force"] == pytest.approx(50.0, rel=1e-8)


def test_active_set_iterations_bounded(multiplier_method: str) -> None:
    sol, data = run_case(
        "hertz", _graded(0.02, 0.2), SolveRequest.parse(multiplier_method), comm=MPI.COMM_SELF
    )
    data = data.to_json()
    assert data["iterations"] <= 4
    hist = data["active_set"]
    assert hist[-1]["entered"] == hist[-1]["left"] == 0
    assert hist[-1]["residual"] < 1e-10
    # The answer is the complementarity solution: no tension, no penetration.
    lam, gap = sol.pressure, sol.gap
    scale = np.abs(lam).max()
    assert lam.min() > -1e-10 * scale
    assert gap.min() > -1e-10
    assert np.abs(lam * gap).max() < 1e-10 * scale


def test_plain_update_needs_many_more_iterations() -> None:
    # The predictor is what makes it cheap: without it the same scene takes > 10 solves.
    from contactfx.methods.active_set import ActiveSetOptions
    from contactfx.methods.multipliers import solve_contact
    from contactfx.options import Method
    from contactfx.scenes import build_scene

    scene = build_scene("hertz", _graded(0.02, 0.2), comm=MPI.COMM_SELF)
    fast = solve_contact(scene, SolveRequest.parse(Method.MORTAR))
    slow = solve_contact(
        scene, SolveRequest.parse(Method.MORTAR), aso=ActiveSetOptions(probes=False)
    )
    assert fast.iterations <= 4 < 10 < slow.iterations
    assert np.array_equal(fast.active, slow.active)
    assert np.allclose(fast.pressure, slow.pressure, rtol=0, atol=1e-9 * fast.pressure.max())


def test_lcp_kernel_on_a_small_m_matrix() -> None:
    # Independent reference: enumerate all 2^4 active sets of a 4x4 LCP.
    k = np.array([[4.0, -1, 0, 0], [-1, 4, -1, 0], [0, -1, 4, -1], [0, 0, -1, 4]])
    lam0 = np.array([3.0, 1.0, -2.0, -5.0])
    act = lcp_active_set(k, lam0)
    assert act is not None
    accepted = []
    for bits in range(16):
        a = np.array([(bits >> i) & 1 for i in range(4)], dtype=bool)
        s = np.zeros(4)
        if (~a).any():
            s[~a] = np.linalg.solve(k[np.ix_(~a, ~a)], -lam0[~a])
        lam = lam0 + k @ s
        if (s >= -1e-12).all() and (lam[a] >= -1e-12).all():
            accepted.append(a)
    # An M-matrix LCP has exactly one solution: the enumeration finds one set, the kernel's.
    assert len(accepted) == 1 and np.array_equal(accepted[0], act)


def test_pulling_load_is_a_clear_error() -> None:
    with pytest.raises(SingularSystemError, match="pulls the bodies apart"):
        run_case(
            "blocks",
            BlockParams(p=-50.0, size1=0.5, size2=0.5),
            SolveRequest.parse("mortar"),
            comm=MPI.COMM_SELF,
        )
    # A negative Hertz load has no Hertz solution: rejected as input.
    with pytest.raises(InputError, match="P must be a positive"):
        run_case("hertz", HertzParams(P=-100.0), SolveRequest.parse("mortar"), comm=MPI.COMM_SELF)


@pytest.mark.parametrize("preset", ["S1", "S4"])
def test_block_scenes_still_one_iteration(preset: str) -> None:
    from contactfx.scenes import BLOCK_SCENES

    _, data = run_case(
        "blocks", BLOCK_SCENES[preset], SolveRequest.parse("mortar"), comm=MPI.COMM_SELF
    )
    data = data.to_json()
    assert data["iterations"] == 1
    assert data["active_nodes"] == data["multipliers"]
