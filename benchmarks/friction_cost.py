"""What friction costs: a frictional solve over the frictionless one, both solver paths.

A cylinder (R = 60) pressed on a block and then pushed sideways: the built-in Hertz scene's
structured grid (contactfx.meshes.hertz_grid_part) mirrored about x = 0 into a full model
(a push breaks the half model's symmetry), E = 7000, nu = 0.23, dual mortar. The cylinder's
top face carries the line load P = 100 (named `press`) and a prescribed u_x (named `push`,
0 in the first step: it also holds the cylinder sideways); the block's bottom is clamped.
Two load steps: {press = 1}, then {push = 1}. Each run is one process; the time is the
wall time of `contactfx.solve` (assembly, contact search, every load step), the mesh apart.

Compared, per mesh and solver path: mu = 0.3 over mu = 0 on the same scene with the same
two steps (frictionless, each step is its own solve, so the reference is two solves: the
press alone and the final loads, press and push). Paths: `mumps` (frictionless: LDL^T of the
saddle point; frictional: LU of the unsymmetric saddle point, its analysis kept) and
`condensed-gamg` (frictionless: CG; frictional: GMRES; GAMG on the condensed operator: the
mirrored grid has no geometric levels).

    OPENBLAS_NUM_THREADS=1 python benchmarks/friction_cost.py sweep            # the table
    OPENBLAS_NUM_THREADS=1 python benchmarks/friction_cost.py one 0.2 condensed-gamg 0.3

(`one REFINE SOLVER MU` prints one run's JSON line; `sweep [REFINE ...]` runs each in a
child process, writes friction_cost.json and friction_cost.png.) The direct path stops
after the first size whose frictional run took over 60 s or 2.5 GB (the next, about twice
the DOFs, would pass 3 minutes or 5 GB).
"""

from __future__ import annotations

import json
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
# Contact element sizes (h_far = 10 h, slope 0.1): about 20k to 2M DOFs.
REFINES = (0.25, 0.12, 0.06, 0.035, 0.025, 0.015)
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


def sweep(refines: list[float]) -> None:
    """Each size on each path, mu = 0.3 then 0; the JSON, the chart and a table."""
    rows: list[dict[str, Any]] = []
    direct_on = True
    for refine in refines:
        for solver in SOLVERS:
            if solver == "mumps" and not direct_on:
                continue
            runs = {}
            for mu in (MU, 0.0):
                runs[mu] = _child(refine, solver, mu, 600.0)
            fr, fl = runs[MU], runs[0.0]
            if fr is None or fl is None:
                print(f"h {refine} {solver}: failed", flush=True)
                direct_on = direct_on and solver != "mumps"
                continue
            row = {"refine": refine, "solver": solver, "dofs": fr["dofs"], "friction": fr}
            row |= {"frictionless": fl, "ratio": fr["solve_s"] / fl["solve_s"]}
            rows.append(row)
            print(
                f"{fr['dofs']:>9} {solver:>15}: mu 0.3 {fr['solve_s']:7.2f} s "
                f"its {fr['iterations']}, mu 0 {fl['solve_s']:7.2f} s its {fl['iterations']}, "
                f"ratio {row['ratio']:.2f}, Q/muP {fr['Q'] / (MU * fr['P']):.3f}, "
                f"peak {fr['peak_gb']:.2f} GB",
                flush=True,
            )
            too_big = fr["solve_s"] > DIRECT_STOP_S or fr["peak_gb"] > DIRECT_STOP_GB
            if solver == "mumps" and too_big:
                direct_on = False
            (HERE / "friction_cost.json").write_text(json.dumps(rows, indent=1) + "\n")
    chart(rows)


def chart(rows: list[dict[str, Any]]) -> None:
    """Frictional over frictionless time against the DOFs, one line per path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 3.6))
    for solver, marker in zip(SOLVERS, "os", strict=True):
        mine = [r for r in rows if r["solver"] == solver]
        ax.semilogx([r["dofs"] for r in mine], [r["ratio"] for r in mine], marker=marker,
                    label=solver)  # fmt: skip
    ax.axhline(2.0, color="k", lw=0.8, ls="--", label="target 2x")
    ax.set_xlabel("DOFs")
    ax.set_ylabel("time mu = 0.3 / time mu = 0")
    ax.set_title("Pressed and pushed cylinder: friction's cost (2 load steps)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(HERE / "friction_cost.png", dpi=90)


if __name__ == "__main__":
    if sys.argv[1] == "one":
        print(json.dumps(one(sys.argv[2], float(sys.argv[3]), sys.argv[4], float(sys.argv[5]))))
    elif sys.argv[1] == "sweep":
        sweep([float(a) for a in sys.argv[2:]] or list(REFINES))
    else:
        chart(json.loads((HERE / "friction_cost.json").read_text()))
