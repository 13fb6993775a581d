"""A new mesh size from the error indicators: equidistribution at the element's rate.

For Q1 elements the energy error converges like h^p, p = 1, so a cell's indicator scales
like eta_K ~ h_K^(p + 1) in 2D (h^p times the square root of the area). A cell of size h'
in K's place has eta' = eta_K (h'/h_K)^(p+1); asking every new cell for the same eta_t
gives h'_K = h_K (eta_t / eta_K)^(1/(p+1)), N' = sum_K (eta_K/eta_t)^(2/(p+1)) cells and
a predicted total eta'^2 = N' eta_t^2. eta_t is the larger of the value that meets the
tolerance and the value that keeps N' within the growth and DOF budget; the change of size
per level is clipped (x 1/4 .. x 2: the indicators are asymptotic statements).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from ..methods.solution import Solution
from ..scenes import SizeField
from .estimate import Estimate
from .pressure_sizing import pressure_cell_sizes


@dataclass(frozen=True)
class SizingRule:
    """How the next mesh is sized: the rate, the clipping of each step, the contact weight.

    The cells a level may have are the loop's (`plan_mesh`'s max_cells).
    """

    rate: float = 1.0  # p: energy-norm convergence rate of the element (Q1: 1)
    finest: float = 0.25  # a cell's size shrinks at most to this fraction per level
    coarsest: float = 2.0  # and grows at most by this factor
    # Sizing (not the estimate) takes each cell's contact terms times this weight (its
    # default per goal: AdaptOptions.weight, adapt/records.py).
    contact_weight: float = 1.0


@dataclass(frozen=True)
class Plan:
    """The next mesh: its size field (on rank 0) and the cells it is planned to have."""

    field: SizeField
    cells: float
    predicted: float  # predicted relative estimate on it


def owned_cells(sol: Solution) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 4, 2) in gmsh order, global vertex ids (n, 4)) of the owned cells."""
    msh = sol.scene.mesh
    tdim = msh.topology.dim
    n = msh.topology.index_map(tdim).size_local
    msh.topology.create_connectivity(tdim, 0)
    c2v = msh.topology.connectivity(tdim, 0).array.reshape(-1, 4)[:n]
    geo = msh.geometry.dofmaps[0][:n]
    # DOLFINx orders a quad's vertices (0,0),(1,0),(0,1),(1,1); gmsh goes round the cell.
    order = [0, 1, 3, 2]
    gv = msh.topology.index_map(0).local_to_global(c2v[:, order].ravel().astype(np.int32))
    return msh.geometry.x[geo][:, order, :2], gv.reshape(-1, 4)


def cell_sizes(quads: np.ndarray) -> np.ndarray:
    """Each quad's size: the square root of its area (from the diagonals' cross product)."""
    d1, d2 = quads[:, 2] - quads[:, 0], quads[:, 3] - quads[:, 1]
    return np.sqrt(0.5 * np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]))


def vertex_sizes(comm: MPI.Comm, quads: np.ndarray, verts: np.ndarray, h: np.ndarray) -> SizeField:
    """The size field on rank 0: at each vertex the smallest new size of the cells around it.

    Gathered first, so that a vertex on a process boundary sees the cells of both ranks;
    the cells sorted by midpoint, so that the field does not depend on the partition.
    """
    parts = comm.gather((quads, verts, h), root=0)
    if parts is None:
        return SizeField(np.zeros((0, 4, 2)), np.zeros((0, 4)))
    quads = np.concatenate([p[0] for p in parts])
    verts = np.concatenate([p[1] for p in parts])
    h = np.concatenate([p[2] for p in parts])
    mid = quads.mean(axis=1)
    order = np.lexsort((mid[:, 1], mid[:, 0]))
    quads, verts, h = quads[order], verts[order], h[order]
    ids, inverse = np.unique(verts, return_inverse=True)
    node = np.full(len(ids), np.inf)
    np.minimum.at(node, inverse.ravel(), np.repeat(h, 4))
    return SizeField(quads, significant(node[inverse.reshape(verts.shape)], SIZE_DIGITS))


# Sizes handed to gmsh keep this many significant digits. gmsh's discrete decisions flip on
# round-off (a size perturbed by 1e-13 moved a node in one of three trials), and the sizes
# of 1 and 2 ranks differ at round-off: rounded, they are equal unless a value sits within
# round-off of a rounding boundary (about 1e-9 of the values at this precision).
SIZE_DIGITS = 6


