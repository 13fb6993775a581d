"""The penalty baseline on the mortar gap: exact patch test, O(1/eps) consistency, CLI output."""

from __future__ import annotations

import itertools
import json
from dataclasses import replace
from pathlib import Path

import dolfinx_solver  # noqa: F401
import numpy as np
import pytest
from conftest import cli
from mpi4py import MPI

from contactfx import SolveRequest
from contactfx.api import run_case
from contactfx.methods.penalty import DEFAULT_FACTOR, penetration
from contactfx.results.interface import u_at_points
from contactfx.results.paper import patch_errors
from contactfx.results.stress import body_stress_deviation
from contactfx.scenes import BLOCK_SCENES, HertzParams

S4 = replace(BLOCK_SCENES["S4"], size1=0.3, size2=0.4)
HERTZ = HertzParams(refine=0.1)


@pytest.mark.parametrize("active", [1, 2])
def test_patch_test_uniform_penetration(active: int) -> None:
    # Exact solution: sigma_yy = -p everywhere, pressure p, and a uniform penetration p / eps.
    eps = 1e7
    sol, data = run_case(
        "blocks", S4, SolveRequest.parse("penalty", penalty=eps), active=active, comm=MPI.COMM_SELF
    )
    data = data.to_json()
    p = S4.p
    err = patch_errors(data["interface"], p)
    dev = body_stress_deviation(sol, -p)
    assert err["pressure"] < 1e-9, err
    assert max(dev.values()) < 1e-8, dev
    assert np.allclose(sol.gap, -p / eps, rtol=1e-8, atol=0)
    assert data["penetration"] == pytest.approx(p / eps, rel=1e-8)
    assert data["contact_force"] == pytest.approx(p * S4.l2 / 2, rel=1e-12)


def test_hertz_converges_to_mortar_like_one_over_eps() -> None:
    # The penalty solution differs from the Lagrange (mortar) one on the same mesh by O(1/eps)
    # once the contact zone is settled: ten times eps, a tenth of the difference.
    ref, _ = run_case("hertz", HERTZ, SolveRequest.parse("mortar"), comm=MPI.COMM_SELF)
    diffs = []
    for eps in (1e7, 1e8, 1e9):  # about 70, 700, 7000 E / h on this mesh
        sol, data = run_case(
            "hertz", HERTZ, SolveRequest.parse("penalty", penalty=eps), comm=MPI.COMM_SELF
        )
        data = data.to_json()
        assert data["contact_force"] == pytest.approx(HERTZ.P / 2, rel=1e-9)
        assert np.array_equal(sol.layout.x, ref.layout.x)
        assert np.array_equal(sol.active, ref.active)
        diffs.append(np.max(np.abs(sol.pressure - ref.pressure)) / np.max(ref.pressure))
    assert diffs[0] < 2e-2  # measured 6.3e-3 at eps = 1e7 MPa/cm
    for coarse, fine in itertools.pairwise(diffs):
        assert 8.0 < coarse / fine < 12.0, diffs


def test_small_penalty_spreads_the_contact() -> None:
    # A soft penalty lets the cylinder sink in: more nodes carry load, the peak drops.
    stiff, d_stiff = run_case(
        "hertz", HERTZ, SolveRequest.parse("penalty", penalty=1e8), comm=MPI.COMM_SELF
    )
    d_stiff = d_stiff.to_json()
    soft, d_soft = run_case(
        "hertz", HERTZ, SolveRequest.parse("penalty", penalty=1e3), comm=MPI.COMM_SELF
    )
    d_soft = d_soft.to_json()
    assert soft.active.sum() > stiff.active.sum()
    assert d_soft["hertz"]["p0"] < 0.8 * d_stiff["hertz"]["p0"]
    assert d_soft["penetration"] > 100 * d_stiff["penetration"]


def test_cli_json_has_penalty_and_penetration(tmp_path: Path) -> None:
    out = tmp_path / "p.json"
    args = ("--preset", "S4", "--size1", "0.3", "--size2", "0.4", "--method", "penalty")
    proc = cli("solve", "blocks", *args, "--json", str(out), "-q")
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert data["method"] == "penalty"
    # Default: DEFAULT_FACTOR * E_max / h, h the median contact weight of the code's own
    # multiplier layout (the mortar weights: about the active element size).
    sol, _ = run_case("blocks", S4, SolveRequest.parse("penalty"), comm=MPI.COMM_SELF)
    h = float(np.median(sol.layout.weights))
    assert data["penalty"] == pytest.approx(DEFAULT_FACTOR * max(S4.E1, S4.E2) / h, rel=1e-12)
    assert data["penetration"] == pytest.approx(S4.p / data["penalty"], rel=1e-8)


def test_default_penalty_penetration_is_load_over_stiffness() -> None:
    """The default eps (1e3 E_max / h) carries the uniform S4 pressure with the uniform
    penetration p / eps, measured on the displacement field itself (not on the gap)."""
    sol, data = run_case("blocks", S4, SolveRequest.parse("penalty"), comm=MPI.COMM_SELF)
    data = data.to_json()
    eps = data["penalty"]
    # Jump of u_y across the interface at the multiplier nodes (x sorted, both bodies).
    u = u_at_points(sol)
    at_line = np.abs(u[:, 1] - S4.h1) < 1e-9
    uy = u[at_line]
    x_nodes = np.unique(np.round(uy[:, 0], 9))
    lower = [uy[(np.abs(uy[:, 0] - x) < 1e-9), 3] for x in x_nodes]
    # Where both bodies have a node at the same x the jump is the penetration there.
    jumps = [abs(v.max() - v.min()) for v in lower if len(v) == 2]
    assert jumps, "no coincident interface nodes to compare"
    assert np.allclose(jumps, S4.p / eps, rtol=1e-6)
    assert penetration(sol) == pytest.approx(S4.p / eps, rel=1e-8)
