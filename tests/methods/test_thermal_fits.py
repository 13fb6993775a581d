"""Thermal strain and interference fits in whole solves, against closed forms.

- A block heated by dT between two rigid walls (tests/scenes/heated_block.toml), free in y:
  eps_xx = 0, sigma_yy = 0, and in plane strain eps_zz = 0, so (by hand, 3D Hooke with
  eps0 = alpha dT): sigma_zz = nu sigma_xx - E alpha dT, and eps_xx = 0 gives
  sigma_xx (1 - nu^2) = -E alpha dT (1 + nu), the wall pressure E alpha dT / (1 - nu); in
  plane stress (sigma_zz = 0) it is E alpha dT. The displacement is linear: a patch test,
  exact to round-off on the unstructured mesh.
- A shrink fit of two rings (tests/scenes/shrink_fit.toml, quarter model): Lame's pressure
  (docs/models.md) to 1 %, every node of the pair active.
"""

from __future__ import annotations

import math
from pathlib import Path

import dolfinx.fem.petsc
import numpy as np
import pytest
import ufl
from conftest import ROOT
from dolfinx import fem, mesh
from mpi4py import MPI

from contactfx import SolveRequest, load_scene_file, run_scene
from contactfx.discretize import elasticity
from contactfx.discretize.thermal import (
    axisymmetric_thermal_load,
    plane_strain_szz,
    thermal_stress,
)
from contactfx.results.references import lame_pressure
from contactfx.scenes import Model

SCENES = ROOT / "tests" / "scenes"
E, NU, ALPHA, DT = 1000.0, 0.3, 1e-5, 100.0


def test_thermal_stress_by_hand() -> None:
    """sigma0 = C alpha dT I per model, and the walls' closed forms from it (plane strain)."""
    eps0 = ALPHA * DT
    ps = thermal_stress(E, NU, ALPHA, DT, Model.PLANE_STRAIN)
    assert ps.in_plane == pytest.approx(E * eps0 / (1 - 2 * NU), rel=1e-14)
    pst = thermal_stress(E, NU, ALPHA, DT, Model.PLANE_STRESS)
    assert (pst.in_plane, pst.out_of_plane) == (pytest.approx(E * eps0 / (1 - NU)), 0.0)
    axi = thermal_stress(E, NU, ALPHA, DT, Model.AXISYMMETRIC)
    assert axi.in_plane == axi.out_of_plane == pytest.approx(E * eps0 / (1 - 2 * NU))
    # Plane strain between walls: eps_xx = 0, sigma_yy = 0 fixes eps_yy; then sigma_xx.
    lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    eps_yy = ps.in_plane / (lam + 2 * mu)
    sxx = lam * eps_yy - ps.in_plane
    assert sxx == pytest.approx(-E * eps0 / (1 - NU), rel=1e-13)
    # ... and 3D Hooke agrees: eps_zz = (szz - nu sxx) / E + eps0 = 0.
    szz = plane_strain_szz(sxx, 0.0, E, NU, eps0)
    assert (szz - NU * sxx) / E + eps0 == pytest.approx(0.0, abs=1e-16)


def _walls(path: Path, method: str) -> tuple[dict, np.ndarray]:
    sol, run = run_scene(load_scene_file(path), SolveRequest.parse(method))
    data = run.to_json()
    p = np.concatenate([sol.pressure[pv.rows] for pv in sol.pairs])
    return data, p


@pytest.mark.parametrize("method", ["mortar", "nts"])
def test_heated_block_between_walls_plane_strain(method: str) -> None:
    """Wall pressure E alpha dT / (1 - nu) at every node to 1e-8 (measured ~1e-14), the
    stress sigma_xx = -E alpha dT / (1 - nu), sigma_yy = 0 everywhere (the thermal part
    subtracted), forces balanced, nothing overlapping before the solve."""
    exact = E * ALPHA * DT / (1 - NU)
    data, p = _walls(SCENES / "heated_block.toml", method)
    assert np.max(np.abs(p / exact - 1.0)) < 1e-8, p
    assert data["patch"]["max"] < 1e-8, data["patch"]
    left, right = data["contacts"]
    assert left["force"][0] == pytest.approx(exact * 1.0, rel=1e-10)  # height H = 1
    assert right["force"][0] == pytest.approx(-exact * 1.0, rel=1e-10)
    assert left["initial_overlap"] == right["initial_overlap"] == 0.0


