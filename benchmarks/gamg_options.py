"""GAMG's options for the condensed solver on stretched cells: CG iterations per option set.

One process per mesh (`--mesh structured|gmsh`, Hertz, `--refine H --h-far 10H`, gmsh also
`--refine-edge H/4`: benchmarks/run.py's 10H family), dual mortar, the Hertz zone x < a
active (a fixed set: no active-set loop). For every option set (`SETS`: each adds PETSc
options to the `condensed` preset) one fresh condensed solve from zero to the preset's final
tolerance (the throwaway solver of `--reference-timing`): CG iterations, setup and solve
seconds (ratios within one process only). `--bonded` also solves the same K with the active
pivots fixed (the contact rows' coupling terms E^T K + K E + E^T K E left out: a Dirichlet
version of the same mesh), to see what the contact block costs the cycle.

    python benchmarks/gamg_options.py --mesh structured --dofs 100e3,400e3 --json out.json
    python benchmarks/gamg_options.py --mesh gmsh --dofs 2e6 --sets base,chosen --mumps

`--mumps`: also the `mumps` saddle-point solve of the same set (analysis + factorization +
solve), timed in the same process. Appends one record per (size, set) to the JSON file.
"""

from __future__ import annotations

import argparse
import gc
import json
import time
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace
from typing import Any, cast

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

# benchmarks/run.py, next to this script: on sys.path as its folder.
from run import EDGE_RATIO, refine_for
from scaling_model import parse_log_view

from contactfx.contact import Kernel
from contactfx.discretize.setup import prepare_contact
from contactfx.discretize.supports import rigid_body_modes
from contactfx.linalg import condensed
from contactfx.linalg.elimination import LocalRows, condensed_matrix
from contactfx.linalg.nullspace import orthonormalize
from contactfx.linalg.petsc_options import PrefixedOptions, global_options
from contactfx.linalg.pivots import pivots
from contactfx.methods.multipliers import _timed_fresh_solve
from contactfx.options import SOLVERS, Basis, Multigrid, SolverSpec
from contactfx.scenes import HertzParams, hertz
from contactfx.timers import Timers

