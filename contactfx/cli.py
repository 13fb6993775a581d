"""Command line: contactfx solve|study SCENE [options]; thin layers over contactfx.api.

Over ~300 lines only because argparse declarations (two subcommands, one option per block
as the formatter writes them) are long; the logic is the last hundred lines.
"""

from __future__ import annotations

import argparse
import logging
import sys
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)

from .errors import ContactFxError, InputError
from .methods import Method
from .scenes import BlockParams, HertzParams

BLOCK_KEYS = (
    "l1",
    "l2",
    "h1",
    "h2",
    "E1",
    "E2",
    "nu1",
    "nu2",
    "p",
    "size1",
    "size2",
    "grading1",
    "grading2",
)
HERTZ_KEYS = (
    "R",
    "P",
    "E1",
    "E2",
    "nu1",
    "nu2",
    "refine",
    "r_refine",
    "refine_edge",
    "slope",
    "width",
    "height",
    "h_far",
)

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
    "h_far": "hertz: largest element size, far from the contact (cm; default R / 6)",
}


def _builtin_scene_options(p: argparse.ArgumentParser) -> None:
    """The options of the built-in scenes (blocks, hertz), shared by solve and study."""
    g = p.add_argument_group("built-in scenes (blocks, hertz)")
    g.add_argument(
        "--preset",
        choices=["S1", "S2", "S3", "S4"],
        help="block scene of the paper to start from (other options override it)",
    )
    for key in sorted(set(BLOCK_KEYS) | set(HERTZ_KEYS)):
        g.add_argument(
            f"--{key.replace('_', '-')}",
            dest=key,
            type=float,
            default=None,
            help=PARAM_HELP.get(key, key),
        )
    g.add_argument(
        "--mesh",
        choices=["gmsh", "structured"],
        default=None,
        help="hertz only: gmsh graded quads (default) or a structured graded mesh "
        "built in DOLFINx (fast to make for millions of DOFs)",
    )
    g.add_argument(
        "--active",
        type=int,
        default=None,
        choices=[1, 2],
        help="which body is active (slave, carries the multipliers; default 2)",
    )


def _study_parser(sub: Any) -> None:
    s = sub.add_parser(
        "study",
        help="convergence study: every method on refined meshes, errors, rates, charts",
        description="Run a convergence study of one scene: every method on "
        "LEVELS meshes, each with all mesh sizes 1/RATIO of the previous one, "
        "against the exact solution where the scene has one, else against the "
        "finest level of mortar. Writes study.json, study.csv, "
        "convergence.png and accuracy_vs_time.png to --out (docs/study.md).",
    )
    s.add_argument("scene", help="blocks, hertz or a scene .toml file whose mesh is a .geo")
    _builtin_scene_options(s)
    st = s.add_argument_group("study")
    st.add_argument(
        "--methods",
        default="nts,sts,mortar",
        help="comma-separated methods (default nts,sts,mortar)",
    )
    st.add_argument("--levels", type=int, default=4, help="number of meshes (default 4)")
    st.add_argument(
        "--ratio", type=float, default=2.0, help="mesh-size ratio of consecutive levels (default 2)"
    )
    st.add_argument(
        "--size-factor",
        type=float,
        default=1.0,
        metavar="F",
        help="mesh sizes of the first (coarsest) level relative to the scene's "
        "(default 1: the scene as given; e.g. 8 to start coarser)",
    )
    st.add_argument("--max-iterations", type=int, default=50, help="active-set iteration limit")
    _solver_options(s)
    o = s.add_argument_group("output")
    o.add_argument(
        "--out",
        type=Path,
        required=True,
        help="directory for study.json, study.csv and the two charts",
    )
    o.add_argument("-q", "--quiet", action="store_true", help="log warnings only")
    o.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        help="also log every active-set iteration (default: one line per run)",
    )


def _solver_options(p: argparse.ArgumentParser) -> Any:
    """The linear-solver option group, shared by solve and study."""
    v = p.add_argument_group("linear solver")
    v.add_argument(
        "--solver",
        default="mumps",
        help="mumps | fieldsplit | fieldsplit-gamg | condensed (multipliers "
        "eliminated, CG + GAMG; needs --method nts or mortar --basis dual)",
    )
    v.add_argument(
        "--petsc-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="extra PETSc option for the saddle-point KSP (no leading dash)",
    )
    return v


