"""`python fail_on_rank.py STAGE RANK KIND TIMEFILE -- contactfx arguments`: the CLI with an
exception raised on one rank only, at one stage of a run (tests/cli/test_failures.py).

STAGE: parsing (the scene's parameters), meshing (DOLFINx reading the gmsh mesh), assembly
(the stiffness matrix), solve (the saddle-point solve), writing (the fields of --out).
KIND: input (an InputError: a refusal only this rank makes) or internal (a RuntimeError: a
bug). The time of the raise is written to TIMEFILE, for the test to measure how long the
other ranks take to end.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

import dolfinx_solver  # noqa: F401
from mpi4py import MPI

import contactfx.cli.params
import contactfx.discretize.elasticity
import contactfx.linalg.saddle
import contactfx.results.files
import contactfx.scenes.gmsh_io
import contactfx.scenes.mesh_cache
from contactfx.cli import entry
from contactfx.errors import InputError

# (module, attribute) of the function that raises at each stage.
STAGES: dict[str, list[tuple[Any, str]]] = {
    "parsing": [(contactfx.cli.params, "scene_params")],
    "meshing": [
        (contactfx.scenes.mesh_cache, "mesh_from_model"),
        (contactfx.scenes.gmsh_io, "mesh_from_model"),
    ],
    "assembly": [(contactfx.discretize.elasticity, "petsc_matrix")],
    "solve": [(contactfx.linalg.saddle.SaddleSolver, "solve")],
    "writing": [(contactfx.results.files, "field_grid")],
}


def main() -> int:
    stage, rank, kind, timefile = sys.argv[1:5]
    sys.argv = [sys.argv[0], *sys.argv[6:]]
    if MPI.COMM_WORLD.rank == int(rank):

        def boom(*args: object, **kwargs: object) -> Any:
            Path(timefile).write_text(repr(time.time()))
            text = f"raised on purpose at {stage}"
            raise InputError(text) if kind == "input" else RuntimeError(text)

        for owner, name in STAGES[stage]:
            setattr(owner, name, boom)
    return entry()


if __name__ == "__main__":
    sys.exit(main())
