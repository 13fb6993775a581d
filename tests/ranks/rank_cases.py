"""The cases that must give the serial answer on 2 ranks, and their 2-rank runner.

Each case solves on MPI.COMM_WORLD and returns (Solution, arrays): the arrays in an order
that does not depend on the partition (u at the sorted nodes, the x-sorted interface, the
layout sorted by position), all ranks holding the same values. tests/ranks/test_ranks.py runs a
case in the pytest process (1 rank) and compares it with this file's output on 2 ranks:

    mpirun -n 2 python -m mpi4py tests/ranks/rank_cases.py OUTDIR case1 case2 ...

runs the named cases in one process pair; rank 0 writes OUTDIR/<case>.npz with the arrays,
`_ranks` and `_owned_cells` (each rank's owned cells: both must own part of the mesh).
"""

from __future__ import annotations

import functools
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from unittest import mock

import dolfinx_solver  # noqa: F401  (before dolfinx and petsc4py)
import numpy as np
from mpi4py import MPI
from rank_checks import Abs, Approx, Check, Exact, Rel, u_checks

from contactfx import cli, load_scene_file, run_scene, solve
from contactfx.api import run_case
from contactfx.cli import solve as cli_solve
from contactfx.methods.solution import Solution
from contactfx.request import SolveRequest
from contactfx.results import RunSummary
from contactfx.results.interface import u_at_points
from contactfx.scenes import BLOCK_SCENES, HertzParams, hertz

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "tests" / "scenes"
DEMO_SCENES = ROOT / "demos" / "scenes"
Arrays = dict[str, np.ndarray]


@dataclass(frozen=True)
class Case:
    """A run on COMM_WORLD and one check per array it returns."""

    run: Callable[[], tuple[Solution, Arrays]]
    checks: Mapping[str, Check]


CASES: dict[str, Case] = {}


def u_split(sol: Solution) -> Arrays:
    """(x, y) and (ux, uy) of every node, sorted by position (collective)."""
    u = u_at_points(sol)
    return {"u_xy": u[:, :2], "u": u[:, 2:]}


def by_position(sol: Solution) -> np.ndarray:
    """The layout rows sorted by position (rows are ordered by owner rank)."""
    x = np.round(sol.layout.x, 9)
    return np.lexsort((x[:, 1], x[:, 0]))


@contextmanager
def cli_solution() -> Iterator[list[Solution]]:
    """Record the Solution that `contactfx solve` computes (its run_scene, unchanged)."""
    seen: list[Solution] = []

    def recording(*args: Any, **kwargs: Any) -> tuple[Solution, RunSummary]:
        sol, record = run_scene(*args, **kwargs)
        seen.append(sol)
        return sol, record

    with mock.patch.object(cli_solve, "run_scene", recording):
        yield seen


def cli_json(argv: list[str]) -> tuple[Solution, dict[str, Any]]:
    """`contactfx solve argv --json F` in this process; its Solution and F (on every rank)."""
    import json

    comm = MPI.COMM_WORLD
    with tempfile.TemporaryDirectory() as tmp:
        path = comm.bcast(str(Path(tmp) / "r.json"))
        with cli_solution() as seen:
            code = cli.main([*argv, "--json", path, "-q"])
        assert code == 0, f"contactfx {' '.join(argv)}: exit {code}"
        data = json.loads(Path(path).read_text()) if comm.rank == 0 else None
        comm.barrier()  # rank 0 has read the file before the directory goes
    return seen[-1], comm.bcast(data)


# --- the built-in block scenes (test_parallel, test_schwarz) ------------------------------


def blocks(scene: str, method: str, active: int, solver: str) -> Callable[[], Any]:
    """The paper's block scene `scene`: u, interface x and pressure."""

    def run() -> tuple[Solution, Arrays]:
        sol, data = run_case(
            "blocks", BLOCK_SCENES[scene], SolveRequest.parse(method, solver=solver), active=active
        )
        data = data.to_json()
        itf = data["interface"]
        return sol, {**u_split(sol), "x": np.asarray(itf["x"]), "p": np.asarray(itf["pressure"])}

    return run


BLOCK_CHECKS = {**u_checks(), "x": Abs(1e-12), "p": Rel(1e-8)}
for _scene, _method, _active, _solver in (
    ("S2", "nts", 2, "mumps"),
    ("S3", "sts", 1, "mumps"),
    ("S4", "mortar", 2, "mumps"),
    ("S2", "mortar", 1, "fieldsplit"),
):
    CASES[f"blocks-{_scene}-{_method}-a{_active}-{_solver}"] = Case(
        blocks(_scene, _method, _active, _solver), BLOCK_CHECKS
    )


