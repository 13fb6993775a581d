"""`contactfx adapt SCENE ...`: the adaptive loop, its JSON, final mesh, fields and charts."""

from __future__ import annotations

import argparse
import logging
import time
from pathlib import Path

from mpi4py import MPI

from ..adapt.goal import Goal
from ..adapt.loop import AdaptOptions, uniform_levels
from ..adapt.mesh_file import write_msh
from ..adapt.planned import run_loop
from ..adapt.sizing import SizingRule, default_contact_weight
from ..errors import InputError
from ..methods.predictor import scene_dofs
from ..results.files import write_fields, write_json
from ..scenes import parse_scene_file
from .params import build_from_args, is_scene_file, reject_structured_adapt, request_from_args

# --tol's defaults: the goal's relative error, and the residual estimate's (--goal residual).
GOAL_TOL = 0.01
RESIDUAL_TOL = 0.05
RESIDUAL_GROWTH = 4.0  # --goal residual's --growth default


def check_remeshable(args: argparse.Namespace) -> None:
    """InputError before anything runs: a .msh scene, or the structured Hertz mesh."""
    if is_scene_file(args.scene):
        mesh = parse_scene_file(Path(args.scene))[0]
        if mesh.suffix.lower() != ".geo":
            raise InputError(
                f"scene {Path(args.scene).name}: its mesh {mesh.name} is a {mesh.suffix} "
                "file: there is no geometry to remesh (give the mesh as a .geo)"
            )
    reject_structured_adapt(args)


def contact_weight(args: argparse.Namespace) -> float:
    """--weight-contact, or its default (1; --goal residual: 10, or 1 with --pressure-tol)."""
    if args.weight_contact is not None:
        return float(args.weight_contact)
    if args.goal != "residual":
        return 1.0
    return default_contact_weight(args.pressure_tol)


def adapt_options(args: argparse.Namespace) -> AdaptOptions:
    """The loop's options: the goal loop's defaults, or --goal residual's (the old loop)."""
    residual = args.goal == "residual"
    tol = args.tol if args.tol is not None else (RESIDUAL_TOL if residual else GOAL_TOL)
    growth = args.growth if args.growth is not None else RESIDUAL_GROWTH
    return AdaptOptions(
        tol,
        args.max_dofs,
        args.max_levels,
        SizingRule(growth=growth, contact_weight=contact_weight(args)),
        args.pressure_tol,
        None if residual else Goal(args.goal),
    )


def run_adapt(args: argparse.Namespace) -> int:
    """Run the adaptive loop the arguments describe and write DIR's files."""
    comm = MPI.COMM_WORLD
    if not args.verbose:
        logging.getLogger("contactfx").setLevel(logging.WARNING)
    opts = adapt_options(args)
    opts.check()
    check_remeshable(args)
    request = request_from_args(args)
    say = (lambda line: print(line, flush=True)) if comm.rank == 0 else (lambda line: None)
    t0 = time.perf_counter()
    scene = build_from_args(args)
    mesh_time = time.perf_counter() - t0
    start = scene_dofs(scene)
    if start > opts.max_dofs:
        # Refused before solving: a level 0 over budget could only stop at once, and a stop
        # after a solve reads as if the loop had run out of room on its own.
        raise InputError(
            f"the starting mesh already has {start} DOFs > --max-dofs {opts.max_dofs}: "
            "raise --max-dofs or start from a coarser mesh"
        )
    paper = not is_scene_file(args.scene)
    say(
        f"adapt {args.scene} ({args.method}): tol {opts.tol:g}, max {opts.max_dofs} DOFs, "
        f"{comm.size} rank{'s' * (comm.size > 1)}"
    )
    result = run_loop(
        scene,
        request,
        opts,
        paper_interface=paper,
        say=say,
        mesh_time=mesh_time,
        growth_cap=args.growth,
    )
    if args.compare_uniform:
        result.uniform = uniform_levels(
            scene,
            request,
            max(opts.max_dofs, result.levels[-1].dofs),
            max_levels=max(opts.max_levels, 2),
            paper_interface=paper,
            say=say,
        )
    out = args.out
    final = result.levels[-1]
    written = write_fields(final.solution, out, (final.est.eta,))
    msh = write_msh(final.solution, out / "mesh.msh")
    if comm.rank == 0:
        from ..adapt.charts import chart_title, plot_adapt  # matplotlib: rank 0, at the end

        assert msh is not None
        write_json(out / "adapt.json", result.to_json(args.scene, args.method, opts, args.solver))
        levels, uni = result.levels, result.uniform
        title = chart_title(args.scene, args.method, bool(uni))
        written += [
            out / "adapt.json",
            msh,
            plot_adapt(levels, uni, out / "adapt_dofs.png", "dofs", title),
            plot_adapt(levels, uni, out / "adapt_time.png", "time", title),
        ]
        print("wrote " + ", ".join(str(p) for p in written))
    return 0
