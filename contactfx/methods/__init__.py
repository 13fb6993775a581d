"""The outer iterations over linear solves, and what a solve returns."""

from ..request import SchwarzOptions
from .active_set import ActiveSetOptions, InitialSet, lcp_active_set
from .multipliers import solve_contact
from .penalty import ConditionOptions, solve_penalty
from .schwarz import solve_schwarz
from .solution import Fields, PairView, PenaltyResult, Solution

__all__ = [
    "ActiveSetOptions",
    "ConditionOptions",
    "Fields",
    "InitialSet",
    "PairView",
    "PenaltyResult",
    "SchwarzOptions",
    "Solution",
    "lcp_active_set",
    "solve_contact",
    "solve_penalty",
    "solve_schwarz",
]
