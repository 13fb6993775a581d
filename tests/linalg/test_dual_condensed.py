"""Dual mortar in the full pipeline, and the condensed solver (multipliers eliminated).

References: the exact uniform stress of the patch tests, plane-strain Hertz, and MUMPS on the
saddle point (an independent solver of the same discrete equations).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, solver_for
from mpi4py import MPI

from contactfx import SolveRequest, load_scene_file, run_scene, solve
from contactfx.errors import InputError
from contactfx.scenes import BLOCK_SCENES, HertzParams, build_scene, hertz

SCENES = ROOT / "tests" / "scenes"


@pytest.mark.parametrize("name", ["inclined_patch.toml", "inclined_patch_b1.toml"])
def test_dual_mortar_inclined_patch_test(name: str) -> None:
    """Dual mortar passes the inclined patch test (either side active) to 1e-8."""
    _, data = run_scene(load_scene_file(SCENES / name), SolveRequest.parse("mortar", basis="dual"))
    data = data.to_json()
    assert data["patch"]["max"] < 1e-8, data["patch"]
    assert data["basis"] == "dual"


@pytest.mark.parametrize("active", [1, 2])
def test_dual_mortar_straight_patch_test(active: int) -> None:
    """S4 (graded non-matching, E ratio 10): sigma_yy = -p to 1e-8 with the dual basis."""
    scene = build_scene("blocks", BLOCK_SCENES["S4"], active=active, comm=MPI.COMM_SELF)
    _, data = run_scene(scene, SolveRequest.parse("mortar", basis="dual"))
    data = data.to_json()
    assert data["patch"]["max"] < 1e-8


def test_dual_hertz_within_ten_percent_of_standard() -> None:
    """Hertz errors (a, p0, L2) of the dual basis stay within 10 % of the standard basis'.

    The band is on the errors themselves: |err_dual| <= 1.1 |err_std| (measured: a 1.09e-3
    vs 1.03e-3, p0 1.24e-3 vs 1.53e-3, L2 2.46e-3 vs 3.43e-3)."""
    scene = build_scene("hertz", HertzParams(), comm=MPI.COMM_SELF)
    out = {
        b: run_scene(scene, SolveRequest.parse("mortar", basis=b))[1].to_json()["hertz"]
        for b in ("standard", "dual")
    }
    for key, exact in (("a", "a_exact"), ("p0", "p0_exact")):
        errs = {b: abs(h[key] / h[exact] - 1) for b, h in out.items()}
        assert errs["dual"] <= 1.1 * errs["standard"], (key, errs)
    assert out["dual"]["l2_error"] <= 1.1 * out["standard"]["l2_error"]


@pytest.fixture(scope="module")
def small_hertz():
    """A structured Hertz mesh (about 50k DOFs) for solver comparisons."""
    return hertz(HertzParams(refine=0.08, h_far=0.8, mesh="structured"), comm=MPI.COMM_SELF)


@pytest.mark.parametrize("solver", ["condensed", "condensed-gamg"])
@pytest.mark.parametrize(("method", "basis"), [("nts", "standard"), ("mortar", "dual")])
def test_condensed_equals_mumps(small_hertz, method: str, basis: str, solver: str) -> None:
    """Eliminating the multipliers gives MUMPS' saddle-point answer: same set, 1e-6, with
    the structured grid's geometric multigrid (`condensed`) and with GAMG."""
    ref = solve(small_hertz, method, basis=basis, solver="mumps")
    sol = solve(small_hertz, method, basis=basis, solver=solver)
    assert np.array_equal(sol.active, ref.active)
    assert np.abs(sol.pressure - ref.pressure).max() <= 1e-6 * np.abs(ref.pressure).max()
    du = np.abs(sol.u.x.array - ref.u.x.array).max()
    assert du <= 1e-6 * np.abs(ref.u.x.array).max()
    assert all(h["linear_iterations"] > 0 for h in sol.history)  # CG really ran


def _condensed_solver(scene, reuse: bool = True, solver: str = "condensed-gamg"):
    """The setup of the NTS Hertz problem and a condensed solver on it (GAMG: the tests of
    its kept multigrid; `condensed` on this structured mesh: the geometric multigrid)."""
    from contactfx.discretize.setup import prepare_contact
    from contactfx.methods.active_set import ActiveSetOptions
    from contactfx.options import Method
    from contactfx.timers import Timers

    setup = prepare_contact(scene, Method.NTS.kernel, ActiveSetOptions().penetration_tol, Timers())
    return setup, solver_for(setup, solver, scene, reuse=reuse)


