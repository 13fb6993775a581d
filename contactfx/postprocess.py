"""Quantities users read off a solution, pair by pair: stresses along the normal, forces.

Stresses are each body's own FE stress, averaged at the surface nodes over the adjacent
cells, resolved on the active surface's outward normal n and the tangent t (the direction of
increasing arc length s along the active surface).

One module (~320 lines) because every quantity here is computed on the same gathered pair
data (nodal stresses by global node, arc length, projections); the JSON assembly is in
report.py.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from .contact import Surface
from .contact.geometry import chains, nodal_normals, project
from .elasticity import sigma
from .solution import Solution
from .surfaces import owned_facets, vertex_coordinates, vertex_to_block

# The numeric columns of every pair's `interface` (plus the boolean `active`), in order.
INTERFACE_FIELDS = (
    "x",
    "y",
    "s",
    "pressure",
    "gap",
    "sigma_nn_active",
    "sigma_nn_passive",
    "sigma_nt_active",
    "sigma_nt_passive",
)

REF_VERTICES = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])


def nodal_stress(sol: Solution, group: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(global node, x, sigma (k, 2, 2)) at the nodes of curve group `group`, cell-averaged."""
    key = ("nodal_stress", group)
    if key not in sol.cache:
        sol.cache[key] = _nodal_stress(sol, group)
    return sol.cache[key]  # type: ignore[return-value]


