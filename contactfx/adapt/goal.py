"""An estimate of the error in the quantity a run stops on: a two-level comparison.

The level's solution is compared with a second solve of the same scene on a mesh whose
cells near the contact are halved (the pressure goal: the cells within a few contact cells
of the surfaces and within REACH zone lengths of each contact zone, where the pressure's
error is made) or whose every cell is halved (energy, force). If the error behaves like
C h^r, the difference d = ||q_h - q_h/2|| lies between (1 - 2^-r) and (1 + 2^-r) times
||q - q_h||, so d / (1 - 2^-r) is between 1 and (1 + 2^-r) / (1 - 2^-r) times the error:
for the pressure (P1 multipliers, a square-root edge: L2 rate 1.5 in h) between 1 and 2.1.
That bound needs the refined solution in the asymptotic range, and a zone of two or three
cells is not: halved once, such a zone's refined error stays close to the level's, and the
estimate overshoots the band. So the pressure goal halves the contact cells k times, k the
smallest (at most MAX_HALVINGS) that puts ZONE_SEGMENTS loaded segments across the
narrowest zone, and extrapolates with q = 2^(-1.5 k). A resolved zone keeps k = 1: the
extra refinement costs something on the coarsest levels only. The same bound needs the
refinement to reach every cell whose error the pressure carries, the near field's too:
halving only the cells within half a zone length missed about half the error on adapted
levels, REACH zone lengths about what halving every cell sees, at a smaller cost. The cells
at a zone's edge are refined twice more: the pressure's error there is O(h) with a constant
set by where the edge falls in the cell, and a refined edge cell only half the level's can
be the unluckier one (a refined solution worse than the level's). The rate
stays the assumed 1.5: an observed one needs a third solve (near-only halvings cannot see
the far part, common to both refined solves) or the level sequence, whose pre-asymptotic
levels (an error that stalls from one level to the next) would make it meaningless where
it matters. docs/adapt.md ("Zone halvings and REACH 4") has the measurements.
In the energy norm the two errors are nearly orthogonal (Galerkin): d / sqrt(1 - q^2), q
the ratio of the residual estimates of the two meshes (the observed rate; the estimator's
constant cancels). The force is an energy-squared quantity: rate 2. docs/adapt.md has the
measured effectivities, the cost and where it fails. A pressure singular like 1/sqrt (a
rigid flat punch's corner) has no finite L2 norm, and one whose peak grows like h^-lambda at
a sharp corner breaks the rate the estimate assumes: where the peak (the largest mean
pressure over a few segments) grows like that over two refinements of the contact cells, the
estimate refuses the scene (GoalUnbounded) and names the goals that exist; `adapt` with its
default goal stops on the energy instead.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from ..api import solve, solve_request
from ..errors import InputError
from ..methods.solution import Solution
from ..options import SolverSpec
from ..request import SolveRequest
from ..results.interface import pair_forces
from ..scenes import Model, SizeField
from .curves import (
    SINGULAR_EXPONENT,
    pair_peak,
    peak_exponent,
    pressure_curve,
    pressure_difference,
    shear_parts,
    singular_growth,
)
from .estimate import estimate
from .sizing import cell_sizes, owned_cells, vertex_sizes
from .true_error import energy_error


class Goal(StrEnum):
    """The quantity a run is accurate in."""

    PRESSURE = "pressure"  # relative L2 error of the contact pressure, worst pair
    ENERGY = "energy"  # relative energy-norm error of the displacement
    FORCE = "force"  # relative error of each pair's contact force, worst pair
    RESIDUAL = "residual"  # the residual estimate (adapt/estimate.py): uncalibrated, no solve


# Convergence rates in h of each goal's error: P1 multipliers against a square-root edge
# (L2), Q1 in the energy norm, and the force (an energy-squared quantity).
RATES = {Goal.PRESSURE: 1.5, Goal.ENERGY: 1.0, Goal.FORCE: 2.0}

# The energy goal's error ratio e_h/2 / e_h is the residual estimate's, at most this (a
# refinement that did not reduce the estimate says nothing of the error).
Q_MAX = 0.9

# The refined mesh of the pressure goal halves the cells within this many local contact
# cell sizes of a contact surface (the zone and its edges; the rest keeps its size).
BAND = 3.0

# And the cells within this many zone lengths of a pair's contact zone: the pressure's error
# is also the near field's (the stresses that set the zone's width), not only its own cells
# (the docstring; docs/adapt.md has the measurements).
REACH = 4.0

# The pressure goal's refined mesh puts at least this many loaded segments across each
# contact zone (halving its contact cells up to MAX_HALVINGS times; see the docstring).
ZONE_SEGMENTS = 8
MAX_HALVINGS = 3

# And the cells within EDGE_CELLS of the level's edge cells of a zone's edge (the segment
# the pressure falls to zero in) EDGE_HALVINGS times more: the error there is O(h) with a
# constant set by where the edge falls in the cell, so a refined edge cell of half the
# level's can be the unluckier one and the refined solution worse than the level's
# (measured: docs/adapt.md, "The pre-asymptotic scatter: an edge-refined reference").
EDGE_CELLS = 2.0
EDGE_HALVINGS = 2


class GoalUnbounded(InputError):
    """The goal has no finite value on this scene (e.g. a pressure singular like 1/sqrt).

    `reason`: what was observed, without the advice the message adds.
    """

    def __init__(self, reason: str) -> None:
        super().__init__(f"{reason}: use --goal energy or --goal force")
        self.reason = reason


@dataclass(frozen=True)
class GoalEstimate:
    """A goal's relative error estimate from one refined solve, and what it cost."""

    goal: Goal
    relative: float  # estimated relative error of the level's solution in the goal
    parts: dict[str, float]  # per pair (pressure, force); energy: difference d and ratio q
    rate: float  # r of the extrapolation d / (1 - 2^(-r k))
    dofs: int  # DOFs of the refined solve
    seconds: float  # remesh + refined solve + comparison
    reference: Solution  # the refined solution (a better answer than the level's own)
    halvings: int = 1  # k: the refined mesh's near cells are 2^-k of the level's
    # The pressure goal with friction: the shear's relative L2 difference, extrapolated the
    # same way, per pair. Reported, not bounded (FRICTION_MEANING).
    shear: dict[str, float] = field(default_factory=dict)

    def record(self) -> GoalRecord:
        """The estimate without the refined solution."""
        g = self
        return GoalRecord(
            g.goal, g.relative, dict(g.parts), g.dofs, g.seconds, g.halvings, dict(g.shear)
        )


