"""The energy-norm error of a solution against a finer (overkill) one on another mesh.

||u_ref - u_h||_E^2 = int sigma(e) : eps(e), e = u_ref - u_h, integrated with a 4 x 4 Gauss
rule on every cell of the reference mesh; u_h's gradient is evaluated at those points in
the cell of the same body that contains them (Q1 pull-back by Newton). The meshes need not
be nested (gmsh remeshes them); a point just outside its body's coarse mesh (a curved
boundary's chords) takes the nearest cell's bilinear field. The meshes are gathered to rank 0
(this is a verification tool, for meshes up to a few 100k cells).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..methods.solution import Solution
from ..scenes import Model

_G = np.array([-0.861136311594053, -0.339981043584856, 0.339981043584856, 0.861136311594053])
_W = np.array([0.347854845137454, 0.652145154862546, 0.652145154862546, 0.347854845137454])
GAUSS_X = 0.5 * (1.0 + _G)
GAUSS_W = 0.5 * _W


@dataclass(frozen=True)
class CellData:
    """A Q1 mesh on one rank: per cell its 4 vertices (DOLFINx order), u there, E, nu, body."""

    x: np.ndarray  # (n, 4, 2)
    u: np.ndarray  # (n, 4, 2)
    E: np.ndarray  # (n,)
    nu: np.ndarray  # (n,)
    body: np.ndarray  # (n,) index into the scene's bodies


def cell_data(sol: Solution) -> CellData | None:
    """The owned cells of every rank, gathered on rank 0 (None on the other ranks)."""
    scene = sol.scene
    msh = scene.mesh
    V = sol.fields.V
    nloc = msh.topology.index_map(msh.topology.dim).size_local
    geo = msh.geometry.dofmaps[0][:nloc]
    x = msh.geometry.x[geo][:, :, :2]
    blocks = V.dofmap.list[:nloc]
    u = sol.u.x.array.reshape(-1, 2)[blocks]
    Ef, nuf = sol.fields.E, sol.fields.nu
    E = Ef.x.array[Ef.function_space.dofmap.list[:nloc, 0]]
    nu = nuf.x.array[nuf.function_space.dofmap.list[:nloc, 0]]
    body = np.full(nloc, -1, dtype=np.int64)
    for k, b in enumerate(scene.bodies):
        cells = scene.body_cells(b)
        body[cells[cells < nloc]] = k
    parts = msh.comm.gather((x, u, E, nu, body), root=0)
    if parts is None:
        return None
    return CellData(*(np.concatenate([p[i] for p in parts]) for i in range(5)))


def _shape(xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Q1 basis (k, 4) and reference gradients (k, 4, 2) at reference points xi (k, 2)."""
    s, t = xi[:, 0], xi[:, 1]
    N = np.column_stack([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t])
    dN = np.stack(
        [
            np.column_stack([-(1 - t), (1 - t), -t, t]),
            np.column_stack([-(1 - s), -s, (1 - s), s]),
        ],
        axis=2,
    )
    return N, dN


