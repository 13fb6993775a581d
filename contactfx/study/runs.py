"""One run of a study: a method on a level, its sizes, cost and errors (or why it failed)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .measures import Profiles


@dataclass
class Run:
    """One method on one level: sizes, cost, errors, or why it failed."""

    method: str
    level: int
    factor: float
    status: str = "ok"
    message: str | None = None
    dofs: int | None = None
    elements: int | None = None
    h: float | None = None
    iterations: int | None = None
    times: dict[str, float] = field(default_factory=dict)
    errors: dict[str, float | None] = field(default_factory=dict)
    # Self-convergence: the differences from the same method's next finer level.
    successive: dict[str, float | None] = field(default_factory=dict)
    forces: list[list[float]] | None = None  # the contact force [fx, fy] of every pair
    summary: dict[str, Any] | None = field(default=None, repr=False)
    profiles: Profiles | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        """Whether the run finished."""
        return self.status == "ok"

    @property
    def after_mesh(self) -> float | None:
        """Wall time after meshing: assembly, search and the active-set solves (s)."""
        return self.times["total"] - self.times["mesh"] if self.ok else None
