"""The goal estimates' strategy of the loop: `tol` the goal's relative error, each level planned.

After each level's solve the goal's two-level estimate (adapt/goal.py) is computed; the
loop stops when it is at most `tol`, or when the budget has no room for another level.
Growth: the goal estimate's observed rate between the last two levels (error ~ N^s, s
clipped to [-2, -0.25]; on level 0 the goal's asymptotic s) gives the DOFs that reach the
tolerance, N_k (tol / e_k)^(1/s); the next level asks for that times MARGIN, but at most
the budget left spread over the levels still owed (room^(1/left)), at most G_MAX and at
most the budget itself (90 % of --max-dofs). The levels owed: MIN_LEVELS, or for the
pressure goal more if its contact cells need more. A contact cell shrinks at most x 1/4 per
level (SizingRule.finest), and the pressure's error is made there: a level planned to grow
more than the contact zone can use spends the rest on the bulk, where the pressure gains
little (docs/adapt.md, "Growth rule": a 250k budget spread over six levels). So the
contact cells' request for the tolerance (the pressure indicator aimed at PRESSURE_AIM tol,
unclipped) gives the levels it takes at x 1/4 each, and the budget is spread over at least
those (at most over the levels --max-levels leaves). Sizing: the pressure goal sizes the
contact cells with the pressure indicator (adapt/pressure_sizing.py) aimed at
PRESSURE_AIM times the error the level is planned to reach, unweighted contact terms
(docs/adapt.md: what met the pressure target); energy and force size every cell with the
residual indicators. The budget decides the cell count (the residual tolerance is not
used). The energy goal's refined solve halves every cell (4-5.5 x the DOFs): past a
quarter of the budget its estimate is the residual estimate times the ratio measured on
the last level that had a refined solve (labelled in the parts as `calibration`).
Where the pressure has no finite value on the scene (a singular edge, adapt/goal.py) and
the options name a fallback goal, the loop stops on that one instead (the log and adapt.json
say so): the energy, whose error bounds the field everywhere and the force's with it (the
force converges like the energy error squared, so a force tolerance is met while the edge's
field is still coarse).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np
from mpi4py import MPI

from ..methods.solution import Solution
from ..request import SolveRequest
from .goal import GOAL_MEANING, Goal, GoalRecord, GoalUnbounded, goal_estimate
from .pressure_estimate import PressureEstimate
from .pressure_sizing import pressure_cell_sizes
from .records import AdaptLevel, AdaptOptions
from .sizing import Plan, cell_sizes, owned_cells, plan_mesh

# Error ~ N^s on level 0 (no observed rate yet): P1 pressure h^1.5 on a mesh refined along
# a line (N ~ h^-2 overall: s = -0.75); Q1 energy h^1 (s = -0.5); the force h^2 (s = -1).
FIRST_SLOPE = {Goal.PRESSURE: -0.75, Goal.ENERGY: -0.5, Goal.FORCE: -1.0}
SLOPE_RANGE = (-2.0, -0.25)
MIN_LEVELS = 6  # levels the budget is spread over when the tolerance is far
MARGIN = 1.3  # the next level aims at this many times the DOFs the rate says reach tol
G_MIN = 1.3  # less room than this: the budget is full
G_MAX = 8.0
BUDGET_FILL = 0.9  # gmsh meets a size field only within ~10 %
PRESSURE_AIM = 0.5  # the pressure indicator sized for half the error wanted (docs/adapt.md)
ENERGY_REFINED = 4.0  # the energy goal's refined solve has ~4-5.5 x the level's DOFs
AIM_FLOOR = 0.1  # but not below this fraction of the level's own estimate
OVERSHOOT = 1.15  # a remeshed level with more DOFs than this x planned is planned again


def observed_slope(history: list[tuple[int, float]], goal: Goal) -> float:
    """The slope s in error ~ N^s from the last two levels (clipped), or the goal's asymptotic s."""
    if len(history) >= 2:
        (n0, e0), (n1, e1) = history[-2], history[-1]
        if n1 > 1.05 * n0 and e0 > 0 and e1 > 0:
            s = math.log(e1 / e0) / math.log(n1 / n0)
            return min(max(s, SLOPE_RANGE[0]), SLOPE_RANGE[1])
    return FIRST_SLOPE[goal]