def _nodal_stress(sol: Solution, group: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """nodal_stress, computed (collective)."""
    scene = sol.scene
    msh = scene.mesh
    tdim = msh.topology.dim
    el = sol.elasticity
    expr = fem.Expression(sigma(sol.u, el.E, el.nu), REF_VERTICES)
    facets = owned_facets(scene, group)
    msh.topology.create_connectivity(tdim - 1, tdim)
    msh.topology.create_connectivity(tdim - 1, 0)
    f2v = msh.topology.connectivity(tdim - 1, 0).array.reshape(-1, 2)[facets]
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    cells = f2c.array[f2c.offsets[facets]].astype(np.int32)
    values = (
        expr.eval(msh, cells).reshape(len(cells), 4, 2, 2) if len(cells) else np.zeros((0, 4, 2, 2))
    )
    c2v = msh.topology.connectivity(tdim, 0).array.reshape(-1, 4)[cells]
    xv = vertex_coordinates(msh)
    v2b = vertex_to_block(el.V)
    imap = el.V.dofmap.index_map
    nodes, xs, vals = [], [], []
    for k in range(2):
        col = np.argmax(c2v == f2v[:, [k]], axis=1)
        nodes.append(imap.local_to_global(v2b[f2v[:, k]].astype(np.int32)))
        xs.append(xv[f2v[:, k]])
        vals.append(values[np.arange(len(cells)), col])
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


def arc_length(surface: Surface) -> tuple[np.ndarray, np.ndarray]:
    """(s, t): arc length and unit tangent of every node along the surface's polylines.

    Each polyline starts at its end with the smallest (x, y) so that s does not depend on
    the node numbering (and hence not on the number of ranks); polylines follow one
    another in that order, s continuing from one to the next.
    """
    ch = chains(surface)
    seg = surface.segments
    s = np.full(surface.n_nodes, np.nan)
    t = np.zeros((surface.n_nodes, 2))
    runs = [
        ch.order[st : st + ln]
        for st, ln in sorted({(int(a), int(b)) for a, b in zip(ch.start, ch.length, strict=True)})
    ]
    walks = []
    for run in runs:
        # Node sequence along the run, from the first segment's free end.
        a, b = seg[run[0]]
        if len(run) > 1 and a in seg[run[1]]:
            a, b = b, a
        nodes: list[np.integer] | np.ndarray
        nodes = [a, b]
        for e in run[1:]:
            p, q = seg[e]
            nodes.append(q if p == nodes[-1] else p)
        nodes = np.array(nodes)
        xa, xb = surface.x[nodes[0]], surface.x[nodes[-1]]
        if (xb[0], xb[1]) < (xa[0], xa[1]):
            nodes = nodes[::-1]
        walks.append(nodes)
    walks.sort(key=lambda w: (surface.x[w[0], 0], surface.x[w[0], 1]))
    start = 0.0
    for nodes in walks:
        d = np.diff(surface.x[nodes], axis=0)
        ds = np.hypot(d[:, 0], d[:, 1])
        s[nodes] = start + np.concatenate([[0.0], np.cumsum(ds)])
        start = float(s[nodes[-1]])
        tang = np.zeros((len(nodes), 2))
        tang[:-1] += d / ds[:, None]
        tang[1:] += d / ds[:, None]
        t[nodes] = tang / np.linalg.norm(tang, axis=1)[:, None]
    return s, t


def _resolve(sig: np.ndarray, n: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """n.sigma.n and t.sigma.n, row by row."""
    tr = np.einsum("kij,kj->ki", sig, n)
    return np.einsum("ki,ki->k", n, tr), np.einsum("ki,ki->k", t, tr)


def _none_if_nan(v: np.ndarray) -> list[float | None]:
    return [None if not np.isfinite(x) else float(x) for x in v]


def pair_interface(sol: Solution, k: int) -> dict[str, Any]:
    """Pressure, gap and both bodies' sigma_nn, sigma_nt at pair k's multipliers, by s."""
    key = ("pair_interface", k)
    if key not in sol.cache:
        sol.cache[key] = _pair_interface(sol, k)
    return sol.cache[key]  # type: ignore[return-value]


def _pair_interface(sol: Solution, k: int) -> dict[str, Any]:
    """pair_interface, computed (collective)."""
    pd = sol.pairs[k]
    rows = sol.rows_of(k)
    surf_a, surf_p = pd.active.surface, pd.passive.surface
    # Multiplier rows of this pair are nodes of its active surface.
    node = np.searchsorted(pd.active.gblock, sol.layout.gblock[rows])
    s_all, t_all = arc_length(surf_a)
    n = nodal_normals(surf_a)[node]
    t = t_all[node]
    x = surf_a.x[node]
    gn_a, _, sig_a = nodal_stress(sol, pd.pair.active)
    sa = sig_a[np.searchsorted(gn_a, pd.active.gblock[node])]
    gn_p, _, sig_p = nodal_stress(sol, pd.pair.passive)
    sig_pn = np.full((len(gn_p), 2, 2), np.nan)
    sig_pn[:] = sig_p
    at_node = sig_pn[np.searchsorted(gn_p, pd.passive.gblock)]
    seg, xi, found = project(x, surf_p)
    ends = surf_p.segments[seg]
    sp = (1 - xi)[:, None, None] * at_node[ends[:, 0]] + xi[:, None, None] * at_node[ends[:, 1]]
    sp[~found] = np.nan  # beyond the passive surface's end there is no value
    nn_a, nt_a = _resolve(sa, n, t)
    nn_p, nt_p = _resolve(sp, n, t)
    order = np.argsort(s_all[node], kind="stable")
    values = (
        x[:, 0],
        x[:, 1],
        s_all[node],
        sol.pressure[rows],
        sol.gap[rows],
        nn_a,
        nn_p,
        nt_a,
        nt_p,
    )
    cols = dict(zip(INTERFACE_FIELDS, values, strict=True))
    out: dict[str, Any] = {key: _none_if_nan(np.asarray(v)[order]) for key, v in cols.items()}
    out["active"] = [bool(a) for a in sol.active[rows][order]]
    return out


def pair_forces(sol: Solution, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Total contact force (fx, fy) on pair k's active body and on its passive body."""
    pd = sol.pairs[k]
    rows = sol.rows_of(k)
    # B^T lambda: the multipliers' nodal forces (compression positive pushes the bodies apart).
    nodal = sol.operator.B[sol.order[rows]].T @ sol.pressure[rows]
    fa = np.array([nodal[pd.active.surface.dofs[:, c]].sum() for c in (0, 1)])
    fp = np.array([nodal[pd.passive.surface.dofs[:, c]].sum() for c in (0, 1)])
    return fa, fp


def contacts_summary(sol: Solution) -> list[dict[str, Any]]:
    """The `contacts` list of the JSON: one entry per pair, in the scene's order."""
    out = []
    for k, pd in enumerate(sol.pairs):
        fa, fp = pair_forces(sol, k)
        rows = sol.rows_of(k)
        out.append(
            {
                "active": pd.pair.active,
                "passive": pd.pair.passive,
                "active_body": pd.active_body.name,
                "passive_body": pd.passive_body.name,
                "force": fa.tolist(),
                "force_passive": fp.tolist(),
                "balance": float(np.linalg.norm(fa + fp) / max(np.linalg.norm(fa), 1e-300)),
                "multipliers": len(rows),
                "active_nodes": int(sol.active[rows].sum()),
                "interface": pair_interface(sol, k),
            }
        )
    return out


def surface_stress(
    sol: Solution, group: str, component: tuple[int, int] = (1, 1)
) -> tuple[np.ndarray, np.ndarray]:
    """(x, sigma_ij) at the nodes of curve group `group`, sorted by x (horizontal lines)."""
    _, x, sig = nodal_stress(sol, group)
    order = np.argsort(x[:, 0], kind="stable")
    return x[order, 0], sig[order, component[0], component[1]]


def cartesian_interface(sol: Solution) -> dict[str, list[float | None]]:
    """Pair 0 along x: pressure and sigma_yy of every body at the multipliers (paper's view).

    Only meaningful for a horizontal contact line; the built-in scenes ask for it.
    """
    itf = pair_interface(sol, 0)
    x = np.asarray(itf["x"], dtype=float)
    order = np.argsort(x, kind="stable")
    pd = sol.pairs[0]
    out: dict[str, list[float | None]] = {
        "x": x[order].tolist(),
        "pressure": [itf["pressure"][i] for i in order],
    }
    rows = sol.rows_of(0)
    node = np.searchsorted(pd.active.gblock, sol.layout.gblock[rows])
    xm = pd.active.surface.x[node]
    s_order = np.argsort(arc_length(pd.active.surface)[0][node], kind="stable")
    xm = xm[s_order]
    for k, body in enumerate(sol.scene.bodies, start=1):
        group = pd.pair.active if body == pd.active_body else pd.pair.passive
        if body not in (pd.active_body, pd.passive_body):
            continue
        xs, s = surface_stress(sol, group)
        inside = (xm[:, 0] >= xs[0] - 1e-12) & (xm[:, 0] <= xs[-1] + 1e-12)
        vals = np.where(inside, np.interp(xm[:, 0], xs, s), np.nan)
        out[f"sigma_yy_{k}"] = _none_if_nan(vals[order])
    return out


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


def _body_vertex_stress(sol: Solution) -> dict[str, np.ndarray]:
    """The stress sigma (k, 2, 2) at every owned cell vertex of each body."""
    scene = sol.scene
    msh = scene.mesh
    el = sol.elasticity
    expr = fem.Expression(sigma(sol.u, el.E, el.nu), REF_VERTICES)
    nloc = msh.topology.index_map(msh.topology.dim).size_local
    out = {}
    for body in scene.bodies:
        cells = scene.cell_tags.find(scene.body_tag(body))
        cells = cells[cells < nloc].astype(np.int32)
        out[body.name] = (
            expr.eval(msh, cells).reshape(-1, 2, 2) if cells.size else np.zeros((0, 2, 2))
        )
    return out


def body_stress_deviation(
    sol: Solution, target: float, component: tuple[int, int] = (1, 1)
) -> dict[str, float]:
    """Max |sigma_ij / target - 1| over every cell vertex of each body (the patch-test measure)."""
    comm = sol.scene.comm
    out = {}
    for name, vals in _body_vertex_stress(sol).items():
        v = vals[:, component[0], component[1]]
        out[name] = comm.allreduce(float(np.max(np.abs(v / target - 1.0), initial=0.0)), op=MPI.MAX)
    return out


def _max_error(values: list[float | None], exact: np.ndarray, scale: float) -> float:
    """Max |value - exact| / scale over the values that exist."""
    v = np.array([np.nan if a is None else a for a in values], dtype=float)
    return float(np.nanmax(np.abs(v - exact), initial=0.0) / scale)


def uniform_stress_errors(sol: Solution, ref: np.ndarray) -> dict[str, Any]:
    """Patch test against a uniform stress: max errors relative to the largest |ref_ij|."""
    comm = sol.scene.comm
    scale = float(np.abs(ref).max())
    bodies = {
        name: comm.allreduce(float(np.max(np.abs(v - ref), initial=0.0)), op=MPI.MAX) / scale
        for name, v in _body_vertex_stress(sol).items()
    }
    pairs = []
    for k, pd in enumerate(sol.pairs):
        itf = pair_interface(sol, k)
        rows = sol.rows_of(k)
        node = np.searchsorted(pd.active.gblock, sol.layout.gblock[rows])
        n = nodal_normals(pd.active.surface)[node]
        t = arc_length(pd.active.surface)[1][node]
        order = np.argsort(arc_length(pd.active.surface)[0][node], kind="stable")
        nn, nt = _resolve(np.broadcast_to(ref, (len(n), 2, 2)), n[order], t[order])

        pairs.append(
            {
                "pressure": _max_error(itf["pressure"], -nn, scale),
                **{
                    key: _max_error(itf[key], exact, scale)
                    for key, exact in (
                        ("sigma_nn_active", nn),
                        ("sigma_nn_passive", nn),
                        ("sigma_nt_active", nt),
                        ("sigma_nt_passive", nt),
                    )
                },
            }
        )
    return {
        "bodies": bodies,
        "pairs": pairs,
        "max": max([*bodies.values(), *(v for p in pairs for v in p.values())]),
    }
