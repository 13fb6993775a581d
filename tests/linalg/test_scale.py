"""Scalable solver paths: the persistent saddle-point solver, GAMG fieldsplit, near-nullspace,
reference timing and the structured Hertz mesh (timings themselves live in benchmarks/)."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from conftest import cli
from mpi4py import MPI

from contactfx.contact import Kernel
from contactfx.discretize.elasticity import material_fields, sigma
from contactfx.discretize.setup import prepare_contact
from contactfx.discretize.supports import rigid_body_modes
from contactfx.errors import InputError
from contactfx.linalg.policy import FactorizationPolicy, ReuseMode
from contactfx.linalg.saddle import SaddleSolver
from contactfx.meshes.hertz_structured import graded_points, hertz_grid
from contactfx.methods.active_set import ActiveSetOptions
from contactfx.methods.multipliers import solve_contact
from contactfx.options import SOLVERS, Method, Predictor, SolverKind
from contactfx.request import SolveRequest
from contactfx.scenes import BLOCK_SCENES, HertzParams, build_scene, hertz
from contactfx.timers import Timers


@pytest.fixture(scope="module")
def hertz_system():
    """K, B, f and the weighted gaps of the default Hertz scene with mortar (small)."""
    scene = build_scene("hertz", HertzParams())
    setup = prepare_contact(scene, Kernel.MORTAR, ActiveSetOptions().penetration_tol, Timers())
    yield setup.elasticity, setup.B, setup.g, setup.layout.x[setup.layout.mine, 0]
    setup.B.destroy()


def _close(res, ref) -> None:
    """u and mu of two saddle-point solves agree to 1e-8 relative.

    GMRES on a lagged factorization stops at a relative residual of 1e-13; the saddle-point
    matrix amplifies that by its condition number (about 1e5 here) in the multipliers.
    """
    du = np.abs(res.u - ref.u).max() / np.abs(ref.u).max()
    dmu = np.abs(res.mu - ref.mu).max() / np.abs(ref.mu).max()
    assert du <= 1e-8 and dmu <= 1e-8, (du, dmu)


MUMPS = SOLVERS["mumps"].petsc


def _saddle(el, B, policy=None, gamma: float = 0.0) -> SaddleSolver:
    """A MUMPS saddle-point solver on K, B, f (policy None: a throwaway one)."""
    return SaddleSolver(el.K, B, el.f, MUMPS, direct=True, gamma=gamma, policy=policy)


def _fresh(el, B, g, active):
    """One fresh factorization and solve of `active`: the reference of every reuse path."""
    with _saddle(el, B) as solver:
        return solver.solve(g, active)


def test_probe_responses_do_not_depend_on_augmentation(hertz_system) -> None:
    """Probe responses with A00 = K + gamma B^T B equal those of the plain saddle point."""
    el, B, g, x = hertz_system
    active = x < 1.2
    probes = np.zeros((len(x), 3))
    rows = np.flatnonzero(active)[:3]
    probes[rows, np.arange(len(rows))] = 1.0
    out = []
    for gamma in (0.0, 7000.0 / 0.02**2):
        with _saddle(el, B, FactorizationPolicy(), gamma) as solver:
            solver.solve(g, active, fresh=True)
            out.append(solver.responses(probes, active))
    scale = np.abs(out[0]).max()
    assert scale > 0 and np.abs(out[1] - out[0]).max() <= 1e-8 * scale


def test_persistent_solver_equals_fresh_solves(hertz_system) -> None:
    """Every reuse path (refactor, lagged LU + GMRES, released-row capacitance) is exact."""
    el, B, g, x = hertz_system
    sets = [x < 1.0, x < 1.3, x < 1.2, (x < 1.1) | ((x > 1.4) & (x < 1.5)), x < 0.9]
    with _saddle(el, B, FactorizationPolicy(mode=ReuseMode.REUSE)) as solver:
        paths = []
        for active in sets:
            res = solver.solve(g, active)
            _close(res, _fresh(el, B, g, active))
            paths.append(
                "released" if res.released else "factorized" if res.refactored else "lagged"
            )
        assert solver.factored.count == 1
    # The factorized set stays x < 1: the next three add rows to it, so GMRES runs on the
    # lagged factorization (a low-rank change); the last only releases rows (capacitance).
    assert paths == ["factorized", "lagged", "lagged", "lagged", "released"]


def test_released_rows_use_capacitance(hertz_system) -> None:
    """A subset of the factorized set is solved without a new factorization, exactly."""
    el, B, g, x = hertz_system
    with _saddle(el, B, FactorizationPolicy()) as solver:
        first = solver.solve(g, x < 2.0)
        assert first.refactored
        res = solver.solve(g, x < 1.2)
        assert res.released > 0 and solver.factored.count == 1
        _close(res, _fresh(el, B, g, x < 1.2))
        assert np.all(res.mu[~(x < 1.2)] == 0.0)


def test_an_inexact_capacitance_answer_is_refined(hertz_system, monkeypatch) -> None:
    """A capacitance matrix off by 1e-5 leaves a residual far above the factorization's own:
    the refinement runs (two back-substitutions per step) and ends at the fresh solve.

    Without the error the first answer is accepted after one back-substitution (here below
    RELEASED_RTOL; the ROUNDOFF rule itself acts at round-off, measured in
    benchmarks/release_accuracy.py, not asserted here)."""
    from contactfx.linalg import capacitance

    el, B, g, x = hertz_system
    iterations = []
    for skew in (1.0, 1.0 + 1e-5):

        class Skewed(capacitance.DenseLU):
            factor = skew

            def __init__(self, a: np.ndarray) -> None:
                super().__init__(a * self.factor)

        monkeypatch.setattr(capacitance, "DenseLU", Skewed)
        with _saddle(el, B, FactorizationPolicy()) as solver:
            solver.solve(g, x < 2.0)
            res = solver.solve(g, x < 1.2)
            assert res.released > 0 and solver.factored.count == 1
            floor = solver.factored.own_residual
            assert res.residual is not None
            assert res.residual <= max(capacitance.RELEASED_RTOL, capacitance.ROUNDOFF * floor)
            _close(res, _fresh(el, B, g, x < 1.2))
            iterations.append(res.iterations)
    assert iterations[0] == 1 and iterations[1] in (3, 5), iterations


def test_near_nullspace_is_the_kernel_of_free_bodies() -> None:
    """The three joint rigid modes: orthonormal, K v = 0 without Dirichlet rows, and the
    span of the translations and the rotation written from the dof coordinates."""
    import dolfinx.fem.petsc  # after contactfx, which loads MPI first
    import ufl
    from dolfinx import fem

    scene = build_scene("blocks", BLOCK_SCENES["S1"])
    V = fem.functionspace(scene.mesh, ("Lagrange", 1, (2,)))
    E, nu = material_fields(scene)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    K = dolfinx.fem.petsc.assemble_matrix(
        fem.form(ufl.inner(sigma(u, E, nu), ufl.sym(ufl.grad(v))) * ufl.dx)
    )
    K.assemble()
    modes = rigid_body_modes(V, scene)
    assert len(modes) == 3
    gram = np.array([[a.dot(b) for b in modes] for a in modes])
    np.testing.assert_allclose(gram, np.eye(3), atol=1e-12)
    y = modes[0].duplicate()
    for mode in modes:
        K.mult(mode, y)
        assert y.norm() <= 1e-10 * K.norm() * mode.norm()
    # The rigid motions written out by hand lie in their span.
    nloc = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:nloc, :2]
    rigid = np.zeros((3, 2 * nloc))
    rigid[0, 0::2], rigid[1, 1::2] = 1.0, 1.0
    rigid[2, 0::2], rigid[2, 1::2] = -x[:, 1], x[:, 0]
    basis = np.array([m.array for m in modes])
    for r in rigid:
        coef = np.linalg.lstsq(basis.T, r, rcond=None)[0]
        assert np.abs(basis.T @ coef - r).max() <= 1e-10 * np.abs(r).max()
    # Not trivially zero: a mode stretched on part of the mesh is no longer in the kernel
    # (sanity check on the test itself).
    mode = modes[2].copy()
    mode.array[: len(mode.array) // 3] *= 2.0
    K.mult(mode, y)
    assert y.norm() > 1e-6 * K.norm() * mode.norm()
    K.destroy()


@pytest.mark.parametrize(
    ("kind", "params", "method"),
    [
        ("hertz", HertzParams(), Method.MORTAR),
        ("blocks", BLOCK_SCENES["S2"], Method.MORTAR),
    ],
)
def test_gamg_fieldsplit_agrees_with_mumps(kind, params, method) -> None:
    """GAMG fieldsplit (rtol 1e-10) gives the MUMPS displacement and pressure to ~1e-6."""
    scene = build_scene(kind, params)
    ref = solve_contact(scene, SolveRequest.parse(method, solver="mumps"))
    it = solve_contact(scene, SolveRequest.parse(method, solver="fieldsplit-gamg"))
    assert np.array_equal(it.active, ref.active)
    du = np.abs(it.u.x.array - ref.u.x.array).max() / np.abs(ref.u.x.array).max()
    dp = np.abs(it.pressure - ref.pressure).max() / np.abs(ref.pressure).max()
    assert du < 1e-6 and dp < 1e-5, (du, dp)
    assert max(h["linear_iterations"] for h in it.history) < 100


def test_reference_timing_in_json(tmp_path) -> None:
    """--reference-timing times a fresh solve, a fresh LU and a fresh LDL^T of the final
    saddle point; per-iteration solver data is there."""
    out = tmp_path / "r.json"
    proc = cli("solve", "hertz", "--method", "mortar", "--reference-timing", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    for key in ("reference_solve", "reference_lu", "reference_ldlt"):
        assert data["times"][key] > 0.0, key
    assert {"search", "contact", "solve"} <= data["times"].keys()
    for step in data["active_set"]:
        assert step["linear_iterations"] >= 1 and step["solve_time"] > 0.0


def test_graded_points_follow_the_size_law() -> None:
    """Spacing h0 on [0, r], then growing at the slope, capped at h_far; ends exact."""
    s = graded_points(10.0, 0.01, 1.0, 0.2, 0.5)
    h = np.diff(s)
    assert s[0] == 0.0 and s[-1] == 10.0 and np.all(h > 0)
    # Rounding the cell count to an integer scales every size by at most 1 +- 1/(2 n).
    slack = 0.5 / len(h)
    fine = h[s[1:] <= 1.0]
    assert np.ptp(fine) < 1e-12 and abs(fine[0] / 0.01 - 1.0) <= slack
    assert h.max() <= 0.5 * (1 + slack)
    grow = h[1:] / h[:-1]
    # dh/ds = slope with ds = h per cell: neighbouring sizes grow by exp(slope) at most.
    assert grow.min() > 1.0 - 1e-9 and grow.max() <= np.exp(0.2) * (1 + 1e-9)


def test_structured_hertz_geometry_and_contact() -> None:
    """Areas, tags and the Hertz half-width on the structured mesh (no gmsh)."""
    x, cells, n_block = hertz_grid(60.0, 60.0, 60.0, 0.05, 2.0, 2.0, 0.1)
    p = x[cells][:, [0, 1, 3, 2]]
    area = 0.5 * np.abs(
        np.sum(
            p[..., 0] * np.roll(p[..., 1], -1, 1) - np.roll(p[..., 0], -1, 1) * p[..., 1], axis=1
        )
    )
    assert area[:n_block].sum() == pytest.approx(3600.0, rel=1e-12)
    # The polygonal arc cuts off at most (chord^3 / 12 R) per facet: under 0.1%.
    assert area[n_block:].sum() == pytest.approx(math.pi * 900.0, rel=1e-3)
    assert len(np.unique(cells)) == len(x)  # no orphan nodes
    scene = hertz(HertzParams(refine=0.05, h_far=2.0, mesh="structured"))
    for name in ("contact1", "contact2", "symmetry", "support", "load"):
        n = MPI.COMM_WORLD.allreduce(len(scene.facet_tags.find(scene.groups.by_name[name][1])))
        assert n > 0, name
    sol = solve_contact(scene, SolveRequest.parse(Method.MORTAR, solver="mumps"))
    a_exact = scene.params["hertz_exact"]["a"]
    xs = sol.layout.x[sol.active, 0]
    # Half-width within one contact element of Hertz's a.
    assert abs(xs.max() - a_exact) < 0.05 + 1e-9
    force = float((sol.pressure * sol.layout.weights).sum())
    assert force == pytest.approx(50.0, rel=1e-9)


@pytest.fixture(scope="module")
def structured_pair():
    """A structured Hertz scene (70k dofs, 58 active nodes) and the same scene 8x coarser."""
    fine = hertz(HertzParams(refine=0.025, h_far=1.0, mesh="structured"))
    coarse = hertz(HertzParams(refine=0.2, h_far=8.0, mesh="structured"))
    return fine, coarse


@pytest.mark.parametrize("method", [Method.MORTAR, Method.NTS, Method.STS])
def test_coarse_predictor_same_answer_one_factorization(structured_pair, method) -> None:
    """A coarse solve's zone as the first set: the same converged set and fields, one LU."""
    from contactfx.methods.predictor import coarse_initial_set

    fine, coarse = structured_pair
    # The plain loop: from the touching nodes (the default now starts from every row).
    plain = solve_contact(
        fine, SolveRequest.parse(method, solver="mumps"), aso=ActiveSetOptions(start_all=False)
    )
    init = coarse_initial_set(solve_contact(coarse, SolveRequest.parse(method, solver="mumps")))
    sol = solve_contact(fine, SolveRequest.parse(method, solver="mumps"), initial_active=init)
    assert np.array_equal(sol.active, plain.active)
    p_max = np.abs(plain.pressure).max()
    assert np.abs(sol.pressure - plain.pressure).max() <= 1e-8 * p_max
    du = np.abs(sol.u.x.array - plain.u.x.array).max()
    assert du <= 1e-8 * np.abs(plain.u.x.array).max()
    # The cost: one factorization (plain: two), band probes only, at most two solves.
    assert sum(h["factorized"] for h in sol.history) == 1
    assert sum(h["factorized"] for h in plain.history) >= 2
    assert sol.iterations <= 2
    probes = sum(h["probes"] for h in sol.history)
    assert 0 < probes < int(sol.active.sum()) / 2, probes