GOAL_MEANING = {
    Goal.PRESSURE: "the relative L2 error of the contact pressure (worst pair)",
    Goal.ENERGY: "the relative energy-norm error of the displacement",
    Goal.FORCE: "the relative error of each pair's contact force (worst pair)",
    Goal.RESIDUAL: "the relative residual estimate of the energy-norm error (uncalibrated)",
}

# What adapt bounds with friction (the log, adapt.json's `friction`; docs/adapt.md).
FRICTION_MEANING = (
    "with friction the goal is that of the last load step's solution (the residual "
    "indicators read its normal and shear multipliers); the pressure goal bounds the "
    "pressure; the shear is not bounded: its two-level estimate (shear_estimate) is "
    "reported only"
)


@dataclass(frozen=True)
class GoalRecord:
    """A level's goal estimate as recorded: the number, its parts, how it was had."""

    goal: Goal
    relative: float
    parts: dict[str, float]
    dofs: int  # DOFs of the refined solve (0: none, the residual estimate calibrated)
    seconds: float
    halvings: int = 1  # how often the refined mesh halved the contact cells
    shear: dict[str, float] = field(default_factory=dict)  # per pair; reported, not bounded

    @property
    def shear_estimate(self) -> float | None:
        """The worst pair's shear estimate (None without friction)."""
        return max(self.shear.values()) if self.shear else None

    def to_json(self) -> dict[str, Any]:
        """The JSON's `goal`, `goal_estimate`, `goal_parts`, ...; `shear_*` with friction."""
        extra: dict[str, Any] = {}
        if self.shear:
            extra = {"shear_estimate": self.shear_estimate, "shear_parts": dict(self.shear)}
        return {
            **extra,
            "goal": self.goal.value,
            "goal_estimate": self.relative,
            "goal_parts": dict(self.parts),
            "goal_refined_dofs": self.dofs,
            "goal_seconds": self.seconds,
            "goal_halvings": self.halvings,
        }


