"""Quantities users read off a solution: interface stresses, contact force, the JSON summary."""

from __future__ import annotations

from typing import Any

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from .elasticity import sigma
from .problem import Solution
from .surfaces import vertex_coordinates

REF_VERTICES = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])


def surface_stress(sol: Solution, body: int, component: tuple[int, int] = (1, 1)
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Nodal sigma_ij of `body` on its contact surface (x, value), averaged over adjacent cells."""
    scene = sol.scene
    msh = scene.mesh
    tdim = msh.topology.dim
    el = sol.elasticity
    expr = fem.Expression(sigma(sol.u, el.E, el.nu)[component], REF_VERTICES)
    facets = scene.facet_tags.find(scene.tags[f"contact{body}"])
    facets = facets[facets < msh.topology.index_map(tdim - 1).size_local]
    f2v = msh.topology.connectivity(tdim - 1, 0).array.reshape(-1, 2)[facets]
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    cells = f2c.array[f2c.offsets[facets]].astype(np.int32)
    values = expr.eval(msh, cells).reshape(len(cells), 4)
    c2v = msh.topology.connectivity(tdim, 0).array.reshape(-1, 4)[cells]
    xv = vertex_coordinates(msh)
    local_x, local_v = [], []
    for k in range(2):
        col = np.argmax(c2v == f2v[:, [k]], axis=1)
        local_x.append(xv[f2v[:, k]])
        local_v.append(values[np.arange(len(cells)), col])
    comm = msh.comm
    xs = np.concatenate(comm.allgather(np.concatenate(local_x)))
    vs = np.concatenate(comm.allgather(np.concatenate(local_v)))
    keys, inv = np.unique(np.round(xs, 10), axis=0, return_inverse=True)
    inv = inv.ravel()
    avg = np.bincount(inv, weights=vs) / np.bincount(inv)
    order = np.argsort(keys[:, 0])
    return keys[order, 0], avg[order]


def interface(sol: Solution) -> dict[str, list[float]]:
    """Pressure and both bodies' sigma_yy sampled at the multiplier nodes, sorted by x."""
    order = np.argsort(sol.layout.x[:, 0])
    x = sol.layout.x[order, 0]
    out: dict[str, list[float]] = {"x": x.tolist(), "pressure": sol.pressure[order].tolist()}
    for body in (1, 2):
        xs, s = surface_stress(sol, body)
        # Outside a body's surface (e.g. beyond the top block's corner) there is no value.
        inside = (x >= xs[0] - 1e-12) & (x <= xs[-1] + 1e-12)
        vals = np.where(inside, np.interp(x, xs, s), np.nan)
        out[f"sigma_yy_{body}"] = [None if np.isnan(v) else float(v) for v in vals]
    return out


def contact_force(sol: Solution) -> float:
    """Total vertical force the contact transmits to the active body (per unit thickness)."""
    B = sol.operator.B[sol.order]
    surf = sol.surfaces[sol.scene.active - 1].surface
    ydofs = surf.dofs[:, 1]
    return float(abs(sol.pressure @ np.asarray(B[:, ydofs].sum(axis=1)).ravel()))


def summary(sol: Solution, times: dict[str, float], extra: dict[str, Any] | None = None
            ) -> dict[str, Any]:
    """The JSON-ready summary of a run (schema in README)."""
    scene = sol.scene
    comm = scene.mesh.comm
    V = sol.elasticity.V
    ncells = scene.mesh.topology.index_map(2).size_global
    return {
        "scene": scene.name,
        "method": sol.method.value,
        "params": scene.params_dict(),
        "ranks": comm.size,
        "dofs": V.dofmap.index_map.size_global * V.dofmap.index_map_bs,
        "multipliers": int(sol.layout.size),
        "elements": int(ncells),
        "iterations": sol.iterations,
        "active_set": sol.history,
        "times": times,
        "contact_force": contact_force(sol),
        "active_nodes": int(sol.active.sum()),
        "interface": interface(sol),
        **(extra or {}),
    }


def u_at_points(sol: Solution) -> np.ndarray:
    """Gather (x, y, ux, uy) of all owned nodes, sorted by coordinates (for rank comparisons)."""
    V = sol.elasticity.V
    nloc = V.dofmap.index_map.size_local
    xyz = V.tabulate_dof_coordinates()[:nloc, :2]
    vals = sol.u.x.array[: 2 * nloc].reshape(-1, 2)
    data = np.concatenate(V.mesh.comm.allgather(np.column_stack([xyz, vals])))
    key = np.round(data[:, :2], 9)  # gmsh coordinates carry ~1e-17 noise around zero
    return data[np.lexsort((data[:, 3], data[:, 2], key[:, 1], key[:, 0]))]


def sigma_field(sol: Solution) -> fem.Function:
    """Cellwise (DG0) stress tensor of the solution, for output."""
    msh = sol.scene.mesh
    Q = fem.functionspace(msh, ("DG", 0, (2, 2)))
    s = fem.Function(Q, name="sigma")
    el = sol.elasticity
    s.interpolate(fem.Expression(sigma(sol.u, el.E, el.nu), Q.element.interpolation_points))
    return s



def body_stress_deviation(sol: Solution, target: float, component: tuple[int, int] = (1, 1)
                          ) -> dict[str, float]:
    """Max |sigma_ij / target - 1| over every cell vertex of each body (the patch-test measure)."""
    scene = sol.scene
    msh = scene.mesh
    el = sol.elasticity
    expr = fem.Expression(sigma(sol.u, el.E, el.nu)[component], REF_VERTICES)
    nloc = msh.topology.index_map(msh.topology.dim).size_local
    out = {}
    for body in (1, 2):
        cells = scene.cell_tags.find(scene.tags[f"body{body}"])
        cells = cells[cells < nloc].astype(np.int32)
        vals = expr.eval(msh, cells) if cells.size else np.zeros(0)
        local = float(np.max(np.abs(vals / target - 1.0), initial=0.0))
        out[f"body{body}"] = msh.comm.allreduce(local, op=MPI.MAX)
    return out
