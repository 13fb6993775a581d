"""Quantities users read off a solution, pair by pair: stresses along the normal, forces.

Stresses are each body's own FE stress, averaged at the surface nodes over the adjacent
cells. Each body's traction sigma.m (m its outward normal, the passive one's turned to point
out of the active body) is resolved on the contact frame of `report_frame`: nu, the passive
surface's normal at the node's projection, and tau perpendicular to it (the direction of
increasing arc length s along the active surface). On a frictionless contact sigma_nt then
tends to 0 and sigma_nn to -p at the discretization's order also on curved pairs, where the
active surface's own normal differs from nu by the slope (docs/hertz.md).

The normals are those of the curve the polygon samples, not of its facets (`curve_normals`:
the circle through a node and its neighbours): a facet's normal is off the curve's by up to
half the facet's turn, and the shear read in it is the hoop stress difference times that
angle (p dtheta / 2 on the active side of a frictionless ring fit, (sigma_tt + p) dtheta / 2
on the passive side). The records are assembled in results/summary.py.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..contact.geometry import Surface, nodal_normals
from ..contact.search import project
from ..methods.solution import PairView, Solution
from ..scenes import Model
from .records import ContactSummary
from .stress import nodal_stress, surface_stress

# The numeric columns of every pair's `interface` (plus the boolean `active`), in order.
# How the JSON names contact/friction.Status values.
STATUS_NAMES = ("open", "stick", "slip")

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


def resolve(
    sig: np.ndarray, m: np.ndarray, nu: np.ndarray, tau: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """nu.sigma.m and tau.sigma.m row by row: the traction on normal m in the frame (nu, tau)."""
    tr = np.einsum("kij,kj->ki", sig, m)
    return np.einsum("ki,ki->k", nu, tr), np.einsum("ki,ki->k", tau, tr)


def curve_normals(surface: Surface) -> np.ndarray:
    """Unit outward normal at each node of the curve through the surface's nodes, (n, 2).

    The normal of the circle through the node and its two neighbours (at an end of a chain:
    the next two nodes along it), oriented like the facets' mean normal, which it replaces
    where the three points are collinear (a straight line, or a kink). On a circle it is the
    radius at every node, ends included; on a line, the line's normal.
    """
    base = nodal_normals(surface)
    out = base.copy()
    nbrs = neighbours(surface)
    x = surface.x
    for i, near in enumerate(nbrs):
        if len(near) == 2:
            ordered = (near[0], i, near[1])
        elif len(near) == 1:
            further = [m for m in nbrs[near[0]] if m != i]
            if not further:
                continue
            ordered = (i, near[0], further[0])
        else:
            continue
        centre = circumcentre(*(x[m] for m in ordered))
        if centre is None:
            continue
        n = x[i] - centre
        n /= np.linalg.norm(n)
        out[i] = n if n @ base[i] >= 0 else -n
    return out


def circumcentre(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> np.ndarray | None:
    """Centre of the circle through p, q, r (in order along a curve), or None.

    None where they are collinear, or where the chords turn at q by more than 30 degrees (a
    corner of the polygon, not a sampled curve: the facets' mean normal is kept there).
    """
    u, v = q - p, r - p
    cross = u[0] * v[1] - u[1] * v[0]
    lu, lv = float(u @ u), float(v @ v)
    if abs(cross) <= 1e-9 * lu**0.5 * lv**0.5:
        return None
    w, z = q - p, r - q
    cos_turn = float(w @ z) / (np.linalg.norm(w) * np.linalg.norm(z))
    if cos_turn < np.cos(np.pi / 6):
        return None
    d = 2.0 * cross
    return p + np.array([v[1] * lu - u[1] * lv, u[0] * lv - v[0] * lu]) / d


def neighbours(surface: Surface) -> list[list[int]]:
    """The nodes each node shares a segment with."""
    nbrs: list[list[int]] = [[] for _ in range(surface.n_nodes)]
    for a, b in surface.segments:
        nbrs[int(a)].append(int(b))
        nbrs[int(b)].append(int(a))
    return nbrs


def curve_radius(surface: Surface, point: np.ndarray) -> float:
    """The radius of the circle through the surface node nearest `point` and its neighbours.

    inf where they are collinear (a straight surface) or the node has no two neighbours.
    """
    nbrs = neighbours(surface)
    i = int(np.argmin(np.linalg.norm(surface.x - point, axis=1)))
    near = nbrs[i]
    if len(near) == 2:
        ordered = (near[0], i, near[1])
    elif len(near) == 1 and [m for m in nbrs[near[0]] if m != i]:
        ordered = (i, near[0], next(m for m in nbrs[near[0]] if m != i))
    else:
        return math.inf
    centre = circumcentre(*(surface.x[m] for m in ordered))
    return math.inf if centre is None else float(np.linalg.norm(surface.x[i] - centre))


def report_frame(pv: PairView) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(n, nu, tau): the active curve's normal at each row's node and the contact frame.

    nu is the passive curve's normal at the node's projection (`curve_normals` interpolated
    along the facet and normalized), turned to point out of the active body; against a rigid
    obstacle its exact normal; beyond the passive surface's end the active curve's normal.
    tau is perpendicular to nu, along increasing s. On a straight passive surface nu is
    PairView.frame's (the direction the multipliers act along).
    """
    n = curve_normals(pv.active.surface)[pv.nodes]
    facet_nu, _, found = pv.frame
    if pv.passive is None:
        nu = facet_nu
    else:
        surf = pv.passive.surface
        seg, xi, _ = project(pv.x, surf)
        ends = surf.segments[seg]
        cn = curve_normals(surf)
        m = (1 - xi)[:, None] * cn[ends[:, 0]] + xi[:, None] * cn[ends[:, 1]]
        m /= np.linalg.norm(m, axis=1)[:, None]
        nu = np.where(found[:, None], -m, n)
    t = pv.t
    tau = t - np.einsum("ki,ki->k", t, nu)[:, None] * nu
    tau /= np.linalg.norm(tau, axis=1)[:, None]
    return n, nu, tau


def none_if_nan(v: np.ndarray) -> list[float | None]:
    """The values as floats, None where not finite (JSON has no NaN)."""
    return [None if not np.isfinite(x) else float(x) for x in v]


def pair_interface(sol: Solution, k: int) -> dict[str, Any]:
    """Pressure, gap and both bodies' sigma_nn, sigma_nt at pair k's multipliers, by s."""
    if k not in sol.cache.interface:
        sol.cache.interface[k] = _pair_interface(sol, k)
    return sol.cache.interface[k]


def _pair_interface(sol: Solution, k: int) -> dict[str, Any]:
    """pair_interface, computed (collective)."""
    pv = sol.pairs[k]
    rows = pv.rows
    x, s = pv.x, pv.s
    gn_a, _, sig_a = nodal_stress(sol, pv.pair.active)
    sa = sig_a[np.searchsorted(gn_a, pv.gblock)]
    sp = np.full_like(sa, np.nan)  # a rigid obstacle has no stress of its own
    if pv.passive is not None:
        surf_p = pv.passive.surface
        gn_p, _, sig_p = nodal_stress(sol, pv.pair.passive)
        at_node = sig_p[np.searchsorted(gn_p, pv.passive.gblock)]
        seg, xi, found = project(x, surf_p)
        ends = surf_p.segments[seg]
        sp = (1 - xi)[:, None, None] * at_node[ends[:, 0]] + xi[:, None, None] * at_node[ends[:, 1]]
        sp[~found] = np.nan  # beyond the passive surface's end there is no value
    n, nu, tau = report_frame(pv)
    nn_a, nt_a = resolve(sa, n, nu, tau)
    nn_p, nt_p = resolve(sp, nu, nu, tau)
    order = np.argsort(s, kind="stable")
    values = (x[:, 0], x[:, 1], s, sol.pressure[rows], sol.gap[rows], nn_a, nn_p, nt_a, nt_p)
    cols = dict(zip(INTERFACE_FIELDS, values, strict=True))
    out: dict[str, Any] = {key: none_if_nan(np.asarray(v)[order]) for key, v in cols.items()}
    out["active"] = [bool(a) for a in sol.active[rows][order]]
    fr = sol.friction
    if fr is not None:  # a frictional scene: the tangential side (frictionless: no keys)
        out["shear"] = fr.shear[rows][order].tolist()
        out["slip"] = fr.slip[rows][order].tolist()
        out["status"] = [STATUS_NAMES[int(v)] for v in fr.status[rows][order]]
    return out


def pair_forces(sol: Solution, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Total contact force (fx, fy) on pair k's active body and on its passive body."""
    pv = sol.pairs[k]
    # B^T lambda: the multipliers' nodal forces (compression positive pushes the bodies apart).
    nodal = pv.B.transpose_matmul(sol.pressure[pv.rows])
    if sol.friction is not None:  # the shear's force on the bodies: -B_t^T lambda_t
        nodal -= sol.friction.tangent.rows(pv.rows).transpose_matmul(sol.friction.shear[pv.rows])
    fa = np.array([nodal[pv.active.surface.dofs[:, c]].sum() for c in (0, 1)])
    if pv.motion is not None:  # a rigid obstacle: its force is its columns' share
        fp = pv.motion.transpose_matmul(sol.pressure[pv.rows])
        if sol.friction is not None and sol.friction.tangent_motion is not None:
            moving = sol.friction.tangent_motion.rows(pv.rows)
            fp = fp - moving.transpose_matmul(sol.friction.shear[pv.rows])
        return fa, fp
    assert pv.passive is not None  # a body pair has a passive surface
    fp = np.array([nodal[pv.passive.surface.dofs[:, c]].sum() for c in (0, 1)])
    return fa, fp


def contacts_summary(sol: Solution) -> tuple[ContactSummary, ...]:
    """One ContactSummary per pair, in the scene's order."""
    out = []
    for k, pv in enumerate(sol.pairs):
        fa, fp = pair_forces(sol, k)
        out.append(
            ContactSummary(
                active=pv.pair.active,
                passive=pv.pair.passive,
                active_body=pv.active_body.name,
                # An obstacle pair names the obstacle on both passive keys.
                passive_body=pv.pair.passive if pv.passive_body is None else pv.passive_body.name,
                force=(float(fa[0]), float(fa[1])),
                force_passive=(float(fp[0]), float(fp[1])),
                balance=float(np.linalg.norm(fa + fp) / max(np.linalg.norm(fa), 1e-300)),
                multipliers=len(pv.rows),
                active_nodes=int(sol.active[pv.rows].sum()),
                interface=pair_interface(sol, k),
                obstacle=pv.obstacle,
                initial_overlap=pv.initial_overlap,
                axisymmetric=sol.scene.model is Model.AXISYMMETRIC,
                fit=bool(pv.pair.interference),
            )
        )
    return tuple(out)


def cartesian_interface(sol: Solution) -> dict[str, list[float | None]]:
    """Pair 0 along x: pressure and sigma_yy of every body at the multipliers (paper's view).

    Only meaningful for a horizontal contact line (the paper's scenes).
    """
    itf = pair_interface(sol, 0)
    x = np.asarray(itf["x"], dtype=float)
    order = np.argsort(x, kind="stable")
    pv = sol.pairs[0]
    out: dict[str, list[float | None]] = {
        "x": x[order].tolist(),
        "pressure": [itf["pressure"][i] for i in order],
    }
    xm = pv.x[np.argsort(pv.s, kind="stable")]
    for k, body in enumerate(sol.scene.bodies, start=1):
        if body not in (pv.active_body, pv.passive_body):
            continue
        group = pv.pair.active if body == pv.active_body else pv.pair.passive
        xs, s = surface_stress(sol, group)
        inside = (xm[:, 0] >= xs[0] - 1e-12) & (xm[:, 0] <= xs[-1] + 1e-12)
        vals = np.where(inside, np.interp(xm[:, 0], xs, s), np.nan)
        out[f"sigma_yy_{k}"] = none_if_nan(vals[order])
    return out


def u_at_points(sol: Solution) -> np.ndarray:
    """Gather (x, y, ux, uy) of all owned nodes, sorted by coordinates (for rank comparisons)."""
    V = sol.fields.V
    nloc = V.dofmap.index_map.size_local
    xyz = V.tabulate_dof_coordinates()[:nloc, :2]
    vals = sol.u.x.array[: 2 * nloc].reshape(-1, 2)
    data = np.concatenate(V.mesh.comm.allgather(np.column_stack([xyz, vals])))
    key = np.round(data[:, :2], 9)  # gmsh coordinates carry ~1e-17 noise around zero
    return data[np.lexsort((data[:, 3], data[:, 2], key[:, 1], key[:, 0]))]