@pytest.mark.parametrize("method", [Method.MORTAR, Method.NTS, Method.STS])
def test_start_from_every_row_same_answer_one_factorization(structured_pair, method) -> None:
    """The default serial MUMPS start (every row in contact, all probed): same answer, one LU.

    Then exactly two solves: the probing one, and one that only releases rows (capacitance).
    """
    fine, _ = structured_pair
    plain = solve_contact(
        fine, SolveRequest.parse(method, solver="mumps"), aso=ActiveSetOptions(start_all=False)
    )
    sol = solve_contact(fine, SolveRequest.parse(method, solver="mumps"))
    assert np.array_equal(sol.active, plain.active)
    p_max = np.abs(plain.pressure).max()
    assert np.abs(sol.pressure - plain.pressure).max() <= 1e-8 * p_max
    du = np.abs(sol.u.x.array - plain.u.x.array).max()
    assert du <= 1e-8 * np.abs(plain.u.x.array).max()
    hist = sol.history
    assert [h["factorized"] for h in hist] == [1, 0]
    assert hist[0]["active"] == sol.layout.size and hist[0]["probes"] == sol.layout.size
    assert hist[-1]["entered"] == hist[-1]["left"] == 0


def test_selected_inverse_responses_equal_dense_solves(hertz_system) -> None:
    """Probe responses from MUMPS' selected inverse entries equal solves with f = 0, g = -e_j.

    Column j of the responses is mu of the saddle point with no load and the weighted gap
    of row j opened by 1: solved here column by column on the same factorization.
    """
    el, B, g, x = hertz_system
    active = x < 1.6
    rows = np.flatnonzero(active)
    probes = np.zeros((len(x), len(rows)))
    probes[rows, np.arange(len(rows))] = 1.0
    zero = el.f.duplicate()
    zero.set(0.0)
    with _saddle(el, B, FactorizationPolicy()) as solver:
        assert solver.cheap_responses
        solver.solve(g, active, fresh=True)
        selected = solver.responses(probes, active)
        # MUMPS is back to ordinary solves afterwards: a released set, then a refactored one.
        _close(solver.solve(g, x < 1.2), _fresh(el, B, g, x < 1.2))
        _close(solver.solve(g, x < 1.8), _fresh(el, B, g, x < 1.8))
    picked = np.linspace(0, len(rows) - 1, 5).astype(int)
    with SaddleSolver(el.K, B, zero, MUMPS, direct=True, policy=FactorizationPolicy()) as ref:
        for j in picked:
            unit = np.zeros(len(x))
            unit[rows[j]] = -1.0
            dense = ref.solve(unit, active).mu
            scale = np.abs(dense).max()
            assert scale > 0 and np.abs(selected[:, j] - dense).max() <= 1e-10 * scale
    zero.destroy()