def schwarz_s2() -> tuple[Solution, Arrays]:
    """Schwarz on S2 (active body 1): u, pressure and the iteration count."""
    sol, data = run_case("blocks", BLOCK_SCENES["S2"], SolveRequest.parse("schwarz"), active=1)
    data = data.to_json()
    p = np.asarray(data["interface"]["pressure"])
    return sol, {**u_split(sol), "p": p, "its": np.asarray(data["iterations"])}


CASES["schwarz-S2-a1"] = Case(schwarz_s2, {**u_checks(), "p": Rel(1e-8), "its": Exact()})


# --- scene files (test_own_scene, test_obstacle_input, test_floating_bodies) ---------------


def user_scene(path: Path, method: str) -> Callable[[], Any]:
    """A scene file: u, and every pair's arc length, pressure and sigma_nn (active side)."""

    def run() -> tuple[Solution, Arrays]:
        sol, data = run_scene(load_scene_file(path), SolveRequest.parse(method))
        data = data.to_json()
        itf = [c["interface"] for c in data["contacts"]]
        snn = [v for i in itf for v in i["sigma_nn_active"]]
        return sol, {
            **u_split(sol),
            "s": np.concatenate([i["s"] for i in itf]),
            "p": np.concatenate([i["pressure"] for i in itf]),
            "snn": np.array(snn, dtype=float),
        }

    return run


SCENE_CHECKS = {**u_checks(), "s": Abs(1e-12), "p": Rel(1e-8), "snn": Rel(1e-8)}
CASES["scene-three-bodies-mortar"] = Case(
    user_scene(DEMO_SCENES / "cylinder_between_blocks.toml", "mortar"), SCENE_CHECKS
)
CASES["scene-inclined-patch-sts"] = Case(
    user_scene(SCENES / "inclined_patch.toml", "sts"), SCENE_CHECKS
)


def obstacle(path: Path, method: str, basis: str) -> Callable[[], Any]:
    """A rigid-obstacle scene: u, pair 0's x and pressure, its force."""

    def run() -> tuple[Solution, Arrays]:
        sol, data = run_scene(load_scene_file(path), SolveRequest.parse(method, basis=basis))
        data = data.to_json()
        c = data["contacts"][0]
        return sol, {
            **u_split(sol),
            "x": np.asarray(c["interface"]["x"]),
            "p": np.asarray(c["interface"]["pressure"]),
            "f": np.asarray(c["force"]),
        }

    return run


OBSTACLE_CHECKS = {**u_checks(), "x": Abs(1e-12), "p": Rel(1e-8), "f": Rel(1e-8)}
for _name, _path, _method, _basis in (
    ("indenter-mortar", DEMO_SCENES / "rigid_indenter.toml", "mortar", "standard"),
    ("punch-nts", DEMO_SCENES / "rigid_punch.toml", "nts", "standard"),
    ("floor-mortar-dual", SCENES / "rigid_floor.toml", "mortar", "dual"),
):
    CASES[f"obstacle-{_name}"] = Case(obstacle(_path, _method, _basis), OBSTACLE_CHECKS)


def axisymmetric_sphere() -> tuple[Solution, Arrays]:
    """The axisymmetric sphere on a block (2 pi r in every integral): u, pressure, force."""
    sol, data = run_scene(load_scene_file(SCENES / "axi_sphere.toml"), SolveRequest.parse("mortar"))
    data = data.to_json()
    c = data["contacts"][0]
    return sol, {
        **u_split(sol),
        "x": np.asarray(c["interface"]["x"]),
        "p": np.asarray(c["interface"]["pressure"]),
        "f": np.asarray([c["axial_force"], c["radial_force_per_radian"]]),
        "a": np.asarray(data["hertz"]["a"]),
    }


CASES["axisymmetric-sphere-mortar"] = Case(axisymmetric_sphere, {**OBSTACLE_CHECKS, "a": Rel(1e-8)})


def stacked_blocks() -> tuple[Solution, Arrays]:
    """`contactfx solve stacked_blocks.toml`: every pair's force (the floating checks pass)."""
    sol, data = cli_json(["solve", str(SCENES / "stacked_blocks.toml")])
    return sol, {"forces": np.array([c["force"] for c in data["contacts"]], dtype=float)}