# The `condensed` preset before this study: GAMG's own Chebyshev/Jacobi smoother.
BASE: dict[str, object] = {
    "ksp_type": "cg",
    "ksp_norm_type": "unpreconditioned",
    "ksp_max_it": 5000,
    "pc_type": "gamg",
    "pc_gamg_threshold": 0.01,
    "pc_gamg_aggressive_coarsening": 1,
}
ICC = {"mg_levels_pc_type": "bjacobi", "mg_levels_sub_pc_type": "icc"}
# Each set adds these PETSc options to BASE; "chosen" is the `condensed` preset as it is.
SETS: dict[str, dict[str, object]] = {
    "base": {},
    "chosen": {},
    "gamg": {},
    "thr0": {"pc_gamg_threshold": 0.0},
    "thr0.02": {"pc_gamg_threshold": 0.02},
    "thr0.05": {"pc_gamg_threshold": 0.05},
    "thr0.1": {"pc_gamg_threshold": 0.1},
    "thr0.2": {"pc_gamg_threshold": 0.2},
    "thr0.05s0.5": {"pc_gamg_threshold": 0.05, "pc_gamg_threshold_scale": 0.5},
    "agg0": {"pc_gamg_aggressive_coarsening": 0},
    "agg0-thr0.05": {"pc_gamg_aggressive_coarsening": 0, "pc_gamg_threshold": 0.05},
    "sor": {"mg_levels_pc_type": "sor"},
    "pbjacobi": {"mg_levels_pc_type": "pbjacobi"},
    "icc": ICC,
    "cheby4": {"mg_levels_ksp_max_it": 4},
    "sa_esteig0": {"pc_gamg_use_sa_esteig": False},
    "coarse5k": {"pc_gamg_coarse_eq_limit": 5000},
    "thr0.05-sor": {"pc_gamg_threshold": 0.05, "mg_levels_pc_type": "sor"},
    "thr0.05-icc": {"pc_gamg_threshold": 0.05, **ICC},
    "thr0.1-icc": {"pc_gamg_threshold": 0.1, **ICC},
    "agg0-icc": {"pc_gamg_aggressive_coarsening": 0, **ICC},
    "thr0.05-pbj": {"pc_gamg_threshold": 0.05, "mg_levels_pc_type": "pbjacobi"},
    "icc-it1": {"mg_levels_ksp_max_it": 1, **ICC},
    "icc-coarse5k": {"pc_gamg_coarse_eq_limit": 5000, **ICC},
    "icc-thr0.02": {"pc_gamg_threshold": 0.02, **ICC},
    "icc1": {"mg_levels_sub_pc_factor_levels": 1, **ICC},
    "icc-it3": {"mg_levels_ksp_max_it": 3, **ICC},
    "thr0.05-icc-it3": {"pc_gamg_threshold": 0.05, "mg_levels_ksp_max_it": 3, **ICC},
    "thr0.05-icc1-it3": {
        "pc_gamg_threshold": 0.05,
        "mg_levels_ksp_max_it": 3,
        "mg_levels_sub_pc_factor_levels": 1,
        **ICC,
    },
}
# Issue 33's setup round: the 0.6.0 preset (ICC(0), threshold 0.05, 3 steps) and one change
# each. A key with a leading "-" is a global (unprefixed) PETSc option: GAMG's products read
# only those (linalg/petsc_options.py: global_options).
ICC3: dict[str, object] = {"pc_gamg_threshold": 0.05, "mg_levels_ksp_max_it": 3, **ICC}
ROUND2: dict[str, dict[str, object]] = {
    "icc3": {},
    "icc3-rap": {"-matptap_via": "rap"},
    "icc3-coarse1k": {"pc_gamg_coarse_eq_limit": 1000},
    "icc3-coarse3k": {"pc_gamg_coarse_eq_limit": 3000},
    "icc3-agg0": {"pc_gamg_aggressive_coarsening": 0},
    "icc3-agg2": {"pc_gamg_aggressive_coarsening": 2},
    "icc3-mis2": {"pc_gamg_aggressive_square_graph": False},
    "icc3-mindeg": {"pc_gamg_mis_k_minimum_degree_ordering": True},
    "icc3-ns0": {"pc_gamg_agg_nsmooths": 0},
    "icc3-esteig5": {"mg_levels_esteig_ksp_max_it": 5},
    "icc3-lowmem": {"pc_gamg_low_memory_threshold_filter": True},
    "icc3-w": {"pc_mg_cycle_type": "w"},
    "icc3-w-coarse1k": {"pc_mg_cycle_type": "w", "pc_gamg_coarse_eq_limit": 1000},
    "icc2": {"mg_levels_ksp_max_it": 2},
    "icc3-agg2-mindeg": {
        "pc_gamg_aggressive_coarsening": 2,
        "pc_gamg_mis_k_minimum_degree_ordering": True,
    },
    "icc3-agg2-it4": {"pc_gamg_aggressive_coarsening": 2, "mg_levels_ksp_max_it": 4},
    "icc3-agg2-mindeg-it4": {
        "pc_gamg_aggressive_coarsening": 2,
        "pc_gamg_mis_k_minimum_degree_ordering": True,
        "mg_levels_ksp_max_it": 4,
    },
    "icc3-allatonce": {"-matptap_via": "allatonce"},
    "icc3-scalable": {"-matptap_via": "scalable"},
    "icc3-mindeg-coarse3k": {
        "pc_gamg_mis_k_minimum_degree_ordering": True,
        "pc_gamg_coarse_eq_limit": 3000,
    },
    "icc3-mindeg-esteig5": {
        "pc_gamg_mis_k_minimum_degree_ordering": True,
        "mg_levels_esteig_ksp_max_it": 5,
    },
    "icc3-cheb0.05": {"mg_levels_ksp_chebyshev_esteig": "0,0.05,0,1.1"},
    "icc3-cheb0.2": {"mg_levels_ksp_chebyshev_esteig": "0,0.2,0,1.1"},
    "icc3-thr0.1c": {"pc_gamg_threshold": "0.05,0.1,0.1,0.1,0.1,0.1,0.1,0.1,0.1,0.1"},
    "icc3-thr0.02c": {"pc_gamg_threshold": "0.05,0.02,0.02,0.02,0.02,0.02,0.02,0.02,0.02"},
}
SETS.update({name: {**ICC3, **extra} for name, extra in ROUND2.items()})
# Issue 33's third round: the smoother's Krylov method and steps on the 0.7.0 preset
# (ICC(0), threshold 0.05, two aggressive levels by minimum-degree MIS, 4 Chebyshev steps).
PRESET: dict[str, object] = {
    **ICC3,
    "pc_gamg_aggressive_coarsening": 2,
    "pc_gamg_mis_k_minimum_degree_ordering": True,
    "mg_levels_ksp_max_it": 4,
}
ROUND3: dict[str, dict[str, object]] = {
    "p-rich1": {"mg_levels_ksp_type": "richardson", "mg_levels_ksp_max_it": 1},
    "p-rich2": {"mg_levels_ksp_type": "richardson", "mg_levels_ksp_max_it": 2},
    "p-rich3": {"mg_levels_ksp_type": "richardson", "mg_levels_ksp_max_it": 3},
    "p-w": {"pc_mg_cycle_type": "w"},
    "p-w-it2": {"pc_mg_cycle_type": "w", "mg_levels_ksp_max_it": 2},
    "p-w-it3": {"pc_mg_cycle_type": "w", "mg_levels_ksp_max_it": 3},
    "p-it2": {"mg_levels_ksp_max_it": 2},
    "p-it3": {"mg_levels_ksp_max_it": 3},
    "p-cheb6": {"mg_levels_ksp_max_it": 6},
}
SETS.update({name: {**PRESET, **extra} for name, extra in ROUND3.items()})


