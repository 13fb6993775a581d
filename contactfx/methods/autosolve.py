"""The default solver `auto`: MUMPS' factorization unless MUMPS says it would not fit.

Before any factorization MUMPS' analysis alone runs on the loop's own saddle-point solver
(`SaddleSolver.mumps_estimate`) and gives the memory its factorization will allocate.
On each node the ranks' estimates add up against the memory available there; with room (the
SAFETY factor) the direct path runs and its first factorization reuses that analysis, else
the condensed path runs (multipliers eliminated, CG + GAMG) where D is diagonal, and
elsewhere the run is refused before factorizing. First, on the family it was measured on,
a model of MUMPS' estimate from the graph (`mumps_model`) decides without any analysis
where even its lower bound does not fit. On a large scene the analysis of the
same scene meshed coarser (a quarter of the DOFs) comes first: its estimate scaled to the
fine DOFs is a lower bound, and where even that does not fit the fine analysis is skipped.
The rule and its measurements: docs/scale.md, "The default solver".
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from typing import Any, cast

from dolfinx import mesh
from mpi4py import MPI
from petsc4py import PETSc

from ..discretize.mesh_utils import max_cell_aspect, scene_dofs
from ..discretize.setup import ContactSetup, prepare_contact
from ..errors import InputError
from ..linalg import LinearSolver
from ..linalg.saddle import SaddleSolver
from ..options import SOLVERS, SolverKind
from ..request import SolveRequest, direct_path
from ..scenes import Scene
from ..timers import Timers
from .cleanup import dropped, released
from .mumps_model import MODEL_MAX_ASPECT, model_bound
from .solver_choice import (
    CHECK_KB_PER_DOF,
    COARSE_BOUND_DOFS,
    COARSE_BOUND_FACTOR,
    CONDENSED,
    SAFETY,
    Choice,
    SolverChoice,
    choose,
    node_budget,
    scaled_bound,
)
from .solvers import setup_solver

log = logging.getLogger("contactfx")


@dataclass
class Prepared:
    """A multiplier run's fine setup, its request (solver resolved) and a ready solver."""

    setup: ContactSetup
    request: SolveRequest
    linear: LinearSolver | None = None  # the direct solver whose analysis is done
    choice: SolverChoice | None = None

    def destroy(self) -> None:
        """Free the solver and the setup (on an error before the loop takes them)."""
        if self.linear is not None:
            self.linear.destroy()
        self.setup.destroy()


def prepare_solver(
    scene: Scene, request: SolveRequest, penetration_tol: float, timers: Timers
) -> Prepared:
    """Assemble the contact setup of `scene` and resolve an `auto` solver on it."""
    setup = prepare_contact(scene, request.kernel, penetration_tol, timers, request.basis)
    if request.solver.kind is not SolverKind.AUTO:
        return Prepared(setup, request)
    try:
        with timers("solve"):  # the decision's cost, as the analyses' below
            modelled = _model_bound(setup, scene, request)
        if modelled is not None:
            return modelled
        coarse = _coarse_bound(setup, scene, request, penetration_tol, timers)
        if coarse is not None:
            return coarse
        return _resolve(setup, scene, request, timers)
    except BaseException:
        dropped(scene.comm, setup)
        raise


