"""gmsh scene geometry (blocks S1-S4, Hertz S5) and the structured Hertz grid.

Geometry only: these modules depend on gmsh and numpy, never on contactfx, which loads
them into DOLFINx (contactfx.scenes). Builders raise ValueError for bad parameters.
"""

from meshes.blocks import build_blocks
from meshes.hertz import build_hertz

__all__ = ["build_blocks", "build_hertz"]