@pytest.mark.skipif(
    not hasattr(elasticity, "stress"),
    reason="needs the plane-stress law (elasticity.stress(eps, E, nu, model), branch models)",
)
def test_heated_block_between_walls_plane_stress(tmp_path: Path) -> None:
    """Plane stress: the wall pressure is E alpha dT (runs once sigma knows the model)."""
    text = (SCENES / "heated_block.toml").read_text()
    text = text.replace('mesh = "heated_block.geo"', f'mesh = "{SCENES / "heated_block.geo"}"')
    text = 'model = "plane_stress"\n' + text.replace("-1.4285714285714286", "-1.0")
    path = tmp_path / "heated_block_plane_stress.toml"
    path.write_text(text)
    data, p = _walls(path, "mortar")
    assert np.max(np.abs(p / (E * ALPHA * DT) - 1.0)) < 1e-8, p
    assert data["patch"]["max"] < 1e-8, data["patch"]


def test_shrink_fit_drawn_overlapping_matches_lame() -> None:
    """interference = true: the drawn overlap resolved, every node active, the mean
    pressure within 1 % of Lame (measured +0.034 %), the initial overlap the drawn delta."""
    sol, run = run_scene(load_scene_file(SCENES / "shrink_fit.toml"), SolveRequest.parse("mortar"))
    data = run.to_json()
    (lame,) = data["lame"]
    assert (lame["inner"], lame["outer"], lame["model"]) == ("shaft", "hub", "plane_strain")
    assert lame["p_exact"] == pytest.approx(51.510989010989015, rel=1e-12)
    assert lame["error"] < 0.01, lame
    assert sol.active[sol.pairs[0].rows].all()
    assert lame["active_fraction"] == 1.0
    c = data["contacts"][0]
    assert c["active_nodes"] == c["multipliers"] == 41
    assert c["initial_overlap"] == pytest.approx(0.002, rel=1e-3)


def test_shrink_fit_prescribed_interference_matches_lame() -> None:
    """interference = D on rings drawn touching: the same fit, to 1 % (measured +0.11 %)."""
    sol, run = run_scene(
        load_scene_file(SCENES / "shrink_fit_touching.toml"), SolveRequest.parse("mortar")
    )
    (lame,) = run.to_json()["lame"]
    assert lame["delta"] == 0.002 and lame["error"] < 0.01, lame
    assert sol.active[sol.pairs[0].rows].all()
    assert run.contacts[0].initial_overlap == pytest.approx(0.002, rel=1e-6)


def test_lame_formula_plane_strain_substitution() -> None:
    """Plane strain is plane stress with E -> E/(1 - nu^2), nu -> nu/(1 - nu); a solid shaft
    (a = 0) of one material has p = E delta (c^2 - b^2) / (2 b c^2) in plane stress."""
    E1, nu1, E2, nu2 = 200e3, 0.3, 70e3, 0.33
    pe = lame_pressure(1.0, 2.0, 3.0, 0.002, (E1, nu1), (E2, nu2), Model.PLANE_STRAIN)
    ps = lame_pressure(
        1.0,
        2.0,
        3.0,
        0.002,
        (E1 / (1 - nu1**2), nu1 / (1 - nu1)),
        (E2 / (1 - nu2**2), nu2 / (1 - nu2)),
        Model.PLANE_STRESS,
    )
    assert pe == pytest.approx(ps, rel=1e-14)
    solid = lame_pressure(0.0, 2.0, 3.0, 0.002, (E1, nu1), (E1, nu1), Model.PLANE_STRESS)
    assert solid == pytest.approx(E1 * 0.002 * (9 - 4) / (2 * 2 * 9), rel=1e-14)


