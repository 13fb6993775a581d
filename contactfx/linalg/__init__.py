"""PETSc linear algebra of the contact saddle points; it knows no Scene and no DOLFINx object."""

from .policy import Decision, FactorizationPolicy, ReuseMode
from .protocol import LinearSolver, SaddleResult

__all__ = [
    "Decision",
    "FactorizationPolicy",
    "LinearSolver",
    "ReuseMode",
    "SaddleResult",
]
