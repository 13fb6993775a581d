"""`contactfx solve SCENE ...`: one solve, its summary on the terminal, its files."""

from __future__ import annotations

import argparse
import logging
import time
from dataclasses import replace
from typing import Any

from mpi4py import MPI

from ..api import run_scene
from ..errors import InputError
from ..methods.solution import Solution
from ..options import Enforcement
from ..request import SolveRequest
from ..results.records import ContactSummary, RunSummary
from ..timers import Timers
from .params import build_from_args, is_scene_file, request_from_args


def half_width_failure(run: RunSummary, pair: int) -> str:
    """Why a pair has no fitted half-width: too few active nodes, or no fit."""
    n = run.contacts[pair].active_nodes if pair < len(run.contacts) else 0
    if n < 4:
        # The fit of p^2 = p0^2 (1 - x^2/a^2) has two unknowns: with a node or two to spare
        # it follows the discretization's wiggles, not the ellipse.
        return f"{n} active node{'s' * (n != 1)}, too few to fit the half-width"
    return f"no half-width fits the pressures of the {n} active nodes"


def _counts(c: ContactSummary) -> str:
    """A frictional pair's stick and slip node counts ("" for a frictionless scene)."""
    status = c.interface.get("status")
    if status is None:
        return ""
    return f", {status.count('stick')} stick, {status.count('slip')} slip"


def terminal_summary(run: RunSummary) -> list[str]:
    """What a user came for, last: each pair's force, and the errors against references."""
    lines = [
        f"{run.scene} / {run.method.value}: {run.dofs} dofs, "
        f"{run.multipliers} multipliers, {run.iterations} iterations, "
        f"total {run.times['total']:.2f} s"
    ]
    for n, step in enumerate(run.steps, start=1):
        for k, c in enumerate(step.contacts):
            lines.append(
                f"step {n}, pair {k}: {c.force_text()}{_counts(c)}, {step.iterations} iterations"
            )
        lines += [f"step {n}, {r.text()}" for r in step.cattaneo]
        lines += [f"step {n}, {r.text()}" for r in step.pushout]
        lines += [f"step {n}, {r.text()}" for r in step.spence]
    for k, c in enumerate(run.contacts):
        lines.append(f"pair {k} ({c.active} on {c.passive}): {c.force_text()}{_counts(c)}")
    if run.patch is not None:
        lines.append(
            f"patch test: max stress/pressure error {run.patch.max:.2e} "
            "(relative to the exact uniform stress)"
        )
    for h in run.hertz:
        if h.a is None:
            a_text = f"a: n/a ({half_width_failure(run, h.pair)}; exact {h.a_exact:.4g})"
        else:
            a_err = 100 * (h.a / h.a_exact - 1)
            a_text = f"a = {h.a:.4g} (exact {h.a_exact:.4g}, {a_err:+.2f} %)"
        lines.append(
            f"Hertz, pair {h.pair}: {a_text}, p0 = {h.p0:.4g} (exact "
            f"{h.p0_exact:.4g}, {100 * (h.p0 / h.p0_exact - 1):+.2f} %), "
            f"L2 error {100 * h.l2_error:.2f} %"
        )
        lines.append(f"  against {h.description}, {h.validity}")
    for r in run.lame:
        lines.append(
            f"Lame, pair {r.pair} ({r.model}): mean pressure {r.p_mean:.6g} (exact "
            f"{r.p_exact:.6g}, {100 * (r.p_mean / r.p_exact - 1):+.3f} %)"
            + ("" if r.exact else f"; {r.validity}")
        )
    for cm in run.cattaneo:
        lines.append(cm.text())
        if cm.warning is not None:
            lines.append(f"  warning: {cm.warning}")
    for po in run.pushout:
        lines += po.lines()
    for sp in run.spence:
        lines.append(sp.text())
        if sp.warning is not None:
            lines.append(f"  warning: {sp.warning}")
    lines += [p.text() for p in run.probes]
    e = run.estimate
    if e is not None:
        lines.append(
            f"estimate (relative to the energy norm): {100 * e.total:.3g} % (contact "
            f"{100 * e.contact:.3g} %, bulk {100 * e.bulk:.3g} %)"
        )
        if e.pressure:
            lines.append(f"pressure estimate (relative L2): {100 * e.pressure:.3g} %")
        g = e.goal or {}
        if g.get("goal_estimate") is not None:
            from ..adapt.goal import GOAL_MEANING, Goal  # the goal loop only with --goal

            lines.append(
                f"{g['goal']} goal estimate: {100 * g['goal_estimate']:.3g} % "
                f"({GOAL_MEANING[Goal(g['goal'])]}; refined solve {g['goal_refined_dofs']} DOFs)"
            )
    return lines