def _model_bound(setup: ContactSetup, scene: Scene, request: SolveRequest) -> Prepared | None:
    """The choice without any analysis where even the model's lower bound does not fit.

    `mumps_model.model_bound` bounds MUMPS' estimate from below from the graph (DOFs, K's
    nonzeros, the ranks) on the family it was measured on, with auto's own MUMPS options;
    where 1.25 x that bound exceeds the memory available, the analysis would choose the
    condensed path (or refuse) too. None (an analysis decides) where it fits or does not apply.
    """
    if request.solver.petsc != SOLVERS["auto"].petsc:
        return None  # other MUMPS options (ordering, out-of-core) estimate otherwise
    comm = scene.comm
    K = setup.elasticity.K
    nnz = int(K.getInfo(cast(Any, PETSc.Mat.InfoType.GLOBAL_SUM))["nz_used"])
    bound = model_bound(K.getSize()[0], nnz, comm.size)
    if bound is None:
        return None
    needed, avail = node_budget(comm, bound / comm.size, request.available_mb)
    choice = choose(needed, avail, request.diagonal)
    if choice is Choice.DIRECT:
        return None
    # Checked only where it would decide (a pass over the cells): stretched cells fill less.
    if comm.allreduce(max_cell_aspect(scene.mesh), op=MPI.MAX) > MODEL_MAX_ASPECT:
        return None
    assert needed is not None and avail is not None
    ran = CONDENSED if choice is Choice.CONDENSED else direct_path(request.solver).name
    return _condensed(setup, comm, request, SolverChoice(ran, needed, avail, None, model=True))


def _coarse_bound(
    setup: ContactSetup,
    scene: Scene,
    request: SolveRequest,
    penetration_tol: float,
    timers: Timers,
) -> Prepared | None:
    """The choice from a coarse system's analysis where even its lower bound does not fit.

    Runs on a remeshable scene whose coarse system (sizes x COARSE_BOUND_FACTOR) holds at
    least COARSE_BOUND_DOFS, where CHECK_KB_PER_DOF says the fine estimate might not fit:
    MUMPS' estimate for the coarse system, scaled to the fine DOFs, is a lower bound of the
    fine estimate, compared with the memory available before any fine analysis. None (the
    fine analysis decides) where it fits or is unknown.
    """
    dofs = scene_dofs(scene)
    if not scene.can_remesh or dofs < COARSE_BOUND_DOFS * COARSE_BOUND_FACTOR**2:
        return None
    comm = scene.comm
    share = CHECK_KB_PER_DOF * dofs / 1e3 / comm.size  # MB per rank
    if choose(*node_budget(comm, share, request.available_mb), True) is Choice.DIRECT:
        return None  # it would fit even at that much per DOF: the fine analysis decides
    direct = direct_path(request.solver)
    with timers("solve"):
        coarse = scene.remeshed(COARSE_BOUND_FACTOR)
        coarse_dofs = scene_dofs(coarse)
        csetup = prepare_contact(coarse, request.kernel, penetration_tol, Timers(), request.basis)
        with released(comm, csetup):
            linear = setup_solver(csetup, direct, coarse, reuse=True)
            with released(comm, linear):
                est = linear.mumps_estimate() if isinstance(linear, SaddleSolver) else None
    rank_mb = None if est is None else scaled_bound(est.rank_mb, coarse_dofs, dofs)
    needed, avail = node_budget(comm, rank_mb, request.available_mb)
    choice = choose(needed, avail, request.diagonal)
    if choice is Choice.DIRECT:
        if comm.rank == 0:  # it may fit: the fine analysis decides (and is reused if so)
            bound = SolverChoice(direct.name, needed, avail, None, coarse_dofs=coarse_dofs)
            log.info("solver: coarse check: %s; the fine analysis decides", bound.reason)
        return None
    assert needed is not None and avail is not None and est is not None
    ran = CONDENSED if choice is Choice.CONDENSED else direct.name
    record = SolverChoice(ran, needed, avail, est.seconds, coarse_dofs=coarse_dofs)
    return _condensed(setup, scene.comm, request, record)


