"""The graph model of MUMPS' memory estimate (methods/mumps_model.py) and `auto` deciding
with it: the bound stays below MUMPS' own analysis, and the solver chosen is the one the
analysis chooses.

References: MUMPS' analysis of the same saddle point (an independent computation, not the
model), and `auto` with the model switched off (the rule as it was).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from mpi4py import MPI

import contactfx.methods.mumps_model as mumps_model
from contactfx import run_scene
from contactfx.discretize.mesh_utils import scene_dofs
from contactfx.discretize.setup import prepare_contact
from contactfx.errors import InputError
from contactfx.linalg.saddle import SaddleSolver
from contactfx.methods.mumps_model import model_bound, model_mb
from contactfx.methods.solver_choice import SAFETY
from contactfx.methods.solvers import setup_solver
from contactfx.options import SOLVERS, Basis, Method
from contactfx.request import SolveRequest
from contactfx.scenes import HertzParams, hertz
from contactfx.timers import Timers

SMALL = HertzParams(refine=0.08, h_far=0.8, mesh="structured")  # about 50k DOFs


@pytest.fixture(scope="module")
def scene():
    return hertz(SMALL, comm=MPI.COMM_SELF)


def _analysis(scene) -> tuple[float, int, int]:
    """MUMPS' estimate (MB) of the loop's saddle point, its DOFs and K's nonzeros."""
    setup = prepare_contact(scene, Method.MORTAR.kernel, 1e-8, Timers(), Basis.DUAL)
    solver = setup_solver(setup, SOLVERS["mumps"], scene, reuse=True)
    assert isinstance(solver, SaddleSolver)
    est = solver.mumps_estimate()
    assert est is not None
    K = setup.elasticity.K
    nnz = int(K.getInfo(K.InfoType.GLOBAL_SUM)["nz_used"])
    out = (est.rank_mb, K.getSize()[0], nnz)
    solver.destroy()
    setup.destroy()
    return out


@pytest.mark.parametrize(
    "params",
    [
        SMALL,
        HertzParams(refine=0.045, h_far=0.45, mesh="structured"),  # about 150k DOFs
        HertzParams(refine=0.05, h_far=0.5, refine_edge=0.0125),  # gmsh, about 60k DOFs
    ],
)
def test_model_bound_is_below_the_analysis(params: HertzParams) -> None:
    """On the measured family the bound is below MUMPS' estimate, even at sizes under the
    model's floor (where the estimate per DOF is larger still); the fit itself is within a
    factor 2 of it."""
    est, dofs, nnz = _analysis(hertz(params, comm=MPI.COMM_SELF))
    assert mumps_model.NNZ_PER_DOF[0] <= nnz / dofs <= mumps_model.NNZ_PER_DOF[1]
    assert model_mb(dofs, 1, lower=True) <= est
    assert 0.5 * est <= model_mb(dofs, 1) <= 1.1 * est


def test_model_applies_only_where_measured() -> None:
    """Below the floor, on other rank counts and on other graphs the analysis decides."""
    n = 2 * mumps_model.MODEL_MIN_DOFS
    assert model_bound(n, 18 * n, 2) == pytest.approx(model_mb(n, 2) * mumps_model.LOWER)
    assert model_bound(mumps_model.MODEL_MIN_DOFS - 1, 18 * n, 1) is None
    assert model_bound(n, 18 * n, 3) is None and math.isnan(model_mb(n, 3))
    assert model_bound(n, 14 * n, 1) is None  # P1 triangles' sparser graph: not measured
    # The fit grows per DOF with N (nested dissection in 2D): 10M needs more per DOF than 1M.
    assert model_mb(10**7, 2) / 10**7 > model_mb(10**6, 2) / 10**6


def test_auto_keeps_the_analysis_on_stretched_cells(monkeypatch) -> None:
    """The default grading's cells (hundreds to one) fill less per DOF than the model's
    families: there the analysis decides even with the model's floor opened."""
    stretched = hertz(HertzParams(refine=0.02, mesh="structured"), comm=MPI.COMM_SELF)
    calls: list[int] = []
    estimate = SaddleSolver.mumps_estimate

    def counted(linear):
        calls.append(linear._m.A.getSize()[0])
        return estimate(linear)

    monkeypatch.setattr(SaddleSolver, "mumps_estimate", counted)
    monkeypatch.setattr(mumps_model, "MODEL_MIN_DOFS", 0)
    _, out, fine = _auto(stretched, 1.0, calls)
    assert out["solver_choice"]["estimate_of"] == "fine" and len(fine) == 1


def _auto(scene, available: float, calls: list[int]):
    request = SolveRequest.parse("mortar", basis="dual", solver="auto", available_mb=available)
    before = len(calls)
    sol, data = run_scene(scene, request)
    fine = [n for n in calls[before:] if n >= scene_dofs(scene)]
    return sol, data.to_json(), fine


def test_auto_decides_as_the_analysis(scene, monkeypatch) -> None:
    """The model's floor opened for the 50k scene: with no room even for its bound, condensed
    with no analysis of the fine system; between the bound and the estimate, the analysis
    decides (condensed); with room, MUMPS after its analysis. Each choice and answer is the
    one `auto` without the model makes."""
    calls: list[int] = []
    estimate = SaddleSolver.mumps_estimate

    def counted(linear):
        calls.append(linear._m.A.getSize()[0])  # the saddle point analysed
        return estimate(linear)

    monkeypatch.setattr(SaddleSolver, "mumps_estimate", counted)
    est, dofs, _ = _analysis(scene)
    bound = model_mb(dofs, 1, lower=True)
    assert bound < est
    cases = [(1.0, "condensed", False), (SAFETY * (bound + est) / 2, "condensed", True)]
    cases.append((1e9, "mumps", True))
    for available, preset, analysed in cases:
        monkeypatch.setattr(mumps_model, "MODEL_MIN_DOFS", 10**12)  # the rule as it was
        ref, ref_json, _ = _auto(scene, available, calls)
        monkeypatch.setattr(mumps_model, "MODEL_MIN_DOFS", 0)
        sol, out, fine = _auto(scene, available, calls)
        choice = out["solver_choice"]
        assert ref_json["solver_choice"]["ran"] == choice["ran"] == out["solver"] == preset
        assert bool(fine) is analysed
        if not analysed:
            assert choice["estimate_of"] == "graph model (a lower bound)"
            assert choice["mumps_estimate_mb"] == pytest.approx(bound)
            assert "the model of its estimate from the graph" in choice["reason"]
        assert np.array_equal(sol.active, ref.active)
        scale = np.abs(ref.pressure).max()
        assert np.abs(sol.pressure - ref.pressure).max() <= 1e-9 * scale
        for key in ("l2_error", "a", "p0"):
            assert out["hertz"][key] == pytest.approx(ref_json["hertz"][key], rel=1e-6)


def test_auto_model_refuses_without_a_diagonal_d(scene, monkeypatch) -> None:
    """The standard basis where even the model's bound does not fit: the one-line refusal,
    before any analysis."""
    calls: list[int] = []
    monkeypatch.setattr(SaddleSolver, "mumps_estimate", lambda lin: calls.append(1))
    monkeypatch.setattr(mumps_model, "MODEL_MIN_DOFS", 0)
    request = SolveRequest.parse("mortar", basis="standard", solver="auto", available_mb=1.0)
    with pytest.raises(InputError, match=r"would not fit: MUMPS estimates >= .*--basis dual"):
        run_scene(scene, request)
    assert not calls