def _solve_parser(sub: Any) -> None:
    s = sub.add_parser(
        "solve",
        help="solve a scene, print a summary, optionally write JSON",
        description="Solve one contact scene. SCENE is blocks (the paper's S1-S4), "
        "hertz (S5) or a scene file SCENE.toml (see README, 'Your own scene').",
    )
    s.add_argument("scene", help="blocks, hertz or a path to a scene .toml file")
    _builtin_scene_options(s)
    m = s.add_argument_group("method")
    m.add_argument(
        "--method",
        default=Method.MORTAR.value,
        choices=[m.value for m in Method],
        help="contact discretization (default mortar: the only one that passes the "
        "patch test on non-matching meshes)",
    )
    m.add_argument(
        "--penalty",
        type=float,
        default=None,
        metavar="EPS",
        help="penalty normal stiffness (pressure = EPS * penetration) for --method "
        "penalty; default 1e3 * max E / h, h the median contact element size",
    )
    m.add_argument(
        "--basis",
        choices=["standard", "dual"],
        default="standard",
        help="mortar multiplier basis: standard (N_j) or dual (biorthogonal, D "
        "diagonal: what --solver condensed needs)",
    )
    m.add_argument("--max-iterations", type=int, default=50, help="active-set iteration limit")
    m.add_argument(
        "--predictor",
        choices=["auto", "coarse", "none"],
        default="auto",
        help="first active set from a coarser solve of the same scene: auto = above "
        "200k DOFs on several ranks, always for --solver condensed, never for serial MUMPS "
        "(which probes every row from its selected inverse); the answer does not depend "
        "on it",
    )
    v = _solver_options(s)
    v.add_argument(
        "--reference-timing",
        action="store_true",
        help="also time a fresh solve of the final saddle-point system (the cost "
        "floor) and report it as times.reference_solve",
    )
    o = s.add_argument_group("output")
    o.add_argument("--json", type=Path, help="write the JSON summary here")
    o.add_argument(
        "--out",
        type=Path,
        help="directory for XDMF fields, contact surfaces (VTK) "
        "and one interface figure per contact pair",
    )
    o.add_argument("-q", "--quiet", action="store_true", help="log warnings only")


def parser() -> argparse.ArgumentParser:
    """The argument parser (defaults of scene parameters are the paper's, filled in later)."""
    ap = argparse.ArgumentParser(
        prog="contactfx", description="2D frictionless contact of elastic bodies"
    )
    sub = ap.add_subparsers(dest="command", required=True)
    _solve_parser(sub)
    _study_parser(sub)
    return ap


def is_scene_file(scene: str) -> bool:
    """Whether the SCENE argument names a scene file rather than a built-in scene."""
    return scene.endswith(".toml")


def scene_params(args: argparse.Namespace) -> BlockParams | HertzParams:
    """Scene parameters from the paper's defaults, a preset, and the options given."""
    from .scenes import BLOCK_SCENES

    base: BlockParams | HertzParams
    if args.scene == "blocks":
        base, keys = BLOCK_SCENES[args.preset or "S1"], BLOCK_KEYS
    elif args.scene == "hertz":
        if args.preset:
            raise InputError("--preset applies to the blocks scene only")
        base, keys = HertzParams(), HERTZ_KEYS
    else:
        raise InputError(
            f"unknown scene '{args.scene}' (choose blocks, hertz or a .toml scene file)"
        )
    given = {k: getattr(args, k) for k in keys if getattr(args, k) is not None}
    if args.mesh is not None:
        if args.scene != "hertz":
            raise InputError("option --mesh applies to the hertz scene only")
        given["mesh"] = args.mesh
    unused = [
        k
        for k in set(BLOCK_KEYS) | set(HERTZ_KEYS)
        if k not in keys and getattr(args, k) is not None
    ]
    if unused:
        raise InputError(f"option --{unused[0]} does not apply to the {args.scene} scene")
    assert {f.name for f in fields(BlockParams)} >= set(BLOCK_KEYS)
    return replace(base, **given)


def solver_options(args: argparse.Namespace) -> dict[str, object]:
    """The PETSc options of --solver with every --petsc-option applied."""
    from .solvers import SOLVERS

    if args.solver not in SOLVERS:
        raise InputError(f"unknown solver '{args.solver}' (choose {', '.join(SOLVERS)})")
    options = dict(SOLVERS[args.solver])
    for item in args.petsc_option:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise InputError(f"--petsc-option expects KEY=VALUE, got '{item}'")
        options[key.lstrip("-")] = value
    return options


