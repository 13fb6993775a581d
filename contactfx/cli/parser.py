"""The argument parser of `contactfx solve|study` (option groups shared by both commands)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..options import SOLVERS, Basis, Enforcement, Method, Predictor
from ..scenes import BLOCK_SCENES, MESHERS, Model
from .params import BLOCK_KEYS, HERTZ_KEYS, PARAM_HELP

# adapt/goal.py's Goal values (named here so that the parser imports no solver).
GOALS = ("pressure", "energy", "force")


def _builtin_scene_options(p: argparse.ArgumentParser) -> None:
    """The options of the built-in scenes (blocks, hertz), shared by solve and study."""
    g = p.add_argument_group("built-in scenes (blocks, hertz)")
    g.add_argument(
        "--preset",
        choices=list(BLOCK_SCENES),
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
        choices=list(MESHERS),
        default=None,
        help="hertz only: gmsh graded quads (default) or a structured graded mesh "
        "built in DOLFINx (fast to make for millions of DOFs)",
    )
    g.add_argument(
        "--model",
        choices=[m.value for m in Model],
        default=None,
        help="the 2D model: plane_strain (default), plane_stress or axisymmetric (x = r, "
        "y the axis: blocks are stacked cylinders, hertz a sphere on a block, P the total force)",
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
    st.add_argument(
        "--adaptive",
        action="store_true",
        help="also run the adaptive loop (contactfx adapt) of each method from level 0 up "
        "to its finest level's DOFs: the adaptive levels on the time chart, in study.json "
        "(`adaptive`) and on accuracy_vs_dofs.png (also under mpirun; not schwarz)",
    )
    st.add_argument(
        "--pressure-tol",
        type=float,
        default=None,
        metavar="P",
        help="with --adaptive --goal residual: also size the contact cells for a relative "
        "L2 pressure indicator of P (as adapt's --pressure-tol)",
    )
    s.add_argument(
        "--goal",
        default=None,
        choices=[*GOALS, "residual"],
        help="with --adaptive (refused without it): the goal loop's quantity (as adapt's "
        "--goal, default pressure; the loop runs to the finest uniform level's DOFs)",
    )
    _solver_options(s)
    o = s.add_argument_group("output")
    o.add_argument(
        "--out",
        type=Path,
        required=True,
        help="directory for study.json, study.csv and the charts",
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
        default="auto",
        help=f"one of {', '.join(SOLVERS)}: mumps factorizes the saddle point, condensed "
        "eliminates the multipliers (CG + GAMG; needs --method nts or mortar --basis dual); "
        "auto (default): mumps unless MUMPS' own memory estimate does not fit, then condensed",
    )
    v.add_argument(
        "--petsc-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="extra PETSc option for the solver's KSP (no leading dash); it cannot change "
        "the solver's kind (choose that with --solver)",
    )
    v.add_argument(
        "--available-memory",
        type=float,
        default=None,
        metavar="MB",
        help="memory per node (MB) that --solver auto compares MUMPS' estimate with "
        "(default: MemAvailable of /proc/meminfo)",
    )
    return v


def _enforcement_option(group: Any) -> None:
    """--enforcement: how the constraint of the --method discretization is enforced."""
    group.add_argument(
        "--enforcement",
        choices=[e.value for e in Enforcement],
        default=None,
        help="how the contact constraint is enforced on the --method discretization "
        "(default: multipliers, or the one --method penalty/schwarz names)",
    )


def _solve_parser(sub: Any) -> None:
    s = sub.add_parser(
        "solve",
        help="solve a scene, print a summary, optionally write JSON",
        description="Solve one contact scene. SCENE is blocks (the paper's S1-S4), "
        "hertz (S5) or a scene file SCENE.toml (see docs/scenes.md).",
    )
    s.add_argument("scene", help="blocks, hertz or a path to a scene .toml file")
    _builtin_scene_options(s)
    m = s.add_argument_group("method")
    m.add_argument(
        "--method",
        default=Method.MORTAR.value,
        choices=[m.value for m in Method],
        help="contact discretization (default mortar: the only one that passes the "
        "patch test on non-matching meshes); penalty and schwarz stand for mortar with that "
        "enforcement",
    )
    _enforcement_option(m)
    m.add_argument(
        "--penalty",
        type=float,
        default=None,
        metavar="EPS",
        help="penalty normal stiffness (pressure = EPS * penetration) for --method "
        "penalty (with friction also the tangential stiffness); default 1e3 * max E / h, "
        "h the median contact element size",
    )
    m.add_argument(
        "--basis",
        choices=[b.value for b in Basis],
        default=Basis.STANDARD.value,
        help="mortar multiplier basis: standard (N_j) or dual (biorthogonal, D "
        "diagonal: what --solver condensed needs)",
    )
    m.add_argument("--max-iterations", type=int, default=50, help="active-set iteration limit")
    m.add_argument(
        "--predictor",
        choices=[v.value for v in Predictor],
        default=Predictor.AUTO.value,
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
    o.add_argument(
        "--estimate",
        action="store_true",
        help="estimate the error (residual estimator and the --goal's two-level estimate, "
        "docs/adapt.md): `estimate` in the JSON, the indicators eta in the fields of --out",
    )
    o.add_argument(
        "--goal",
        default=None,
        choices=GOALS,
        help="with --estimate (refused without it): the quantity whose relative error is "
        "estimated by a second solve on a refined mesh (default pressure; energy, force)",
    )
    o.add_argument("--json", type=Path, help="write the JSON summary here")
    o.add_argument(
        "--out",
        type=Path,
        help="directory for the fields (fields.pvtu: u, sigma, E; pyvista and ParaView), "
        "the contact surfaces (VTK) and one interface figure per contact pair",
    )
    o.add_argument("-q", "--quiet", action="store_true", help="log warnings only")


def _adapt_parser(sub: Any) -> None:
    s = sub.add_parser(
        "adapt",
        help="adaptive meshing: solve, estimate, remesh with gmsh until --tol is met",
        description="Adapt the mesh of one scene until the relative error of --goal is "
        "estimated to be at most --tol (docs/adapt.md). Each level solves, estimates the error "
        "(the goal's two-level estimate and the residual indicators), sizes the next mesh and "
        "remeshes the geometry with gmsh. Stops at --tol, --max-levels, or when the next "
        "mesh would exceed --max-dofs. Writes adapt.json, mesh.msh, fields.pvtu (with the "
        "indicators eta) and the charts adapt_dofs.png, adapt_time.png to --out. Example: "
        "`contactfx adapt hertz --refine 1 --h-far 10 --refine-edge 0 --max-dofs 60000 "
        "--out results/adapt` adapts an ungraded start (1,052 DOFs) over four levels to a "
        "pressure estimate of 0.69 % at 7,332 DOFs (`adapt hertz` alone starts from the "
        "graded default mesh, already within --tol 0.01 at level 0).",
    )
    s.add_argument("scene", help="blocks, hertz or a scene .toml file whose mesh is a .geo")
    _builtin_scene_options(s)
    m = s.add_argument_group("method")
    m.add_argument(
        "--method",
        default=Method.MORTAR.value,
        choices=[v.value for v in Method if v is not Method.SCHWARZ],
        help="contact discretization (default mortar; penalty: mortar with penalty)",
    )
    m.add_argument(
        "--basis",
        choices=[b.value for b in Basis],
        default=Basis.STANDARD.value,
        help="mortar multiplier basis: standard (N_j) or dual (biorthogonal)",
    )
    m.add_argument("--max-iterations", type=int, default=50, help="active-set iteration limit")
    _solver_options(s)
    a = s.add_argument_group("adaptivity")
    a.add_argument(
        "--goal",
        default=None,
        choices=[*GOALS, "residual"],
        help="the quantity --tol bounds: pressure (relative L2 error of the contact "
        "pressure), energy (energy-norm error), force (each pair's contact force); each "
        "level's estimate is a second solve on a refined mesh (docs/adapt.md). residual: the "
        "residual estimate (uncalibrated, no second solve). Default: pressure, or energy "
        "where the scene's pressure is singular (its peak grows like a singular edge's over "
        "two refinements: a flat punch, a press fit's hub edges); the log and adapt.json "
        "say which",
    )
    a.add_argument(
        "--tol",
        type=float,
        default=None,
        help="relative error of the goal to reach (default 0.01; 0.05 for --goal residual)",
    )
    a.add_argument(
        "--max-dofs",
        type=int,
        default=200_000,
        help="DOF budget of a mesh; a starting mesh above it is refused (default 200000)",
    )
    a.add_argument("--max-levels", type=int, default=8, help="most levels (default 8)")
    a.add_argument(
        "--growth",
        type=float,
        default=None,
        help="expert: most cells of a level relative to the previous one, > 1 (default: planned "
        "from the goal estimate's observed rate and the budget left; 4 for --goal residual)",
    )
    a.add_argument(
        "--weight-contact",
        type=float,
        default=None,
        metavar="W",
        help="expert: size the next mesh with each cell's contact terms times W (the "
        "estimate itself is unweighted; default 1; for --goal residual 10, or 1 with "
        "--pressure-tol, whose sizing does that better)",
    )
    a.add_argument(
        "--pressure-tol",
        type=float,
        default=None,
        metavar="P",
        help="expert, --goal residual only: also size the cells along the contact surfaces "
        "for a relative L2 pressure indicator of P, and stop only when it is met too "
        "(docs/adapt.md; the pressure goal aims it at half the error it plans for)",
    )
    a.add_argument(
        "--compare-uniform",
        action="store_true",
        help="also refine the starting mesh uniformly (sizes / 2 per level) up to the "
        "same DOFs, for the charts",
    )
    o = s.add_argument_group("output")
    o.add_argument("--out", type=Path, required=True, help="directory for the outputs")
    o.add_argument("-q", "--quiet", action="store_true", help="log warnings only")
    o.add_argument("-v", "--verbose", action="store_true", help="log the solver's iterations")


def parser() -> argparse.ArgumentParser:
    """The argument parser (defaults of scene parameters are the paper's, filled in later)."""
    ap = argparse.ArgumentParser(
        prog="contactfx", description="2D frictionless contact of elastic bodies"
    )
    sub = ap.add_subparsers(dest="command", required=True)
    _solve_parser(sub)
    _study_parser(sub)
    _adapt_parser(sub)
    return ap
