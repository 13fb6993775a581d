"""contactfx against GetFEM: a cylinder pressed on a block with friction, then pushed.

tests/scenes/cylinder_block.toml (friction from the first step: the approach locks in a shear,
Cattaneo-Mindlin does not hold) solved by contactfx, and the same mesh solved by GetFEM's
Alart-Curnier Coulomb law (benchmarks/getfem_cylinder_block.py, its JSON committed beside this
script). Per step and method: the forces, and on the cylinder's arc nodes the pressure and the
shear (the contact traction on the cylinder, normal and tangential to the block's top face),
their relative L2 differences (nodal, over the arc) and largest differences (over p0 and
mu p0), the stick zone of each (its half-width and centre, stick nodes halfway to their slip
neighbours), the iterations and the wall times. Commands (the meshes, the GetFEM runs with
Debian's python3-getfem, the comparison):

    .venv/bin/python benchmarks/cylinder_block_compare.py --write-mesh /tmp/cb1.msh
    .venv/bin/python benchmarks/cylinder_block_compare.py --write-mesh /tmp/cb2.msh --size-factor 2
    /usr/bin/python3 benchmarks/getfem_cylinder_block.py /tmp/cb1.msh \
        --json benchmarks/getfem_cylinder_block.json
    /usr/bin/python3 benchmarks/getfem_cylinder_block.py /tmp/cb1.msh --frame bisector \
        --repeat 3 --json benchmarks/getfem_cylinder_block_bisector.json
    /usr/bin/python3 benchmarks/getfem_cylinder_block.py /tmp/cb2.msh --frame bisector \
        --json benchmarks/getfem_cylinder_block_coarse.json
    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/cylinder_block_compare.py \
        benchmarks/getfem_cylinder_block.json benchmarks/getfem_cylinder_block_bisector.json \
        --repeat 3 --out benchmarks/cylinder_block_compare.json

(all with OPENBLAS_NUM_THREADS=1; the coarse JSON is what tests/methods/test_friction_getfem.py
compares with). Times: the median of --repeat solves of both steps in each code (GetFEM's
Newton solves; contactfx's `solve` after the mesh), one process each, one core, on a machine
other jobs shared.
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from contactfx import solve
from contactfx.contact.geometry import nodal_normals
from contactfx.methods.solution import Solution
from contactfx.scenes.scene_file import load_scene_file

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "tests" / "scenes" / "cylinder_block.toml"
MU = 0.3
# GetFEM's stick nodes: slip increment below this fraction of the largest (getfem_interface).
# Measured on the scene's step 2: 1e-6 reads 3 cells narrower (a/h = 76), 1e-3 one wider.
STICK_SLIP = 1e-4


@dataclass(frozen=True)
class Interface:
    """The contact traction on the cylinder at its arc nodes, in the block's frame."""

    x: np.ndarray  # (n,) arc node coordinates along x, sorted
    y: np.ndarray
    pressure: np.ndarray  # traction along the block's normal (0, 1)
    shear: np.ndarray  # minus the traction along x (positive against a push along +x)
    stick: np.ndarray  # bool, each code's own statuses
    force: np.ndarray  # (2,) the contact force on the cylinder


def write_mesh(path: Path, size_factor: float) -> None:
    """The scene's .geo meshed by this environment's gmsh, as a gmsh 2.2 .msh for GetFEM."""
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Verbosity", 2)
        gmsh.open(str(SCENE.with_suffix(".geo")))
        gmsh.option.setNumber("Mesh.MeshSizeFactor", size_factor)
        gmsh.model.mesh.generate(2)
        gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()