def test_selected_responses_on_the_probed_rows_equal_dense_solves(hertz_system) -> None:
    """Responses asked on the probed rows only: those rows equal dense solves, others zero.

    The loop reads only the probed rows (its complementarity problem, a later release), so
    MUMPS is asked for those entries alone; the reference is the same columns solved with
    dense right-hand sides on a fresh factorization.
    """
    el, B, g, x = hertz_system
    active = x < 1.6
    rows = np.flatnonzero(active)
    picked = rows[np.linspace(0, len(rows) - 1, 6).astype(int)]
    probes = np.zeros((len(x), len(picked)))
    probes[picked, np.arange(len(picked))] = 1.0
    wanted = probes.any(axis=1)
    zero = el.f.duplicate()
    zero.set(0.0)
    with _saddle(el, B, FactorizationPolicy()) as solver:
        solver.solve(g, active, fresh=True)
        part = solver.responses(probes, active, wanted)
    assert not part[~wanted].any()
    with SaddleSolver(el.K, B, zero, MUMPS, direct=True, policy=FactorizationPolicy()) as ref:
        for j, row in enumerate(picked):
            unit = np.zeros(len(x))
            unit[row] = -1.0
            dense = ref.solve(unit, active).mu
            scale = np.abs(dense).max()
            assert scale > 0
            assert np.abs(part[wanted, j] - dense[wanted]).max() <= 1e-10 * scale
    zero.destroy()


