"""A study's records: one run (a method on a level), an adaptive level, the whole study.

Each writes its part of study.json with `to_json()`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from ..results.records import RunSummary
from .levels import Level
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
    # Every pair's [fx, fy]; axisymmetric: [radial resultant per radian, axial force].
    forces: list[list[float]] | None = None
    summary: RunSummary | None = field(default=None, repr=False)
    profiles: Profiles | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        """Whether the run finished."""
        return self.status == "ok"

    @property
    def after_mesh(self) -> float | None:
        """Wall time after meshing: assembly, search and the active-set solves (s)."""
        return self.times["total"] - self.times["mesh"] if self.ok else None

    def to_json(self, sizes: dict[str, float]) -> dict[str, Any]:
        """The run's entry of study.json; `sizes` are its level's mesh sizes."""
        return {
            "method": self.method,
            "level": self.level,
            "factor": self.factor,
            "sizes": sizes,
            "status": self.status,
            "message": self.message,
            "dofs": self.dofs,
            "elements": self.elements,
            "h": self.h,
            "iterations": self.iterations,
            "times": self.times,
            "after_mesh": self.after_mesh,
            "errors": self.errors,
            "successive": self.successive,
            "forces": self.forces,
        }


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


@dataclass
class Study:
    """A finished study: its levels, runs, reference and fitted rates."""

    scene: str
    methods: list[str]
    levels: list[Level]
    runs: list[Run]
    reference: dict[str, Any]
    error_names: list[str]
    rates: dict[str, dict[str, float | None]]
    time_rates: dict[str, dict[str, float | None]]
    wall: float
    ranks: int
    settings: dict[str, Any] = field(default_factory=dict)
    # Per method and error: why its rate is not a convergence rate ("non-monotone").
    flags: dict[str, dict[str, str]] = field(default_factory=dict)
    # `study --adaptive`: the adaptive levels of every method (study/adaptive.py).
    adaptive: list[AdaptiveRun] = field(default_factory=list)

    def to_json(self) -> dict[str, Any]:
        """study.json: the settings, the levels, every run, the reference and the rates."""
        return {
            "scene": self.scene,
            "ranks": self.ranks,
            "methods": self.methods,
            **self.settings,
            "wall": self.wall,
            "levels": [
                {"level": lv.index, "factor": lv.factor, "sizes": lv.sizes} for lv in self.levels
            ],
            "reference": self.reference,
            "error_names": self.error_names,
            "runs": [r.to_json(self.levels[r.level].sizes) for r in self.runs],
            "rates": self.rates,
            "rate_flags": self.flags,
            "time_rates": self.time_rates,
            "h": "median length of the active-surface elements carrying pressure",
            **({"adaptive": self._adaptive_json()} if self.adaptive else {}),
        }

    def _adaptive_json(self) -> dict[str, Any]:
        """study.json's `adaptive` block: how the levels were made and measured, the levels."""
        return {
            "description": "each method's adaptive loop (contactfx adapt) from level 0's mesh "
            "up to the DOFs of its finest uniform level; errors measured as the uniform runs' "
            "(without an exact solution: against the reference, not the next level)",
            "time": "cumulative: level 0's meshing, then the solves, estimates and remeshing "
            "of the levels up to each; after_mesh is the level's own solve",
            "runs": [asdict(r) for r in self.adaptive],
        }