def refined_field(
    sol: Solution,
    far: float = 1.0,
    near: float = 0.5,
    band: float = BAND,
    reach: float = REACH,
    edge: float | None = None,
) -> SizeField:
    """The current mesh's sizes, times `near` near the contact surfaces, `far` elsewhere.

    Near: within `band` local contact cell sizes of a contact surface, or within `reach`
    times a pair's contact zone length of that zone. `far` 1 leaves the rest unchanged,
    0.5 halves it too. `edge` (if not None): the factor of the cells within EDGE_CELLS
    edge-segment lengths of a zone's edge (`_edges`). Collective; the field's arrays on
    rank 0.
    """
    quads, verts = owned_cells(sol)
    h = cell_sizes(quads)
    factor = np.full(len(h), far)
    if near != far:
        mid = quads.mean(axis=1)
        pts, size = _surface_points(sol)
        dist, nearest = cKDTree(pts).query(mid)
        close = dist <= band * size[nearest]
        for zone, length in _zones(sol):
            if reach > 0 and len(zone):
                close |= cKDTree(zone).query(mid)[0] <= reach * length
        factor[close] = near
        if edge is not None:
            ends, lengths = _edges(sol)
            if len(ends):
                dist, nearest = cKDTree(ends).query(mid)
                factor[dist <= EDGE_CELLS * lengths[nearest]] = edge
    return vertex_sizes(sol.scene.comm, quads, verts, h * factor)


def _edges(sol: Solution) -> tuple[np.ndarray, np.ndarray]:
    """Both end nodes of every segment a zone ends in (one end loaded), and its length."""
    points, lengths = [], []
    for pv in sol.pairs:
        x, seg = pv.active.surface.x[:, :2], pv.active.surface.segments
        p = pv.nodal(sol.pressure)
        ends = seg[(p[seg[:, 0]] > 0) ^ (p[seg[:, 1]] > 0)]
        length = np.linalg.norm(x[ends[:, 1]] - x[ends[:, 0]], axis=1)
        points += [x[ends[:, 0]], x[ends[:, 1]]]
        lengths += [length, length]
    if not points:
        return np.zeros((0, 2)), np.zeros(0)
    return np.concatenate(points), np.concatenate(lengths)


def zone_halvings(sol: Solution) -> int:
    """k: halvings of the contact cells that put ZONE_SEGMENTS loaded segments across each zone.

    1 when every zone already has ZONE_SEGMENTS / 2 (or no pair carries load), at most
    MAX_HALVINGS.
    """
    counts = [len(zone) for zone, _ in _zones(sol) if len(zone)]
    k = 1
    while counts and min(counts) * 2**k < ZONE_SEGMENTS and k < MAX_HALVINGS:
        k += 1
    return k


def _zones(sol: Solution) -> list[tuple[np.ndarray, float]]:
    """Per pair: midpoints of the active surface's loaded segments, and their total length."""
    out = []
    for pv in sol.pairs:
        x, seg = pv.active.surface.x[:, :2], pv.active.surface.segments
        p = pv.nodal(sol.pressure)
        on = (p[seg[:, 0]] > 0) | (p[seg[:, 1]] > 0)
        a, b = x[seg[on, 0]], x[seg[on, 1]]
        out.append((0.5 * (a + b), float(np.sum(np.linalg.norm(b - a, axis=1)))))
    return out


def _surface_points(sol: Solution) -> tuple[np.ndarray, np.ndarray]:
    """Midpoints and lengths of every contact segment (both sides of every pair)."""
    mids, lengths = [], []
    for pv in sol.pairs:
        for side in (pv.active, pv.passive):
            if side is None:
                continue
            x, seg = side.surface.x[:, :2], side.surface.segments
            mids.append(0.5 * (x[seg[:, 0]] + x[seg[:, 1]]))
            lengths.append(np.linalg.norm(x[seg[:, 1]] - x[seg[:, 0]], axis=1))
    return np.concatenate(mids), np.concatenate(lengths)


def _check_bounded(
    sol: Solution,
    ref: Solution,
    solver: SolverSpec | str | SolveRequest,
    options: dict[str, Any],
) -> None:
    """GoalUnbounded if a pair's peak pressure grows like a singularity's over two refinements.

    `ref` (the goal's refined solve) is the first refinement; only where a pair's peak grew
    on it is the second solved: the refined mesh's contact cells halved again.
    """
    first = [
        (pair_peak(a, sol.pressure), pair_peak(b, ref.pressure))
        for a, b in zip(sol.pairs, ref.pairs, strict=True)
    ]
    if all(peak_exponent(*f) < SINGULAR_EXPONENT for f in first):
        return
    again = _refined(ref, refined_field(ref, far=1.0, near=0.5, reach=0.0), solver, options)
    for pv, (p0, p1), pw in zip(sol.pairs, first, again.pairs, strict=True):
        p2 = pair_peak(pw, again.pressure)
        exponents = singular_growth([p0, p1, p2])
        if exponents is not None:
            grew = ", ".join(f"h^-{e:.2f}" for e in exponents)
            raise GoalUnbounded(
                f"{pv.label}: the peak pressure grows like {grew} over two refinements of the "
                f"contact cells ({p0[0]:.4g}, {p1[0]:.4g}, {p2[0]:.4g}): a singular edge, "
                "whose pressure has no L2 error to bound"
            )


