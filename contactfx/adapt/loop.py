"""The adaptive loop: solve, estimate, mark (size the next mesh), remesh with gmsh; repeat.

DOLFINx cannot refine quadrilaterals, so every level remeshes the scene's geometry (a
built-in scene's gmsh model or a .geo) from a background size field built from the
indicators (adapt/sizing.py). One loop for every goal; what differs is a Strategy's: how a
level is assessed (the goal estimates' refined solve, adapt/planned.py; nothing more for the
residual estimate, `ResidualPlan` below), when the loop stops (`stop`: the estimate at most
`tol`) and how the next mesh is planned (`plan`, and `replan` when gmsh overshoots). The loop
also stops after `max_levels` levels, or when the next mesh would exceed `max_dofs`.
`uniform_levels` refines the same starting scene uniformly, for the comparison charts.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Protocol

from ..api import run_scene
from ..methods.predictor import scene_dofs
from ..methods.solution import Solution
from ..request import SolveRequest
from ..scenes import Scene
from ..timers import Timers
from .estimate import estimate
from .goal import FRICTION_MEANING, Goal
from .records import AdaptLevel, AdaptOptions, AdaptResult
from .sizing import Plan, plan_mesh

Say = Callable[[str], None]


def solve_level(
    scene: Scene,
    index: int,
    mesh_time: float,
    request: SolveRequest,
    paper_interface: bool,
    previous: Solution | None = None,
) -> AdaptLevel:
    """Solve one mesh and estimate its error; the summary carries the estimate.

    `previous` (the level before) gives the first active set: remeshing a coarser copy of
    an adapted mesh for the predictor costs more than it saves, and gmsh may fail to
    recombine it.
    """
    t0 = time.perf_counter()
    sol, run = run_scene(
        scene, request, timers=Timers(), paper_interface=paper_interface, initial=previous
    )
    est = estimate(sol)
    run = run.with_estimate(est.summary()).with_times(mesh=mesh_time)
    elapsed = mesh_time + time.perf_counter() - t0
    return AdaptLevel(index, run, sol, est, elapsed)


# Remeshings with another plan when gmsh's mesh exceeds what was planned or --max-dofs.
REPLANS = 2


class Strategy(Protocol):
    """What a goal decides in the loop: the level's estimate, the stop, the next mesh."""

    goal: Goal  # the goal the loop is stopping on now
    note: str  # why the goal is not the one asked for ("" if it is)

    def assess(self, level: AdaptLevel, say: Say) -> AdaptLevel:
        """The level with its goal estimate (collective)."""
        ...

    def stop(self, level: AdaptLevel) -> str | None:
        """Why the loop stops at this level (the estimate reached tol), or None."""
        ...

    def reached(self, level: AdaptLevel) -> str:
        """What the level's estimate reached, for a stop on the budget or the levels ("")."""
        ...

    def plan(self, level: AdaptLevel, history: list[AdaptLevel]) -> Plan | str:
        """The next mesh's plan, or why there is none (the budget is full). Collective."""
        ...

    def replan(self, level: AdaptLevel, dofs: int) -> Plan | None:
        """Another plan when gmsh made `dofs` of the last one, or None to keep it."""
        ...

    def remeshed(self, level: AdaptLevel, dofs: int) -> str:
        """The progress line's account of the remeshed level's DOFs."""
        ...


