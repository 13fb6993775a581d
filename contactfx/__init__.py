"""contactfx: 2D frictionless contact of linear-elastic bodies with Lagrange multipliers.

`Scene` (built-in scenes, scene files or `Scene.from_gmsh`) and `solve(scene, method)` are
the Python API; `python -m contactfx solve ...` is the command line over the same calls.
"""

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)

__version__ = "0.2.0"

from .api import run_scene, solve
from .scenes import Scene, load_scene_file

__all__ = ["Scene", "load_scene_file", "run_scene", "solve"]