def test_axisymmetric_thermal_load_is_a_free_expansion() -> None:
    """The axisymmetric thermal load (used once the axisymmetric elasticity is there) is
    K u for the free expansion u = eps0 (r, z), whose strain is eps0 in rr, zz and the hoop:
    K assembled here from the 3D law with 2 pi r dx (measured 2e-15)."""
    msh = mesh.create_rectangle(
        MPI.COMM_SELF, [[0.5, 0.0], [2.0, 1.0]], [6, 5], mesh.CellType.quadrilateral
    )
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    Q = fem.functionspace(msh, ("DG", 0))
    Ef, nuf, e0 = fem.Function(Q), fem.Function(Q), fem.Function(Q)
    Ef.x.array[:], nuf.x.array[:], e0.x.array[:] = E, NU, ALPHA * DT
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    r = ufl.SpatialCoordinate(msh)[0]

    def eps3(w: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        e = ufl.sym(ufl.grad(w))
        return ufl.as_matrix([[e[0, 0], e[0, 1], 0], [e[1, 0], e[1, 1], 0], [0, 0, w[0] / r]])

    lam, mu = Ef * nuf / ((1 + nuf) * (1 - 2 * nuf)), Ef / (2 * (1 + nuf))

    def sig(e: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        return 2 * mu * e + lam * ufl.tr(e) * ufl.Identity(3)

    a = fem.form(ufl.inner(sig(eps3(u)), eps3(v)) * 2 * math.pi * r * ufl.dx)
    K = dolfinx.fem.petsc.assemble_matrix(a)
    K.assemble()
    free = fem.Function(V)
    free.interpolate(lambda x: np.vstack([ALPHA * DT * x[0], ALPHA * DT * x[1]]))
    Ku = K.createVecLeft()
    K.mult(free.x.petsc_vec, Ku)
    form = fem.form(axisymmetric_thermal_load(msh, v, Ef, nuf, e0))
    L = dolfinx.fem.petsc.assemble_vector(form)
    assert np.max(np.abs(Ku.array - L.array)) < 1e-12 * np.max(np.abs(L.array))


AXI_DISK = """\
// A disk r in [0, 1], z in [0, 0.5] between two rigid plates z = 0 and z = 0.5.
h = 0.13;
Point(1) = {0, 0, 0, h}; Point(2) = {1, 0, 0, h};
Point(3) = {1, 0.5, 0, 0.6 * h}; Point(4) = {0, 0.5, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Mesh.Algorithm = 8; Mesh.RecombinationAlgorithm = 3; Mesh.RecombineAll = 1;
Recombine Surface{1};
Physical Surface("disk") = {1};
Physical Curve("bottom") = {1}; Physical Curve("top") = {3};
Physical Curve("rim") = {2}; Physical Curve("axis") = {4};
"""

AXI_DISK_SCENE = """\
model = "axisymmetric"
mesh = "disk.geo"
[bodies.disk]
E = 1000.0
nu = 0.3
alpha = 1e-5
dT = 100.0
[[obstacle]]
name = "floor"
shape = "plane"
point = [0.0, 0.0]
normal = [0.0, 1.0]
surface = "bottom"
[[obstacle]]
name = "ceiling"
shape = "plane"
point = [0.0, 0.5]
normal = [0.0, -1.0]
surface = "top"
[[reference]]
type = "uniform_stress"
sigma = [[0.0, 0.0], [0.0, -1.0]]
"""


@pytest.mark.serial
@pytest.mark.parametrize("method", ["mortar", "nts"])
def test_heated_disk_between_plates_axisymmetric(tmp_path: Path, method: str) -> None:
    """A heated disk held axially by two rigid plates, free radially: sigma_zz = -E alpha dT
    (= -1), sigma_rr = sigma_theta = 0, u_r = (1 + nu) alpha dT r (a patch test: exact)."""
    (tmp_path / "disk.geo").write_text(AXI_DISK)
    (tmp_path / "disk.toml").write_text(AXI_DISK_SCENE)
    sol, run = run_scene(load_scene_file(tmp_path / "disk.toml"), SolveRequest.parse(method))
    assert run.patch is not None and run.patch.max < 1e-8, run.patch
    force = sum(np.asarray(c.force) for c in run.contacts if c.passive == "floor")
    # The floor pushes the disk up with E alpha dT over the disc's area pi r^2 (a total
    # force over the circumference, as every force of an axisymmetric model).
    assert force[1] == pytest.approx(math.pi * 1.0, rel=1e-8)
    x = sol.fields.V.tabulate_dof_coordinates()[:, 0]
    ur = sol.u.x.array.reshape(-1, 2)[: len(x), 0]
    assert np.allclose(ur, 1.3e-3 * x, rtol=0, atol=1e-11)
