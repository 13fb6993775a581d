"""Stresses of a solution: at the nodes of a curve group, per cell, at every cell vertex.

Nodal values are each body's own FE stress averaged at the surface nodes over the adjacent
cells (every rank computes its own facets; the values are gathered).
"""

from __future__ import annotations

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from ..discretize.elasticity import sigma, sigma_zz
from ..discretize.mesh_utils import facet_ends, owned_facets
from ..discretize.thermal import thermal_correction, thermal_zz
from ..methods.solution import Solution
from ..scenes import Model

REF_VERTICES = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])

NodalStress = tuple[np.ndarray, np.ndarray, np.ndarray]


def stress_of(sol: Solution) -> ufl.core.expr.Expr:
    """The physical stress of the solution: C eps(u), less a thermal strain's sigma0."""
    el = sol.fields
    thermal = thermal_correction(sol.scene, el.E, el.nu)
    elastic = sigma(sol.u, el.E, el.nu, sol.scene.model)
    return elastic if thermal is None else elastic - thermal


def nodal_stress(sol: Solution, group: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(global node, x, sigma (k, 2, 2)) at the nodes of curve group `group`, cell-averaged."""
    if group not in sol.cache.stress:
        sol.cache.stress[group] = _nodal_stress(sol, group)
    return sol.cache.stress[group]


def _nodal_stress(sol: Solution, group: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """nodal_stress, computed (collective)."""
    scene = sol.scene
    msh = scene.mesh
    tdim = msh.topology.dim
    el = sol.fields
    expr = fem.Expression(stress_of(sol), REF_VERTICES)
    facets = owned_facets(scene, group)
    msh.topology.create_connectivity(tdim - 1, tdim)
    msh.topology.create_connectivity(tdim - 1, 0)
    f2v = msh.topology.connectivity(tdim - 1, 0).array.reshape(-1, 2)[facets]
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    cells = f2c.array[f2c.offsets[facets]].astype(np.int32)
    values = (
        expr.eval(msh, cells).reshape(len(cells), 4, 2, 2) if len(cells) else np.zeros((0, 4, 2, 2))
    )
    _, cols, ends, blocks = facet_ends(el.V, cells, f2v)
    imap = el.V.dofmap.index_map
    at = np.arange(len(cells))
    nodes, xs, vals = [], [], []
    for k in range(2):
        nodes.append(imap.local_to_global(blocks[:, k].astype(np.int32)))
        xs.append(ends[:, k])
        vals.append(values[at, cols[:, k]])
    comm = msh.comm
    gnode = np.concatenate(comm.allgather(np.concatenate(nodes)))
    gx = np.concatenate(comm.allgather(np.concatenate(xs)))
    gv = np.concatenate(comm.allgather(np.concatenate(vals)))
    uniq, first, inv = np.unique(gnode, return_index=True, return_inverse=True)
    count = np.bincount(inv.ravel())
    avg = np.stack(
        [np.bincount(inv.ravel(), weights=gv[:, i, j]) / count for i in range(2) for j in range(2)],
        axis=1,
    ).reshape(-1, 2, 2)
    return uniq, gx[first], avg


def surface_stress(
    sol: Solution, group: str, component: tuple[int, int] = (1, 1)
) -> tuple[np.ndarray, np.ndarray]:
    """(x, sigma_ij) at the nodes of curve group `group`, sorted by x (horizontal lines)."""
    _, x, sig = nodal_stress(sol, group)
    order = np.argsort(x[:, 0], kind="stable")
    return x[order, 0], sig[order, component[0], component[1]]


def sigma_field(sol: Solution) -> fem.Function:
    """Cellwise (DG0) stress tensor of the solution, for output."""
    msh = sol.scene.mesh
    Q = fem.functionspace(msh, ("DG", 0, (2, 2)))
    s = fem.Function(Q, name="sigma")
    s.interpolate(fem.Expression(stress_of(sol), Q.element.interpolation_points))
    return s


def sigma_zz_field(sol: Solution) -> fem.Function:
    """Cellwise (DG0) out-of-plane stress sigma_zz.

    nu (sxx + syy) in plane strain, 0 in plane stress, the hoop stress in axisymmetric.
    """
    msh = sol.scene.mesh
    Q = fem.functionspace(msh, ("DG", 0))
    s = fem.Function(Q, name="sigma_zz")
    el = sol.fields
    if sol.scene.model is Model.PLANE_STRESS:
        return s  # zero (a constant expression has no mesh to interpolate on)
    expr = sigma_zz(sol.u, el.E, el.nu, sol.scene.model)
    thermal = thermal_zz(sol.scene, el.E, el.nu)
    if thermal is not None:
        expr = expr - thermal
    s.interpolate(fem.Expression(expr, Q.element.interpolation_points))
    return s


def body_vertex_stress(sol: Solution) -> dict[str, np.ndarray]:
    """The stress sigma (k, 2, 2) at every owned cell vertex of each body."""
    scene = sol.scene
    msh = scene.mesh
    expr = fem.Expression(stress_of(sol), REF_VERTICES)
    nloc = msh.topology.index_map(msh.topology.dim).size_local
    out = {}
    for body in scene.bodies:
        cells = scene.body_cells(body)
        cells = cells[cells < nloc].astype(np.int32)
        out[body.name] = (
            expr.eval(msh, cells).reshape(-1, 2, 2) if cells.size else np.zeros((0, 2, 2))
        )
    return out


def body_stress_deviation(
    sol: Solution, target: float, component: tuple[int, int] = (1, 1)
) -> dict[str, float]:
    """Max abs(sigma_ij / target - 1) over every cell vertex of each body (patch-test measure)."""
    comm = sol.scene.comm
    out = {}
    for name, vals in body_vertex_stress(sol).items():
        v = vals[:, component[0], component[1]]
        out[name] = comm.allreduce(float(np.max(np.abs(v / target - 1.0), initial=0.0)), op=MPI.MAX)
    return out