def build_from_args(args: argparse.Namespace) -> Any:
    """The Scene the arguments describe (a built-in scene or a scene file)."""
    from mpi4py import MPI

    from .scenes import build_scene, load_scene_file

    comm = MPI.COMM_WORLD
    if is_scene_file(args.scene):
        given = [k for k in set(BLOCK_KEYS) | set(HERTZ_KEYS) if getattr(args, k) is not None]
        for flag, value in (("preset", args.preset), ("mesh", args.mesh), ("active", args.active)):
            if value is not None:
                given.append(flag)
        if given:
            raise InputError(
                f"option --{given[0].replace('_', '-')} applies to the built-in "
                "scenes only (a scene file sets everything itself)"
            )
        return load_scene_file(Path(args.scene), comm)
    return build_scene(args.scene, scene_params(args), active=args.active or 2, comm=comm)


def terminal_summary(data: dict[str, Any]) -> list[str]:
    """What a user came for, last: each pair's force, and the errors against references."""
    lines = [
        f"{data['scene']} / {data['method']}: {data['dofs']} dofs, "
        f"{data['multipliers']} multipliers, {data['iterations']} iterations, "
        f"total {data['times']['total']:.2f} s"
    ]
    for k, c in enumerate(data["contacts"]):
        f = c["force"]
        lines.append(
            f"pair {k} ({c['active']} on {c['passive']}): force ({f[0]:.6g}, "
            f"{f[1]:.6g}), balance {c['balance']:.1e}, {c['active_nodes']} active nodes"
        )
    if "patch" in data:
        lines.append(
            f"patch test: max stress/pressure error {data['patch']['max']:.2e} "
            "(relative to the exact uniform stress)"
        )
    for h in data.get("hertz_pairs", [data["hertz"]] if "hertz" in data else []):
        a = h["a"]
        a_err = f"{100 * (a / h['a_exact'] - 1):+.2f} %" if a else "n/a"
        lines.append(
            f"Hertz, pair {h['pair']}: a = {a or float('nan'):.4g} (exact "
            f"{h['a_exact']:.4g}, {a_err}), p0 = {h['p0']:.4g} (exact "
            f"{h['p0_exact']:.4g}, {100 * (h['p0'] / h['p0_exact'] - 1):+.2f} %), "
            f"L2 error {100 * h['l2_error']:.2f} %"
        )
    return lines


def run(args: argparse.Namespace) -> int:
    """Run one solve and write its outputs; return the exit code."""
    import time

    from mpi4py import MPI

    from .api import run_scene
    from .output import plot_interface, plot_pair, write_contact_surfaces, write_fields, write_json
    from .timers import Timers

    comm = MPI.COMM_WORLD
    method = Method(args.method)
    options = solver_options(args)
    if args.penalty is not None and method != Method.PENALTY:
        raise InputError("--penalty applies to --method penalty only")
    if method == Method.SCHWARZ and (args.solver != "mumps" or args.petsc_option):
        raise InputError(
            "schwarz factorizes each body with MUMPS: --solver and --petsc-option "
            "do not apply to it"
        )
    t_start = time.perf_counter()
    timers = Timers()
    with timers("mesh"):
        scene = build_from_args(args)
    sol, data = run_scene(
        scene,
        method,
        solver=options,
        t_start=t_start,
        timers=timers,
        max_iterations=args.max_iterations,
        penalty=args.penalty,
        reference_timing=args.reference_timing,
        predictor=args.predictor,
        basis=args.basis,
    )
    data["solver"] = "mumps (each body)" if method == Method.SCHWARZ else args.solver
    if args.out is not None:
        write_fields(sol, args.out)
    log = logging.getLogger("contactfx")
    if comm.rank == 0:
        if args.json is not None:
            write_json(args.json, data)
            log.info("wrote %s", args.json)
        if args.out is not None:
            written = write_contact_surfaces(data, args.out)
            written += [
                plot_pair(data, k, args.out / f"interface_pair{k}.png")
                for k in range(len(data["contacts"]))
            ]
            if "interface" in data:
                written.append(plot_interface(data, args.out / "interface.png"))
            log.info("wrote fields (XDMF), %s to %s", ", ".join(p.name for p in written), args.out)
        for line in terminal_summary(data):
            print(line)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point: parse, run, and turn contactfx errors into one line on stderr."""
    args = parser().parse_args(argv)
    from mpi4py import MPI

    rank = MPI.COMM_WORLD.rank
    logging.basicConfig(
        level=logging.WARNING if args.quiet or rank else logging.INFO,
        format="%(message)s",
        stream=sys.stdout,
    )
    try:
        if args.command == "study":
            from .study.command import run_command

            return run_command(args)
        return run(args)
    except ContactFxError as err:
        if rank == 0:
            print(f"contactfx: error: {err}", file=sys.stderr)
        return 2