class ResidualPlan:
    """The residual goal: the residual estimate at most tol; sizes for tol within the growth.

    `size` is `plan_mesh` (tests pass their own to steer the loop).
    """

    goal = Goal.RESIDUAL
    note = ""

    def __init__(self, opts: AdaptOptions, size: Callable[..., Plan] = plan_mesh) -> None:
        self.opts = opts
        self.size = size
        growth = opts.level_growth
        assert growth is not None, "the residual goal's growth is never planned"
        self.growth = growth
        self.budget = 0.0
        self.sizes: Plan | None = None

    def assess(self, level: AdaptLevel, say: Say) -> AdaptLevel:
        """The level as it is: its residual estimate is the goal's."""
        return level

    def stop(self, level: AdaptLevel) -> str | None:
        """The estimate (and the pressure estimate, with pressure_tol) reached."""
        return self.opts.met(level.est)

    def reached(self, level: AdaptLevel) -> str:
        """Nothing to add: the level lines print the estimates."""
        return ""

    def _sized(self, level: AdaptLevel) -> Plan:
        opts = self.opts
        cells = min(self.growth * level.summary.elements, self.budget)
        self.sizes = self.size(
            level.solution, level.est, opts.tol, cells, opts.rule, opts.pressure_tol
        )
        return self.sizes

    def plan(self, level: AdaptLevel, history: list[AdaptLevel]) -> Plan | str:
        """Sized for tol within the growth and 90 % of --max-dofs; a full budget stops."""
        opts = self.opts
        ratio = level.dofs / max(level.summary.elements, 1)
        # 10 % margin: gmsh meets a size field only approximately.
        self.budget = 0.9 * opts.max_dofs / ratio
        sizes = self._sized(level)
        before = history[-2].est if len(history) > 1 else None
        if (
            (opts.tol is None or sizes.predicted > opts.tol)
            and sizes.cells < 1.1 * level.summary.elements
            and opts.pressure_settled(level.est, before)
        ):
            return f"the next mesh would exceed --max-dofs {opts.max_dofs}"
        return sizes

    def replan(self, level: AdaptLevel, dofs: int) -> Plan | None:
        """Over --max-dofs: a smaller budget.

        Rather than stop a level early: on Hertz the last level is the one the pressure
        target needs.
        """
        if dofs <= self.opts.max_dofs:
            return None
        self.budget *= 0.95 * self.opts.max_dofs / dofs
        return self._sized(level)

    def remeshed(self, level: AdaptLevel, dofs: int) -> str:
        """The DOFs and the estimate they were planned for."""
        predicted = self.sizes.predicted if self.sizes is not None else float("nan")
        return f"{dofs} DOFs planned for an estimate of {100 * predicted:.3g} %"


def strategy_for(opts: AdaptOptions, request: SolveRequest) -> Strategy:
    """The options' goal's strategy: the residual estimate's, or a goal estimate's."""
    if opts.goal is Goal.RESIDUAL:
        return ResidualPlan(opts)
    from .planned import GoalPlan  # the goal estimates' refined solves

    return GoalPlan(opts, request)


def adapt(
    scene: Scene,
    request: SolveRequest,
    opts: AdaptOptions,
    *,
    paper_interface: bool = False,
    say: Say | None = None,
    mesh_time: float = 0.0,
    count_dofs: Callable[[Scene], int] = scene_dofs,
    strategy: Strategy | None = None,
) -> AdaptResult:
    """Run the adaptive loop from `scene` until opts.goal's estimate is at most opts.tol.

    Collective; `say` prints progress (rank 0). `count_dofs` counts a remeshed scene's DOFs
    against the budget; `strategy` (default: the goal's) decides the estimate, the stop and
    the plans.

    Raises:
        GoalUnbounded: The goal has no finite value on this scene and opts.fallback is None.
    """
    scene.require_recipe()
    comm = scene.comm
    say = say or (lambda line: print(line, flush=True) if comm.rank == 0 else None)
    strategy = strategy or strategy_for(opts, request)
    levels: list[AdaptLevel] = []
    stop = f"max levels ({opts.max_levels})"
    for k in range(opts.max_levels):
        previous = levels[-1].solution if levels else None
        level = solve_level(scene, k, mesh_time, request, paper_interface, previous)
        if k == 0 and level.solution.friction is not None:
            say(f"friction: {FRICTION_MEANING}")
        level = strategy.assess(level, say)
        levels.append(level)
        say(level_line(level))
        reached = strategy.stop(level)
        if reached is not None:
            stop = reached
            break
        suffix = strategy.reached(level)
        if k + 1 == opts.max_levels:
            stop += suffix
            break
        sizes = strategy.plan(level, levels)
        if isinstance(sizes, str):
            stop = sizes + suffix
            break
        t0 = time.perf_counter()
        nxt = scene.remeshed_to(sizes.field)
        dofs = count_dofs(nxt)
        for _ in range(REPLANS):
            again = strategy.replan(level, dofs)
            if again is None:
                break
            nxt = scene.remeshed_to(again.field)
            dofs = count_dofs(nxt)
        mesh_time = time.perf_counter() - t0
        if dofs > opts.max_dofs:
            stop = f"the next mesh would have {dofs} DOFs > --max-dofs {opts.max_dofs}{suffix}"
            break
        say(f"  remeshed: {strategy.remeshed(level, dofs)} ({mesh_time:.2f} s)")
        scene = nxt
    say(f"stopped: {stop}")
    return AdaptResult(levels, stop, strategy.goal, strategy.note)