def plan_growth(
    history: list[tuple[int, float]],
    tol: float | None,
    max_dofs: int,
    goal: Goal,
    cap: float | None = None,
    owed: int = 0,
    allowed: int | None = None,
) -> float | None:
    """The next level's DOFs / this level's, or None when the budget has no room left.

    `history`: (DOFs, goal estimate) of the levels so far; `tol` None: the budget decides.
    `cap`: an expert's --growth.
    `owed`: the levels the contact cells still need (contact_levels); `allowed`: the
    levels --max-levels leaves after this one (the budget is spread over at most these).
    """
    n, e = history[-1]
    room = BUDGET_FILL * max_dofs / n
    if room < G_MIN:
        return None
    s = observed_slope(history, goal)
    if tol is None:
        need = math.inf
    else:
        need = (tol / e) ** (1.0 / s) if e > tol else 1.0
    left = max(MIN_LEVELS - len(history), owed, 1)
    if allowed is not None:
        left = max(min(left, allowed), 1)
    g = min(MARGIN * need, room ** (1.0 / left), G_MAX if cap is None else cap, room)
    return max(g, min(G_MIN, room))


def contact_levels(sol: Solution, pe: PressureEstimate | None, aim: float, finest: float) -> int:
    """Levels the contact cells need to reach the sizes the pressure indicator asks for `aim`.

    `pe`: the pressure indicators of `sol`. The smallest requested size / today's size,
    unclipped, over the contact cells of every rank, in steps of `finest` (x 1/4) per
    level; 0 without a pressure. Collective.
    """
    ratio = np.inf
    if pe is not None:
        quads, _ = owned_cells(sol)
        h = cell_sizes(quads)
        asked = pressure_cell_sizes(pe, aim, quads, h, 0.0) / np.maximum(h, 1e-300)
        ratio = float(np.min(asked, initial=np.inf))
    ratio = sol.scene.comm.allreduce(ratio, op=MPI.MIN)
    if not np.isfinite(ratio) or ratio >= 1.0:
        return 0
    return math.ceil(math.log(ratio) / math.log(finest) - 1e-9)


