"""The goal loop: `--tol` is the relative error of a chosen quantity, each level planned.

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
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable

import numpy as np
from mpi4py import MPI

from ..methods.predictor import scene_dofs
from ..methods.solution import Solution
from ..request import SolveRequest
from ..scenes import Scene
from .goal import GOAL_MEANING, Goal, GoalRecord, goal_estimate
from .loop import REPLANS, AdaptLevel, AdaptOptions, AdaptResult, adapt, level_line, solve_level
from .pressure_estimate import PressureEstimate
from .pressure_sizing import pressure_cell_sizes
from .sizing import Plan, SizingRule, cell_sizes, owned_cells, plan_mesh

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
NO_TOL = 1e-12  # the residual sizing's own tolerance: the planned budget decides


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
    tol: float,
    max_dofs: int,
    goal: Goal,
    cap: float | None = None,
    owed: int = 0,
    allowed: int | None = None,
) -> float | None:
    """The next level's DOFs / this level's, or None when the budget has no room left.

    `history`: (DOFs, goal estimate) of the levels so far. `cap`: an expert's --growth.
    `owed`: the levels the contact cells still need (contact_levels); `allowed`: the
    levels --max-levels leaves after this one (the budget is spread over at most these).
    """
    n, e = history[-1]
    room = BUDGET_FILL * max_dofs / n
    if room < G_MIN:
        return None
    s = observed_slope(history, goal)
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


def _goal_record(
    level: AdaptLevel,
    goal: Goal,
    request: SolveRequest,
    max_dofs: int,
    calibration: float | None,
) -> tuple[GoalRecord, float | None]:
    """The level's goal estimate, and the energy goal's calibration of the residual one."""
    residual = level.est.relative
    if goal is Goal.ENERGY and calibration is not None and level.dofs * ENERGY_REFINED > max_dofs:
        parts = {"residual": residual, "calibration": calibration}
        return GoalRecord(goal, calibration * residual, parts, 0, 0.0), calibration
    ge = goal_estimate(level.solution, goal, solver=request)
    if goal is Goal.ENERGY and residual > 0:
        calibration = ge.relative / residual
    return ge.record(), calibration


def _plan(
    level: AdaptLevel, goal: Goal, rule: SizingRule, cells: float, pressure_aim: float
) -> Plan:
    """The next mesh for `cells` cells: pressure sizing (pressure goal) + residual sizing."""
    rule = dataclasses.replace(rule, growth=cells / max(level.summary.elements, 1))
    aim = pressure_aim if goal is Goal.PRESSURE else None
    return plan_mesh(level.solution, level.est, NO_TOL, cells, rule, aim)


def adapt_to_goal(
    scene: Scene,
    request: SolveRequest,
    opts: AdaptOptions,
    *,
    paper_interface: bool = False,
    say: Callable[[str], None] | None = None,
    mesh_time: float = 0.0,
    count_dofs: Callable[[Scene], int] = scene_dofs,
    growth_cap: float | None = None,
) -> AdaptResult:
    """Adapt until the goal's estimate is at most opts.tol or the budget is full (collective).

    Raises:
        GoalUnbounded: The goal has no finite value on this scene (before any output).
    """
    assert opts.goal is not None
    goal = opts.goal
    opts.check()
    scene.require_recipe()
    comm = scene.comm
    say = say or (lambda line: print(line, flush=True) if comm.rank == 0 else None)
    levels: list[AdaptLevel] = []
    history: list[tuple[int, float]] = []
    calibration: float | None = None
    stop = f"max levels ({opts.max_levels})"
    for k in range(opts.max_levels):
        previous = levels[-1].solution if levels else None
        level = solve_level(scene, k, mesh_time, request, paper_interface, previous)
        rec, calibration = _goal_record(level, goal, request, opts.max_dofs, calibration)
        level = dataclasses.replace(level, goal=rec, time=level.time + rec.seconds)
        if k == 0:
            say(f"goal: {goal.value}; --tol {opts.tol:g} bounds {GOAL_MEANING[goal]}")
        levels.append(level)
        history.append((level.dofs, rec.relative))
        say(level_line(level))
        est, tol = f"{100 * rec.relative:.3g} %", f"{100 * opts.tol:g} %"
        reached = f"the {goal.value} estimate reached {est} (tol {tol})"
        if rec.relative <= opts.tol:
            stop = f"{goal.value} estimate {est} <= tol {tol}"
            stop += f": it bounds {GOAL_MEANING[goal]}"
            break
        if k + 1 == opts.max_levels:
            stop = f"max levels ({opts.max_levels}); {reached}"
            break
        owed = 0
        if goal is Goal.PRESSURE:
            pe, aim_tol = level.est.pressure, PRESSURE_AIM * opts.tol
            owed = contact_levels(level.solution, pe, aim_tol, opts.rule.finest)
        allowed = opts.max_levels - len(history)
        g = plan_growth(history, opts.tol, opts.max_dofs, goal, growth_cap, owed, allowed)
        if g is None:
            stop = f"the budget (--max-dofs {opts.max_dofs}) is full; {reached}"
            break
        s = observed_slope(history, goal)
        aim = PRESSURE_AIM * max(opts.tol, rec.relative * AIM_FLOOR)
        cells = g * level.summary.elements
        t0 = time.perf_counter()
        nxt = scene.remeshed_to(_plan(level, goal, opts.rule, cells, aim).field)
        dofs = count_dofs(nxt)
        target = min(g * level.dofs, BUDGET_FILL * opts.max_dofs)
        for _ in range(REPLANS):
            if dofs <= opts.max_dofs and dofs <= OVERSHOOT * target:
                break
            # gmsh made more than planned (vertex sizes are the smallest of the cells
            # around, which overshoots most on coarse levels) or than the budget: plan again for the
            # growth planned, rather than stop or take a level off the plan.
            cells *= target / dofs
            if dofs > opts.max_dofs:
                aim *= dofs / target
            nxt = scene.remeshed_to(_plan(level, goal, opts.rule, cells, aim).field)
            dofs = count_dofs(nxt)
        mesh_time = time.perf_counter() - t0
        if dofs > opts.max_dofs:
            stop = f"the next mesh would have {dofs} DOFs > --max-dofs {opts.max_dofs}; {reached}"
            break
        say(
            f"  remeshed: {dofs} DOFs (x {dofs / level.dofs:.2f}; planned x {g:.2f} from the "
            f"observed rate N^{s:.2f}; the contact cells need {owed} more levels; "
            f"{mesh_time:.2f} s)"
        )
        scene = nxt
    say(f"stopped: {stop}")
    return AdaptResult(levels, stop)


def run_loop(
    scene: Scene,
    request: SolveRequest,
    opts: AdaptOptions,
    *,
    paper_interface: bool = False,
    say: Callable[[str], None] | None = None,
    mesh_time: float = 0.0,
    growth_cap: float | None = None,
) -> AdaptResult:
    """The goal loop (opts.goal set) or the residual estimate's loop (opts.goal None)."""
    if opts.goal is None:
        return adapt(
            scene, request, opts, paper_interface=paper_interface, say=say, mesh_time=mesh_time
        )
    return adapt_to_goal(
        scene,
        request,
        opts,
        paper_interface=paper_interface,
        say=say,
        mesh_time=mesh_time,
        growth_cap=growth_cap,
    )
