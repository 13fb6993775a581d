"""`contactfx adapt SCENE ...`: the adaptive loop, its JSON, final mesh, fields and charts."""

from __future__ import annotations

import argparse
import logging
import time
from pathlib import Path

from mpi4py import MPI

from ..adapt.goal import Goal
from ..adapt.loop import adapt, uniform_levels
from ..adapt.mesh_file import write_msh
from ..adapt.records import AdaptOptions, default_tol
from ..errors import InputError
from ..methods.predictor import scene_dofs
from ..results.files import write_fields, write_json
from ..scenes import parse_scene_file
from .params import build_from_args, is_scene_file, reject_structured_adapt, request_from_args


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


def adapt_options(args: argparse.Namespace) -> AdaptOptions:
    """The loop's options (InputError for a value out of range).

    Without --goal the pressure goal, or the energy where the scene's pressure is singular
    (the loop decides, AdaptOptions.fallback); an explicit --goal pressure is refused there.
    """
    goal = Goal.PRESSURE if args.goal is None else Goal(args.goal)
    return AdaptOptions(
        goal,
        default_tol(goal) if args.tol is None else args.tol,
        args.max_dofs,
        args.max_levels,
        args.growth,
        args.weight_contact,
        args.pressure_tol,
        Goal.ENERGY if args.goal is None else None,
    )


def run_adapt(args: argparse.Namespace) -> int:
    """Run the adaptive loop the arguments describe and write DIR's files."""
    comm = MPI.COMM_WORLD
    if not args.verbose:
        logging.getLogger("contactfx").setLevel(logging.WARNING)
    opts = adapt_options(args)
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
        f"adapt {args.scene} ({request.label}): tol {opts.tol:g}, max {opts.max_dofs} DOFs, "
        f"{comm.size} rank{'s' * (comm.size > 1)}"
    )
    result = adapt(scene, request, opts, paper_interface=paper, say=say, mesh_time=mesh_time)
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
        write_json(out / "adapt.json", result.to_json(args.scene, request, opts))
        levels, uni = result.levels, result.uniform
        title = chart_title(args.scene, request.label, bool(uni))
        written += [
            out / "adapt.json",
            msh,
            plot_adapt(levels, uni, out / "adapt_dofs.png", "dofs", title),
            plot_adapt(levels, uni, out / "adapt_time.png", "time", title),
        ]
        print("wrote " + ", ".join(str(p) for p in written))
    return 0