class GoalPlan:
    """The goal estimates' strategy: a refined solve per level, the growth planned from the rate.

    The pressure goal falls back to `opts.fallback` where the scene's pressure is singular.
    """

    def __init__(self, opts: AdaptOptions, request: SolveRequest) -> None:
        self.opts = opts
        self.request = request
        self.goal = opts.goal
        self.note = ""
        self.calibration: float | None = None
        self.history: list[tuple[int, float]] = []  # (DOFs, estimate) of the current goal
        self.cells = self.aim = self.target = self.g = self.s = 0.0
        self.owed = 0

    def _record(self, level: AdaptLevel) -> GoalRecord:
        """The level's goal estimate (the energy goal's calibrated past a quarter budget)."""
        residual = level.est.relative
        big = level.dofs * ENERGY_REFINED > self.opts.max_dofs
        if self.goal is Goal.ENERGY and self.calibration is not None and big:
            parts = {"residual": residual, "calibration": self.calibration}
            return GoalRecord(self.goal, self.calibration * residual, parts, 0, 0.0)
        ge = goal_estimate(level.solution, self.goal, solver=self.request)
        if self.goal is Goal.ENERGY and residual > 0:
            self.calibration = ge.relative / residual
        return ge.record()

    def _tol(self) -> str:
        tol = self.opts.tol
        return "no tol: the budget decides" if tol is None else f"--tol {tol:g} bounds"

    def assess(self, level: AdaptLevel, say: Callable[[str], None]) -> AdaptLevel:
        """The level with its goal estimate; the fallback goal's where the pressure is singular."""
        if level.index == 0:
            say(f"goal: {self.goal.value}; {self._tol()} {GOAL_MEANING[self.goal]}")
        try:
            rec = self._record(level)
        except GoalUnbounded as err:
            fallback = self.opts.fallback
            if fallback is None or self.goal is not Goal.PRESSURE:
                raise
            self.note = (
                f"the pressure goal is unbounded on this scene ({err.reason}); "
                f"stopped on the {fallback.value} goal instead"
            )
            self.goal, self.history = fallback, []
            say(f"goal: {fallback.value} ({err.reason}); {self._tol()} {GOAL_MEANING[fallback]}")
            rec = self._record(level)
        self.history.append((level.dofs, rec.relative))
        return dataclasses.replace(level, goal=rec, time=level.time + rec.seconds)

    def _reached(self, level: AdaptLevel) -> tuple[str, str]:
        assert level.goal is not None
        est = f"{100 * level.goal.relative:.3g} %"
        return est, "no tol" if self.opts.tol is None else f"{100 * self.opts.tol:g} %"

    def stop(self, level: AdaptLevel) -> str | None:
        """The goal's estimate at most tol."""
        assert level.goal is not None
        if self.opts.tol is None or level.goal.relative > self.opts.tol:
            return None
        est, tol = self._reached(level)
        return f"{self.goal.value} estimate {est} <= tol {tol}: it bounds {GOAL_MEANING[self.goal]}"

    def reached(self, level: AdaptLevel) -> str:
        """The stop's suffix: "; the <goal> estimate reached <e> (tol <t>)"."""
        est, tol = self._reached(level)
        return f"; the {self.goal.value} estimate reached {est} (tol {tol})"

    def _sized(self, level: AdaptLevel) -> Plan:
        """The next mesh for `cells` cells: pressure sizing (pressure goal) + residual sizing."""
        aim = self.aim if self.goal is Goal.PRESSURE else None
        return plan_mesh(level.solution, level.est, None, self.cells, self.opts.rule, aim)

    def plan(self, level: AdaptLevel, history: list[AdaptLevel]) -> Plan | str:
        """The growth from the observed rate and the budget left; a full budget stops."""
        opts, tol = self.opts, self.opts.tol
        assert level.goal is not None
        allowed = opts.max_levels - len(history)
        self.owed = 0
        if self.goal is Goal.PRESSURE:
            # Without a tolerance the contact cells could always use more: every level allowed.
            self.owed = (
                allowed
                if tol is None
                else contact_levels(
                    level.solution, level.est.pressure, PRESSURE_AIM * tol, opts.rule.finest
                )
            )
        g = plan_growth(
            self.history, tol, opts.max_dofs, self.goal, opts.growth, self.owed, allowed
        )
        if g is None:
            return f"the budget (--max-dofs {opts.max_dofs}) is full"
        self.g, self.s = g, observed_slope(self.history, self.goal)
        self.aim = PRESSURE_AIM * max(tol or 0.0, level.goal.relative * AIM_FLOOR)
        self.cells = g * level.summary.elements
        self.target = min(g * level.dofs, BUDGET_FILL * opts.max_dofs)
        return self._sized(level)

    def replan(self, level: AdaptLevel, dofs: int) -> Plan | None:
        """Plan again for the growth planned where gmsh made more DOFs than planned or budgeted.

        Vertex sizes are the smallest of the cells around, which overshoots most on coarse
        levels; a new plan rather than a stop or a level taken off the plan.
        """
        if dofs <= self.opts.max_dofs and dofs <= OVERSHOOT * self.target:
            return None
        self.cells *= self.target / dofs
        if dofs > self.opts.max_dofs:
            self.aim *= dofs / self.target
        return self._sized(level)

    def remeshed(self, level: AdaptLevel, dofs: int) -> str:
        """The growth made and planned, and the contact cells' levels owed."""
        return (
            f"{dofs} DOFs (x {dofs / level.dofs:.2f}; planned x {self.g:.2f} from the "
            f"observed rate N^{self.s:.2f}; the contact cells need {self.owed} more levels)"
        )
