"""The pressure estimate against brute-force L2 errors of known functions, and its sizing."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import COARSE_HERTZ, cli

import contactfx
from contactfx.adapt.estimate import estimate
from contactfx.adapt.pressure_estimate import l2_norm, segment_indicators
from contactfx.adapt.sizing import SizingRule, plan_mesh
from contactfx.results.references import exact_pressure
from contactfx.scenes import HertzParams, hertz

A, P0 = 1.4378, 44.28  # the built-in Hertz scene's half-width and peak


def _line(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(points, segments) of a polyline along the x axis through the abscissae x."""
    seg = np.column_stack([np.arange(len(x) - 1), np.arange(1, len(x))])
    return np.column_stack([x, np.zeros_like(x)]), seg


def _true_l2(x: np.ndarray, p: np.ndarray, f: object) -> np.ndarray:
    """Per segment, ||f - I f|| by dense trapezoid sampling (independent of the estimate)."""
    out = []
    for a, b, pa, pb in zip(x[:-1], x[1:], p[:-1], p[1:], strict=True):
        s = np.linspace(a, b, 4001)
        lin = pa + (pb - pa) * (s - a) / (b - a)
        out.append(np.sqrt(np.trapezoid((f(s) - lin) ** 2, s)))
    return np.array(out)


def test_interior_segments_exact_for_a_parabola() -> None:
    """p = c (1 - x^2) > 0: each inner segment's estimate is its interpolation error."""
    x = np.linspace(-0.9, 0.9, 41)  # f'' from two slopes is exact on uniform spacing

    def f(s: np.ndarray) -> np.ndarray:
        return 3.0 * (1.0 - s**2)

    pts, seg = _line(x)
    eta, edge = segment_indicators(pts, seg, f(x))
    assert not edge.any()
    true = _true_l2(x, f(x), f)
    inner = slice(1, -1)  # the end segments have one node without curvature
    assert np.allclose(eta[inner], true[inner], rtol=1e-6)
    assert np.allclose(eta[[0, -1]], true[[0, -1]] / np.sqrt(2), rtol=1e-6)
    s = np.linspace(-0.9, 0.9, 400001)
    by_sampling = np.sqrt(np.trapezoid(np.interp(s, x, f(x)) ** 2, s))
    assert l2_norm(pts, seg, f(x)) == pytest.approx(by_sampling, rel=1e-8)


def test_orientation_does_not_matter() -> None:
    x = np.linspace(0.0, 1.5 * A, 60)
    pts, seg = _line(x)
    p = exact_pressure(x, A, P0)
    flipped = seg[:, ::-1][::-1]
    eta, edge = segment_indicators(pts, seg, p)
    eta_f, edge_f = segment_indicators(pts, flipped, p)
    assert np.allclose(eta, eta_f[::-1], rtol=1e-12) and np.array_equal(edge, edge_f[::-1])
    assert edge.sum() == 2


@pytest.mark.parametrize("h", [0.04, 0.01, 0.0025])
def test_edge_estimate_tracks_the_hertz_pressure(h: float) -> None:
    """Exact Hertz pressure at the nodes, the edge anywhere between two nodes: the total
    estimate is 0.95-1.3 times the true L2 error (measured 0.99-1.24); the interpolation
    estimate alone (no square-root fit at the edge) is 0.26-1.1 times it."""
    ratios = []
    for shift in np.linspace(0.0, 1.0, 17)[:-1]:
        inner = np.arange(0.0, A - 0.1, max(h, 0.01))
        x = np.concatenate([inner, np.arange(inner[-1] + h * (1 + shift), 1.5 * A, h)])
        p = exact_pressure(x, A, P0)
        pts, seg = _line(x)
        eta, _ = segment_indicators(pts, seg, p)
        true = _true_l2(x, p, lambda s: exact_pressure(s, A, P0))
        ratios.append(np.sqrt(np.sum(eta**2) / np.sum(true**2)))
    assert 0.95 < min(ratios) and max(ratios) < 1.3, ratios


def test_plan_asks_small_cells_at_the_zone_edge_only() -> None:
    """With a pressure tolerance the plan is finer at the zone edge (a, 60), the same far off."""
    scene = hertz(HertzParams(refine=0.1, refine_edge=0.0, slope=0.3))
    sol = contactfx.solve(scene, "mortar")
    est = estimate(sol)
    assert est.pressure is not None and 0 < est.pressure.relative < 1
    rule = SizingRule(contact_weight=1.0)
    cells = 1e9  # no budget: only the tolerances act
    plain = plan_mesh(sol, est, 0.5, cells, rule)
    with_p = plan_mesh(sol, est, 0.5, cells, rule, pressure_tol=1e-3)
    mid = plain.field.quads.mean(axis=1)
    size_plain = plain.field.sizes.min(axis=1)
    size_p = with_p.field.sizes.min(axis=1)
    assert np.all(size_p <= size_plain * (1 + 1e-12))
    near_edge = np.linalg.norm(mid - [A, 60.0], axis=1) < 0.2
    far = np.linalg.norm(mid - [A, 60.0], axis=1) > 3.0
    assert np.min(size_p[near_edge] / size_plain[near_edge]) < 0.5
    assert np.allclose(size_p[far], size_plain[far])
    assert with_p.cells > plain.cells


def test_hertz_target_with_pressure_tol(tmp_path: Path) -> None:
    """Issue 20's target: from the ungraded h = 2 mesh, L2 <= 0.1 % within 57k DOFs
    (docs/adapt.md: 0.059 % at 56,148; over 14 neighbouring settings 0.053-0.099 %). The
    expert flags' loop (--goal residual); test_goal_loop.py has the defaults'."""
    proc = cli(
        "adapt",
        *COARSE_HERTZ,
        *("--max-dofs", "57000", "--tol", "0.001", "--max-levels", "14", "--growth", "1.5"),
        *("--pressure-tol", "0.0005", "--goal", "residual", "--out", str(tmp_path)),
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    data = json.loads((tmp_path / "adapt.json").read_text())
    assert data["settings"]["pressure_tol"] == 0.0005
    assert data["settings"]["weight_contact"] == 1.0
    levels = data["levels"]
    last = levels[-1]
    assert last["dofs"] <= 57000 and last["hertz"]["l2_error"] <= 1e-3, last["hertz"]
    pressure = [lv["estimate_parts"]["pressure"] for lv in levels]
    assert pressure[-1] < 0.01 * pressure[0], pressure
    assert "pressure" in proc.stdout


def test_bad_pressure_tol_refused(tmp_path: Path) -> None:
    proc = cli("adapt", *COARSE_HERTZ, "--pressure-tol", "0", "--out", str(tmp_path / "o"))
    assert proc.returncode == 2 and "--pressure-tol" in proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "o").exists()
