"""contactfx: 2D frictionless two-body contact with Lagrange multipliers on DOLFINx."""

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)

__version__ = "0.1.0"
