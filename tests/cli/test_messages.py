"""Messages and logs a new user reads: a conforming mesh, the condensed solver's refusal, the
active-set line after probes, the predictor's lines, and no X-server warning from VTK."""

from __future__ import annotations

import itertools
import logging
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from conftest import ENV, ROOT
from mpi4py import MPI

from contactfx import load_scene_file, solve
from contactfx.errors import InputError, MeshError
from contactfx.options import SOLVERS
from contactfx.scenes import HertzParams, build_scene

SCENES = ROOT / "tests" / "scenes"

CONFORMING = """
h = 0.25;
Point(1) = {0, 0, 0, h}; Point(2) = {2, 0, 0, h}; Point(3) = {2, 1, 0, h};
Point(4) = {0, 1, 0, h}; Point(5) = {2, 2, 0, h}; Point(6) = {0, 2, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {3, 5}; Line(6) = {5, 6}; Line(7) = {6, 4};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {-3, 5, 6, 7}; Plane Surface(2) = {2};
Mesh.Algorithm = 8; Mesh.RecombinationAlgorithm = 3; Mesh.RecombineAll = 1;
Physical Surface("lower") = {1};
Physical Surface("upper") = {2};
Physical Curve("lower_top") = {3};
Physical Curve("upper_bottom") = {3};
Physical Curve("base") = {1};
Physical Curve("load") = {6};
Physical Curve("sym") = {4, 7};
"""

SCENE = """
mesh = "{mesh}"
[bodies.lower]
E = 7000.0
nu = 0.3
[bodies.upper]
E = 7000.0
nu = 0.3
[[contact]]
active = "upper_bottom"
passive = "lower_top"
[[dirichlet]]
group = "base"
uy = 0.0
[[dirichlet]]
group = "sym"
ux = 0.0
[[pressure]]
group = "load"
p = 10.0
"""


@pytest.mark.serial
def test_a_single_conforming_mesh_says_so_and_how_to_fix_it(tmp_path: Path) -> None:
    """Two rectangles sharing their interface line: the bodies share its 9 nodes."""
    (tmp_path / "c.geo").write_text(CONFORMING)
    (tmp_path / "c.toml").write_text(SCENE.format(mesh="c.geo"))
    with pytest.raises(MeshError) as err:
        load_scene_file(tmp_path / "c.toml", MPI.COMM_SELF)
    text = str(err.value)
    assert "bodies 'lower' and 'upper' share 9 mesh nodes" in text, text
    assert "conforming" in text and "own points and curves" in text


@pytest.mark.serial
def test_rotate_merging_the_touching_points_is_caught(tmp_path: Path) -> None:
    """rotated_hertz.geo without Geometry.AutoCoherence = 0: Rotate merges the two points
    at the origin, one shared node glues the bodies (it gave p0 +30 %)."""
    geo = (SCENES / "rotated_hertz.geo").read_text().replace("Geometry.AutoCoherence = 0;", "")
    (tmp_path / "rotated_hertz.geo").write_text(geo)
    toml = (SCENES / "rotated_hertz.toml").read_text()
    (tmp_path / "rotated_hertz.toml").write_text(toml)
    with pytest.raises(MeshError, match=r"share 1 mesh node \(e\.g\. at \(0, 0\)\).*AutoCoherence"):
        load_scene_file(tmp_path / "rotated_hertz.toml", MPI.COMM_SELF)


@pytest.mark.serial
def test_condensed_refusal_names_the_pair_and_why() -> None:
    """An active node with both components prescribed cannot be eliminated: the pair, where,
    and why. (The curved passive surface that was refused here is condensed since the coupled
    elimination of linalg/pivots.py: tests/linalg/test_direct_floor.py.)"""
    from dataclasses import replace

    from contactfx.scenes import BLOCK_SCENES, Dirichlet

    # Non-matching meshes (S2): the pinned corner's dual mortar row still reaches a free
    # passive dof, so it is a constraint (with matching meshes it would be data and dropped).
    scene = build_scene("blocks", BLOCK_SCENES["S2"], comm=MPI.COMM_SELF)
    pinned = (Dirichlet("symmetry", ux=0.0, uy=0.0), Dirichlet("support", uy=0.0))
    with pytest.raises(InputError) as err:
        solve(replace(scene, dirichlet=pinned), "mortar", basis="dual", solver="condensed")
    text = str(err.value)
    assert "pair 0 (contact2 on contact1) at (0, 3)" in text, text
    assert "fully prescribed" in text and "--solver mumps" in text


LINE = re.compile(
    r"^(?P<label>[a-z ]+?)\s+(?P<it>\d+):\s+(?P<n>\d+) active, \+(?P<e>\d+) -(?P<l>\d+)"
)
NEXT = re.compile(r"next set: .*, \+(?P<a>\d+) -(?P<r>\d+) -> (?P<m>\d+) active")


def iteration_lines(caplog: pytest.LogCaptureFixture, label: str) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.getMessage().startswith(label)]


