"""MUMPS' memory estimate over a size sweep, against the model `auto` decides with.

`[mpirun -n R] python benchmarks/mumps_model.py [--out FILE] FAMILY:DOFS [FAMILY:DOFS ...]`
(FAMILY: `structured` = `--mesh structured --refine H --h-far 10H`, `gmsh` = gmsh with
`--refine-edge H/4` too, `stretched` = structured with the default grading; DOFS a target
such as 1e6, or for `stretched` the refine value itself) meshes each Hertz size (dual
mortar), runs the loop's direct solver's analysis alone as `--solver auto` does
(`SaddleSolver.mumps_estimate`) and prints one JSON line per size: DOFs, the nonzeros of K
and B, the estimate summed over the ranks (INFO(15)), the analysis seconds, and the model's
estimate and lower bound (`contactfx.methods.mumps_model`) with their ratios to MUMPS'.
`--out FILE` appends the lines to FILE. `python benchmarks/mumps_model.py --fit FILE [FILE
...]` reads such lines, fits the model's constants (KB per DOF = a + b ln(N / 1e6) per rank
count, least squares from MODEL_MIN_DOFS; LOWER = the smallest estimate over the fit at any
size) and writes `benchmarks/mumps_model.json` (the rows with the shipped model's columns,
the fit, and the smallest ratio of the shipped bound); the constants in
contactfx/methods/mumps_model.py are those of this fit, rounded down (docs/scale.md, "How
`auto` decides").
"""

from __future__ import annotations

import json
import sys
import time

from mpi4py import MPI

from contactfx.discretize.setup import prepare_contact
from contactfx.linalg.saddle import SaddleSolver
from contactfx.methods.mumps_model import model_mb
from contactfx.methods.solvers import setup_solver
from contactfx.options import SOLVERS, Basis, Method
from contactfx.scenes import HertzParams, build_scene
from contactfx.timers import Timers

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from run import refine_for


def params_for(family: str, size: float) -> HertzParams:
    """The Hertz parameters of one family at about `size` DOFs (`stretched`: refine = size)."""
    if family == "stretched":
        return HertzParams(mesh="structured", refine=size)
    mesh = "gmsh" if family == "gmsh" else "structured"
    h = refine_for(size, mesh)
    edge = {"refine_edge": h / 4} if mesh == "gmsh" else {}
    return HertzParams(mesh=mesh, refine=h, h_far=10 * h, **edge)  # type: ignore[arg-type]


def measure(family: str, size: float, comm: MPI.Comm) -> dict[str, object]:
    """MUMPS' estimate and the model's for one size (collective)."""
    t0 = time.perf_counter()
    scene = build_scene("hertz", params_for(family, size), comm=comm)
    setup = prepare_contact(scene, Method.MORTAR.kernel, 1e-8, Timers(), Basis.DUAL)
    t_setup = time.perf_counter() - t0
    solver = setup_solver(setup, SOLVERS["mumps"], scene, reuse=True)
    assert isinstance(solver, SaddleSolver)
    estimate = solver.mumps_estimate()
    assert estimate is not None
    K, B = setup.elasticity.K, setup.B
    dofs = K.getSize()[0]
    total = comm.allreduce(estimate.rank_mb)
    model, bound = model_mb(dofs, comm.size), model_mb(dofs, comm.size, lower=True)
    row: dict[str, object] = {
        "family": family,
        "size": size,
        "refine": params_for(family, size).refine,
        "ranks": comm.size,
        "dofs": dofs,
        "multipliers": B.getSize()[0],
        "nnz_K": int(K.getInfo(PETSc_GLOBAL_SUM)["nz_used"]),
        "nnz_B": int(B.getInfo(PETSc_GLOBAL_SUM)["nz_used"]),
        "estimate_sum_info15_mb": total,
        "analysis_s": estimate.seconds,
        "mesh_and_setup_s": comm.allreduce(t_setup, op=MPI.MAX),
        "model_mb": model,
        "model_bound_mb": bound,
        "model_over_estimate": model / total,
        "bound_over_estimate": bound / total,
    }
    solver.destroy()
    setup.destroy()
    return row