def _inv2(J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverses and determinants of 2 x 2 matrices (k, 2, 2), in closed form (fast)."""
    det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
    inv = np.empty_like(J)
    inv[:, 0, 0], inv[:, 1, 1] = J[:, 1, 1] / det, J[:, 0, 0] / det
    inv[:, 0, 1], inv[:, 1, 0] = -J[:, 0, 1] / det, -J[:, 1, 0] / det
    return inv, det


def _grad(xc: np.ndarray, uc: np.ndarray, xi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(grad u (k, 2, 2), det J (k,)) of bilinear cells xc, uc (k, 4, 2) at reference xi."""
    _, dN = _shape(xi)
    J = np.einsum("kai,kaj->kij", xc, dN)  # dx_i / dxi_j
    Jinv, det = _inv2(J)
    dNx = np.einsum("kaj,kji->kai", dN, Jinv)
    return np.einsum("kac,kai->kci", uc, dNx), det


def _pull_back(xc: np.ndarray, p: np.ndarray, steps: int = 8) -> np.ndarray:
    """Reference coordinates of points p (k, 2) in bilinear cells xc (k, 4, 2), by Newton."""
    xi = np.full((len(p), 2), 0.5)
    for _ in range(steps):
        N, dN = _shape(xi)
        r = np.einsum("ka,kai->ki", N, xc) - p
        J = np.einsum("kai,kaj->kij", xc, dN)
        xi -= np.einsum("kij,kj->ki", _inv2(J)[0], r)
        xi = np.clip(xi, -1.0, 2.0)  # far candidates must not diverge
    return xi


def _locate(
    coarse: CellData, cells: np.ndarray, p: np.ndarray, k: int = 16
) -> tuple[np.ndarray, np.ndarray]:
    """For points p of one body, the containing (or nearest) cell among `cells` and its xi.

    Candidates by centroid distance, nearest first; a point stops at the first cell that
    contains it, the others try up to k cells and keep the least outside one.
    """
    centre = coarse.x[cells].mean(axis=1)
    k = min(k, len(cells))
    _, cand = cKDTree(centre).query(p, k=k)
    cand = cand.reshape(len(p), k)
    best = np.full(len(p), -1)
    best_xi = np.zeros((len(p), 2))
    best_out = np.full(len(p), np.inf)
    todo = np.arange(len(p))
    for j in range(k):
        c = cells[cand[todo, j]]
        xi = _pull_back(coarse.x[c], p[todo])
        out = np.max(np.maximum(np.maximum(-xi, xi - 1.0), 0.0), axis=1)
        better = out < best_out[todo]
        idx = todo[better]
        best[idx], best_xi[idx], best_out[idx] = c[better], xi[better], out[better]
        todo = todo[best_out[todo] > 1e-10]
        if not len(todo):
            break
    return best, np.clip(best_xi, 0.0, 1.0)


def _energy_density(
    g: np.ndarray, E: np.ndarray, nu: np.ndarray, model: Model, hoop: np.ndarray | None = None
) -> np.ndarray:
    """sigma(g) : eps(g) for displacement gradients g (k, 2, 2) in `model`.

    Plane stress takes lambda* = E nu / (1 - nu^2); axisymmetric adds the hoop strain
    `hoop` (u_r / r at the points) to the strain and its trace.
    """
    eps = 0.5 * (g + np.transpose(g, (0, 2, 1)))
    mu = E / (2 * (1 + nu))
    if model is Model.PLANE_STRESS:
        lam = E * nu / (1 - nu**2)
    else:
        lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    tr = eps[:, 0, 0] + eps[:, 1, 1]
    out = 2 * mu * np.einsum("kij,kij->k", eps, eps)
    if model is Model.AXISYMMETRIC and hoop is not None:
        return out + 2 * mu * hoop**2 + lam * (tr + hoop) ** 2
    return out + lam * tr**2


def energy_error(sol: Solution, ref: Solution) -> dict[str, float] | None:
    """{"error", "norm", "relative"}: ||u_ref - u_h||_E, ||u_ref||_E and their ratio.

    Collective; the numbers on rank 0 (None elsewhere). Both solutions must be of the same
    scene (the same bodies, in the same order) on any two meshes.
    """
    fine, coarse = cell_data(ref), cell_data(sol)
    if fine is None or coarse is None:
        return None
    q = np.array([[a, b] for b in GAUSS_X for a in GAUSS_X])
    qw = np.array([a * b for b in GAUSS_W for a in GAUSS_W])
    nq = len(q)
    xr = np.repeat(fine.x, nq, axis=0)
    ur = np.repeat(fine.u, nq, axis=0)
    xiq = np.tile(q, (len(fine.x), 1))
    gref, det = _grad(xr, ur, xiq)
    N, _ = _shape(xiq)
    pts = np.einsum("ka,kai->ki", N, xr)
    weight = np.tile(qw, len(fine.x)) * np.abs(det)
    body = np.repeat(fine.body, nq)
    gh = np.zeros_like(gref)
    uh = np.zeros((len(pts), 2))
    for b in np.unique(body):
        mine = np.flatnonzero(body == b)
        cells = np.flatnonzero(coarse.body == b)
        c, xi = _locate(coarse, cells, pts[mine])
        gh[mine] = _grad(coarse.x[c], coarse.u[c], xi)[0]
        uh[mine] = np.einsum("ka,kai->ki", _shape(xi)[0], coarse.u[c])
    E, nu = np.repeat(fine.E, nq), np.repeat(fine.nu, nq)
    model = sol.scene.model
    hoop_ref = hoop_err = None
    if model is Model.AXISYMMETRIC:
        # u_r / r at the Gauss points (never on the axis) and the 2 pi r of the measure.
        r = pts[:, 0]
        uref = np.einsum("ka,kai->ki", N, ur)
        hoop_ref, hoop_err = uref[:, 0] / r, (uref[:, 0] - uh[:, 0]) / r
        weight = weight * 2 * np.pi * r
    err = float(np.sqrt(np.sum(weight * _energy_density(gref - gh, E, nu, model, hoop_err))))
    norm = float(np.sqrt(np.sum(weight * _energy_density(gref, E, nu, model, hoop_ref))))
    return {"error": err, "norm": norm, "relative": err / norm}
