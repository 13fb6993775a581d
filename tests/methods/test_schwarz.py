"""The alternating Schwarz (Dirichlet-Neumann) reference solver on the block scenes."""

from __future__ import annotations

import json
import logging
from dataclasses import replace

import numpy as np
import pytest
from conftest import cli

from contactfx.api import run_case
from contactfx.errors import ConvergenceError, InputError
from contactfx.methods.schwarz import SchwarzOptions, solve_schwarz
from contactfx.request import SolveRequest
from contactfx.results.interface import u_at_points
from contactfx.results.stress import body_stress_deviation
from contactfx.scenes import BLOCK_SCENES, build_scene


def _arr(data: dict, key: str) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in data["interface"][key]], dtype=float)


@pytest.fixture(scope="module")
def s1_pair() -> tuple[dict, dict]:
    """S1 solved by the mortar multipliers and by Schwarz (default: Aitken from 0.5)."""
    _, mortar = run_case("blocks", BLOCK_SCENES["S1"], SolveRequest.parse("mortar"))
    mortar = mortar.to_json()
    _, schwarz = run_case("blocks", BLOCK_SCENES["S1"], SolveRequest.parse("schwarz"))
    schwarz = schwarz.to_json()
    return mortar, schwarz


def test_s1_agrees_with_mortar_away_from_corner(s1_pair) -> None:
    """The paper's check: sigma_yy and pressure of Schwarz and mortar agree to 0.1 %."""
    mortar, schwarz = s1_pair
    x = _arr(schwarz, "x")
    np.testing.assert_array_equal(x, _arr(mortar, "x"))
    # The paper's 0.1 % away from the corner is implied: the Schwarz fixed point solves the
    # mortar equations, so the two agree to the iteration tolerance everywhere, the singular
    # corner included (measured 6e-10 p).
    p = BLOCK_SCENES["S1"].p
    for key in ("pressure", "sigma_yy_1", "sigma_yy_2"):
        assert np.nanmax(np.abs(_arr(schwarz, key) - _arr(mortar, key))) < 1e-7 * p, key


def test_s1_summary_reports_iterations_and_force(s1_pair) -> None:
    """The JSON has the Schwarz iteration count, its history and the applied load."""
    _, schwarz = s1_pair
    hist = schwarz["active_set"]
    assert schwarz["method"] == "schwarz"
    assert schwarz["iterations"] == len(hist) == 14
    assert hist[-1]["residual"] < 1e-8 and hist[-1]["traction_change"] < 1e-8
    assert hist[0]["relaxation"] == 0.5 and hist[0]["traction_change"] is None
    p = BLOCK_SCENES["S1"]
    assert schwarz["contact_force"] == pytest.approx(p.p * p.l2 / 2, rel=1e-10)
    json.dumps(schwarz, allow_nan=False)


@pytest.mark.parametrize("active", [2, 1])
def test_s2_nonmatching_equals_mortar_with_b2_slave(active: int) -> None:
    """Non-matching S2: displacements equal those of mortar with B2 active, either report."""
    params = BLOCK_SCENES["S2"]
    _m_sol, mortar = run_case("blocks", params, SolveRequest.parse("mortar"), active=active)
    mortar = mortar.to_json()
    ref_sol, _ = run_case("blocks", params, SolveRequest.parse("mortar"), active=2)
    s_sol, schwarz = run_case("blocks", params, SolveRequest.parse("schwarz"), active=active)
    schwarz = schwarz.to_json()
    u_ref, u = u_at_points(ref_sol), u_at_points(s_sol)
    scale = np.abs(u_ref[:, 2:]).max()
    assert np.abs(u[:, 2:] - u_ref[:, 2:]).max() < 1e-7 * scale
    # The multipliers are reported on the scene's active body, like the other methods. With
    # B1 active (the wider block) mortar's end rows merge B1's node at the top block's corner
    # into its neighbour (contact/operator.py, end_rows); schwarz keeps the unmodified basis
    # (every node facing the interface has its own row), so it reports that node as well.
    xs, xm = _arr(schwarz, "x"), _arr(mortar, "x")
    if active == 2:
        np.testing.assert_array_equal(xs, xm)
    else:
        assert len(xs) == len(xm) + 1 and np.isin(xm, xs).all()
        np.testing.assert_allclose(np.setdiff1d(xs, xm), [params.l2 / 2], rtol=1e-12)
    assert schwarz["contact_force"] == pytest.approx(params.p * params.l2 / 2, rel=1e-10)
    if active == 2:
        assert np.max(np.abs(_arr(schwarz, "pressure") - _arr(mortar, "pressure"))) < 1e-6


