"""Cattaneo-Mindlin on mirrored meshes (tests/scenes/cattaneo_mirrored.toml), mortar and nts.

Two identical half-cylinders, the lower mesh the upper one's mirror image node for node, so
that the pressed bodies lock in no shear (the unstructured meshes of cattaneo_cylinders.geo
left 2 % of mu p), pressed and then pushed. Checked here at size factor 2 (h = 0.001 on the
contact, a/h = 100, 9,060 DOFs): the mesh is a mirror image, the approach locks in under
0.5 % of mu p, the stick half-width lies within 1.5 contact cells of Cattaneo-Mindlin's c,
|shear| = mu p on the slip nodes to 1e-6, and the shear's L2 error against the closed form
(`cattaneo_errors`) is pinned (a regression lock: refresh by printing `check.shear_l2` after
an intended change of the mesh or the method). The scene's own size (factor 1, a/h = 200,
30,668 DOFs) meets the 1.5 % bound with both methods in about half a minute each:
benchmarks/cattaneo_mirrored.py and its JSON, docs/friction_verification.md.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

from contactfx import solve
from contactfx.results.cattaneo import cattaneo_checks
from contactfx.scenes import Scene
from contactfx.scenes.scene_file import load_scene_file

SCENE = ROOT / "tests" / "scenes" / "cattaneo_mirrored.toml"
FACTOR = 2.0
# Regression locks of the shear's L2 error at FACTOR (benchmarks/cattaneo_mirrored.json).
SHEAR_L2 = {"mortar": 0.022787, "nts": 0.018282}


def test_the_lower_mesh_mirrors_the_upper_one() -> None:
    """gmsh copies the upper body's mesh across y = 0 (Periodic ... Affine): every lower node
    is an upper node mirrored, to the 2e-8 of gmsh's reparametrization of the curves."""
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Verbosity", 1)
        gmsh.open(str(SCENE.with_suffix(".geo")))
        gmsh.option.setNumber("Mesh.MeshSizeFactor", 4.0)
        gmsh.model.mesh.generate(2)
        groups = {gmsh.model.getPhysicalName(2, t): t for _, t in gmsh.model.getPhysicalGroups(2)}
        xyz = {}
        for name in ("upper", "lower"):
            (ent,) = gmsh.model.getEntitiesForPhysicalGroup(2, groups[name])
            _, coords, _ = gmsh.model.mesh.getNodes(2, int(ent), includeBoundary=True)
            xyz[name] = coords.reshape(-1, 3)[:, :2]
    finally:
        gmsh.finalize()
    up, low = xyz["upper"], xyz["lower"] * [1.0, -1.0]
    assert len(up) == len(low) > 500
    d = np.linalg.norm(up[:, None, :] - low[None, :, :], axis=2).min(axis=1)
    assert d.max() < 1e-7


@pytest.fixture(scope="module")
def scene() -> Scene:
    """The scene at FACTOR, meshed once for both methods."""
    return load_scene_file(SCENE, size_factor=FACTOR)


@pytest.mark.parametrize("method", ["mortar", "nts"])
def test_cattaneo_mindlin_on_mirrored_meshes(scene: Scene, method: str) -> None:
    """Pressed then pushed to Q = 0.62 mu P at a/h = 100: no locked-in shear, c within 1.5
    cells, Coulomb's law on the slip nodes, the shear's L2 error pinned."""
    sol = solve(scene, method)
    (check,) = cattaneo_checks(sol)[0]
    assert sol.dofs == 9060
    assert check.a_exact / check.h == pytest.approx(100.6, rel=1e-2)
    assert check.Q / (check.mu * check.P) == pytest.approx(0.6216, rel=1e-3)
    assert check.approach_shear is not None and check.approach_shear < 0.005
    assert check.c_error_cells < 1.5
    assert check.slip_law < 1e-6
    assert check.shear_l2 == pytest.approx(SHEAR_L2[method], rel=1e-3)
