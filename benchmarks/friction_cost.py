"""What friction costs: a frictional solve over the frictionless one, both solver paths.

Two families (PLAN), E = 7000, nu = 0.23, dual mortar, mu = 0.3 against mu = 0:

- `hertz`: the built-in Hertz half model on its structured grid (`--mesh structured
  --refine H --h-far 10H`), pressed with friction in one step; paths `mumps` and
  `condensed` (its geometric multigrid).
- `pushed`: a cylinder (R = 60) on a block, the same grid (contactfx.meshes.hertz_grid_part)
  mirrored about x = 0 into a full model (a push breaks the half model's symmetry); the
  cylinder's top face moved down by PRESS (named `press`) and then sideways by PUSH (named
  `push`; 0 in the first step, which also holds the cylinder sideways), the block's bottom
  clamped. Two load steps: {press = 1}, then {push = 1}. Paths `mumps` and `condensed-gamg`
  (GAMG: the mirrored grid has no geometric levels).

Each run is one process; the time is the wall time of `contactfx.solve` (assembly, search,
predictor, every load step), the mesh apart. The frictionless reference is the same scene
with the same steps and solver (without friction each step is its own solve: for `pushed`,
two solves, the press alone and the final loads). Paths: `mumps` (frictionless: LDL^T of the
saddle point; frictional: LU of the unsymmetric one, analysis and factorization kept) and
the condensed ones (frictionless: CG; frictional: GMRES).

    OPENBLAS_NUM_THREADS=1 python benchmarks/friction_cost.py sweep [hertz[:PATH]] [pushed] [--all3]
    OPENBLAS_NUM_THREADS=1 python benchmarks/friction_cost.py table    # README rows, chart
    OPENBLAS_NUM_THREADS=1 python benchmarks/friction_cost.py one pushed 0.06 mumps 0.3

(`one FAMILY REFINE SOLVER MU` prints one run's JSON line; `sweep` runs each in a child
process and writes friction_cost.json and friction_cost.png; about 26 minutes on the shared
2-core machine.) The direct path stops after the first size whose frictional run took over
60 s or 2.5 GB (the next, about twice the DOFs, would pass 3 minutes or 5 GB); the
condensed-gamg path after the first size over CONDENSED_GAMG_MAX / 2 DOFs (GAMG's setup on
this mesh costs minutes from 500k).
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import dolfinx_solver  # noqa: F401  (before dolfinx and petsc4py)
import numpy as np

HERE = Path(__file__).resolve().parent
R, WIDTH, HEIGHT, P, E, NU = 60.0, 60.0, 60.0, 100.0, 7000.0, 0.23
MU = 0.3
# The press and the push (cm): the cylinder's top face moved down, then sideways.
PRESS, PUSH = 0.1, 0.02
SOLVERS = ("mumps", "condensed-gamg")
DIRECT_STOP_S, DIRECT_STOP_GB = 60.0, 2.5


def mirrored_hertz(refine: float, mu: float) -> Any:
    """The full cylinder-on-block scene on the mirrored structured grid (one rank)."""
    import basix.ufl
    import ufl
    from dolfinx import mesh as dmesh
    from mpi4py import MPI

    from contactfx.meshes import hertz_grid_part
    from contactfx.scenes import Dirichlet, HertzParams, Material
    from contactfx.scenes.builtin import hertz_exact
    from contactfx.scenes.checks import check_scene
    from contactfx.scenes.model import Body, ContactPair, Groups, Scene, Units
    from contactfx.scenes.structured import TAGS

    params = replace(HertzParams(), refine=refine, h_far=10 * refine)
    r_refine = round(1.4 * hertz_exact(params)["a"], 6)
    part = hertz_grid_part(R, WIDTH, HEIGHT, refine, r_refine, 10 * refine, 0.1, 0, 1)
    x, cells, nb = part.x, part.cells, part.n_block
    n = len(x)
    on_axis = np.flatnonzero(np.abs(x[:, 0]) <= 1e-12 * R)
    image = np.arange(n, 2 * n)
    image[on_axis] = on_axis  # the mirror shares the axis' nodes
    keep = np.ones(n, dtype=bool)
    keep[on_axis] = False
    renumber = np.full(2 * n, -1)
    renumber[:n] = np.arange(n)
    renumber[n:][keep] = n + np.arange(keep.sum())
    renumber[n:][~keep] = on_axis
    mirror = renumber[image[cells]][:, [1, 0, 3, 2]]  # the reflection, its orientation kept
    xs = np.vstack([x, x[keep] * [-1.0, 1.0]])
    all_cells = np.vstack([cells[:nb], mirror[:nb], cells[nb:], mirror[nb:]]).astype(np.int64)
    element = ufl.Mesh(basix.ufl.element("Lagrange", "quadrilateral", 1, shape=(2,)))
    msh = dmesh.create_mesh(MPI.COMM_WORLD, all_cells, element, xs)
    tdim = msh.topology.dim
    idx = np.asarray(msh.topology.original_cell_index, dtype=np.int64)
    body = np.where(idx < 2 * nb, 1, 2).astype(np.int32)
    cell_tags = dmesh.meshtags(msh, tdim, np.arange(len(body), dtype=np.int32), body)
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets = dmesh.exterior_facet_indices(msh.topology)
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    fbody = body[f2c.array[f2c.offsets[facets]]]
    xf = msh.geometry.x[dmesh.entities_to_geometry(msh, tdim - 1, facets)][:, :, :2]
    yc, extent = HEIGHT + R, R / 4.0
    mid = np.abs(xf[:, :, 0].mean(axis=1))
    arc = np.abs(np.hypot(xf[:, :, 0], xf[:, :, 1] - yc) - R) <= 1e-10 * R
    values = np.zeros(len(facets), dtype=np.int32)
    rules = [
        (fbody == 1, (xf[:, :, 1] == HEIGHT).all(axis=1) & (mid <= extent), "contact1"),
        (fbody == 2, arc.all(axis=1) & (mid <= extent), "contact2"),
        (fbody == 1, (xf[:, :, 1] == 0.0).all(axis=1), "support"),
        (fbody == 2, (xf[:, :, 1] == yc).all(axis=1), "load"),
    ]
    for in_body, cond, name in rules:
        values[(values == 0) & in_body & cond] = TAGS[name].tag
    sel = values > 0
    order = np.argsort(facets[sel])
    facet_tags = dmesh.meshtags(
        msh, tdim - 1, facets[sel][order].astype(np.int32), values[sel][order]
    )
    groups = {k: v for k, v in TAGS.items() if k != "symmetry"}
    scene = Scene(
        msh,
        cell_tags,
        facet_tags,
        None,
        Groups.of(groups),
        (Body("body1", Material(E, NU)), Body("body2", Material(E, NU))),
        (ContactPair("contact2", "contact1", mu=mu),),
        (
            Dirichlet("support", ux=0.0, uy=0.0),
            Dirichlet("load", uy=-PRESS, name="press"),
            Dirichlet("load", ux=PUSH, name="push"),
        ),
        (),
        (),
        name="pushed-cylinder",
        units=Units("cm", "MPa"),
        steps=({"press": 1.0}, {"push": 1.0}),
    )
    return check_scene(scene)


def half_hertz(refine: float, mu: float) -> Any:
    """The built-in Hertz half model (structured, its geometric levels), pressed only."""
    from contactfx.scenes import HertzParams, hertz

    return hertz(HertzParams(mesh="structured", refine=refine, h_far=10 * refine, mu=mu))


def one(family: str, refine: float, solver: str, mu: float) -> dict[str, Any]:
    """One run: the scene meshed, then solved and timed; what it cost and found."""
    from contactfx import solve

    t0 = time.perf_counter()
    scene = mirrored_hertz(refine, mu) if family == "pushed" else half_hertz(refine, mu)
    t1 = time.perf_counter()
    sol = solve(scene, "mortar", basis="dual", solver=solver)
    t2 = time.perf_counter()
    steps = sol.steps or [sol]
    out: dict[str, Any] = {
        "family": family,
        "refine": refine,
        "solver": solver,
        "mu": mu,
        "dofs": int(sol.u.function_space.dofmap.index_map.size_global * 2),
        "mesh_s": t1 - t0,
        "solve_s": t2 - t1,
        "iterations": [int(s.iterations) for s in steps],
        "peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20,
        "active": [int(s.active.sum()) for s in steps],
    }
    w = sol.layout.weights
    out["P"] = float(w @ sol.pressure)
    if sol.friction is not None:
        fr = sol.friction
        out["Q"] = float(w @ fr.shear)
        out["stick"] = [int(np.sum(s.friction.status == 1)) for s in steps if s.friction]
        out["slip"] = [int(np.sum(s.friction.status == 2)) for s in steps if s.friction]
    return out


def _child(
    family: str, refine: float, solver: str, mu: float, timeout: float
) -> dict[str, Any] | None:
    cmd = [sys.executable, __file__, "one", family, str(refine), solver, str(mu)]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, check=False)
    except subprocess.TimeoutExpired:
        return None
    lines = [ln for ln in done.stdout.splitlines() if ln.startswith("{")]
    if done.returncode != 0 or not lines:
        print(done.stdout[-2000:], done.stderr[-2000:], file=sys.stderr)
        return None
    return dict(json.loads(lines[-1]))


# Each family's sizes (contact element size) and solver paths, the condensed path of the
# pushed family (GAMG, no geometric levels) up to CONDENSED_GAMG_MAX DOFs.
PLAN = {
    "hertz": ((0.12, 0.06, 0.03, 0.02, 0.014, 0.011), ("mumps", "condensed")),
    "pushed": ((0.25, 0.12, 0.06, 0.035, 0.025), ("mumps", "condensed-gamg")),
}
CONDENSED_GAMG_MAX = 500_000
REPEATS_BELOW = 200_000  # sizes below this many DOFs run three times (medians)
# `sweep ... --all3`: every size three times (the environment variable, read by _measure).
ALL_THREE = "FRICTION_COST_ALL3"


def sweep(families: list[str]) -> None:
    """Each family's sizes on each path, mu = 0.3 and 0 in turn; the JSON, chart, table.

    A family given as FAMILY:SOLVER reruns that path only (the other rows are kept).
    """
    path = HERE / "friction_cost.json"
    rows: list[dict[str, Any]] = json.loads(path.read_text()) if path.exists() else []
    chosen = [
        (f.partition(":")[0], solver)
        for f in families
        for solver in PLAN[f.partition(":")[0]][1]
        if f.partition(":")[2] in ("", solver)
    ]
    rows = [r for r in rows if (r["family"], r["solver"]) not in chosen]
    for family, solver in chosen:
        refines = PLAN[family][0]
        for refine in refines:
            row = _measure(family, refine, solver)
            if row is None:
                break
            rows.append(row)
            path.write_text(json.dumps(rows, indent=1) + "\n")
            fr = row["friction"][0]
            if solver == "mumps" and (
                fr["solve_s"] > DIRECT_STOP_S or fr["peak_gb"] > DIRECT_STOP_GB
            ):
                break
            if solver == "condensed-gamg" and fr["dofs"] > CONDENSED_GAMG_MAX / 2:
                break
    chart(rows)


def _measure(family: str, refine: float, solver: str) -> dict[str, Any] | None:
    """mu = 0.3 and mu = 0 alternately (three times below REPEATS_BELOW DOFs)."""
    fr: list[dict[str, Any]] = []
    fl: list[dict[str, Any]] = []
    for k in range(3):
        a = _child(family, refine, solver, MU, 900.0)
        b = _child(family, refine, solver, 0.0, 900.0)
        if a is None or b is None:
            print(f"{family} h {refine} {solver}: failed or timed out", flush=True)
            return None
        fr.append(a)
        fl.append(b)
        if (a["dofs"] >= REPEATS_BELOW and not os.environ.get(ALL_THREE)) or k == 2:
            break
    ratios = [a["solve_s"] / b["solve_s"] for a, b in zip(fr, fl, strict=True)]
    row = {"family": family, "refine": refine, "solver": solver, "dofs": fr[0]["dofs"]}
    row |= {"friction": fr, "frictionless": fl, "ratio": float(np.median(ratios))}
    row["ratios"] = ratios
    a, b = fr[0], fl[0]
    print(
        f"{family:>6} {a['dofs']:>9} {solver:>15}: mu 0.3 "
        f"{np.median([r['solve_s'] for r in fr]):7.2f} s its {a['iterations']}, mu 0 "
        f"{np.median([r['solve_s'] for r in fl]):7.2f} s its {b['iterations']}, ratio "
        f"{row['ratio']:.2f} (of {len(ratios)}), peak {a['peak_gb']:.2f} GB",
        flush=True,
    )
    return row


def chart(rows: list[dict[str, Any]]) -> None:
    """Frictional over frictionless time against the DOFs, one line per family and path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    for (family, (_, solvers)), style in zip(PLAN.items(), ("-", "--"), strict=True):
        for solver, marker in zip(solvers, "os", strict=True):
            mine = [r for r in rows if r["solver"] == solver and r["family"] == family]
            if mine:
                ax.semilogx([r["dofs"] for r in mine], [r["ratio"] for r in mine], style,
                            marker=marker, label=f"{family}, {solver}")  # fmt: skip
    ax.axhline(2.0, color="k", lw=0.8, ls=":", label="target 2x")
    ax.set_xlabel("DOFs")
    ax.set_ylabel("time mu = 0.3 / time mu = 0")
    ax.set_title("Friction's cost (hertz: pressed; pushed: pressed, then pushed)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "friction_cost.png", dpi=90)


def table(rows: list[dict[str, Any]]) -> None:
    """The README's rows: family, path, DOFs, times, iterations per step, ratio."""
    for r in rows:
        a, b = r["friction"][0], r["frictionless"][0]
        ta = np.median([x["solve_s"] for x in r["friction"]])
        tb = np.median([x["solve_s"] for x in r["frictionless"]])
        print(
            f"| {r['family']} | {r['solver']} | {r['dofs']:,} | {ta:.2f} | {tb:.2f} | "
            f"{r['ratio']:.2f} ({len(r['ratios'])}) | {a['iterations']} | {b['iterations']} | "
            f"{a['peak_gb']:.2f} |"
        )


if __name__ == "__main__":
    if sys.argv[1] == "one":
        print(json.dumps(one(sys.argv[2], float(sys.argv[3]), sys.argv[4], float(sys.argv[5]))))
    elif sys.argv[1] == "sweep":
        if "--all3" in sys.argv:
            os.environ[ALL_THREE] = "1"
        sweep([a for a in sys.argv[2:] if a != "--all3"] or list(PLAN))
    else:
        done = json.loads((HERE / "friction_cost.json").read_text())
        chart(done)
        table(done)