@pytest.mark.serial
def test_active_set_lines_add_up_after_probes(caplog: pytest.LogCaptureFixture) -> None:
    """Each line's count follows from the line before: its update (+entered -left), or the
    next set it announces (the probes' prediction: 157 -> 79 on the default Hertz scene)."""
    caplog.set_level(logging.INFO, logger="contactfx")
    solve(build_scene("hertz", HertzParams(), comm=MPI.COMM_SELF), "mortar")
    lines = [m for m in iteration_lines(caplog, "active set") if LINE.match(m)]
    assert len(lines) >= 2
    for before, after in itertools.pairwise(lines):
        b, a = LINE.match(before), LINE.match(after)
        assert b and a
        nxt = NEXT.search(before)
        expected = int(nxt["m"]) if nxt else int(b["n"]) + int(b["e"]) - int(b["l"])
        assert int(a["n"]) == expected, (before, after)
        if nxt:
            assert int(nxt["m"]) == int(b["n"]) + int(nxt["a"]) - int(nxt["r"])
    assert "probes' complementarity problem, +0 -78 -> 79 active" in lines[0]


@pytest.mark.serial
def test_the_predictors_lines_are_labelled_as_its_own(caplog: pytest.LogCaptureFixture) -> None:
    """--predictor coarse: every line up to the predictor's last iteration says
    "predictor", the linear algebra's too (an option the reused factorization overrides,
    said once by the predictor's solver and once by the fine one)."""
    caplog.set_level(logging.INFO, logger="contactfx")
    scene = build_scene("hertz", HertzParams(), comm=MPI.COMM_SELF)
    solve(
        scene, "mortar", predictor="coarse", solver=SOLVERS["mumps"].with_petsc(["ksp_rtol=1e-6"])
    )
    messages = [r.getMessage() for r in caplog.records]
    last = max(k for k, m in enumerate(messages) if re.match(r"predictor\s+\d+:", m))
    assert last >= 1 and any(m.startswith("active set ") for m in messages[last:])
    assert all(m.startswith("predictor") for m in messages[: last + 1]), messages[: last + 1]
    overrides = [m for m in messages if "ksp_rtol" in m]
    assert len(overrides) == 2, overrides
    assert overrides[0].startswith("predictor: saddle solver:"), overrides
    assert overrides[1].startswith("saddle solver:"), overrides


RENDER = textwrap.dedent(
    """
    from pathlib import Path
    from mpi4py import MPI
    from contactfx import SolveRequest, run_case
    from contactfx.results.figures import deformed_fields
    from contactfx.scenes import BLOCK_SCENES
    mortar = SolveRequest.parse("mortar")
    sol, _ = run_case("blocks", BLOCK_SCENES["S1"], mortar, comm=MPI.COMM_SELF)
    print(deformed_fields(sol, Path(__import__("sys").argv[1])))
    """
)


@pytest.mark.serial
def test_field_pictures_render_off_screen_without_an_x_warning(tmp_path: Path) -> None:
    """No DISPLAY (as in `make demo` here): a picture, and no 'bad X server' line from VTK."""
    env = {k: v for k, v in ENV.items() if k != "DISPLAY"}
    png = tmp_path / "fields.png"
    proc = subprocess.run(
        [sys.executable, "-c", RENDER, str(png)],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "X server" not in proc.stderr + proc.stdout, proc.stderr[-2000:]
    assert png.stat().st_size > 20_000


@pytest.mark.serial
def test_a_refine_too_fine_is_refused_before_gmsh_with_the_memory_it_needs() -> None:
    """--refine 1e-9 ran into gmsh and ended in "gmsh failed: " with an empty reason: the
    cells are estimated first and the memory they need compared with what there is."""
    from conftest import cli

    from contactfx.cli.params import check_hertz_size

    proc = cli("solve", "hertz", "--refine", "1e-9")
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "--refine 1e-09 (--slope 0.1) makes a mesh of about 4e+10 cells" in lines[0]
    assert re.search(r"needs at least 8.86e\+04 GB of memory, more than the [\d.]+ GB", lines[0])
    assert proc.stdout == ""
    with pytest.raises(InputError, match=r"about 4e\+06 cells .* more than the 1 GB available"):
        check_hertz_size(HertzParams(refine=1e-5), 1000.0)
    check_hertz_size(HertzParams(refine=1e-5), 10_000.0)  # 8.8 GB: fits


@pytest.mark.serial
@pytest.mark.parametrize("params", [{}, {"refine": 0.05, "slope": 0.3}])
def test_the_hertz_cell_estimate_is_within_30_percent_of_gmsh(params: dict) -> None:
    from contactfx.cli.params import hertz_cells

    p = HertzParams(**params)
    scene = build_scene("hertz", p, comm=MPI.COMM_SELF)
    cells = scene.mesh.topology.index_map(2).size_local
    assert abs(cells / hertz_cells(p) - 1) < 0.3, (cells, hertz_cells(p))


@pytest.mark.mpi
def test_a_usage_error_under_mpirun_is_printed_once() -> None:
    """argparse's usage and error lines came once per rank."""
    from conftest import run_cli

    proc = run_cli("solve", "blocks", "--no-such-option", ranks=2)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("usage: contactfx") == 1, proc.stderr
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("contactfx: error:")]
    assert errors == ["contactfx: error: unrecognized arguments: --no-such-option"], proc.stderr
