"""The default solver `auto`: the choice rule alone, and the whole run with the available
memory forced (SolveRequest.available_mb / --available-memory) on a small Hertz mesh.

References: the explicit presets (`--solver mumps`, `--solver condensed`) on the same scene,
independent runs of the paths `auto` chooses between.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import run_cli
from mpi4py import MPI

from contactfx import run_scene, solve
from contactfx.api import as_request
from contactfx.discretize.mesh_utils import max_cell_aspect, scene_dofs
from contactfx.errors import InputError
from contactfx.linalg.saddle import SaddleSolver
from contactfx.methods import solver_choice
from contactfx.methods.autosolve import STRETCHED_ASPECT, warn_if_stretched
from contactfx.methods.solver_choice import (
    SAFETY,
    Choice,
    SolverChoice,
    choose,
    mem_available_mb,
    node_budget,
)
from contactfx.options import SOLVERS, SolverKind
from contactfx.request import SolveRequest
from contactfx.scenes import HertzParams, hertz

SMALL = HertzParams(refine=0.08, h_far=0.8, mesh="structured")  # about 50k DOFs


@pytest.mark.parametrize(
    ("needed", "available", "condensable", "expected"),
    [
        (1000.0, 4000.0, True, Choice.DIRECT),
        (1000.0, 1000.0 * SAFETY, False, Choice.DIRECT),  # exactly fits with the margin
        (1000.0, 1000.0 * SAFETY - 1.0, True, Choice.CONDENSED),
        (1000.0, 1100.0, False, Choice.REFUSE),
        (None, 10.0, False, Choice.DIRECT),  # no estimate: the direct default
        (1000.0, None, True, Choice.DIRECT),  # no MemAvailable: likewise
    ],
)
def test_choose(needed, available, condensable: bool, expected: Choice) -> None:
    assert choose(needed, available, condensable) is expected


def test_choose_safety_factor() -> None:
    assert choose(1000.0, 1000.0, True, safety=1.0) is Choice.DIRECT
    assert choose(1000.0, 1000.0, True, safety=1.01) is Choice.CONDENSED


def test_node_budget_one_rank(monkeypatch) -> None:
    comm = MPI.COMM_SELF
    assert node_budget(comm, 300.0, 500.0) == (300.0, 500.0)
    assert node_budget(comm, None, 500.0) == (None, None)
    avail = mem_available_mb()
    assert avail is None or avail > 0.0
    # MemAvailable moves between two reads while other processes run: read it once.
    monkeypatch.setattr(solver_choice, "mem_available_mb", lambda: avail)
    assert node_budget(comm, 300.0, None) == ((300.0, avail) if avail else (None, None))


def test_auto_is_the_default_and_direct_elsewhere() -> None:
    assert as_request("mortar").solver.kind is SolverKind.AUTO
    # Penalty and Schwarz factorize with MUMPS: nothing to choose.
    assert as_request("penalty").solver.kind is SolverKind.DIRECT
    assert as_request("schwarz").solver.kind is SolverKind.DIRECT
    with pytest.raises(InputError, match="available memory must be positive"):
        SolveRequest(available_mb=0.0)


@pytest.fixture(scope="module")
def scene():
    return hertz(SMALL, comm=MPI.COMM_SELF)


def _run(scene, solver: str, available_mb: float | None = None, basis: str = "dual"):
    request = SolveRequest.parse("mortar", basis=basis, solver=solver, available_mb=available_mb)
    return run_scene(scene, request)


@pytest.mark.parametrize(("available", "preset"), [(1.0, "condensed"), (1e9, "mumps")])
def test_auto_runs_what_fits(scene, available: float, preset: str) -> None:
    """Tiny memory: condensed, its answer; ample: MUMPS, its answer (same set, 1e-7)."""
    sol, data = _run(scene, "auto", available)
    ref, _ = _run(scene, preset)
    out = data.to_json()
    assert out["solver"] == preset
    choice = out["solver_choice"]
    assert choice["ran"] == preset and choice["available_mb"] == available
    assert choice["mumps_estimate_mb"] > 1.0  # a real estimate, compared with the override
    assert np.array_equal(sol.active, ref.active)
    scale = np.abs(ref.pressure).max()
    assert np.abs(sol.pressure - ref.pressure).max() <= 1e-7 * scale
    du = np.abs(sol.u.x.array - ref.u.x.array).max()
    assert du <= 1e-7 * np.abs(ref.u.x.array).max()
    if preset == "condensed":
        assert all(h["linear_iterations"] > 1 for h in sol.history)  # CG ran, not MUMPS


def test_auto_refuses_where_nothing_fits(scene, caplog) -> None:
    """The standard basis cannot be condensed: one clear refusal before factorizing."""
    with pytest.raises(InputError, match=r"would not fit.*GB available.*--basis dual"):
        _run(scene, "auto", 1.0, basis="standard")
    # An explicit MUMPS is honoured whatever the estimate, with a warning.
    request = SolveRequest.parse("mortar", solver=SOLVERS["mumps"], available_mb=1.0)
    with caplog.at_level("WARNING", logger="contactfx"):
        _, data = run_scene(scene, request)
    assert data.to_json()["solver"] == "mumps"
    assert "solver: mumps, although MUMPS needs" in caplog.text


def test_coarse_bound_reason() -> None:
    """The log says the coarse estimate is a scaled lower bound, with the coarse DOFs."""
    record = SolverChoice("condensed", 14_760.0, 15_000.0, 5.0, coarse_dofs=695_006)
    assert record.reason == (
        "MUMPS would need >= 14.76 GB (analysis of the 695,006-DOF coarse system, scaled), "
        "15.00 GB available; margin x1.25"
    )
    assert record.to_json()["coarse_dofs"] == 695_006
    assert SolverChoice("mumps", 1.0, 2.0, 0.1).to_json()["coarse_dofs"] is None


@pytest.mark.parametrize(("available", "preset"), [(1.0, "condensed"), (1e9, "mumps")])
def test_auto_coarse_bound(scene, monkeypatch, available: float, preset: str) -> None:
    """With the coarse check on (its size floor and gate opened for this small scene): where
    the scaled coarse estimate does not fit, condensed after the coarse analysis alone (the
    fine one is skipped); where it fits, the fine analysis decides as before. Answers: the
    presets'.
    """
    import contactfx.methods.autosolve as autosolve

    calls: list[int] = []

    def counted(linear):
        calls.append(linear._m.A.getSize()[0])  # the saddle point analysed
        return estimate(linear)

    estimate = SaddleSolver.mumps_estimate
    remeshed = type(scene).remeshed
    meshes: list[float] = []

    def counted_remesh(self, factor: float):
        meshes.append(factor)
        return remeshed(self, factor)

    monkeypatch.setattr(autosolve, "COARSE_BOUND_DOFS", 0)
    monkeypatch.setattr(autosolve, "CHECK_KB_PER_DOF", 1e12)
    monkeypatch.setattr(SaddleSolver, "mumps_estimate", counted)
    monkeypatch.setattr(type(scene), "remeshed", counted_remesh)
    sol, data = _run(scene, "auto", available)
    seen = list(calls)  # the auto run's analyses (an explicit mumps run checks too)
    ref, _ = _run(scene, preset)
    choice = data.to_json()["solver_choice"]
    assert choice["ran"] == preset
    dofs = scene_dofs(scene)
    fine = [n for n in seen if n >= dofs]
    assert meshes[0] == 2.0  # the coarse check's mesh: a quarter of the DOFs
    assert seen and seen[0] < dofs / 2  # its analysis comes first
    if preset == "condensed":
        assert not fine  # skipped (later coarse ones: the predictor's direct solve)
        assert 0 < choice["coarse_dofs"] < dofs / 2
        assert "coarse system, scaled" in choice["reason"]
    else:
        assert len(fine) == 1  # it fits: the fine analysis decides, as before
        assert choice["coarse_dofs"] is None
    assert np.array_equal(sol.active, ref.active)
    scale = np.abs(ref.pressure).max()
    assert np.abs(sol.pressure - ref.pressure).max() <= 1e-7 * scale


def test_auto_coarse_check_only_where_it_could_decide(scene, monkeypatch) -> None:
    """Size floor open, gate as shipped: ample memory skips the coarse check (one analysis,
    the fine one); the gate is what keeps the check off where MUMPS plainly fits."""
    import contactfx.methods.autosolve as autosolve

    calls: list[int] = []
    estimate = SaddleSolver.mumps_estimate
    monkeypatch.setattr(autosolve, "COARSE_BOUND_DOFS", 0)
    monkeypatch.setattr(
        SaddleSolver, "mumps_estimate", lambda lin: calls.append(1) or estimate(lin)
    )
    _, data = _run(scene, "auto", 1e9)
    assert len(calls) == 1 and data.to_json()["solver_choice"]["coarse_dofs"] is None
    _, data = _run(scene, "auto", 1.0)  # no room even at CHECK_KB_PER_DOF: the check runs
    assert data.to_json()["solver_choice"]["coarse_dofs"] is not None


def test_auto_coarse_bound_refuses_without_a_diagonal_d(scene, monkeypatch) -> None:
    """The standard basis where even the coarse bound does not fit: the one-line refusal."""
    import contactfx.methods.autosolve as autosolve

    monkeypatch.setattr(autosolve, "COARSE_BOUND_DOFS", 0)
    monkeypatch.setattr(autosolve, "CHECK_KB_PER_DOF", 1e12)
    with pytest.raises(InputError, match=r"would not fit: MUMPS estimates >= .*GB available"):
        _run(scene, "auto", 1.0, basis="standard")


HERTZ = ["hertz", "--mesh", "structured", "--refine", "0.08", "--h-far", "0.8", "--method"]


@pytest.mark.mpi
def test_auto_under_mpi(tmp_path: Path) -> None:
    """Two ranks: tiny memory runs condensed (logged); without dual mortar a one-line exit 2."""
    out = tmp_path / "run.json"
    args = [*HERTZ, "mortar", "--basis", "dual", "--available-memory", "1", "--json", str(out)]
    proc = run_cli("solve", *args, ranks=2)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "solver: condensed (MUMPS would need" in proc.stdout + proc.stderr
    data = json.loads(out.read_text())
    assert data["solver"] == "condensed" and data["ranks"] == 2
    bad = run_cli("solve", *HERTZ, "mortar", "--available-memory", "1", ranks=2)
    assert bad.returncode == 2
    lines = [ln for ln in bad.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "would not fit" in lines[0], bad.stderr
    assert "Traceback" not in bad.stderr


def test_cell_aspect_of_a_stretched_grid() -> None:
    """10 x 1 cm in 2 x 10 quadrilaterals: every cell 5 cm by 0.1 cm, aspect 50."""
    from dolfinx import mesh

    grid = mesh.create_rectangle(
        MPI.COMM_SELF, [[0.0, 0.0], [10.0, 1.0]], [2, 10], mesh.CellType.quadrilateral
    )
    assert max_cell_aspect(grid) == pytest.approx(50.0, rel=1e-12)


def test_explicit_condensed_warns_on_stretched_cells(scene, caplog) -> None:
    """The default grading (cells past 100:1): an explicit condensed solver runs, with one
    warning line; the accurate grading (`scene`, h_far = 10 h), or mumps: no warning."""
    stretched = hertz(HertzParams(refine=0.08, mesh="structured"), comm=MPI.COMM_SELF)
    assert max_cell_aspect(stretched.mesh) > STRETCHED_ASPECT > max_cell_aspect(scene.mesh)
    with caplog.at_level("WARNING", logger="contactfx"):
        sol = solve(stretched, "nts", solver="condensed")
    assert sol.history and all(h["linear_iterations"] > 1 for h in sol.history)  # CG ran
    warned = [r.getMessage() for r in caplog.records if "stretched" in r.getMessage()]
    assert len(warned) == 1, warned
    assert warned[0].startswith("solver: condensed, although cells are stretched up to ")
    caplog.clear()
    with caplog.at_level("WARNING", logger="contactfx"):
        warn_if_stretched(scene.mesh, SolveRequest.parse("nts", solver="condensed"))
        warn_if_stretched(stretched.mesh, SolveRequest.parse("nts", solver="mumps"))
        warn_if_stretched(stretched.mesh, SolveRequest.parse("nts", solver="auto"))
    assert "stretched" not in caplog.text