def spec_for(name: str) -> SolverSpec:
    """The condensed preset as it is (`chosen`), `condensed-gamg` (`gamg`), or GAMG with the
    former options and SETS[name]."""
    preset = SOLVERS["condensed"]
    if name == "chosen":
        return preset  # on the structured mesh: its geometric multigrid
    if name == "gamg":
        return SOLVERS["condensed-gamg"]
    # GAMG with these options on every mesh (no geometric levels).
    return replace(
        preset, petsc={**BASE, **SETS[name]}, name=f"condensed-{name}", multigrid=Multigrid.GAMG
    )


def split_global(spec: SolverSpec) -> tuple[SolverSpec, dict[str, object]]:
    """The spec without its "-key" options, and those options without the dash."""
    local = {k: v for k, v in spec.petsc.items() if not k.startswith("-")}
    glob = {k[1:]: v for k, v in spec.petsc.items() if k.startswith("-")}
    return replace(spec, petsc=local), glob


def bonded_solve(setup: Any, scene: Any, active: np.ndarray, spec: SolverSpec) -> tuple[int, float]:
    """The same K with the active pivots fixed (no contact coupling), CG + GAMG from zero."""
    K, f = setup.elasticity.K, setup.elasticity.f
    comm = K.getComm()
    r0 = K.getOwnershipRange()[0]
    n = K.getSize()[0]
    pv = pivots(LocalRows.of(setup.B, setup.node_dofs()), active, comm.tompi4py(), r0, n)
    piv = pv.dofs
    ip: Any = piv.astype(PETSc.IntType)
    diag = K.getDiagonal()
    A = condensed_matrix(K, {}, r0, piv, diag)  # no coupling rows: Dirichlet pivots
    modes = rigid_body_modes(setup.elasticity.V, scene)
    for m in modes:
        m.setValues(ip, cast(Any, np.zeros(len(piv))))
        m.assemble()
    orthonormalize(modes)
    A.setNearNullSpace(PETSc.NullSpace().create(vectors=modes, comm=comm))
    b = f.copy()
    b.setValues(ip, cast(Any, np.zeros(len(piv))))
    b.assemble()
    x = b.duplicate()
    x.set(0.0)
    opts = PrefixedOptions(spec.petsc)
    ksp = PETSc.KSP().create(comm)
    ksp.setOptionsPrefix(opts.prefix)
    t0 = time.perf_counter()
    with opts.inserted():
        ksp.setOperators(A)
        ksp.setFromOptions()
        ksp.setTolerances(rtol=spec.rtol)
        ksp.setUp()
        ksp.solve(b, x)
    seconds = time.perf_counter() - t0
    its = ksp.getIterationNumber()
    for obj in (ksp, A, diag, b, x, *modes):
        obj.destroy()
    return its, seconds