def significant(a: np.ndarray, digits: int) -> np.ndarray:
    """Positive `a` rounded to `digits` significant digits."""
    scale = 10.0 ** np.floor(np.log10(np.maximum(a, 1e-300)))
    return np.round(a / scale, digits - 1) * scale


def _budget_target(
    comm: MPI.Comm, eta: np.ndarray, budget: float, q: float, rule: SizingRule
) -> float:
    """The eta_t whose clipped sizes give `budget` cells (bisection in log eta_t).

    Without clipping eta_t = (S / budget)^(q/2); clipping changes the count (weighted
    indicators coarsen the bulk to the x 2 limit while the contact zone is held at x 1/4),
    so the count is matched after clipping: it falls monotonically with eta_t.
    """

    def cells(t: float) -> float:
        f = np.clip((t / eta) ** (1 / q), rule.finest, rule.coarsest)
        return float(comm.allreduce(float(np.sum(f**-2.0))))

    S = comm.allreduce(float(np.sum(eta ** (2 / q))))
    lo = hi = (S / budget) ** (q / 2)
    while cells(lo) < budget and lo > 1e-300:
        lo /= 4.0
    while cells(hi) > budget and hi < 1e300:
        hi *= 4.0
    for _ in range(60):
        mid = float(np.exp(0.5 * (np.log(lo) + np.log(hi))))  # sqrt(lo hi) would overflow
        lo, hi = (mid, hi) if cells(mid) > budget else (lo, mid)
    return float(hi)


def _factor(
    comm: MPI.Comm,
    eta: np.ndarray,
    budget: float,
    eta_tol: float,
    q: float,
    rule: SizingRule,
    cap: np.ndarray | None = None,
) -> np.ndarray:
    """Each cell's new size / old size: the energy's, at most `cap` (the pressure's)."""
    eta_t = max(_budget_target(comm, eta, budget, q, rule), eta_tol)
    factor = np.clip((eta_t / eta) ** (1 / q), rule.finest, rule.coarsest)
    return factor if cap is None else np.minimum(factor, cap)


def plan_mesh(
    sol: Solution,
    est: Estimate,
    tol: float | None,
    max_cells: float,
    rule: SizingRule = SizingRule(),
    pressure_tol: float | None = None,
) -> Plan:
    """The size field of the next level (collective; the field's arrays on rank 0).

    At most `max_cells` cells; fewer where they reach the relative estimate `tol` (None: the
    cells decide). With `pressure_tol`, the cells along the contact surfaces are also sized for the
    pressure estimate (results/pressure_sizing.py) and the energy sizing gets the budget
    that leaves.
    """
    comm = sol.scene.comm
    msh = sol.scene.mesh
    Q = est.eta.function_space
    nloc = msh.topology.index_map(2).size_local
    eta_true = est.eta.x.array[Q.dofmap.list[:nloc, 0]]
    quads, verts = owned_cells(sol)
    eta = est.marking(rule.contact_weight)
    h = cell_sizes(quads)
    q = rule.rate + 1.0
    eta = np.maximum(eta, 1e-300)
    S = comm.allreduce(float(np.sum(eta ** (2 / q))))
    budget = max_cells
    eta_tol = 0.0 if tol is None else ((tol * est.energy) ** 2 / S) ** (1 / (2 - 2 / q))
    h_p = np.full(len(h), np.inf)
    if pressure_tol is not None and est.pressure is not None:
        h_p = pressure_cell_sizes(est.pressure, pressure_tol, quads, h, rule.finest)
    factor = _factor(comm, eta, budget, eta_tol, q, rule, h_p / h)
    cells = comm.allreduce(float(np.sum(factor**-2.0)))
    if cells > budget:
        # The pressure's cells come first: the energy sizing gets what they leave.
        extra = cells - comm.allreduce(
            float(np.sum(_factor(comm, eta, budget, eta_tol, q, rule) ** -2.0))
        )
        factor = _factor(comm, eta, max(budget - extra, 0.1 * budget), eta_tol, q, rule, h_p / h)
        cells = comm.allreduce(float(np.sum(factor**-2.0)))
    eta_true = np.maximum(eta_true, 1e-300)
    predicted = float(np.sqrt(comm.allreduce(float(np.sum((eta_true * factor ** (q - 1)) ** 2)))))
    field = vertex_sizes(comm, quads, verts, h * factor)
    return Plan(field, cells, predicted / est.energy)
