"""The coarse predictor: a first active set from a solve of the same scene on a coarser mesh.

A superset of the converged set makes the loop factorize once and then only release rows;
for the condensed solver (no probes) every ring of nodes it need not add or release saves a
whole solve. Whether it pays is `use_coarse`'s rule (measured in docs/scale.md).
"""

from __future__ import annotations

import logging
from dataclasses import replace

import numpy as np

from ..contact.grid import PointGrid
from ..contact.zone import covered, edge_distances
from ..discretize.mesh_utils import owned_facets, scene_dofs
from ..errors import InputError, MeshError
from ..logs import stage
from ..options import SOLVERS, CoarseStart, Predictor, SolverSpec, System
from ..request import SolveRequest
from ..scenes import Scene
from ..timers import Timers
from .active_set import ActiveSetOptions, InitialSet
from .multipliers import solve_contact
from .solution import Solution

log = logging.getLogger("contactfx")

# Above this many DOFs, "auto" starts from a coarser solve where the kind says so
# (CoarseStart.DOFS: fieldsplit): one factorization then suffices.
COARSE_PREDICTOR_DOFS = 200_000
# The least coarsening of a user's scene that gmsh cannot mesh at the kind's factor.
COARSE_FACTOR = 8.0
# The condensed first set reaches this many fine elements past each estimated zone edge
# (issue 33: fitted on the cases of docs/scale.md, "An exact first set").
EDGE_MARGIN = 0.17


# A direct solver's probes are selected entries of the inverse, whose cost grows with the
# candidates: up to this many rows the loop starts from every row and probes them all, above
# it from the coarse solve, probing only its uncertain band; the crossover is
# measured in docs/scale.md#measured-constants ("Probe every row up to").
PROBE_ALL_ROWS = 300
# The coarse solve itself starts from every row and probes them all: its mesh is coarsened
# until it has at most this many (docs/scale.md#measured-constants, "Coarse factor").
COARSE_ROWS = 500


def contact_facets(scene: Scene) -> int:
    """Facets on the pairs' active surfaces: about the multiplier rows (collective)."""
    groups = [p.active for p in scene.contacts] + [o.surface for o in scene.obstacles]
    return int(scene.comm.allreduce(sum(len(owned_facets(scene, g)) for g in groups)))


def use_coarse(predictor: Predictor, scene: Scene, spec: SolverSpec) -> bool:
    """Whether `predictor` asks for a coarse solve of `scene` with this solver.

    auto: as the kind's `coarse_start` says: ROWS (a factorization) when the active surfaces
    hold more than PROBE_ALL_ROWS rows and the scene can be remeshed (else every row is
    probed), ALWAYS (the condensed loop has no probes), DOFS from COARSE_PREDICTOR_DOFS.
    """
    if predictor is not Predictor.AUTO:
        return predictor is Predictor.COARSE
    start = spec.traits.coarse_start
    if start is CoarseStart.ROWS:
        return scene.can_remesh and contact_facets(scene) > PROBE_ALL_ROWS
    if start is CoarseStart.ALWAYS:
        return True
    return scene_dofs(scene) >= COARSE_PREDICTOR_DOFS


# The condensed loop runs unprobed: on its coarse mesh too it adds a ring of nodes, then
# releases a few per step, each step CG with a lagged multigrid, which is slow
# (docs/scale.md#measured-constants, "Direct predictor"). The coarse set is only a guess, so
# it is solved by the kind's `coarse_solver` (the direct default: one factorization, all
# rows probed) up to this many coarse DOFs.
DIRECT_PREDICTOR_DOFS = 2_000_000


def predictor_solver(spec: SolverSpec, coarse_dofs: int) -> SolverSpec:
    """The solver of the coarse solve: the kind's `coarse_solver` up to DIRECT_PREDICTOR_DOFS."""
    name = spec.traits.coarse_solver
    if name is not None and coarse_dofs <= DIRECT_PREDICTOR_DOFS:
        return SOLVERS[name]
    return spec


def coarse_factor(spec: SolverSpec, scene: Scene) -> float:
    """How much coarser the predictor's mesh is (every size times this; collective).

    The kind's `coarse_factor`; a factorization's is doubled until the coarse rows (about
    the fine ones over the factor: the surfaces are curves) are at most COARSE_ROWS, since
    the coarse solve probes them all; a wider fine band costs its probes little
    (docs/scale.md#measured-constants, "Coarse factor").
    """
    traits = spec.traits
    factor = traits.coarse_factor
    if not traits.factorizes:
        return factor
    rows = contact_facets(scene)
    while rows / factor > COARSE_ROWS:
        factor *= 2.0
    return factor


def coarse_margin(spec: SolverSpec) -> float:
    """Coarse elements of margin around the coarse zone (the kind's `coarse_margin`).

    A direct solver probes the uncertain band, so a generous superset costs it nothing; the
    condensed loop pays a solve per ring it must release (docs/scale.md, "Coarse predictor").
    """
    return spec.traits.coarse_margin


