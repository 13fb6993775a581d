"""`contactfx study SCENE ...`: levels from the command line, the study, its files and table."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from mpi4py import MPI

from ..adapt.goal import Goal
from ..errors import InputError
from ..options import Method
from ..request import SolveRequest
from ..study import builtin_levels, run_study, scene_file_levels, size_factors, write_outputs
from ..study.adaptive import adaptive_requests, adaptive_runs
from ..study.levels import Level
from ..study.report import adaptive_lines, level_lines, table_lines
from .params import (
    is_scene_file,
    reject_builtin_options,
    reject_structured_adapt,
    scene_params,
    spec_from_args,
)


def parse_methods(text: str) -> list[str]:
    """--methods nts,sts,mortar -> ["nts", "sts", "mortar"] (InputError on unknown names)."""
    names = [m.strip() for m in text.split(",") if m.strip()]
    known = [m.value for m in Method]
    bad = [m for m in names if m not in known]
    if bad or not names:
        raise InputError(
            f"--methods: unknown method '{bad[0] if bad else text}' (choose from "
            f"{', '.join(known)}, comma-separated)"
        )
    if len(set(names)) != len(names):
        raise InputError(f"--methods lists a method twice: {text}")
    return names


def levels_from_args(args: argparse.Namespace, comm: MPI.Comm) -> list[Level]:
    """The levels of the SCENE argument (built-in scene with its options, or a scene file)."""
    factors = size_factors(args.levels, args.ratio, args.size_factor)
    if is_scene_file(args.scene):
        reject_builtin_options(args)
        return scene_file_levels(Path(args.scene), factors, comm)
    return builtin_levels(args.scene, scene_params(args), factors, args.active or 2, comm)


def check_adaptive(args: argparse.Namespace, requests: list[SolveRequest]) -> None:
    """InputError before anything runs if --adaptive cannot be done."""
    if not adaptive_requests(requests):
        raise InputError("study --adaptive needs a method with an estimate (not only schwarz)")
    if args.pressure_tol is not None and not args.pressure_tol > 0:
        raise InputError(f"--pressure-tol must be > 0 (got {args.pressure_tol})")
    reject_structured_adapt(args)


def run_command(args: argparse.Namespace) -> int:
    """Run the study the arguments describe, write its files on rank 0 and print the table."""
    comm = MPI.COMM_WORLD
    if not args.verbose:
        # One progress line per run is the display; the solver's per-iteration log is noise.
        logging.getLogger("contactfx").setLevel(logging.WARNING)
    methods = parse_methods(args.methods)
    spec = spec_from_args(args)
    requests = [
        SolveRequest.parse(m, solver=spec, max_iterations=args.max_iterations) for m in methods
    ]
    if args.adaptive:
        check_adaptive(args, requests)
    elif args.goal is not None or args.pressure_tol is not None:
        given = "--goal" if args.goal is not None else "--pressure-tol"
        raise InputError(
            f"{given} applies to study --adaptive only: add --adaptive or leave it out"
        )
    levels = levels_from_args(args, comm)
    say = print if comm.rank == 0 else (lambda *a, **k: None)
    say(
        f"study {args.scene}: {len(methods)} methods x {len(levels)} levels (ratio "
        f"{args.ratio:g}), solver {args.solver}, {comm.size} rank{'s' * (comm.size > 1)}",
        flush=True,
    )
    study = run_study(
        levels,
        requests,
        ratio=args.ratio,
        comm=comm,
        say=lambda line: say(line, flush=True),
        settings={
            "scene_arg": args.scene,
            "ratio": args.ratio,
            "size_factor": args.size_factor,
            "solver": args.solver,
            "petsc_options": list(args.petsc_option),
        },
    )
    if args.adaptive:
        study.adaptive = adaptive_runs(
            study,
            levels[0].build(),
            requests,
            paper_interface=levels[0].paper_interface,
            max_levels=3 * len(levels),
            pressure_tol=args.pressure_tol,
            goal=Goal(args.goal or "pressure"),
            say=lambda line: say(line, flush=True),
        )
    if comm.rank == 0:
        written = write_outputs(study, args.out)
        for line in ["", *level_lines(study), "", *table_lines(study), *adaptive_lines(study)]:
            print(line)
        print("wrote " + ", ".join(str(p) for p in written))
    return 0
