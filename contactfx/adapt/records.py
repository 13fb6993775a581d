"""The adaptive loop's records: its options (validated once), one solved level, the result."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..errors import InputError
from ..methods.solution import Solution
from ..request import SolveRequest
from ..results.records import RunSummary
from .estimate import Estimate
from .goal import FRICTION_MEANING, GOAL_MEANING, Goal, GoalRecord
from .sizing import SizingRule

# --tol's default: the goal's relative error; the residual estimate's is looser (it is an
# uncalibrated bound, 1-3 x the energy error, docs/adapt.md).
GOAL_TOL = 0.01
RESIDUAL_TOL = 0.05
# --growth's default for the residual goal (the goal estimates plan their growth).
RESIDUAL_GROWTH = 4.0
# Sizing by the residual goal takes each cell's contact terms times this weight unless the
# pressure sizing is on: the energy estimate is bulk-dominated, a pressure needs the contact
# zone resolved; larger weights did worse, and with the pressure sizing on the weight only
# takes cells from the bulk (the measurements: benchmarks/log/adapt.md). The goal estimates
# size with 1.
RESIDUAL_WEIGHT = 10.0
# On a full budget, the residual goal's pressure sizing goes on while its estimate falls below
# this fraction of the previous level's.
PRESSURE_PROGRESS = 0.8


def default_tol(goal: Goal) -> float:
    """--tol's default for `goal`."""
    return RESIDUAL_TOL if goal is Goal.RESIDUAL else GOAL_TOL


@dataclass(frozen=True)
class AdaptOptions:
    """When the loop stops and how it sizes meshes (validated on construction).

    Attributes:
        goal: The quantity `tol` bounds (Goal.RESIDUAL: the residual estimate, uncalibrated).
        tol: The goal's relative error to reach; None: no tolerance, the budget decides.
        max_dofs: The DOF budget of a mesh.
        max_levels: The most levels.
        growth: The most cells of a level over the previous one; None: the goal estimates
            plan it from their observed rate, the residual goal takes RESIDUAL_GROWTH.
        contact_weight: The sizing's weight of each cell's contact terms; None: `weight`.
        pressure_tol: The residual goal only: also size the contact cells for a relative L2
            pressure indicator of this, and stop only when it is met too.
        fallback: Where the pressure goal has no finite value on the scene (its peak grows
            like a singularity's, adapt/goal.py), the goal the loop stops on instead; None:
            refuse the scene (GoalUnbounded).
    """

    goal: Goal = Goal.PRESSURE
    tol: float | None = GOAL_TOL
    max_dofs: int = 200_000
    max_levels: int = 8
    growth: float | None = None
    contact_weight: float | None = None
    pressure_tol: float | None = None
    fallback: Goal | None = Goal.ENERGY

    def __post_init__(self) -> None:
        """InputError for a value out of range (one line naming the option)."""
        if self.tol is not None and not (self.tol > 0):
            raise InputError(f"--tol must be > 0 (got {self.tol})")
        if self.growth is not None and not (self.growth > 1.0):
            raise InputError(
                f"--growth must be > 1: the most cells of a level relative to the previous "
                f"one (got {self.growth:g})"
            )
        if self.max_dofs < 10:
            raise InputError(f"--max-dofs must be at least 10 (got {self.max_dofs})")
        if self.contact_weight is not None and not (self.contact_weight >= 1.0):
            raise InputError(f"--weight-contact must be >= 1 (got {self.contact_weight})")
        if self.max_levels < 1:
            raise InputError(f"--max-levels must be at least 1 (got {self.max_levels})")
        if self.pressure_tol is not None and not (self.pressure_tol > 0):
            raise InputError(f"--pressure-tol must be > 0 (got {self.pressure_tol})")
        if self.pressure_tol is not None and self.goal is not Goal.RESIDUAL:
            raise InputError(
                "--pressure-tol sizes the residual goal's contact cells: give it with "
                "--goal residual (the pressure goal sizes them itself)"
            )
        if self.fallback in (Goal.PRESSURE, Goal.RESIDUAL):
            raise InputError(f"the fallback goal must be energy or force (got {self.fallback})")

    @property
    def weight(self) -> float:
        """The contact weight the sizing uses: the given one, or the goal's default."""
        if self.contact_weight is not None:
            return self.contact_weight
        if self.goal is Goal.RESIDUAL and self.pressure_tol is None:
            return RESIDUAL_WEIGHT
        return 1.0

    @property
    def level_growth(self) -> float | None:
        """The most cells of a level over the previous one: `growth`, or the goal's default.

        RESIDUAL_GROWTH for the residual goal; None for the goal estimates, which plan it.
        """
        if self.growth is None and self.goal is Goal.RESIDUAL:
            return RESIDUAL_GROWTH
        return self.growth

    @property
    def rule(self) -> SizingRule:
        """How the next mesh is sized (the growth is the loop's: `growth`)."""
        return SizingRule(contact_weight=self.weight)

    def pressure_met(self, est: Estimate) -> bool:
        """Whether the pressure estimate needs nothing more (always, without pressure_tol)."""
        if self.pressure_tol is None or est.pressure is None:
            return True
        return est.pressure.relative <= self.pressure_tol

    def pressure_settled(self, est: Estimate, before: Estimate | None) -> bool:
        """Whether the pressure sizing has nothing left to gain on a full budget.

        Met, or fallen by less than PRESSURE_PROGRESS on the last level: past that the
        pressure error is the bulk's (a three-body scene's discrete half-width settles
        0.09 % short of Hertz's while the estimate creeps down, docs/adapt.md).
        """
        if self.pressure_met(est):
            return True
        if before is None or before.pressure is None or est.pressure is None:
            return False
        return est.pressure.relative > PRESSURE_PROGRESS * before.pressure.relative

    def met(self, est: Estimate) -> str | None:
        """The residual goal: why the loop may stop at this estimate, or None."""
        if self.tol is None or est.relative > self.tol:
            return None
        if not self.pressure_met(est):
            return None
        # Percent, as the level lines print the estimates.
        reached = f"estimate {100 * est.relative:.2g} % <= tol {100 * self.tol:g} %"
        if self.pressure_tol is None or est.pressure is None:
            return reached
        return (
            f"{reached}, pressure estimate {100 * est.pressure.relative:.2g} % "
            f"<= {100 * self.pressure_tol:g} %"
        )

    def settings(self) -> dict[str, Any]:
        """adapt.json's `settings` (the goal as asked; the result says which one stopped)."""
        rule = self.rule
        return {
            "tol": self.tol,
            "max_dofs": self.max_dofs,
            "max_levels": self.max_levels,
            "rate": rule.rate,
            "growth": self.level_growth,
            "weight_contact": rule.contact_weight,
            "pressure_tol": self.pressure_tol,
            "goal": self.goal.value,
            "fallback": None if self.fallback is None else self.fallback.value,
        }


