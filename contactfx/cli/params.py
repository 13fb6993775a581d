"""What the command line's arguments mean: scene parameters, the solver spec, the Scene.

Shared by `solve` and `study` (cli/solve.py, cli/study.py).
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace
from pathlib import Path

from mpi4py import MPI

from ..errors import InputError
from ..methods.solver_choice import mem_available_mb
from ..options import Basis, Predictor, SolverSpec, solver_spec
from ..request import SolveRequest
from ..scenes import (
    BLOCK_SCENES,
    BlockParams,
    HertzParams,
    Model,
    Scene,
    build_scene,
    hertz_exact,
    load_scene_file,
    validate,
)

# The least memory a solve takes per DOF: the condensed solver's peak, the leanest of the
# solvers (docs/results.md, "peak MB per 100k DOFs").
LEAST_BYTES_PER_DOF = 1.1e3

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
    "mu",
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
    "mu",
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
    "mu": "Coulomb friction coefficient on the contact pair (default 0: frictionless)",
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


def check_outputs(args: argparse.Namespace) -> None:
    """InputError before anything runs if --out or --json cannot be written as asked.

    --out names a directory (an existing file of that name would fail only after the solve);
    --json a file. Decided on rank 0 (the rank that writes) for every rank.
    """
    comm = MPI.COMM_WORLD
    problem = None
    if comm.rank == 0:
        out, json = getattr(args, "out", None), getattr(args, "json", None)
        if out is not None and out.exists() and not out.is_dir():
            problem = (
                f"--out {out}: a file of that name exists, and --out names a directory for "
                "the outputs: give another path or remove the file"
            )
        elif json is not None and json.is_dir():
            problem = f"--json {json} is a directory: give the path of the JSON file"
        for option, path in (("--out", out), ("--json", json)):
            blocked = _file_above(path) if path is not None else None
            if problem is None and blocked is not None:
                problem = f"{option} {path}: {blocked} is a file, not a directory to write in"
    problem = comm.bcast(problem, root=0)
    if problem is not None:
        raise InputError(problem)


def _file_above(path: Path) -> Path | None:
    """The nearest existing folder above `path` if it is a file (it cannot hold `path`)."""
    for parent in path.absolute().parents:
        if parent.exists():
            return None if parent.is_dir() else parent
    return None


def reject_structured_adapt(args: argparse.Namespace) -> None:
    """InputError before anything runs: the structured Hertz mesh has no gmsh geometry."""
    if not is_scene_file(args.scene) and getattr(args, "mesh", None) == "structured":
        raise InputError(
            "the structured Hertz mesh cannot be adapted: use --mesh gmsh (gmsh remeshes "
            "the geometry from a size field)"
        )


def is_scene_file(scene: str) -> bool:
    """Whether the SCENE argument names a scene file rather than a built-in scene."""
    return scene.endswith(".toml")


def reject_builtin_options(args: argparse.Namespace) -> None:
    """InputError if a scene file comes with options that only the built-in scenes take."""
    given = [k for k in (*BLOCK_KEYS, *HERTZ_KEYS) if getattr(args, k) is not None]
    given += [
        k for k in ("preset", "mesh", "active", "model") if getattr(args, k, None) is not None
    ]
    if given:
        raise InputError(
            f"option --{given[0].replace('_', '-')} applies to the built-in "
            "scenes only (a scene file sets everything itself)"
        )


def scene_params(args: argparse.Namespace) -> BlockParams | HertzParams:
    """Scene parameters from the paper's defaults, a preset, and the options given."""
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
    for key in ("r_refine", "h_far"):
        if given.get(key) == 0.0:
            given[key] = None  # 0: the default (1.4 a, R / 6), as the option always took it
    if getattr(args, "model", None) is not None:
        given["model"] = Model.parse(args.model, "--model")
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
    params = replace(base, **given)
    if isinstance(params, HertzParams):
        check_hertz_size(params, mem_available_mb())
    return params


def hertz_cells(params: HertzParams) -> float:
    """About how many cells the graded Hertz mesh has (both bodies), before any meshing.

    Sizes grow as refine + slope d with the distance d from the refined stretch of the
    contact line (length r_refine): its strips hold length / (slope refine) cells per body,
    its ends (pi / slope^2) ln(1 + h_far / refine). Within 30 % of gmsh's count from the
    defaults to refine 0.005 (tests/cli/test_messages.py).
    """
    length = params.r_refine or 1.4 * hertz_exact(params)["a"]
    h_far = params.h_far or params.R / 6
    h, s = params.refine, params.slope
    return 2 * (length / (s * h) + math.pi / s**2 * math.log(1 + h_far / h))


def check_hertz_size(params: HertzParams, available_mb: float | None) -> None:
    """InputError before gmsh runs if the Hertz mesh of --refine could not be solved here.

    The memory of its DOFs (2 a cell) at the least any solver takes (LEAST_BYTES_PER_DOF)
    against `available_mb` (MemAvailable; not --available-memory, which steers --solver
    auto's choice); nothing is refused where it is unknown.
    """
    validate(params)
    cells = hertz_cells(params)
    need_mb = 2 * cells * LEAST_BYTES_PER_DOF / 1e6
    # Under mpirun the memory is per node: this node holds its ranks' share of the DOFs.
    world = MPI.COMM_WORLD
    node = world.Split_type(MPI.COMM_TYPE_SHARED)
    share = node.size / world.size
    node.Free()
    available = available_mb
    short = available is not None and need_mb * share > available
    if world.allreduce(short, op=MPI.LOR):  # the fullest node decides, on every rank
        raise InputError(
            f"--refine {params.refine:g} (--slope {params.slope:g}) makes a mesh of about "
            f"{cells:.2g} cells ({2 * cells:.2g} DOFs), whose solve needs at least "
            f"{need_mb / 1e3:.3g} GB of memory, more than the "
            f"{(available or 0.0) / share / 1e3:.3g} GB available: give a larger --refine"
        )


def spec_from_args(args: argparse.Namespace) -> SolverSpec:
    """The spec of --solver with every --petsc-option applied (checked against its kind)."""
    return solver_spec(args.solver).with_petsc(args.petsc_option)


def request_from_args(args: argparse.Namespace) -> SolveRequest:
    """The SolveRequest of --method, --enforcement, --solver and the other method options.

    The options a subcommand does not have take their defaults.
    """
    return SolveRequest.parse(
        args.method,
        enforcement=getattr(args, "enforcement", None),
        solver=spec_from_args(args),
        basis=getattr(args, "basis", Basis.STANDARD),
        predictor=getattr(args, "predictor", Predictor.AUTO),
        max_iterations=args.max_iterations,
        penalty=getattr(args, "penalty", None),
        reference_timing=getattr(args, "reference_timing", False),
        available_mb=getattr(args, "available_memory", None),
    )


def build_from_args(args: argparse.Namespace) -> Scene:
    """The Scene the arguments describe (a built-in scene or a scene file)."""
    comm = MPI.COMM_WORLD
    if is_scene_file(args.scene):
        reject_builtin_options(args)
        return load_scene_file(Path(args.scene), comm)
    return build_scene(args.scene, scene_params(args), active=args.active or 2, comm=comm)
