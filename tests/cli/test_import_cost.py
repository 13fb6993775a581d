"""A plain solve loads no plotting, no pyvista, no scipy at all, no gmsh, no cffi parser.

Module presence in a fresh interpreter, not a timing: importing the command line, parsing
`solve hertz` and importing the module that runs it must leave matplotlib (the charts),
pyvista (the field files), scipy (scipy.sparse: the contact operators are contact.sparse.CSR;
scipy.linalg: the capacitance solve of a few released rows is numpy's; scipy.optimize: the
floating-body LP; scipy.spatial: no longer used, larger searches use contact.grid's bucket
grid (also on a solve whose searches are above `_ALL_PAIRS`); scipy.sparse.csgraph and
scipy.sparse.linalg: a mesh split over ranks, the condensed and Schwarz solvers), gmsh
(meshing) and dolfinx.fem.petsc with the pycparser its import runs (the elasticity assembly
makes the same C++ calls itself) unloaded; each is imported where it is first used
(docs/scale.md, "Time to the first answer"). A whole solve of a built-in scene loads gmsh
only when its mesh is not in the mesh cache yet, pycparser only when FFCx compiles a form.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

DEFERRED = (
    "matplotlib",
    "pyvista",
    "scipy",
    "scipy.linalg",
    "scipy.sparse",
    "scipy.optimize",
    "scipy.spatial",
    "scipy.sparse.csgraph",
    "scipy.sparse.linalg",
    "gmsh",
    "dolfinx.fem.petsc",
    "pycparser",
)

PROBE = f"""
import json, sys
from contactfx.cli import parser
args = parser().parse_args(["solve", "hertz"])
assert args.command == "solve"
import contactfx.cli.solve  # what main() imports to run it
print(json.dumps(sorted(m for m in {DEFERRED!r} if m in sys.modules)))
"""


# A whole solve (coarse Hertz: one free mode, decided without the LP; searches small
# enough to compare every point with every segment; a capacitance solve of a few released
# rows) loads none of them either, but gmsh while the mesh is not cached and pycparser while
# FFCx compiles the forms (its JIT cache is under the same empty XDG_CACHE_HOME).
SOLVE = f"""
import json, sys
from contactfx.cli import main
assert main(["solve", "hertz", "--refine", "0.1", "-q"]) == 0
print(json.dumps(sorted(m for m in {DEFERRED!r} if m in sys.modules)))
"""


# A solve whose searches are above `_ALL_PAIRS` (the spy below asserts it did search so)
# runs the grid search, and still loads no scipy.spatial (nor scipy).
GRID_SOLVE = f"""
import json, sys
from contactfx.contact.search import SegmentSearch
calls = []
search = SegmentSearch._grid_search
def spy(self, *args):
    calls.append(len(args[0]))
    return search(self, *args)
SegmentSearch._grid_search = spy
from contactfx.cli import main
assert main(["solve", "hertz", "--refine", "0.005", "--method", "mortar", "-q"]) == 0
assert calls, "no search above _ALL_PAIRS"
print(json.dumps(sorted(m for m in {DEFERRED!r} if m in sys.modules)))
"""


def loaded(probe: str, tmp_path: Path) -> list[str]:
    """The DEFERRED modules present at the end of `probe` in a fresh interpreter."""
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"))  # an empty mesh cache
    out = subprocess.run(
        [sys.executable, "-c", probe],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
        cwd=tmp_path,
        env=env,
    )
    return list(json.loads(out.stdout.strip().splitlines()[-1]))


@pytest.mark.serial
def test_command_line_imports_no_plotting_and_no_scipy(tmp_path: Path) -> None:
    assert loaded(PROBE, tmp_path) == []


@pytest.mark.serial
def test_plain_solve_loads_no_plotting_no_pyvista_no_scipy(tmp_path: Path) -> None:
    assert loaded(SOLVE, tmp_path) == ["gmsh", "pycparser"]  # meshed and compiled: caches empty
    assert loaded(SOLVE, tmp_path) == []  # the same scene again: mesh and forms from the caches


@pytest.mark.serial
def test_solve_with_grid_searches_loads_no_scipy_spatial(tmp_path: Path) -> None:
    assert "scipy.spatial" not in loaded(GRID_SOLVE, tmp_path)
    assert loaded(GRID_SOLVE, tmp_path) == []  # mesh and forms from the caches