def test_condensed_matrix_equals_ptap(small_hertz) -> None:
    """K + E^T K + K E + E^T K E with the pivots decoupled is PETSc's PtAP T^T K T + P.

    Also: K is left as it was (the sum is built into a new matrix), and T = I + E applied
    without an assembled T (`t_mult`, `t_mult_transpose`) is the assembled T's product.
    """
    from petsc4py import PETSc

    from contactfx.linalg.elimination import (
        LocalRows,
        condensed_matrix,
        elimination_matrix,
        t_mult,
        t_mult_transpose,
    )
    from contactfx.linalg.pivots import pivots

    setup, solver = _condensed_solver(small_hertz)
    x = setup.layout.x[setup.layout.mine, 0]
    K = setup.elasticity.K
    rows_b = LocalRows.of(setup.B, setup.node_dofs())
    r0, r1 = K.getOwnershipRange()
    n = K.getSize()[0]
    pv = pivots(rows_b, x < small_hertz.params["hertz_exact"]["a"], setup.comm, r0, n)
    piv, prows = pv.dofs, pv.e_rows
    T = elimination_matrix(prows, r0, r1, K.getSize()[0], K.getComm(), identity=True)
    E = elimination_matrix(prows, r0, r1, K.getSize()[0], K.getComm(), identity=False)
    ip = piv.astype(PETSc.IntType)
    k_norm = K.norm()
    A = condensed_matrix(K, prows, r0, piv, K.getDiagonal())
    assert K.norm() == k_norm
    x, y, z = K.createVecRight(), K.createVecLeft(), K.createVecLeft()
    x.setRandom()
    for assembled, free in ((T.mult, t_mult), (T.multTranspose, t_mult_transpose)):
        assembled(x, y)
        free(E, x, z)
        z.axpy(-1.0, y)
        assert z.norm() <= 1e-14 * y.norm()
    E.destroy()
    R = K.ptap(T)
    R.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    d = R.createVecLeft()
    d.set(0.0)
    d.setValues(ip, K.getDiagonal().getValues(ip))
    d.assemble()
    R.setDiagonal(d, addv=PETSc.InsertMode.ADD_VALUES)
    R.assemble()
    assert len(piv) >= 10
    R.axpy(-1.0, A, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
    assert R.norm() <= 1e-13 * A.norm()
    for obj in (T, A, R, d, x, y, z):
        obj.destroy()
    solver.destroy()


def test_reused_multigrid_gives_the_fresh_answer(small_hertz) -> None:
    """A set a few pivots away from the multigrid's (matrix-free operator) is solved exactly."""
    setup, solver = _condensed_solver(small_hertz)
    x = setup.layout.x[setup.layout.mine, 0]
    a = small_hertz.params["hertz_exact"]["a"]
    first, second = x < 1.2 * a, x < a
    assert 0 < (first & ~second).sum() <= 64  # within the reuse rule
    solver.solve(setup.g, first)
    reused = solver.solve(setup.g, second, stationary=lambda res: True)
    assert reused.final and not reused.refactored
    _, fresh_solver = _condensed_solver(small_hertz, reuse=False)
    fresh = fresh_solver.solve(setup.g, second)
    assert fresh.refactored
    scale = np.abs(fresh.u).max()
    assert np.abs(reused.u - fresh.u).max() <= 1e-7 * scale
    assert np.abs(reused.mu - fresh.mu).max() <= 1e-6 * np.abs(fresh.mu).max()
    solver.destroy()
    fresh_solver.destroy()


def test_a_stationary_set_goes_on_in_the_same_cg_run(small_hertz) -> None:
    """Asked at the loose tolerance, the loop's answer stops CG or lets it go on unrestarted.

    Going on gives the answer of a run restarted from the loose iterate (1e-7) in at most
    its iterations; the loop is asked once, with the iterate the stopped run returns.
    """
    setup, stopped = _condensed_solver(small_hertz)
    going, failing = (_condensed_solver(small_hertz)[1] for _ in range(2))
    x = setup.layout.x[setup.layout.mine, 0]
    zone = x < small_hertz.params["hertz_exact"]["a"]
    asked: list[np.ndarray] = []

    def no(res) -> bool:
        asked.append(res.u)
        return False

    loose = stopped.solve(setup.g, zone, stationary=no)
    assert not loose.final and len(asked) == 1
    assert np.array_equal(asked[0], loose.u)
    restarted = stopped.solve(setup.g, zone, stationary=lambda res: True)
    on = going.solve(setup.g, zone, stationary=lambda res: True)
    assert restarted.final and on.final
    assert on.iterations <= loose.iterations + restarted.iterations
    assert np.abs(on.u - restarted.u).max() <= 1e-7 * np.abs(restarted.u).max()
    assert np.abs(on.mu - restarted.mu).max() <= 1e-6 * np.abs(restarted.mu).max()

    def fails(res) -> bool:
        raise InputError("the loop's own error")

    with pytest.raises(InputError, match="the loop's own error"):  # not a PETSc error
        failing.solve(setup.g, zone, stationary=fails)
    # From a start already at the final tolerance nothing is asked, and the answer is final.
    assert going.solve(setup.g, zone, stationary=fails).final
    for s in (stopped, going, failing):
        s.destroy()


def test_condensed_on_the_default_graded_hertz_mesh() -> None:
    """The default gmsh mesh: MUMPS' set and pressures, every step iterating.

    From a warm start a loose solve measured against ||b|| could stop at 0 iterations and
    judge the set by the previous set's displacements; the set then cycled (26 <-> 25 nodes).
    """
    scene = build_scene("hertz", HertzParams(), comm=MPI.COMM_SELF)
    ref = solve(scene, "nts", solver="mumps")
    sol = solve(scene, "nts", solver="condensed")
    assert np.array_equal(sol.active, ref.active)
    assert np.abs(sol.pressure - ref.pressure).max() <= 1e-6 * np.abs(ref.pressure).max()
    assert all(h["linear_iterations"] > 0 for h in sol.history)


def test_loose_solves_then_the_end_in_the_log(small_hertz) -> None:
    """The loop stops its solves early and solves only the stationary set to the end.

    With GAMG (the geometric multigrid's loose and final solves differ by one or two
    iterations on this mesh: too few to tell them apart by count).
    """
    sol = solve(small_hertz, "nts", solver="condensed-gamg", predictor="none")
    its = [h["linear_iterations"] for h in sol.history]
    assert len(its) >= 3
    # The last step goes on from 1e-4 to 1e-9: more iterations than any loose one from the
    # previous set's displacements (the first starts from zero).
    assert its[-1] > max(its[1:-1])


@pytest.mark.parametrize(("method", "basis"), [("mortar", "standard"), ("sts", "standard")])
def test_condensed_refuses_a_non_diagonal_d(small_hertz, method: str, basis: str) -> None:
    """Standard mortar and STS couple neighbouring active nodes: a clear error."""
    with pytest.raises(InputError, match="needs a diagonal D"):
        solve(small_hertz, method, basis=basis, solver="condensed")


def test_basis_and_solver_errors() -> None:
    """The dual basis is a mortar option; Schwarz takes no solver option."""
    scene = build_scene("blocks", BLOCK_SCENES["S1"], comm=MPI.COMM_SELF)
    with pytest.raises(InputError, match="mortar method only"):
        solve(scene, "nts", basis="dual")
    with pytest.raises(InputError, match="schwarz factorizes"):
        solve(scene, "schwarz", solver="fieldsplit")
    with pytest.raises(InputError, match="unknown solver"):
        solve(scene, "mortar", solver="cholmod")


def test_condensed_predictor_is_solved_directly(small_hertz, caplog) -> None:
    """The condensed solver's coarse solve is a direct, probed one; the fine loop is CG."""
    import logging

    from contactfx import solve

    with caplog.at_level(logging.INFO, logger="contactfx"):
        sol = solve(small_hertz, "nts", solver="condensed")
    coarse = [r.getMessage() for r in caplog.records if r.getMessage().startswith("predictor")]
    assert coarse and "probes" in coarse[0]  # only a direct solver probes
    assert all(h["probes"] == 0 for h in sol.history)  # the fine loop has no probes
    assert any(h["linear_iterations"] > 1 for h in sol.history)  # CG ran on the fine mesh


def test_release_solve_stops_at_the_first_solves_accuracy(small_hertz, monkeypatch) -> None:
    """A loose solve after a release stops at loose_rtol ||b|| (the first solve's accuracy),
    having reduced its own residual by WARM_REDUCTION: fewer iterations than reducing it by
    loose_rtol (the former rule), the same updated signs, and it still iterates.
    """
    import contactfx.linalg.condensed as condensed

    setup = None
    runs = {}
    for name, warm in (("now", condensed.WARM_REDUCTION), ("former", 1e-4)):
        monkeypatch.setattr(condensed, "WARM_REDUCTION", warm)
        setup, solver = _condensed_solver(small_hertz)
        x = setup.layout.x[setup.layout.mine, 0]
        a = small_hertz.params["hertz_exact"]["a"]
        solver.solve(setup.g, x < 1.12 * a)  # from zero to loose_rtol ||b||
        second = x < a
        assert 0 < (x < 1.12 * a).sum() - second.sum() <= 8  # a release, multigrid kept
        res = solver.solve(setup.g, second)
        assert not res.refactored and res.iterations >= 1
        runs[name] = res
        solver.destroy()
    assert runs["now"].iterations < runs["former"].iterations
    mu = {k: r.mu for k, r in runs.items()}
    assert np.array_equal(mu["now"] < 0, mu["former"] < 0)  # the same tension signs
    scale = np.abs(mu["former"]).max()
    assert np.abs(mu["now"] - mu["former"]).max() <= 1e-2 * scale


def test_geometric_multigrid_on_the_structured_grid(small_hertz) -> None:
    """On the structured mesh `condensed` runs PCMG on the grid's own coarser grids: a fresh
    solve of the Hertz zone to 1e-9 in at most 12 CG iterations (GAMG on the same system:
    more than 15; docs/scale.md, "Geometric multigrid on the structured grid"), every level
    a grid of the mesh, the pivots' rows of the finest prolongation zero, MUMPS' answer."""
    x = None
    its = {}
    answers = {}
    for name in ("condensed", "condensed-gamg"):
        setup, solver = _condensed_solver(small_hertz, reuse=False, solver=name)
        x = setup.layout.x[setup.layout.mine, 0]
        zone = x < small_hertz.params["hertz_exact"]["a"]
        res = solver.solve(setup.g, zone)
        assert res.reason > 0 and res.final
        its[name] = res.iterations
        answers[name] = res
        pc = solver._ksp.getPC()
        assert (pc.getType() == "mg") == (name == "condensed")
        if name == "condensed":
            n = pc.getMGLevels()
            assert n >= 3
            sizes = [pc.getMGInterpolation(k).getSize() for k in range(1, n)]
            assert sizes[-1][0] == setup.elasticity.K.getSize()[0]
            assert all(a[1] == b[0] for a, b in zip(sizes[1:], sizes[:-1], strict=False))
        solver.destroy()
    assert its["condensed"] <= 12 and its["condensed-gamg"] > 15, its
    a, b = answers["condensed"], answers["condensed-gamg"]
    assert np.abs(a.u - b.u).max() <= 1e-6 * np.abs(b.u).max()
    assert np.abs(a.mu - b.mu).max() <= 1e-5 * np.abs(b.mu).max()


def test_geometric_multigrid_on_gmsh_remeshes() -> None:
    """On a gmsh mesh `condensed` runs PCMG on the scene remeshed x8 (non-nested): a fresh
    solve of the Hertz zone to 1e-9 in at most 6 CG iterations, at least 3 fewer than GAMG on
    the same system (5 against 10 here; 5 against 12-15 from 100k to 2M DOFs: docs/scale.md,
    "A geometric multigrid on gmsh meshes"), and GAMG's answer."""
    scene = hertz(
        HertzParams(refine=0.1, h_far=1.0, refine_edge=0.025, mesh="gmsh"), comm=MPI.COMM_SELF
    )
    its, answers = {}, {}
    for name in ("condensed", "condensed-gamg"):
        setup, solver = _condensed_solver(scene, reuse=False, solver=name)
        zone = setup.layout.x[setup.layout.mine, 0] < scene.params["hertz_exact"]["a"]
        res = solver.solve(setup.g, zone)
        assert res.reason > 0 and res.final
        its[name], answers[name] = res.iterations, res
        pc = solver._ksp.getPC()
        assert (pc.getType() == "mg") == (name == "condensed")
        if name == "condensed":
            assert pc.getMGLevels() == 2  # this mesh and its x8 remesh
        solver.destroy()
    assert its["condensed"] <= 6 and its["condensed"] + 3 <= its["condensed-gamg"], its
    a, b = answers["condensed"], answers["condensed-gamg"]
    assert np.abs(a.u - b.u).max() <= 1e-6 * np.abs(b.u).max()
    assert np.abs(a.mu - b.mu).max() <= 1e-5 * np.abs(b.mu).max()


def test_condensed_preset_on_stretched_cells(small_hertz) -> None:
    """The `condensed-gamg` preset on cells of aspect up to 10 (issue 33): a fresh solve of the
    Hertz zone from zero to the final 1e-9 in at most 30 CG iterations, the issue's bound
    (the counts of this and earlier presets: docs/scale.md, "GAMG on stretched cells"; a
    point smoother needs several times more here), on a hierarchy whose fine level is in
    2x2 blocks (the displacement components) and whose coarse levels are in 3x3 blocks (the
    three rigid modes of the near-nullspace).
    """
    setup, solver = _condensed_solver(small_hertz, reuse=False)
    x = setup.layout.x[setup.layout.mine, 0]
    res = solver.solve(setup.g, x < small_hertz.params["hertz_exact"]["a"])
    assert res.reason > 0 and res.iterations <= 30, res.iterations
    pc = solver._ksp.getPC()
    ops = [pc.getMGSmoother(k).getOperators()[0] for k in range(pc.getMGLevels())]
    assert len(ops) >= 3
    assert ops[-1].getBlockSize() == 2
    assert all(A.getBlockSize() == 3 for A in ops[:-1])
    solver.destroy()