# 1e-8 p L with p = 10 on the blocks' width L = 2.
CASES["cli-stacked-blocks"] = Case(stacked_blocks, {"forces": Abs(1e-8 * 10.0 * 2.0)})


def friction_push(*options: str) -> Callable[[], tuple[Solution, Arrays]]:
    """`contactfx solve friction_push.toml [options]`: each step's force, shear and statuses."""

    def run() -> tuple[Solution, Arrays]:
        sol, data = cli_json(["solve", str(SCENES / "friction_push.toml"), *options])
        pairs = [step["contacts"][0] for step in data["steps"]]
        names = ("open", "stick", "slip")
        return sol, {
            "forces": np.array([c["force"] for c in pairs], dtype=float),
            "shear": np.array([c["interface"]["shear"] for c in pairs], dtype=float),
            "status": np.array([[names.index(v) for v in c["interface"]["status"]] for c in pairs]),
        }

    return run


# p = 10 on the block's width 1; the statuses exactly serial's. The penalty baseline too.
FRICTION_CHECKS = {"forces": Abs(1e-9 * 10.0), "shear": Abs(1e-9 * 10.0), "status": Exact()}
CASES["cli-friction-push"] = Case(friction_push(), FRICTION_CHECKS)
CASES["cli-friction-push-penalty"] = Case(friction_push("--method", "penalty"), FRICTION_CHECKS)


def held_sideways() -> tuple[Solution, Arrays]:
    """`contactfx solve friction_held_sideways.toml`: a block held along x by stick alone (the
    free-body program with friction's rows on 2 ranks): its force, shear and statuses."""
    sol, data = cli_json(["solve", str(SCENES / "friction_held_sideways.toml")])
    c = data["contacts"][0]
    names = ("open", "stick", "slip")
    return sol, {
        "forces": np.array(c["force"], dtype=float),
        "shear": np.array(c["interface"]["shear"], dtype=float),
        "status": np.array([names.index(v) for v in c["interface"]["status"]]),
    }


# p = 10 on the block's width 1; the statuses exactly serial's.
CASES["cli-friction-held-sideways"] = Case(
    held_sideways, {"forces": Abs(1e-9 * 10.0), "shear": Abs(1e-9 * 10.0), "status": Exact()}
)
# The condensed dual path: GMRES to rtol 1e-9 (the frictionless condensed case's 1e-6).
CASES["cli-friction-push-condensed"] = Case(
    friction_push("--basis", "dual", "--solver", "condensed"),
    {"forces": Abs(1e-6 * 10.0), "shear": Abs(1e-6 * 10.0), "status": Exact()},
)


def pushout() -> tuple[Solution, Arrays]:
    """`contactfx solve press_fit_pushout.toml` (the pushout reference): each step's axial
    force, normal force and statuses (the interface sorted by arc length)."""
    scene = ROOT / "demos" / "scenes" / "press_fit_pushout.toml"
    sol, data = cli_json(["solve", str(scene)])
    steps = [step["pushout"][0] for step in data["steps"]]
    names = ("open", "stick", "slip")
    return sol, {
        "forces": np.array([[s["axial_force"], s["normal_force"]] for s in steps]),
        "status": np.array(
            [
                [names.index(v) for v in st["contacts"][0]["interface"]["status"]]
                for st in data["steps"]
            ]
        ),
    }


# mu N = 0.2 * 4429 at full slip; the statuses exactly serial's.
CASES["cli-pushout"] = Case(pushout, {"forces": Abs(1e-9 * 1000.0), "status": Exact()})


# --- Hertz (test_hertz, test_scale, test_dual_condensed, test_direct_floor, test_penalty) ----


def hertz_graded() -> tuple[Solution, Arrays]:
    """The graded gmsh Hertz scene, mortar: the pressure profile and the Hertz measures."""
    params = HertzParams(refine=0.08, refine_edge=0.02, slope=0.2)
    sol, d = run_case("hertz", params, SolveRequest.parse("mortar"))
    d = d.to_json()
    h = d["hertz"]
    return sol, {
        "x": np.asarray(d["interface"]["x"]),
        "p": np.asarray(d["interface"]["pressure"]),
        "measures": np.array([h["a"], h["p0"], h["l2_error"]], dtype=float),
        "a_bracket": np.asarray(h["a_bracket"], dtype=float),
    }


