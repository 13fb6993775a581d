"""contactfx: 2D frictionless contact of linear-elastic bodies with Lagrange multipliers.

A `Scene` (built-in scenes, scene files or `scene_from_gmsh`) and `solve(scene, method)` are
the Python API; `python -m contactfx solve ...` is the command line over the same calls.
"""

import gc as _gc
from importlib.metadata import version as _version

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)

# The package's own modules allocate many objects on top of DOLFINx's: the collector would walk
# all of them once on the way (a full collection); it is off while they load and back as it
# was after, whatever happens. DOLFINx loads before, with the collector on: its objects, held
# back too, would make the first young collection after this walk them all (measured:
# docs/scale.md, "Time to the first answer").
_collecting = _gc.isenabled()
import dolfinx  # noqa: F401  (with the collector on)

_gc.disable()
try:
    from .api import run_case, run_scene, solve  # every stage below loads with it
finally:
    if _collecting:
        _gc.enable()
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
from .methods import Solution
from .options import (
    SOLVERS,
    Basis,
    Discretization,
    Enforcement,
    Method,
    Predictor,
    SolverKind,
    SolverSpec,
)
from .request import SchwarzOptions, SolveRequest
from .scenes import (
    CattaneoReference,
    ContactPair,
    HertzReference,
    LameReference,
    Material,
    Obstacle,
    Probe,
    PushoutReference,
    Scene,
    SpenceReference,
    UniformStress,
    load_scene_file,
    scene_from_gmsh,
)

__version__ = _version("contactfx")

__all__ = [
    "SOLVERS",
    "ActiveSetError",
    "Basis",
    "CattaneoReference",
    "ContactFxError",
    "ContactPair",
    "ConvergenceError",
    "Discretization",
    "Enforcement",
    "GeometryError",
    "HertzReference",
    "InputError",
    "LameReference",
    "Material",
    "MeshError",
    "Method",
    "Obstacle",
    "Predictor",
    "Probe",
    "PushoutReference",
    "Scene",
    "SchwarzOptions",
    "SingularSystemError",
    "Solution",
    "SolveRequest",
    "SolverError",
    "SolverKind",
    "SolverSpec",
    "SpenceReference",
    "UniformStress",
    "load_scene_file",
    "run_case",
    "run_scene",
    "scene_from_gmsh",
    "solve",
]