@dataclass(frozen=True)
class AdaptLevel:
    """One solved level: its summary (with the estimate), the solution and the estimate."""

    index: int
    summary: RunSummary
    solution: Solution
    est: Estimate
    time: float  # seconds: meshing (remesh) + solve + estimate (+ the goal's refined solve)
    goal: GoalRecord | None = None  # the goal estimate (None: the residual goal)

    @property
    def dofs(self) -> int:
        """Displacement DOFs of the level."""
        return self.summary.dofs

    @property
    def relative(self) -> float:
        """The estimate the loop stops on: the goal's, or the residual estimate."""
        return self.est.relative if self.goal is None else self.goal.relative

    def to_json(self) -> dict[str, Any]:
        """The level's entry of adapt.json: the run's JSON, `estimate` the relative total."""
        out = self.summary.to_json()
        out["estimate"] = self.est.relative
        out["estimate_parts"] = self.est.summary().to_json()
        out["level"] = self.index
        out["time"] = self.time
        if self.goal is not None:
            out.update(self.goal.to_json())
            out["estimate"] = self.goal.relative
            exact = self.exact_error
            if exact is not None:
                out["exact_error"] = exact
                out["effectivity"] = self.goal.relative / exact if exact > 0 else None
            shear, exact_shear = self.goal.shear_estimate, self.exact_shear_error
            if shear is not None and exact_shear is not None:
                out["exact_shear_error"] = exact_shear
                out["shear_effectivity"] = shear / exact_shear if exact_shear > 0 else None
        return out

    @property
    def exact_error(self) -> float | None:
        """The goal's exact relative error where the scene has one (the pressure goal).

        Against Hertz, or Cattaneo-Mindlin (whose pressure is Hertz's under the pair's force).
        """
        if self.goal is None or self.goal.goal is not Goal.PRESSURE:
            return None
        if self.summary.hertz:
            return max(h.l2_error for h in self.summary.hertz)
        errors = [c.pressure_l2 for c in self.summary.cattaneo if c.pressure_l2 is not None]
        return max(errors) if errors else None

    @property
    def exact_shear_error(self) -> float | None:
        """The shear's exact relative L2 error on a Cattaneo-Mindlin scene (worst pair)."""
        return max((c.shear_l2 for c in self.summary.cattaneo), default=None)


@dataclass
class AdaptResult:
    """The levels, why the loop stopped, the goal it stopped on, and uniform levels if asked.

    `goal` differs from the options' where the pressure goal was unbounded on the scene;
    `goal_note` says why (empty otherwise).
    """

    levels: list[AdaptLevel]
    stop: str
    goal: Goal
    goal_note: str = ""
    uniform: list[AdaptLevel] = field(default_factory=list)

    @property
    def _frictional(self) -> bool:
        return any(lv.solution.friction is not None for lv in self.levels)

    def to_json(self, scene: str, request: SolveRequest, opts: AdaptOptions) -> dict[str, Any]:
        """adapt.json: the settings, every level (estimate a number), why the loop stopped.

        `scene` as the user named it; the method and the solver as the request resolved them.
        """
        return {
            "scene": scene,
            "method": request.label,
            "settings": {**opts.settings(), "solver": request.solver.name},
            "goal": self.goal.value,
            "goal_meaning": GOAL_MEANING[self.goal],
            "goal_note": self.goal_note,
            **({"friction": FRICTION_MEANING} if self._frictional else {}),
            "stop": self.stop,
            "levels": [lv.to_json() for lv in self.levels],
            **({"uniform": [lv.to_json() for lv in self.uniform]} if self.uniform else {}),
        }