CASES["hertz-graded-mortar"] = Case(
    hertz_graded,
    {"x": Abs(1e-12), "p": Abs(1e-8), "measures": Approx(1e-8), "a_bracket": Abs(1e-12)},
)


def structured_hertz(solver: str, refine: float, h_far: float) -> Callable[[], Any]:
    """The structured Hertz mesh, mortar, a persistent solver: layout x and pressure."""

    def run() -> tuple[Solution, Arrays]:
        from contactfx.methods.multipliers import solve_contact
        from contactfx.options import Method

        scene = hertz(HertzParams(refine=refine, h_far=h_far, mesh="structured"))
        sol = solve_contact(scene, SolveRequest.parse(Method.MORTAR, solver=solver))
        return sol, {"x": sol.layout.x, "p": sol.pressure}

    return run


# fieldsplit-gamg on the mesh 4x coarser: 8 active-set steps, each a GAMG setup and ~60
# FGMRES iterations, 2-3 s. At refine 0.05 the loop takes 17 steps (no probes: the set is
# released 1-3 rows a step) and on 2 ranks FGMRES needs ~220 iterations, past its restart
# length 200 (serial: ~94): 80 s on 2 ranks for the same path.
for _solver, _refine, _h_far, _tol in (
    ("mumps", 0.05, 2.0, 1e-8),
    ("fieldsplit-gamg", 0.2, 8.0, 1e-5),
):
    CASES[f"hertz-structured-{_solver}"] = Case(
        structured_hertz(_solver, _refine, _h_far), {"x": Abs(1e-12), "p": Rel(_tol)}
    )


def condensed_nts() -> tuple[Solution, Arrays]:
    """The condensed solver (CG-GAMG), NTS, structured Hertz: active flags and pressures, and
    the size of the coarse predictor's first set (the edges estimated from its pressures)."""
    sol = solve(hertz(HertzParams(refine=0.08, h_far=0.8, mesh="structured")), "nts",
                solver="condensed")  # fmt: skip
    order = np.lexsort(sol.layout.x.T[::-1])
    first = np.array([sol.history[0]["active"]])
    return sol, {"act": sol.active[order], "p": sol.pressure[order], "first": first}


# CG to rtol 1e-9 on the residual: 1e-6 on the pressures.
CASES["hertz-condensed-nts"] = Case(
    condensed_nts, {"act": Exact(), "p": Rel(1e-6), "first": Exact()}
)


def auto_condensed() -> tuple[Solution, Arrays]:
    """The default solver with the memory forced tiny: condensed, dual mortar, on any ranks."""
    request = SolveRequest.parse("mortar", basis="dual", available_mb=1.0)
    sol = solve(hertz(HertzParams(refine=0.08, h_far=0.8, mesh="structured")), request)
    assert sol.solver_choice is not None and sol.solver_choice.ran == "condensed"
    order = np.lexsort(sol.layout.x.T[::-1])
    return sol, {"act": sol.active[order], "p": sol.pressure[order]}


CASES["hertz-auto-condensed"] = Case(auto_condensed, {"act": Exact(), "p": Rel(1e-6)})


def condensed_gmsh() -> tuple[Solution, Arrays]:
    """The condensed solver on a gmsh mesh, dual mortar: every rank remeshes the scene x8
    for the multigrid's level (the same serial meshes, split over the ranks)."""
    sol = solve(hertz(HertzParams(refine=0.1, h_far=1.0, refine_edge=0.025)), "mortar",
                basis="dual", solver="condensed")  # fmt: skip
    its = np.array([h["linear_iterations"] for h in sol.history])
    assert its.max() <= 8, its  # GAMG: 10 and more on this mesh (test_dual_condensed.py)
    return sol, {"act": sol.active[by_position(sol)], "p": sol.pressure[by_position(sol)]}


CASES["hertz-condensed-gmsh"] = Case(condensed_gmsh, {"act": Exact(), "p": Rel(1e-6)})


def probe_by_selected_inverse(solver: str) -> Callable[[], Any]:
    """Mortar on Hertz: the rows probed in step 1 (selected inverse) and the pressures."""

    def run() -> tuple[Solution, Arrays]:
        sol = solve(hertz(HertzParams(refine=0.05)), "mortar", solver=solver)
        probes = np.asarray(sol.history[0]["probes"])
        return sol, {"probes": probes, "p": sol.pressure[by_position(sol)]}

    return run


for _solver in ("mumps", "mumps-lu"):
    CASES[f"hertz-probe-{_solver}"] = Case(
        probe_by_selected_inverse(_solver), {"probes": Exact(positive=True), "p": Rel(1e-8)}
    )


