"""The outer iterations over linear solves, and what a solve returns.

The penalty and Schwarz modules load on first use of their names (a plain solve runs
neither: docs/scale.md, "Time to the first answer").
"""

from typing import TYPE_CHECKING, Any

from ..request import SchwarzOptions
from .active_set import ActiveSetOptions, InitialSet, lcp_active_set
from .multipliers import solve_contact
from .solution import Fields, PairView, PenaltyResult, Solution

if TYPE_CHECKING:
    from .penalty import ConditionOptions, solve_penalty
    from .schwarz import solve_schwarz

_LAZY = {"ConditionOptions": "penalty", "solve_penalty": "penalty", "solve_schwarz": "schwarz"}


def __getattr__(name: str) -> Any:
    """The penalty and Schwarz names, imported on first use."""
    if name in _LAZY:
        from importlib import import_module

        return getattr(import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