def test_response_cache_refuses_rows_it_did_not_compute() -> None:
    """Kept responses computed on some rows only are not read on the others (zeros there)."""
    from contactfx.linalg.responses import ResponseCache

    comm = MPI.COMM_SELF
    probes = np.zeros((4, 2))
    probes[1, 0] = probes[3, 1] = 1.0
    active = np.ones(4, dtype=bool)
    values = np.arange(8.0).reshape(4, 2)
    cache = ResponseCache()
    cache.store(1, probes, active, values, 0, comm, np.array([False, True, False, True]))
    both = np.array([False, True, False, True])
    assert np.array_equal(cache.lookup(1, np.array([1, 3]), both, comm), values)
    cache.store(1, probes, active, values, 0, comm, np.array([False, True, False, False]))
    assert cache.lookup(1, np.array([1, 3]), both, comm) is None
    assert cache.lookup(1, np.array([1]), np.array([False, True, False, False]), comm) is not None
    assert cache.lookup(2, np.array([1]), np.array([False, True, False, False]), comm) is None


def test_coarse_factor_keeps_the_coarse_rows_probeable(structured_pair, monkeypatch) -> None:
    """A direct solver's coarse mesh is coarser still when the fine rows over the factor
    exceed COARSE_ROWS (the coarse solve probes them all): the same converged answer.

    The 70k-DOF scene (121 rows) is too small for x32: the direct factor is set to 8 and
    COARSE_ROWS lowered so that its rows over 8 exceed it (x16, a 16-row coarse mesh);
    PROBE_ALL_ROWS too, so that auto starts from the coarse solve.
    """
    from contactfx import options
    from contactfx.api import solve
    from contactfx.methods import predictor

    fine, _ = structured_pair
    rows = predictor.contact_facets(fine)
    mumps = SOLVERS["mumps"]
    direct = options.TRAITS[SolverKind.DIRECT]
    assert predictor.coarse_factor(mumps, fine) == direct.coarse_factor == 16.0
    eight = {**options.TRAITS, SolverKind.DIRECT: replace(direct, coarse_factor=8.0)}
    monkeypatch.setattr(options, "TRAITS", eight)
    limit = int(rows / 12)  # between rows / 16 and rows / 8
    monkeypatch.setattr(predictor, "COARSE_ROWS", limit)
    monkeypatch.setattr(predictor, "PROBE_ALL_ROWS", limit)  # auto: the coarse start
    assert predictor.coarse_factor(mumps, fine) == 16.0
    assert predictor.coarse_factor(SOLVERS["fieldsplit"], fine) == 8.0
    plain = solve(fine, "mortar", solver="mumps", predictor="none")
    sol = solve(fine, "mortar", solver="mumps", predictor="auto")
    assert sum(h["probes"] for h in sol.history) < 0.5 * rows  # the band, not every row
    assert np.array_equal(sol.active, plain.active)
    p_max = np.abs(plain.pressure).max()
    assert np.abs(sol.pressure - plain.pressure).max() <= 1e-8 * p_max