def penalty_cli() -> tuple[Solution, Arrays]:
    """`contactfx solve hertz --method penalty`: iterations, pressure, penetration."""
    argv = ["solve", "hertz", "--refine", "0.1", "--method", "penalty", "--penalty", "1e6"]
    sol, data = cli_json(argv)
    p = np.asarray(data["interface"]["pressure"])
    assert p.min() >= 0.0  # so that max |p| (Rel's scale) is max p
    return sol, {
        "its": np.asarray(data["iterations"]),
        "p": p,
        "penetration": np.asarray(data["penetration"]),
    }


CASES["cli-hertz-penalty"] = Case(
    penalty_cli, {"its": Exact(), "p": Rel(1e-8), "penetration": Approx(1e-8)}
)


# --- the error estimate and the adaptive loop (test_estimate, test_adapt) -----------------


def estimate_arrays(sol: Solution) -> Arrays:
    """The estimate: relative total and squared terms, the cell indicators by midpoint."""
    from contactfx.adapt.estimate import BULK_TERMS, CONTACT_TERMS, estimate

    est = estimate(sol)
    comm = sol.scene.comm
    msh = sol.scene.mesh
    nloc = msh.topology.index_map(msh.topology.dim).size_local
    mid = msh.geometry.x[msh.geometry.dofmaps[0][:nloc], :2].mean(axis=1)
    eta = est.eta.x.array[est.eta.function_space.dofmap.list[:nloc, 0]]
    mid, eta = np.concatenate(comm.allgather(mid)), np.concatenate(comm.allgather(eta))
    order = np.lexsort(np.round(mid, 9).T[::-1])
    terms = [est.terms[k] for k in (*BULK_TERMS, *CONTACT_TERMS)]
    return {
        "total": np.array([est.relative]),
        "energy": np.array([est.energy]),
        # Squared (the terms add up as squares): complementarity and gap are the square
        # roots of round-off on a converged active set, their squares are round-off.
        "terms2": (np.array(terms) / est.energy) ** 2,
        "mid": mid[order],
        "eta": eta[order],
    }


def estimate_hertz() -> tuple[Solution, Arrays]:
    """`contactfx solve hertz --estimate` (gmsh, coarse): its JSON estimate, and the cells'."""
    sol, data = cli_json(["solve", "hertz", "--refine", "0.1", "--estimate"])
    e = data["estimate"]
    cli_terms = np.array([e["total"], e["contact"], e["bulk"], *e["terms"].values()])
    return sol, {**estimate_arrays(sol), "cli": cli_terms}


def estimate_blocks() -> tuple[Solution, Arrays]:
    """Blocks S2 (non-matching meshes), mortar: the estimate and the cell indicators."""
    sol, _ = run_case("blocks", BLOCK_SCENES["S2"], SolveRequest.parse("mortar"), active=2)
    return sol, estimate_arrays(sol)


# Round-off terms (complementarity, gap: squares ~1e-16 of the energy) by abs.
ESTIMATE_CHECKS: dict[str, Check] = {
    "total": Approx(1e-10),
    "energy": Approx(1e-10),
    "terms2": Approx(1e-10, abs=1e-13),
    "mid": Abs(1e-12),
    "eta": Rel(1e-10),
}
CASES["estimate-hertz-cli"] = Case(
    estimate_hertz, {**ESTIMATE_CHECKS, "cli": Approx(1e-10, abs=1e-7)}
)
CASES["estimate-blocks-S2-mortar"] = Case(estimate_blocks, ESTIMATE_CHECKS)