def main() -> None:
    """Mesh each size once, then every option set on the same fixed set; append to JSON."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--mesh", default="structured", choices=("structured", "gmsh"))
    ap.add_argument("--dofs", default="100e3,400e3", help="comma list of target DOFs")
    ap.add_argument("--sets", default=",".join(SETS), help="comma list of SETS names")
    ap.add_argument("--bonded", action="store_true", help="also the Dirichlet version")
    ap.add_argument("--mumps", action="store_true", help="also the MUMPS saddle-point solve")
    ap.add_argument("--json", type=Path, default=Path("gamg_options.json"))
    ap.add_argument(
        "--cpu", action="store_true", help="setup and solve as this rank's CPU seconds (serial)"
    )
    ap.add_argument("--extra", default="", help="KEY=VALUE,... added to every set's options")
    ap.add_argument(
        "--log-view", type=Path, help="PETSc's -log_view here, one stage per (size, set)"
    )
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    extra = dict(kv.split("=", 1) for kv in args.extra.split(",") if kv)
    if args.cpu:
        # The solver's own setup/solve clocks read CPU time: on a shared machine the wall
        # clock counts the other jobs' turns (serially the CPU time is this solve's work).
        condensed.time = SimpleNamespace(perf_counter=time.process_time)  # type: ignore[assignment]
    if args.log_view:
        PETSc.Log.begin()
    stages: list[tuple[dict[str, Any], str]] = []
    records: list[dict[str, Any]] = []
    if args.json.exists() and comm.rank == 0:
        records = json.loads(args.json.read_text())
    for target in (float(d) for d in args.dofs.split(",")):
        h = refine_for(target, args.mesh)
        params = HertzParams(
            refine=h,
            h_far=10 * h,
            mesh=args.mesh,
            **({"refine_edge": h / EDGE_RATIO} if args.mesh == "gmsh" else {}),
        )
        scene = hertz(params, comm=comm)
        setup = prepare_contact(scene, Kernel.MORTAR, 1e-8, Timers(), Basis.DUAL)
        layout = setup.layout
        active = layout.x[layout.mine, 0] < scene.params["hertz_exact"]["a"]
        dofs = setup.elasticity.K.getSize()[0]
        common = {"mesh": args.mesh, "h": h, "dofs": dofs, "ranks": comm.size}
        common["active"] = comm.allreduce(int(active.sum()))
        if args.mumps:
            gc.collect()
            res, sec = _timed_fresh_solve(setup, SOLVERS["mumps"], scene, active)
            records.append({**common, "set": "mumps", "its": res.iterations, "seconds": sec})
            say(records[-1], comm)
        for k, name in enumerate(args.sets.split(",")):
            gc.collect()
            spec = spec_for(name)
            if extra:
                spec = replace(spec, petsc={**spec.petsc, **extra})
            rec: dict[str, Any] = {**common, "set": name, "options": dict(spec.petsc)}
            stage = PETSc.Log.Stage(f"{dofs}:{k}:{name}") if args.log_view else None
            if stage is not None:
                stage.push()
                stages.append((rec, stage.getName()))
            try:
                local, glob = split_global(spec)
                cpu = time.process_time()
                with global_options(glob):
                    res, sec = _timed_fresh_solve(setup, local, scene, active)
                cpu = time.process_time() - cpu  # this rank's CPU: less noisy than wall time
                rec.update(its=res.iterations, seconds=sec, setup=res.setup, solve=res.solve)
                rec["cpu"] = cpu
            except Exception as err:  # one set's failure must not hide the others
                rec["error"] = f"{type(err).__name__}: {err}"
            finally:
                if stage is not None:
                    stage.pop()
            if args.bonded:
                its, sec = bonded_solve(setup, scene, active, spec)
                rec.update(bonded_its=its, bonded_seconds=sec)
            records.append(rec)
            say(rec, comm)
            if comm.rank == 0:
                args.json.write_text(json.dumps(records, indent=1))
        setup.destroy()
        del scene
    if args.log_view:
        add_setup_events(args.log_view, stages, comm)
    if comm.rank == 0:
        args.json.write_text(json.dumps(records, indent=1))


# The setup's events in each set's stage (seconds, max over ranks): what the setup spends.
SETUP_EVENTS = (
    "PCSetUp",
    "PCGAMGCreateG",
    "GAMG Coarsen",
    "PCGAMGProl",
    "PCGAMGOptProl",
    "GAMG PtAP",
    "MatCholFctrNum",
    "MatICCFactorSym",
    "MatMatMultSym",
    "MatMatMultNum",
    "MatPtAPSymbolic",
    "MatPtAPNumeric",
    "MatAXPY",
    "KSPSolve",
    "PCApply",
)


def add_setup_events(path: Path, stages: list[tuple[dict[str, Any], str]], comm: MPI.Comm) -> None:
    """Write PETSc's log to `path` and add each stage's setup events to its record."""

    viewer = PETSc.Viewer().createASCII(str(path), comm=comm)
    PETSc.Log.view(viewer)
    viewer.destroy()
    comm.Barrier()
    if comm.rank != 0:
        return
    events = parse_log_view(path.read_text())["events"]
    for rec, name in stages:
        ev = events.get(name, {})
        rec["events"] = {e: ev[e]["time"] for e in SETUP_EVENTS if e in ev}
        print(json.dumps({"set": rec["set"], "dofs": rec["dofs"], **rec["events"]}), flush=True)


def say(rec: dict[str, Any], comm: MPI.Comm) -> None:
    """One line per record (rank 0)."""
    if comm.rank == 0:
        keep = ("mesh", "dofs", "set", "its", "seconds", "cpu", "setup", "solve", "bonded_its")
        keep = (*keep, "error")
        print(json.dumps({k: rec[k] for k in keep if k in rec}), flush=True)


if __name__ == "__main__":
    main()
