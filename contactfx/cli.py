"""Command line: python -m contactfx solve {blocks,hertz} [options] --json FILE [--out DIR]."""

from __future__ import annotations

import argparse
import logging
import sys
from dataclasses import fields, replace
from pathlib import Path

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)

from .errors import ContactFxError
from .methods import Method
from .scenes import BlockParams, HertzParams

BLOCK_KEYS = ("l1", "l2", "h1", "h2", "E1", "E2", "nu1", "nu2", "p", "size1", "size2",
              "grading1", "grading2")
HERTZ_KEYS = ("R", "P", "E1", "E2", "nu1", "nu2", "refine", "r_refine", "refine_edge", "slope",
              "width", "height")


PARAM_HELP = {
    "l1": "blocks: full width of the base B1 (cm, default 10)",
    "l2": "blocks: full width of the top block B2 (cm, default 6)",
    "h1": "blocks: height of B1 (cm, default 3)",
    "h2": "blocks: height of B2 (cm, default 3)",
    "E1": "Young's modulus of body 1 (MPa; blocks 70000, hertz 7000)",
    "E2": "Young's modulus of body 2 (MPa; blocks 70000, hertz 7000)",
    "nu1": "Poisson ratio of body 1 (blocks 0.3, hertz 0.23)",
    "nu2": "Poisson ratio of body 2 (blocks 0.3, hertz 0.23)",
    "p": "blocks: pressure on the top of B2 (MPa, default 50)",
    "size1": "blocks: element size in B1 (cm, default 0.125)",
    "size2": "blocks: element size in B2 (cm, default 0.125)",
    "grading1": "blocks: element-size ratio of neighbours along x in B1 (1 = uniform)",
    "grading2": "blocks: element-size ratio of neighbours along x in B2 (1 = uniform)",
    "R": "hertz: cylinder radius (cm, default 60)",
    "P": "hertz: load per unit thickness, full model (MPa*cm, default 100)",
    "refine": "hertz: element size on the contact zone (cm, default 0.02)",
    "r_refine": "hertz: extent of the refined zone (cm; default 1.4 x Hertz's a)",
    "refine_edge": "hertz, gmsh mesh: element size at the edge of contact (cm, 0 = off)",
    "slope": "hertz: growth of the element size per cm of distance (default 0.1)",
    "width": "hertz: half width of the block (cm, default 60)",
    "height": "hertz: height of the block (cm, default 60)",
}


def parser() -> argparse.ArgumentParser:
    """The argument parser (defaults of scene parameters are the paper's, filled in later)."""
    ap = argparse.ArgumentParser(prog="python -m contactfx",
                                 description="2D frictionless two-body contact (units: cm, MPa)")
    sub = ap.add_subparsers(dest="command", required=True)
    s = sub.add_parser("solve", help="solve a scene and write a JSON summary")
    s.add_argument("scene", help="blocks (S1-S4, default S1) or hertz (S5)")
    s.add_argument("--preset", choices=["S1", "S2", "S3", "S4"],
                   help="block scene of the paper to start from (other options override it)")
    for key in sorted(set(BLOCK_KEYS) | set(HERTZ_KEYS)):
        s.add_argument(f"--{key.replace('_', '-')}", dest=key, type=float, default=None,
                       help=PARAM_HELP.get(key, key))
    s.add_argument("--mesh", choices=["gmsh", "structured"], default=None,
                   help="hertz only: gmsh graded quads (default) or a structured graded mesh "
                        "built in DOLFINx (fast to make for millions of DOFs)")
    s.add_argument("--method", default="nts", choices=[m.value for m in Method])
    s.add_argument("--active", type=int, default=2, choices=[1, 2],
                   help="which body is active (slave, carries the multipliers)")
    s.add_argument("--solver", default="mumps", help="mumps | fieldsplit | fieldsplit-gamg")
    s.add_argument("--petsc-option", action="append", default=[], metavar="KEY=VALUE",
                   help="extra PETSc option for the saddle-point KSP (no leading dash)")
    s.add_argument("--json", type=Path, required=True, help="where to write the JSON summary")
    s.add_argument("--out", type=Path, help="directory for XDMF fields and figures")
    s.add_argument("--max-iterations", type=int, default=50, help="active-set iteration limit")
    s.add_argument("--penalty", type=float, default=None, metavar="EPS",
                   help="penalty normal stiffness in MPa/cm (pressure = EPS * penetration) for "
                   "--method penalty; default 1e3 * max(E1, E2) / h, h the median contact "
                   "element size")
    s.add_argument("--predictor", choices=["auto", "coarse", "none"], default="auto",
                   help="first active set from a coarser solve of the same scene: auto = hertz "
                        "above 200k DOFs (the answer does not depend on it)")
    s.add_argument("--reference-timing", action="store_true",
                   help="also time a fresh solve of the final saddle-point system (the cost "
                   "floor) and report it as times.reference_solve")
    s.add_argument("-q", "--quiet", action="store_true", help="log warnings only")
    return ap


