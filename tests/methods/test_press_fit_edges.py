"""A press fit's two identical sharp hub edges read the same peak wherever the nodes fall.

tests/scenes/press_fit.geo: an axisymmetric steel shaft longer than its steel hub, the shaft's
nodes placed f_top, f_bot edge cells beyond the hub's two ends. The edges are the same corner
(mirror images), so their peak pressures may differ only by where the nodes fall: within 25 %
(docs/edges.md). Before the end rows (contact/operator.py, `end_rows`) the node beyond an end
carried 10-40x the other edge's peak and its neighbour inside was released.
"""

from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from contactfx import SolveRequest, run_scene
from contactfx.results.interface import pair_interface
from contactfx.scenes.gmsh_io import scene_from_parts
from contactfx.scenes.scene_file import parse_scene_file

SCENE = Path(__file__).parents[1] / "scenes" / "press_fit.toml"
# Coarse far field: ~1.4k dofs, edge cells 0.02.
COARSE = {"hc": 0.02, "slope": 0.2, "h_far": 0.1}
PLACEMENTS = [(0.0, 0.3), (0.5, 0.72), (0.25, 0.95)]
METHODS = [
    ("mortar", "standard"),
    ("mortar", "dual"),
    ("sts", "standard"),
    ("nts", "standard"),
    ("penalty", "standard"),
]
H = 0.5  # the hub's half length


def press_fit(tmp: Path, **params: float):
    """The press-fit scene with the .geo's constants overridden (gmsh's DefineConstant keeps
    a value already defined)."""
    mesh, parts = parse_scene_file(SCENE)
    geo = tmp / "press_fit.geo"
    geo.write_text("".join(f"{k} = {v!r};\n" for k, v in params.items()) + mesh.read_text())
    return scene_from_parts(geo, parts, MPI.COMM_WORLD)


@pytest.fixture(scope="module", params=PLACEMENTS, ids=lambda p: f"top{p[0]}-bot{p[1]}")
def scene(request, tmp_path_factory):
    f_top, f_bot = request.param
    return press_fit(tmp_path_factory.mktemp("fit"), f_top=f_top, f_bot=f_bot, **COARSE)


@pytest.mark.parametrize("method, basis", METHODS)
def test_edges_agree_and_no_node_released_inside(scene, method, basis):
    sol, _ = run_scene(scene, SolveRequest.parse(method, basis=basis))
    it = pair_interface(sol, 0)
    y, p = np.array(it["y"]), np.array(it["pressure"])
    active = np.array(it["active"])
    top, bottom = p[y > 0].max(), p[y < 0].max()
    assert max(top, bottom) / min(top, bottom) < 1.25, (top, bottom)
    # Every row between the first and the last node in contact is in contact and compressed.
    on = np.flatnonzero(active)
    assert active[on[0] : on[-1] + 1].all(), y[~active]
    assert np.all(p[on[0] : on[-1] + 1] > 0)
    # The rows in contact span the hub: the last row at each end (the end rows' anchor: one
    # to two cells inside, the cells growing by `slope`) lies within 2.5 edge cells of it.
    reach = 2.5 * COARSE["hc"]
    assert y[on[0]] < -H + reach and y[on[-1]] > H - reach