def adapt_hertz(extra: tuple[str, ...] = ()) -> tuple[Solution, Arrays]:
    """`contactfx adapt hertz`, 2 levels: per level DOFs, estimates, Hertz error; mesh.msh."""
    import json

    from contactfx.cli import adapt as cli_adapt

    comm = MPI.COMM_WORLD
    seen = []
    loop = cli_adapt.adapt

    def recording(*args: Any, **kwargs: Any) -> Any:
        seen.append(loop(*args, **kwargs))
        return seen[-1]

    argv = ["adapt", "hertz", "--refine", "2", "--h-far", "2", "--refine-edge", "0"]
    argv += ["--slope", "0.3", "--max-dofs", "12000", "--max-levels", "2", "-q", *extra]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(comm.bcast(tmp))
        with mock.patch.object(cli_adapt, "adapt", recording):
            code = cli.main([*argv, "--out", str(out)])
        assert code == 0, f"contactfx {' '.join(argv)}: exit {code}"
        data, counts = None, None
        if comm.rank == 0:
            data = json.loads((out / "adapt.json").read_text())
            lines = (out / "mesh.msh").read_text().split("\n")
            nodes = lines[lines.index("$Nodes") + 1 : lines.index("$EndNodes")]
            elements = lines[lines.index("$Elements") + 2 : lines.index("$EndElements")]
            xy = np.array([[float(v) for v in ln.split()[1:3]] for ln in nodes[1:]])
            kinds = np.array([[int(v) for v in ln.split()[1:4:2]] for ln in elements])
            tags = np.unique(kinds, axis=0, return_counts=True)
            counts = (len(xy), xy.sum(axis=0), tags[0], tags[1])
        comm.barrier()  # rank 0 has read the files before the directory goes
    data, counts = comm.bcast((data, counts))
    levels = data["levels"]
    parts = [lv["estimate_parts"] for lv in levels]
    return seen[-1].levels[-1].solution, {
        "dofs": np.array([lv["dofs"] for lv in levels]),
        "estimate": np.array([lv["estimate"] for lv in levels]),
        "goal_dofs": np.array([lv.get("goal_refined_dofs", 1) for lv in levels]),
        "parts": np.array([[p["contact"], p["bulk"]] for p in parts]),
        "pressure": np.array([p["pressure"] for p in parts]),
        "l2": np.array([lv["hertz"]["l2_error"] for lv in levels]),
        "force": np.array([lv["contact_force"] for lv in levels]),
        "msh_nodes": np.array([counts[0]]),
        "msh_xy_sum": counts[1],
        "msh_kinds": counts[2],
        "msh_kind_counts": counts[3],
    }


# Level 1's mesh comes from the gathered size field, rounded to adapt/sizing.py's
# SIZE_DIGITS so that round-off between rank counts does not reach gmsh's discrete decisions:
# the same mesh, its nodes at round-off of serial's.
ADAPT_CHECKS = {
    "dofs": Exact(positive=True),
    "estimate": Approx(1e-9),
    "parts": Approx(1e-9),
    "pressure": Approx(1e-9),
    "l2": Approx(1e-8),
    "force": Approx(1e-9),
    "msh_nodes": Exact(positive=True),
    "msh_xy_sum": Approx(1e-9),
    "msh_kinds": Exact(),
    "msh_kind_counts": Exact(positive=True),
    "goal_dofs": Exact(positive=True),  # the refined solves' (1 on the residual loop)
}
# The residual estimate's loop (--goal residual: the expert flags' loop).
CASES["cli-adapt-hertz"] = Case(
    functools.partial(adapt_hertz, ("--goal", "residual")), ADAPT_CHECKS
)
# The default goal loop (pressure goal: the two-level estimate's refined solve on each
# level, the pressure sizing mapping the gathered surfaces onto each rank's own cells, the
# growth planned from the estimates): `estimate` is the goal's.
CASES["cli-adapt-hertz-pressure"] = Case(
    functools.partial(adapt_hertz, ("--max-levels", "3", "--tol", "0.002")),
    ADAPT_CHECKS,
)


# --- the runner -----------------------------------------------------------------------------


def owned_cells(sol: Solution) -> np.ndarray:
    """Each rank's owned cell count (collective)."""
    mine = sol.scene.mesh.topology.index_map(sol.scene.mesh.topology.dim).size_local
    return np.array(sol.scene.comm.allgather(mine))


def run(name: str) -> tuple[Arrays, np.ndarray]:
    """Case `name` on COMM_WORLD: its arrays and each rank's owned cells."""
    sol, arrays = CASES[name].run()
    return arrays, owned_cells(sol)


def main(outdir: str, names: list[str]) -> None:
    """Run `names` on COMM_WORLD; rank 0 writes outdir/<name>.npz."""
    unknown = sorted(set(names) - set(CASES))
    assert not unknown, f"unknown cases {unknown}"
    comm = MPI.COMM_WORLD
    for name in names:
        t0 = time.perf_counter()
        arrays, owned = run(name)
        if comm.rank == 0:
            extra = {"_ranks": comm.size, "_owned_cells": owned}
            np.savez(Path(outdir) / f"{name}.npz", **arrays, **extra)
            print(f"{name}: {time.perf_counter() - t0:.1f} s", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2:])
