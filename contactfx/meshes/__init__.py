"""gmsh scene geometry (blocks S1-S4, Hertz S5) and the structured Hertz grid.

Geometry only: these modules depend on gmsh and numpy, never on the rest of contactfx,
which loads them into DOLFINx (contactfx.scenes). The folder is installed as the
subpackage `contactfx.meshes` (pyproject.toml), not as a top-level package. Builders raise
ValueError for bad parameters.
"""

from .blocks import build_blocks
from .grid_levels import Level, grid_levels
from .hertz import QUAD4, build_hertz
from .hertz_structured import GridLines, GridPart, grid_geometry, hertz_grid, hertz_grid_part

__all__ = [
    "QUAD4",
    "GridLines",
    "GridPart",
    "Level",
    "build_blocks",
    "build_hertz",
    "grid_geometry",
    "grid_levels",
    "hertz_grid",
    "hertz_grid_part",
]