def _refined(
    sol: Solution,
    field: SizeField,
    solver: SolverSpec | str | SolveRequest,
    options: dict[str, Any],
) -> Solution:
    """The same scene solved on the mesh of `field`, the level's active set as first guess.

    `solver` a SolveRequest: the level's own request (its enforcement, basis and solver).
    """
    scene = sol.scene.remeshed_to(field)
    if isinstance(solver, SolveRequest):
        return solve_request(scene, solver, initial=sol)
    return solve(scene, sol.method, solver=solver, initial=sol, **options)


def goal_estimate(
    sol: Solution,
    goal: Goal | str,
    *,
    solver: SolverSpec | str | SolveRequest = "mumps",
    options: dict[str, Any] | None = None,
    rate: float | None = None,
    reach: float = REACH,
) -> GoalEstimate:
    """The relative error of `sol` in `goal`, from a solve on a refined mesh (collective).

    Args:
        sol: A multiplier-method solution of a scene that can be remeshed.
        goal: pressure (contact cells halved k times, zone_halvings), energy or force
            (every cell halved).
        solver: The refined solve's solver (the level's own, normally), or the level's
            whole SolveRequest (penalty, mortar's basis: the refined solve is the same).
        options: Further `api.solve` options of the level's solve (not `initial`).
        rate: r of the extrapolation; if None, RATES[goal] (pressure, force) or the
            residual estimate's observed rate between the two meshes (energy).
        reach: The pressure goal's refined region around each zone, in zone lengths.

    Raises:
        GoalUnbounded: The pressure of a pair is singular (its L2 norm is infinite).
    """
    goal = Goal(goal)
    if goal is Goal.RESIDUAL:
        raise ValueError("the residual goal is the residual estimate itself (adapt/estimate.py)")
    r = RATES[goal] if rate is None else rate
    t0 = time.perf_counter()
    # Energy and force halve every cell once; the pressure its contact cells k times.
    k = zone_halvings(sol) if goal is Goal.PRESSURE else 1
    far, near = (1.0, 0.5**k) if goal is Goal.PRESSURE else (0.5, 0.5)
    edge = 0.5 ** (k + EDGE_HALVINGS) if goal is Goal.PRESSURE else None
    field = refined_field(sol, far=far, near=near, reach=reach, edge=edge)
    ref = _refined(sol, field, solver, options or {})
    q = 2.0 ** (-r * k)
    parts: dict[str, float] = {}
    shear: dict[str, float] = {}
    if goal is Goal.ENERGY:
        e = sol.scene.comm.bcast(energy_error(sol, ref), root=0)
        parts["difference"] = e["relative"]
        if rate is None:
            # The residual estimate's ratio is the energy error's (its constant cancels).
            q = min(estimate(ref).total / max(estimate(sol).total, 1e-300), Q_MAX)
            r = -float(np.log2(q))
        parts["ratio"] = q
        relative = e["relative"] / np.sqrt(1.0 - q * q)
    elif goal is Goal.PRESSURE:
        _check_bounded(sol, ref, solver, options or {})
        for pv, pr in zip(sol.pairs, ref.pairs, strict=True):
            d, n = pressure_difference(
                pressure_curve(pv, sol.pressure),
                pressure_curve(pr, ref.pressure),
                radial=sol.scene.model is Model.AXISYMMETRIC,
            )
            parts[pv.label] = d / n / (1.0 - q) if n > 0 else 0.0
        relative = max(parts.values(), default=0.0)
        shear = shear_parts(sol, ref, q)
    else:
        for k, pv in enumerate(sol.pairs):
            fine = _force(ref, k)
            parts[pv.label] = abs(_force(sol, k) - fine) / max(fine, 1e-300) / (1.0 - q)
        relative = max(parts.values(), default=0.0)
    seconds = time.perf_counter() - t0
    return GoalEstimate(goal, float(relative), parts, r, ref.dofs, seconds, ref, k, shear)


def _force(sol: Solution, k: int) -> float:
    """The magnitude of pair k's total contact force on its active body."""
    return float(np.linalg.norm(pair_forces(sol, k)[0]))
