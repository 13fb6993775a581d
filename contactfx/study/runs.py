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


@dataclass
class AdaptiveRun:
    """One level of a method's adaptive loop in a study (`study --adaptive`)."""

    method: str
    level: int
    dofs: int
    elements: int
    h: float | None
    iterations: int
    after_mesh: float  # this level's assembly, search and solves (s)
    time: float  # this level's remeshing + solve + estimate (s)
    cumulative: float  # the loop's time up to and with this level (s)
    estimate: float  # relative estimate
    errors: dict[str, float | None] = field(default_factory=dict)
    stop: str = ""  # why the method's loop stopped (the same on each of its levels)
