"""The 2D models: plane stress, and axisymmetric (sphere on a block, flat punch, patch test).

docs/models.md gives the formulas and the measured errors these tests bound.
"""

import json
import shutil
from dataclasses import replace
from pathlib import Path

import dolfinx_solver  # noqa: F401 - orders MPI ahead of the dolfinx bindings
import numpy as np
import pytest
from conftest import ROOT, cli, run_cli
from mpi4py import MPI

from contactfx import SolveRequest, load_scene_file
from contactfx.api import run_case, run_scene
from contactfx.errors import InputError
from contactfx.results.interface import u_at_points
from contactfx.results.stress import body_stress_deviation, sigma_field, sigma_zz_field
from contactfx.scenes import (
    BLOCK_SCENES,
    HertzParams,
    Material,
    Model,
    hertz_exact,
    scene_from_gmsh,
)

SCENES = ROOT / "tests" / "scenes"
S4 = BLOCK_SCENES["S4"]
# Equal widths on matching uniform meshes: every method must reproduce the uniform state.
MATCHING = replace(S4, size1=0.25, size2=0.25, grading1=1.0, grading2=1.0)


def _settlement(sol) -> float:
    """u_y of the top edge (the largest y), checked uniform."""
    u = u_at_points(sol)
    top = u[:, 1] >= u[:, 1].max() - 1e-9
    uy = u[top, 3]
    assert np.ptp(uy) <= 1e-10 * np.abs(uy).max()
    return float(uy.mean())


@pytest.mark.parametrize("method", ["mortar", "nts"])
def test_plane_stress_blocks_settle_by_p_h_over_e(method: str) -> None:
    """Plane stress: sigma_zz = 0, eps_yy = -p/E, the top moves by p (h1/E1 + h2/E2)."""
    params = replace(S4 if method == "mortar" else MATCHING, model=Model.PLANE_STRESS)
    sol, record = run_case("blocks", params, SolveRequest.parse(method), comm=MPI.COMM_SELF)
    assert record.to_json()["params"]["model"] == "plane_stress"
    exact = -params.p * (params.h1 / params.E1 + params.h2 / params.E2)
    assert _settlement(sol) == pytest.approx(exact, rel=1e-8)
    assert max(body_stress_deviation(sol, -params.p).values()) < 1e-8
    # The plane-strain settlement is (1 - nu^2) times smaller: the model is really switched.
    strain_params = replace(params, model=Model.PLANE_STRAIN)
    strain, _ = run_case("blocks", strain_params, SolveRequest.parse(method), comm=MPI.COMM_SELF)
    assert _settlement(strain) == pytest.approx(exact * (1 - params.nu1**2), rel=1e-8)


AXI_METHODS = [
    pytest.param("nts", {}, id="nts"),
    pytest.param("sts", {}, id="sts"),
    pytest.param("mortar", {}, id="mortar"),
    pytest.param("mortar", {"basis": "dual"}, id="dual-mortar"),
    pytest.param("penalty", {}, id="penalty"),
    pytest.param("nts", {"enforcement": "penalty"}, id="nts-penalty"),
]


@pytest.mark.parametrize(("method", "options"), AXI_METHODS)
def test_axisymmetric_patch_test(method: str, options: dict) -> None:
    """Two stacked cylinders under uniform p: u_r = nu p r / E, u_y linear, exact in Q1."""
    params = replace(MATCHING, model=Model.AXISYMMETRIC)
    sol, record = run_case(
        "blocks", params, SolveRequest.parse(method, **options), comm=MPI.COMM_SELF
    )
    data = record.to_json()
    # The force is the total over the turn: p pi r^2.
    force = params.p * np.pi * (params.l2 / 2) ** 2
    assert data["contact_force"] == pytest.approx(force, rel=1e-10)
    assert max(body_stress_deviation(sol, -params.p).values()) < 1e-8
    exact = -params.p * (params.h1 / params.E1 + params.h2 / params.E2)
    if sol.penalty is not None:  # the penalty's penetration p / eps adds to the settlement
        exact -= params.p / sol.penalty.eps
    assert _settlement(sol) == pytest.approx(exact, rel=1e-8)
    # u_r = nu p r / E in the top cylinder (its top edge, where no other body's node lies).
    u = u_at_points(sol)
    top = u[:, 1] >= u[:, 1].max() - 1e-9
    ur = params.nu2 * params.p * u[top, 0] / params.E2
    assert np.abs(u[top, 2] - ur).max() < 1e-8 * np.abs(ur).max()


def test_axisymmetric_mortar_patch_test_non_matching() -> None:
    """S4's non-matching, graded meshes: segment-based mortar stays exact in axisymmetric."""
    sol, _ = run_case(
        "blocks",
        replace(S4, model=Model.AXISYMMETRIC),
        SolveRequest.parse("mortar"),
        comm=MPI.COMM_SELF,
    )
    assert max(body_stress_deviation(sol, -S4.p).values()) < 1e-8


@pytest.fixture(scope="module")
def sphere() -> dict:
    """The sphere on a block (tests/scenes/axi_sphere.toml, 2232 cells), mortar."""
    scene = load_scene_file(SCENES / "axi_sphere.toml", MPI.COMM_SELF)
    return run_scene(scene, SolveRequest.parse("mortar"))[1].to_json()