def scene_params(args: argparse.Namespace) -> BlockParams | HertzParams:
    """Scene parameters from the paper's defaults, a preset, and the options given."""
    from .errors import InputError
    from .scenes import BLOCK_SCENES

    if args.scene == "blocks":
        base, keys = BLOCK_SCENES[args.preset or "S1"], BLOCK_KEYS
    elif args.scene == "hertz":
        if args.preset:
            raise InputError("--preset applies to the blocks scene only")
        base, keys = HertzParams(), HERTZ_KEYS
    else:
        raise InputError(f"unknown scene '{args.scene}' (choose blocks or hertz)")
    given = {k: getattr(args, k) for k in keys if getattr(args, k) is not None}
    if args.mesh is not None:
        if args.scene != "hertz":
            raise InputError("option --mesh applies to the hertz scene only")
        given["mesh"] = args.mesh
    unused = [k for k in set(BLOCK_KEYS) | set(HERTZ_KEYS)
              if k not in keys and getattr(args, k) is not None]
    if unused:
        raise InputError(f"option --{unused[0]} does not apply to the {args.scene} scene")
    assert {f.name for f in fields(BlockParams)} >= set(BLOCK_KEYS)
    return replace(base, **given)


def run(args: argparse.Namespace) -> int:
    """Run one solve and write its outputs; return the exit code."""
    from mpi4py import MPI

    from .api import run_case
    from .errors import InputError
    from .output import plot_interface, write_fields, write_json
    from .saddle import SOLVERS

    comm = MPI.COMM_WORLD
    params = scene_params(args)
    method = Method(args.method)
    if args.solver not in SOLVERS:
        raise InputError(f"unknown solver '{args.solver}' (choose {', '.join(SOLVERS)})")
    options = dict(SOLVERS[args.solver])
    for item in args.petsc_option:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise InputError(f"--petsc-option expects KEY=VALUE, got '{item}'")
        options[key.lstrip("-")] = value
    if args.penalty is not None and method != Method.PENALTY:
        raise InputError("--penalty applies to --method penalty only")
    sol, data = run_case(args.scene, params, method, args.active, options,
                         args.max_iterations, comm, penalty=args.penalty,
                         reference_timing=args.reference_timing, predictor=args.predictor)
    data["solver"] = args.solver
    if args.out is not None:
        write_fields(sol, args.out)
    if comm.rank == 0:
        write_json(args.json, data)
        log = logging.getLogger("contactfx")
        log.info("contact force %.10g, %d multipliers, %d dofs, total %.2f s",
                 data["contact_force"], data["multipliers"], data["dofs"], data["times"]["total"])
        log.info("wrote %s", args.json)
        if args.out is not None:
            fig = plot_interface(data, args.out / "interface.png")
            log.info("wrote fields (XDMF) and %s to %s", fig.name, args.out)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point: parse, run, and turn contactfx errors into one line on stderr."""
    args = parser().parse_args(argv)
    from mpi4py import MPI

    rank = MPI.COMM_WORLD.rank
    logging.basicConfig(level=logging.WARNING if args.quiet or rank else logging.INFO,
                        format="%(message)s", stream=sys.stdout)
    try:
        return run(args)
    except ContactFxError as err:
        if rank == 0:
            print(f"contactfx: error: {err}", file=sys.stderr)
        return 2
