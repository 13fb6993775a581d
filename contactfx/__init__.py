"""contactfx: 2D frictionless contact of linear-elastic bodies with Lagrange multipliers.

A `Scene` (built-in scenes, scene files or `scene_from_gmsh`) and `solve(scene, method)` are
the Python API; `python -m contactfx solve ...` is the command line over the same calls.
"""

from importlib.metadata import version as _version

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)

from .api import run_case, run_scene, solve
from .errors import (
    ActiveSetError,
    ContactFxError,
    ConvergenceError,
    GeometryError,
    InputError,
    MeshError,
    SingularSystemError,
    SolverError,
)
from .methods import SchwarzOptions, Solution
from .options import SOLVERS, Basis, Method, Predictor, SolverKind, SolverSpec
from .scenes import (
    HertzReference,
    Obstacle,
    Scene,
    UniformStress,
    load_scene_file,
)
from .scenes import from_gmsh as scene_from_gmsh

__version__ = _version("contactfx")

__all__ = [
    "SOLVERS",
    "ActiveSetError",
    "Basis",
    "ContactFxError",
    "ConvergenceError",
    "GeometryError",
    "HertzReference",
    "InputError",
    "MeshError",
    "Method",
    "Obstacle",
    "Predictor",
    "Scene",
    "SchwarzOptions",
    "SingularSystemError",
    "Solution",
    "SolverError",
    "SolverKind",
    "SolverSpec",
    "UniformStress",
    "load_scene_file",
    "run_case",
    "run_scene",
    "scene_from_gmsh",
    "solve",
]