def test_s4_patch_test() -> None:
    """S4 (non-matching, graded): sigma_yy = -p in every cell and pressure = p."""
    params = BLOCK_SCENES["S4"]
    sol, data = run_case("blocks", params, SolveRequest.parse("schwarz"))
    data = data.to_json()
    dev = body_stress_deviation(sol, -params.p)
    # Measured 1.3e-11 in both bodies; the iteration tolerance is 1e-8.
    assert dev["body1"] < 1e-8 and dev["body2"] < 1e-8, dev
    assert np.max(np.abs(_arr(data, "pressure") / params.p - 1)) < 1e-8
    assert data["iterations"] <= 5


def test_aitken_needs_fewer_iterations_than_fixed_relaxation() -> None:
    """Same material (S1): Aitken 14 iterations, fixed 0.5 needs 28 (measured)."""
    params = BLOCK_SCENES["S1"]
    _, fixed = run_case(
        "blocks",
        params,
        SolveRequest.parse("schwarz", schwarz=SchwarzOptions(relaxation=0.5, aitken=False)),
    )
    fixed = fixed.to_json()
    _, aitken = run_case("blocks", params, SolveRequest.parse("schwarz"))
    aitken = aitken.to_json()
    assert aitken["iterations"] < 0.75 * fixed["iterations"]


def test_no_relaxation_converges_with_the_stiffer_body_neumann() -> None:
    """S3: B1 (Neumann side) 10x stiffer, so omega = 1 contracts (8 iterations measured)."""
    _, data = run_case(
        "blocks",
        BLOCK_SCENES["S3"],
        SolveRequest.parse(
            "schwarz", schwarz=SchwarzOptions(relaxation=1.0, aitken=False, max_iterations=15)
        ),
    )
    data = data.to_json()
    assert data["iterations"] <= 10


def test_no_relaxation_same_material_fails_at_the_limit() -> None:
    """S1 with omega = 1 stalls (eigenvalue near -1): ConvergenceError at the limit."""
    with pytest.raises(ConvergenceError, match="did not converge in 30 iterations") as err:
        run_case(
            "blocks",
            BLOCK_SCENES["S1"],
            SolveRequest.parse(
                "schwarz", schwarz=SchwarzOptions(relaxation=1.0, aitken=False, max_iterations=30)
            ),
        )
    last = err.value.history[-1]["residual"]
    # Measured: the relative residual stays near 3e-3 instead of falling below 1e-8.
    assert 1e-4 < last < 1e-1


def test_stiff_top_on_soft_base_diverges() -> None:
    """S3 with the stiffnesses swapped (Dirichlet body 10x stiffer), omega = 1: it blows up."""
    params = replace(BLOCK_SCENES["S3"], E1=70000.0, E2=700000.0)
    with pytest.raises(ConvergenceError, match="diverged at iteration"):
        run_case(
            "blocks",
            params,
            SolveRequest.parse(
                "schwarz", schwarz=SchwarzOptions(relaxation=1.0, aitken=False, max_iterations=50)
            ),
        )


def test_logs_every_iteration(caplog) -> None:
    """One INFO line per iteration with the residual and the relaxation factor."""
    with caplog.at_level(logging.INFO, logger="contactfx"):
        _, data = run_case("blocks", BLOCK_SCENES["S4"], SolveRequest.parse("schwarz"))
        data = data.to_json()
    lines = [r.getMessage() for r in caplog.records if r.getMessage().startswith("schwarz ")]
    its = [m for m in lines if "interface residual" in m and "relaxation" in m]
    assert len(its) == data["iterations"]


def test_hertz_is_rejected() -> None:
    """Hertz's contact line is curved (and its zone unknown): Schwarz refuses it clearly."""
    from contactfx.scenes import HertzParams

    hertz = build_scene("hertz", HertzParams(refine=0.2, refine_edge=0.0))
    with pytest.raises(InputError, match="straight horizontal contact line"):
        solve_schwarz(hertz, SolveRequest.parse("schwarz"))
    scene = build_scene("blocks", BLOCK_SCENES["S1"])
    with pytest.raises(InputError, match="relaxation"):
        solve_schwarz(scene, SolveRequest.parse("schwarz", schwarz=SchwarzOptions(relaxation=0.0)))


def test_cli_writes_the_usual_schema(tmp_path) -> None:
    """python -m contactfx solve blocks --method schwarz --json r.json."""
    out = tmp_path / "r.json"
    proc = cli("solve", "blocks", "--method", "schwarz", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    for key in (
        "scene",
        "method",
        "params",
        "ranks",
        "dofs",
        "multipliers",
        "iterations",
        "times",
        "contact_force",
        "interface",
    ):
        assert key in data
    assert data["method"] == "schwarz" and data["iterations"] == 14
    assert set(data["interface"]) == {"x", "pressure", "sigma_yy_1", "sigma_yy_2"}