def _resolve(setup: ContactSetup, scene: Scene, request: SolveRequest, timers: Timers) -> Prepared:
    """Run MUMPS' analysis on the loop's direct solver and choose (module docstring)."""
    direct = replace(request, solver=direct_path(request.solver))
    linear = setup_solver(setup, direct.solver, scene, reuse=True)
    try:
        with timers("solve"):
            estimate = linear.mumps_estimate() if isinstance(linear, SaddleSolver) else None
        needed, avail = node_budget(
            scene.comm, None if estimate is None else estimate.rank_mb, request.available_mb
        )
        choice = choose(needed, avail, request.diagonal)
    except BaseException:
        dropped(scene.comm, linear)
        raise
    seconds = None if estimate is None else estimate.seconds
    if choice is Choice.DIRECT:
        record = SolverChoice(direct.solver.name, needed, avail, seconds)
        _say(record, scene.comm)
        return Prepared(setup, direct, linear, record)
    linear.destroy()  # frees MUMPS' analysis before the other path runs
    assert needed is not None and avail is not None  # a known estimate that does not fit
    ran = CONDENSED if choice is Choice.CONDENSED else direct.solver.name
    return _condensed(setup, scene.comm, request, SolverChoice(ran, needed, avail, seconds))


def _condensed(
    setup: ContactSetup, comm: MPI.Comm, request: SolveRequest, record: SolverChoice
) -> Prepared:
    """The condensed path where MUMPS does not fit; a one-line refusal where D is not diagonal."""
    if record.ran != CONDENSED:
        assert record.needed_mb is not None and record.available_mb is not None
        bound = ">= " if record.coarse_dofs is not None or record.model else ""
        raise InputError(
            f"the direct solver would not fit: MUMPS estimates {bound}"
            f"{record.needed_mb / 1e3:.2f} GB, {record.available_mb / 1e3:.2f} GB available "
            f"(margin x{SAFETY:g}); use --method mortar --basis dual (or nts) for the "
            "condensed path, or fewer DOFs"
        )
    _say(record, comm)
    if request.solver.petsc != SOLVERS["auto"].petsc and comm.rank == 0:
        log.info("solver: the --petsc-option values were for MUMPS: not applied")
    return Prepared(setup, replace(request, solver=SOLVERS[CONDENSED]), None, record)


def warn_if_too_big(
    linear: LinearSolver, scene: Scene, request: SolveRequest, timers: Timers
) -> None:
    """An explicit MUMPS runs as asked; a log line warns where its estimate does not fit.

    The analysis is the one its first factorization reuses (no cost beyond a collective).
    """
    if not request.solver.traits.factorizes or not isinstance(linear, SaddleSolver):
        return
    with timers("solve"):
        estimate = linear.mumps_estimate()
    rank_mb = None if estimate is None else estimate.rank_mb
    needed, avail = node_budget(scene.comm, rank_mb, request.available_mb)
    if choose(needed, avail, True) is not Choice.DIRECT and scene.comm.rank == 0:
        reason = SolverChoice(request.solver.name, needed, avail, None).reason
        log.warning("solver: %s, although %s", request.solver.name, reason)


# Past this cell aspect (longest over shortest edge) both multigrids of the condensed system
# are poor cycles and MUMPS is much faster; the accurate grading stays far below it (the
# measured iteration counts: docs/scale.md, "Where each solver fails").
STRETCHED_ASPECT = 100.0


def warn_if_stretched(msh: mesh.Mesh, request: SolveRequest) -> None:
    """An explicit condensed solver runs as asked; a log line warns where cells are stretched."""
    if not request.solver.traits.needs_diagonal_d:
        return
    aspect = msh.comm.allreduce(max_cell_aspect(msh), op=MPI.MAX)
    if aspect > STRETCHED_ASPECT and msh.comm.rank == 0:
        log.warning(
            "solver: %s, although cells are stretched up to %.0f:1 (past %.0f:1 its multigrid "
            "needs tens to hundreds of CG iterations; mumps is faster there: docs/scale.md)",
            request.solver.name,
            aspect,
            STRETCHED_ASPECT,
        )


def _say(record: SolverChoice, comm: MPI.Comm) -> None:
    """The log line of the choice (rank 0)."""
    if comm.rank == 0:
        log.info("solver: %s (%s)", record.ran, record.reason)