@pytest.mark.parametrize("guess", ["inside", "far", "nothing"])
def test_any_initial_set_converges_to_the_same_answer(structured_pair, guess) -> None:
    """A wrong first set (a subset, a wide superset, empty) costs iterations, not accuracy."""
    fine, _ = structured_pair
    a = fine.params["hertz_exact"]["a"]
    radius = {"inside": 0.5 * a, "far": 3.0 * a, "nothing": -1.0}[guess]
    plain = solve_contact(fine, SolveRequest.parse(Method.MORTAR, solver="mumps"))
    sol = solve_contact(
        fine,
        SolveRequest.parse(Method.MORTAR, solver="mumps"),
        initial_active=lambda x: x[:, 0] <= radius,
    )
    assert np.array_equal(sol.active, plain.active)
    p_max = np.abs(plain.pressure).max()
    assert np.abs(sol.pressure - plain.pressure).max() <= 1e-8 * p_max


def test_run_case_coarse_predictor() -> None:
    """run_case's coarse predictor: timed apart, same contact zone and force as without it."""
    from contactfx.api import run_case
    from contactfx.methods.predictor import use_coarse

    params = HertzParams(refine=0.025, mesh="structured")
    base, s_base = run_case("hertz", params, SolveRequest.parse("mortar", predictor="none"))
    s_base = s_base.to_json()
    sol, s = run_case("hertz", params, SolveRequest.parse("mortar", predictor="coarse"))
    s = s.to_json()
    assert "predictor" in s["times"] and "predictor" not in s_base["times"]
    assert np.array_equal(sol.active, base.active)
    assert np.abs(sol.pressure - base.pressure).max() <= 1e-8 * np.abs(base.pressure).max()
    assert sum(h["factorized"] for h in sol.history) == 1
    # "auto" leaves small meshes alone.
    assert not use_coarse(Predictor.AUTO, sol.scene, SOLVERS["fieldsplit"])
    with pytest.raises(InputError):
        Predictor.parse("sometimes")


def test_auto_predictor_by_candidate_rows() -> None:
    """auto, direct: every row probed up to PROBE_ALL_ROWS rows, the coarse solve above."""
    from contactfx.api import run_scene
    from contactfx.methods.predictor import PROBE_ALL_ROWS, contact_facets, use_coarse

    few = hertz(HertzParams(refine=0.05))
    many = hertz(HertzParams(refine=0.0025))  # the default grading: 871 rows
    assert contact_facets(few) <= PROBE_ALL_ROWS < contact_facets(many)
    assert not use_coarse(Predictor.AUTO, few, SOLVERS["mumps"])
    assert use_coarse(Predictor.AUTO, many, SOLVERS["mumps"])
    sol, data = run_scene(many, SolveRequest.parse("mortar"))
    data = data.to_json()
    assert abs(contact_facets(many) - data["multipliers"]) <= 1  # facets + 1 nodes per curve
    assert "predictor" in data["times"]
    assert max(h["probes"] for h in sol.history) < 0.1 * data["multipliers"]  # a band only