def uniform_levels(
    scene: Scene,
    request: SolveRequest,
    max_dofs: int,
    *,
    ratio: float = 2.0,
    max_levels: int = 8,
    paper_interface: bool = False,
    say: Callable[[str], None] | None = None,
) -> list[AdaptLevel]:
    """The same scene refined uniformly (every size / ratio per level) up to max_dofs.

    The last level is the first at or beyond max_dofs (so that the uniform curve spans the
    adaptive one), unless it would exceed ratio^2 max_dofs.
    """
    comm = scene.comm
    say = say or (lambda line: print(line, flush=True) if comm.rank == 0 else None)
    out: list[AdaptLevel] = []
    current, mesh_time = scene, 0.0
    for k in range(max_levels):
        if scene_dofs(current) > ratio**2 * max_dofs:
            break
        level = solve_level(current, k, mesh_time, request, paper_interface)
        out.append(level)
        say("uniform " + level_line(level))
        if level.dofs >= max_dofs:
            break
        t0 = time.perf_counter()
        current = scene.remeshed(ratio ** -(k + 1))
        mesh_time = time.perf_counter() - t0
    return out


def level_line(level: AdaptLevel) -> str:
    """One progress line: DOFs, estimate (contact and bulk), the reference error, time."""
    run = level.summary
    e = level.est.summary()
    ref = ""
    if len(run.hertz) == 1:
        ref = f", Hertz L2 {100 * run.hertz[0].l2_error:.3f} %"
    elif run.hertz:
        # Every pair: the first alone hid a pair ten times worse.
        ref = ", Hertz L2 " + ", ".join(
            f"pair {h.pair} {100 * h.l2_error:.3f} %" for h in run.hertz
        )
    elif run.patch is not None:
        ref = f", patch max {run.patch.max:.2e}"
    elif level.exact_error is not None:  # Cattaneo-Mindlin: Hertz's pressure
        ref = f", pressure L2 {100 * level.exact_error:.3f} % against Hertz"
    pressure = f", pressure {100 * e.pressure:.3g} %" if e.pressure else ""
    if level.goal is not None:
        g = level.goal
        eff = level.exact_error
        eff_s = f", effectivity {g.relative / eff:.2f}" if eff else ""
        if g.shear_estimate is not None:
            true = level.exact_shear_error
            eff_s += f"; shear estimate {100 * g.shear_estimate:.3g} % (not bounded"
            eff_s += f", true {100 * true:.3g} %)" if true else ")"
        return (
            f"level {level.index}: {run.dofs} DOFs, {g.goal.value} estimate "
            f"{100 * g.relative:.3g} %{ref}{eff_s} (residual {100 * e.total:.3g} %), "
            f"{level.time:.2f} s"
        )
    return (
        f"level {level.index}: {run.dofs} DOFs, estimate {100 * e.total:.3g} % "
        f"(contact {100 * e.contact:.3g} %, bulk {100 * e.bulk:.3g} %{pressure}){ref}, "
        f"{level.time:.2f} s"
    )