def test_axisymmetric_sphere_on_a_block_against_3d_hertz(sphere: dict) -> None:
    """Total force = the applied load; a and p0 within 2.5 % of the 3D (sphere) Hertz."""
    assert sphere["elements"] < 5000
    assert sphere["params"]["model"] == "axisymmetric"
    force = sphere["contacts"][0]["force"][1]
    assert force == pytest.approx(100.0, rel=1e-6)  # p pi R^2, the load on the equator disc
    hz = sphere["hertz"]
    # E* = E / (2 (1 - nu^2)), a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2)
    e_star = 7000.0 / (2 * (1 - 0.3**2))
    a = (3 * 100.0 * 10.0 / (4 * e_star)) ** (1 / 3)
    assert hz["a_exact"] == pytest.approx(a, rel=1e-6)
    assert hz["p0_exact"] == pytest.approx(3 * 100.0 / (2 * np.pi * a * a), rel=1e-6)
    assert hz["a"] == pytest.approx(a, rel=0.025)
    assert hz["p0"] == pytest.approx(hz["p0_exact"], rel=0.025)
    assert hz["l2_error"] < 0.05


@pytest.mark.parametrize("method", ["mortar", "nts"])
def test_axisymmetric_flat_punch_against_boussinesq(method: str) -> None:
    """A rigid flat punch: p(r) = P / (2 pi a sqrt(a^2 - r^2)) within 2 % at r <= 0.7 a."""
    scene = load_scene_file(SCENES / "axi_punch.toml", MPI.COMM_SELF)
    data = run_scene(scene, SolveRequest.parse(method))[1].to_json()
    pair = data["contacts"][0]
    load = abs(pair["force"][1])
    x = np.array(pair["interface"]["x"])
    p = np.array(pair["interface"]["pressure"])
    inner = x <= 0.7
    exact = load / (2 * np.pi * np.sqrt(1.0 - x[inner] ** 2))
    assert np.abs(p[inner] / exact - 1).max() < 0.02
    # A half-space would take P = 2 E* a d = 2.198; the finite block is somewhat stiffer.
    assert 2.1 < load < 2.5


def test_axisymmetric_builtin_hertz_is_a_sphere(tmp_path: Path) -> None:
    """--model axisymmetric: the built-in Hertz is a sphere on a block, P the total force."""
    out = tmp_path / "r.json"
    run = cli("solve", "hertz", "--model", "axisymmetric", "--refine", "0.1", "--json", str(out))
    assert run.returncode == 0, run.stderr
    data = json.loads(out.read_text())
    assert data["params"]["model"] == "axisymmetric"
    assert data["contact_force"] == pytest.approx(100.0, rel=1e-6)
    exact = hertz_exact(HertzParams(model=Model.AXISYMMETRIC))
    assert data["hertz"]["a_exact"] == pytest.approx(exact["a"], rel=1e-12)
    assert data["hertz"]["a"] == pytest.approx(exact["a"], rel=0.05)


def test_effective_modulus_follows_the_model() -> None:
    """Hertz's E*: E/(1 - nu^2) per body in plane strain and axisymmetric, E in plane stress."""
    strain = hertz_exact(HertzParams())
    stress = hertz_exact(HertzParams(model=Model.PLANE_STRESS))
    assert stress["E_star"] == pytest.approx(7000.0 / 2, rel=1e-14)
    assert strain["E_star"] == pytest.approx(7000.0 / (2 * (1 - 0.23**2)), rel=1e-14)


def test_sigma_zz_of_each_model() -> None:
    """fields.pvtu's sigma_zz: nu (sxx + syy) in plane strain, 0 in plane stress, sigma_theta."""
    coarse = replace(BLOCK_SCENES["S1"], size1=0.5, size2=0.5)
    for model in Model:
        sol, _ = run_case(
            "blocks", replace(coarse, model=model), SolveRequest.parse("mortar"), comm=MPI.COMM_SELF
        )
        s = sigma_field(sol).x.array.reshape(-1, 4)
        szz = sigma_zz_field(sol).x.array
        if model is Model.PLANE_STRAIN:
            assert np.allclose(szz, 0.3 * (s[:, 0] + s[:, 3]), rtol=1e-10, atol=1e-10)
        elif model is Model.PLANE_STRESS:
            assert np.all(szz == 0.0)
        else:
            assert np.abs(szz).max() > 1.0  # the hoop stress of the cylinders


def test_axisymmetric_cell_at_negative_x_is_refused() -> None:
    """x is the radius: a mesh reaching x < 0 is an InputError (one line, exit 2 in the CLI)."""
    with pytest.raises(InputError, match="x is the radius"):
        scene_from_gmsh(
            SCENES / "rotated_hertz.geo",
            bodies={"block": Material(7000.0, 0.3), "disc": Material(7000.0, 0.3)},
            contacts=[("disc_contact", "block_contact")],
            comm=MPI.COMM_SELF,
            model="axisymmetric",
        )


def test_axisymmetric_cli_refuses_negative_x(tmp_path: Path) -> None:
    """The CLI prints one line and exits with 2."""
    shutil.copy(SCENES / "rotated_hertz.geo", tmp_path)
    text = (SCENES / "rotated_hertz.toml").read_text()
    (tmp_path / "s.toml").write_text('model = "axisymmetric"\n' + text)
    run = run_cli("solve", str(tmp_path / "s.toml"))
    assert run.returncode == 2
    assert len(run.stderr.strip().splitlines()) == 1
    assert "x is the radius" in run.stderr