def contactfx_interface(sol: Solution) -> Interface:
    """The pair's multipliers as a traction on the cylinder (rows in the bisector frame)."""
    assert sol.friction is not None
    pv = sol.pairs[0]
    rows, nodes = pv.rows, pv.nodes
    surf = pv.active.surface
    # The rows' frame: the bisector of the block's normal (0, 1) and the arc's nodal normal
    # (exactly nts's; mortar's rows mix their segments' bisectors, within h / 4R of it).
    n = np.array([0.0, 1.0]) - nodal_normals(surf)[nodes]
    n /= np.linalg.norm(n, axis=1)[:, None]
    t = np.stack([n[:, 1], -n[:, 0]], axis=1)
    lam_n, lam_t = sol.pressure[rows], sol.friction.shear[rows]
    trac = lam_n[:, None] * n - lam_t[:, None] * t
    x, y = surf.x[nodes, 0], surf.x[nodes, 1]
    order = np.argsort(x)
    w = sol.layout.weights[rows]
    force = np.array([w @ trac[:, 0], w @ trac[:, 1]])
    return Interface(
        x=x[order],
        y=y[order],
        pressure=trac[order, 1],
        shear=-trac[order, 0],
        stick=(sol.friction.status[rows] == 1)[order],
        force=force,
    )


def getfem_interface(step: dict[str, Any], normal: str) -> Interface:
    """A GetFEM step's traction; its stick nodes: in contact, and their slip increment along
    its frame's tangent below STICK_SLIP of the largest. Its law holds weakly (integrated
    against the multiplier's test functions), so the nodal multipliers of slip nodes next to
    the stick zone may lie inside the cone, and stick nodes keep slips up to about 1e-5 of
    the largest; the first slip node past the stick edge slips about 1e-2 of it."""
    x, y = np.asarray(step["x"]), np.asarray(step["y"])
    trac = np.asarray(step["traction"])
    if normal == "flat":
        n = np.tile([0.0, 1.0], (x.size, 1))
    else:  # the bisector of the block's and the circle's normals (R = 1, centre (0, 1))
        n = np.array([0.0, 1.0]) - np.stack([x, y - 1.0], axis=1)
        n /= np.linalg.norm(n, axis=1)[:, None]
    t = np.stack([n[:, 1], -n[:, 0]], axis=1)
    p_own = np.einsum("ij,ij->i", trac, n)
    slip = np.einsum("ij,ij->i", np.asarray(step["slip_increment"]), t)
    stick = (p_own > 1e-6 * p_own.max()) & (np.abs(slip) < STICK_SLIP * np.abs(slip).max())
    order = np.argsort(x)
    return Interface(
        x=x[order],
        y=y[order],
        pressure=trac[order, 1],
        shear=-trac[order, 0],
        stick=stick[order],
        force=np.asarray(step["force"]),
    )


def stick_zone(x: np.ndarray, stick: np.ndarray) -> tuple[float, float]:
    """(half-width, centre) of the stick nodes' span, edges halfway to the slip neighbours."""
    idx = np.flatnonzero(stick)
    if idx.size == 0:
        return 0.0, 0.0
    lo, hi = idx[0], idx[-1]
    left = 0.5 * (x[lo] + x[lo - 1]) if lo > 0 else x[lo]
    right = 0.5 * (x[hi] + x[hi + 1]) if hi + 1 < x.size else x[hi]
    return 0.5 * (right - left), 0.5 * (right + left)


def compare(ours: Interface, theirs: Interface) -> dict[str, float]:
    """Differences of pressure and shear at the same nodes, and of the stick zones."""
    if ours.x.size != theirs.x.size or np.abs(ours.x - theirs.x).max() > 1e-9:
        raise SystemExit("the two codes' arc nodes differ: not the same mesh")
    p0 = max(ours.pressure.max(), theirs.pressure.max())
    touch = (ours.pressure > 0) | (theirs.pressure > 0)
    cell = float(np.median(np.diff(ours.x[touch])))
    c_ours, m_ours = stick_zone(ours.x, ours.stick)
    c_theirs, m_theirs = stick_zone(theirs.x, theirs.stick)

    def l2(a: np.ndarray, b: np.ndarray) -> float:
        # Nodal, trapezoidal along x over the arc (both are nodal values of the same mesh).
        return float(np.sqrt(np.trapezoid((a - b) ** 2, ours.x) / np.trapezoid(b**2, ours.x)))

    return {
        "P": float(ours.force[1]),
        "Q": float(-ours.force[0]),
        "P_getfem": float(theirs.force[1]),
        "Q_getfem": float(-theirs.force[0]),
        "pressure_l2": l2(ours.pressure, theirs.pressure),
        "pressure_max_over_p0": float(np.abs(ours.pressure - theirs.pressure).max() / p0),
        "shear_l2": l2(ours.shear, theirs.shear),
        "shear_max_over_mu_p0": float(np.abs(ours.shear - theirs.shear).max() / (MU * p0)),
        "contact_nodes": int((ours.pressure > 1e-3 * p0).sum()),
        "contact_nodes_getfem": int((theirs.pressure > 1e-3 * p0).sum()),
        "cell": cell,
        "stick_half_width": c_ours,
        "stick_half_width_getfem": c_theirs,
        "stick_half_width_diff_cells": (c_ours - c_theirs) / cell,
        "stick_centre_diff_cells": (m_ours - m_theirs) / cell,
    }