def _coarse_radius(coarse: Solution, margin: float) -> float:
    """`margin` coarse elements: the largest node spacing in the coarse contact zone."""
    x = np.asarray(coarse.layout.x)[:, :2]
    act = np.asarray(coarse.active, dtype=bool)
    # Bucket grids instead of scipy.spatial's KD-trees: a plain solve then never imports
    # scipy.spatial, whose import is a fixed cost (docs/scale.md, "Time to the first answer").
    extent = float(np.ptp(x, axis=0).max()) if len(x) > 1 else 0.0
    grid = PointGrid(x, extent / max(len(x), 1))  # about the spacing of points on a curve
    spacing = grid.nearest(x[act], np.flatnonzero(act)) if len(x) > 1 else np.zeros(1)
    return margin * float(spacing.max())


def coarse_initial_set(coarse: Solution, margin: float = 1.5, band: float = 2.0) -> InitialSet:
    """An InitialSet from the solution of the same scene on a coarser mesh.

    In contact: nodes within `margin` coarse elements of a coarse active node; uncertain:
    those within `band` coarse elements of a coarse inactive node (the zone's edge, wider
    inwards: a coarse node-to-segment zone overshoots the fine one by up to two elements).
    The coarse element size is the largest node spacing in the coarse contact zone.
    """
    x = np.asarray(coarse.layout.x)[:, :2]
    act = np.asarray(coarse.active, dtype=bool)
    if not act.any():
        return InitialSet(lambda p: np.zeros(len(p), dtype=bool))
    r = _coarse_radius(coarse, margin)
    r_band = r * band / margin
    grid_a = PointGrid(x[act], r)
    grid_i = PointGrid(x[~act], r_band) if (~act).any() else None

    def near(grid: PointGrid | None, p: np.ndarray, d: float) -> np.ndarray:
        if grid is None or len(p) == 0:
            return np.zeros(len(p), dtype=bool)
        return grid.any_within(np.asarray(p)[:, :2], d)

    return InitialSet(lambda p: near(grid_a, p, r), lambda p: near(grid_i, p, r_band))


def _remeshed(scene: Scene, factor: float) -> tuple[Scene, float]:
    """The scene remeshed `factor` times coarser, or less where gmsh cannot, and the factor.

    A user's .geo may have curves with a few elements, which x16 leaves unmeshable (gmsh:
    "1D mesh cannot be divided by 2"): the factor halves down to COARSE_FACTOR.
    """
    while True:
        try:
            return scene.remeshed(factor), factor
        except MeshError:
            if factor <= COARSE_FACTOR:
                raise
            factor /= 2.0
            if scene.comm.rank == 0:
                log.info("coarse predictor: gmsh cannot mesh it that coarse, trying x%g", factor)


def sharp_initial_set(
    coarse: Solution, factor: float, margin: float = 0.5, edge_margin: float = EDGE_MARGIN
) -> InitialSet:
    """An InitialSet for the condensed loop: the coarse zone with each edge estimated.

    Along each pair's coarse active surface, the zone covers the segments between active
    nodes and, past its last active node, reaches the edge estimated from the coarse
    pressures plus `edge_margin` fine elements (a coarse segment over `factor`); where no
    smooth edge is resolved, `margin` coarse elements as `coarse_initial_set`
    (`contact.zone.edge_distances`). A fine node is in contact if it lies on the covered part.
    """
    act = np.asarray(coarse.active, dtype=bool)
    if not act.any():
        return InitialSet(lambda p: np.zeros(len(p), dtype=bool))
    r = _coarse_radius(coarse, margin)
    parts = []
    for pv in coarse.pairs:
        surf = pv.active.surface
        on = np.zeros(surf.n_nodes, dtype=bool)
        on[pv.nodes] = act[pv.rows]
        p = pv.nodal(coarse.pressure)
        parts.append((surf, *edge_distances(surf.x, surf.segments, on, p, r, edge_margin / factor)))

    def active(p: np.ndarray) -> np.ndarray:
        pts = np.asarray(p)[:, :2]
        out = np.zeros(len(pts), dtype=bool)
        for surf, from_a, from_b in parts:
            out |= covered(pts, surf, from_a, from_b, r)
        return out

    return InitialSet(active)


def initial_set(coarse: Solution, spec: SolverSpec, factor: float) -> InitialSet:
    """The first set from the coarse solution: sharp for the condensed system (no probes)."""
    if spec.system is System.CONDENSED:
        return sharp_initial_set(coarse, factor, coarse_margin(spec))
    return coarse_initial_set(coarse, margin=coarse_margin(spec))


def predict(
    scene: Scene, request: SolveRequest, aso: ActiveSetOptions, timers: Timers
) -> InitialSet | None:
    """The coarse predictor's first set for `scene`, or None where it is not used."""
    predictor, spec = request.predictor, request.solver
    if not use_coarse(predictor, scene, spec):
        return None
    if not scene.can_remesh:
        if predictor is Predictor.COARSE:
            raise InputError(
                f"--predictor coarse: scene '{scene.name}' cannot be remeshed (a .msh or an "
                "in-memory gmsh model): use --predictor auto or none"
            )
        if scene.comm.rank == 0:
            log.info("coarse predictor: the scene cannot be remeshed, starting without it")
        return None
    with timers("predictor"), stage("predictor"):
        coarse, factor = _remeshed(scene, coarse_factor(spec, scene))
        coarse_request = replace(
            request, solver=predictor_solver(spec, scene_dofs(coarse)), reference_timing=False
        )
        sol = solve_contact(coarse, coarse_request, aso=aso, label="predictor")
        return initial_set(sol, spec, factor)