def goal_block(args: argparse.Namespace, request: SolveRequest, sol: Solution) -> dict[str, Any]:
    """The `estimate` block's goal fields: the --goal's two-level estimate (collective).

    A scene without a geometry to remesh has none (`goal_estimate` null, `goal_note` why);
    GoalUnbounded (an InputError: one line, exit 2) where the goal has no finite value.
    """
    from ..adapt.goal import Goal, goal_estimate  # the refined solve's machinery, on request

    goal = Goal(args.goal or "pressure")
    if sol.scene.recipe is None or getattr(args, "mesh", None) == "structured":
        note = "no geometry to remesh: the goal estimate needs a refined solve"
        return {"goal": goal.value, "goal_estimate": None, "goal_note": note}
    return goal_estimate(sol, goal, solver=request).record().to_json()


def run(args: argparse.Namespace) -> int:
    """Run one solve and write its outputs; return the exit code."""
    comm = MPI.COMM_WORLD
    request = request_from_args(args)
    schwarz = request.enforcement is Enforcement.SCHWARZ
    if args.estimate and schwarz:
        raise InputError("--estimate needs a multiplier or penalty method, not schwarz")
    if args.goal is not None and not args.estimate:
        # The goal's estimate is a second solve: not implied, so that a run costs what it says.
        raise InputError(
            f"--goal {args.goal} applies with --estimate only (the goal's error is estimated "
            "by a second solve on a refined mesh): add --estimate, or leave --goal out"
        )
    t_start = time.perf_counter()
    timers = Timers()
    with timers("mesh"):
        scene = build_from_args(args)
    sol, record = run_scene(
        scene,
        request,
        paper_interface=not is_scene_file(args.scene),
        t_start=t_start,
        timers=timers,
    )
    cells: tuple[Any, ...] = ()
    if args.estimate:
        from ..adapt.estimate import estimate  # the estimator's forms only with --estimate

        est = estimate(sol)
        summary = replace(est.summary(), goal=goal_block(args, request, sol))
        record = record.with_estimate(summary)
        cells = (est.eta,)
    if args.out is not None or args.json is not None:
        # The writers (and through them pyvista and matplotlib) only when a file is asked for.
        from ..results.figures import contact_window, deformed_fields, plot_interface, plot_pair
        from ..results.files import write_contact_surfaces, write_fields, write_json
    if args.out is not None:
        write_fields(sol, args.out, cells)
    log = logging.getLogger("contactfx")
    if comm.rank == 0:
        if args.json is not None:
            write_json(args.json, record.to_json())
            log.info("wrote %s", args.json)
        if args.out is not None:
            written = write_contact_surfaces(record, args.out)
            written += [
                plot_pair(record, k, args.out / f"interface_pair{k}.png", pv.pair.mu)
                for k, pv in enumerate(sol.pairs)
            ]
            if record.interface is not None:
                written.append(plot_interface(record, args.out / "interface.png"))
            if sol.scene.obstacles:
                # The body against the obstacles' outlines, true scale, on the contact zone
                # (a magnified deformation would not magnify the gaps with it); serial only.
                picture = deformed_fields(
                    sol, args.out / "fields.png", scale=1.0, window=contact_window(record)
                )
                written += [picture] if picture is not None else []
            log.info("wrote fields.pvtu, %s to %s", ", ".join(p.name for p in written), args.out)
        for line in terminal_summary(record):
            print(line)
    return 0