def run(
    method: str, getfem: list[dict[str, Any]], size_factor: float, repeat: int = 1
) -> list[dict[str, Any]]:
    """contactfx with `method` against each GetFEM JSON, per step (the median of `repeat`
    solves' wall times)."""
    scene = load_scene_file(SCENE, size_factor=size_factor)
    walls = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        sol = solve(scene, method)
        walls.append(time.perf_counter() - t0)
    wall = float(np.median(walls))
    rows = []
    for gf in getfem:
        for k, (ours, theirs) in enumerate(zip(sol.steps, gf["steps"], strict=True)):
            row = {"method": method, "getfem_frame": gf["frame"], "step": k + 1}
            row |= compare(contactfx_interface(ours), getfem_interface(theirs, gf["frame"]))
            row |= {
                "dofs": sol.dofs,
                "dofs_getfem": gf["dofs"],
                "iterations": ours.iterations,
                "iterations_getfem": theirs["iterations"],
                "wall_s": wall,
                "wall_s_getfem": gf.get("wall_s_median", sum(s["wall_s"] for s in gf["steps"])),
            }
            rows.append(row)
    return rows


def main() -> None:
    """Write the mesh, or compare."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("getfem", nargs="*", type=Path, help="GetFEM JSON files")
    ap.add_argument("--write-mesh", type=Path, help="write the scene's mesh for GetFEM and stop")
    ap.add_argument("--size-factor", type=float, default=1.0)
    ap.add_argument("--methods", nargs="+", default=["mortar", "nts"])
    ap.add_argument("--repeat", type=int, default=1, help="solves per method (timings)")
    ap.add_argument("--out", type=Path, help="write the comparison here")
    args = ap.parse_args()
    if args.write_mesh is not None:
        write_mesh(args.write_mesh, args.size_factor)
        return
    getfem = [json.loads(p.read_text()) for p in args.getfem]
    rows = [r for m in args.methods for r in run(m, getfem, args.size_factor, args.repeat)]
    for r in rows:
        print(
            f"{r['method']:6s} vs GetFEM ({r['getfem_frame']}), step {r['step']}: "
            f"P {r['P']:.4f} / {r['P_getfem']:.4f}, Q {r['Q']:.4f} / {r['Q_getfem']:.4f}, "
            f"pressure L2 {100 * r['pressure_l2']:.2f} % (max {100 * r['pressure_max_over_p0']:.2f}"
            f" % of p0), shear L2 {100 * r['shear_l2']:.2f} % (max "
            f"{100 * r['shear_max_over_mu_p0']:.2f} % of mu p0), stick half-width "
            f"{r['stick_half_width']:.4f} / {r['stick_half_width_getfem']:.4f} "
            f"({r['stick_half_width_diff_cells']:+.2f} cells, centre "
            f"{r['stick_centre_diff_cells']:+.2f}), its {r['iterations']} / "
            f"{r['iterations_getfem']}"
        )
    for r in (r for r in rows if r["step"] == 1):
        print(
            f"{r['method']}: {r['dofs']} dofs, {r['wall_s']:.2f} s (both steps) against "
            f"GetFEM's ({r['getfem_frame']}) {r['wall_s_getfem']:.2f} s ({r['dofs_getfem']} "
            f"dofs): ratio {r['wall_s'] / r['wall_s_getfem']:.2f}"
        )
    if args.out is not None:
        args.out.write_text(json.dumps({"scene": SCENE.name, "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