# The same estimate measured earlier on the accurate structured family, 2 ranks, with
# benchmarks/mumps_memory.py --analysis-only (the 10.46M row: the default command's own fine
# analysis); benchmarks/log/scale.md, "The coarse check" (2026-12-03).
HISTORY = [(418_590, 570.0), (695_006, 981.0), (878_246, 1302.0), (1_724_328, 2578.0)]
HISTORY += [(2_667_708, 4229.0), (10_455_512, 18180.0)]


def fit(files: list[str]) -> dict[str, object]:
    """The model's constants from the sweep's lines, and the shipped model's ratios.

    Fitted on the accurate families (structured, gmsh: cells at most 10:1, where `auto`
    applies the model); the stretched family's rows are reported beside them.
    """
    import numpy as np

    from contactfx.methods import mumps_model as mm

    rows = [json.loads(ln) for f in files for ln in open(f) if ln.strip()]
    for dofs, mb in HISTORY:
        rows.append(
            {"family": "structured", "ranks": 2, "dofs": dofs, "estimate_sum_info15_mb": mb}
        )
        rows[-1]["source"] = "benchmarks/log/scale.md, 2026-12-03"
    fits: dict[str, object] = {}
    for ranks in sorted({int(r["ranks"]) for r in rows}):
        mine = [r for r in rows if r["ranks"] == ranks and r["family"] != "stretched"]
        big = [r for r in mine if r["dofs"] >= mm.MODEL_MIN_DOFS]
        x = np.log(np.array([r["dofs"] for r in big]) / 1e6)
        y = np.array([r["estimate_sum_info15_mb"] / r["dofs"] * 1e3 for r in big])
        b, a = np.polyfit(x, y, 1)
        ratio = min(
            r["estimate_sum_info15_mb"] / (r["dofs"] * (a + b * np.log(r["dofs"] / 1e6)) / 1e3)
            for r in mine
        )
        fits[str(ranks)] = {"a_kb": a, "b_kb": b, "lower": ratio, "sizes_fitted": len(big)}
    for r in rows:
        model = mm.model_mb(r["dofs"], r["ranks"])
        r["model_mb"], r["model_bound_mb"] = model, model * mm.LOWER
        r["model_over_estimate"] = model / r["estimate_sum_info15_mb"]
        r["bound_over_estimate"] = model * mm.LOWER / r["estimate_sum_info15_mb"]
    worst = max(r["bound_over_estimate"] for r in rows if r["family"] != "stretched")
    shipped = {"fit": mm.FIT, "lower": mm.LOWER, "min_dofs": mm.MODEL_MIN_DOFS}
    return {"fit": fits, "shipped": shipped, "worst_bound_over_estimate": worst, "rows": rows}


if __name__ == "__main__":
    from petsc4py import PETSc

    if sys.argv[1:2] == ["--fit"]:
        result = fit(sys.argv[2:])
        with open(__file__.rsplit("/", 1)[0] + "/mumps_model.json", "w") as f:
            json.dump(result, f, indent=1)
        print(json.dumps({k: v for k, v in result.items() if k != "rows"}, indent=1))
        sys.exit(0)

    PETSc_GLOBAL_SUM = PETSc.Mat.InfoType.GLOBAL_SUM
    args = sys.argv[1:]
    out = None
    if "--out" in args:
        i = args.index("--out")
        out = args[i + 1]
        del args[i : i + 2]
    for arg in args:
        fam, _, size = arg.partition(":")
        row = measure(fam, float(size), MPI.COMM_WORLD)
        if MPI.COMM_WORLD.rank == 0:
            line = json.dumps(row)
            print(line, flush=True)
            if out is not None:
                with open(out, "a") as f:
                    f.write(line + "\n")
