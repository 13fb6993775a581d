"""One factory for every linear solver: it owns gamma, the near-nullspace and the reuse policy.

The methods turn a SolverSpec into a solver here; contactfx/linalg itself knows no spec.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from functools import partial

import numpy as np
from petsc4py import PETSc

from ..discretize.grid_mg import grid_interpolations
from ..discretize.remesh_mg import remesh_interpolations
from ..discretize.setup import ContactSetup
from ..discretize.supports import rigid_body_modes
from ..linalg.nullspace import near_nullspace
from ..linalg.policy import FactorizationPolicy
from ..linalg.protocol import LinearSolver
from ..linalg.saddle import SaddleSolver
from ..option_sets import GAMG, GEOMETRIC_MG
from ..options import Multigrid, SchurPre, SolverKind, SolverSpec, System
from ..request import direct_path
from ..scenes import Scene

log = logging.getLogger("contactfx")

# MUMPS' analysis on several ranks: sequential (ICNTL(28) = 1), with the ordering below on
# the host; parallel analysis with PT-Scotch orders worse on these meshes
# (docs/scale.md#measured-constants, "Sequential analysis").
SEQUENTIAL_ANALYSIS: dict[str, object] = {"mat_mumps_icntl_28": 1}


def with_sequential_analysis(petsc: Mapping[str, object], ranks: int) -> Mapping[str, object]:
    """The options with MUMPS' sequential analysis on several ranks (unless they set it)."""
    if ranks == 1 or any(k in petsc for k in SEQUENTIAL_ANALYSIS):
        return petsc
    return {**petsc, **SEQUENTIAL_ANALYSIS}


# MUMPS' fill-reducing ordering (ICNTL(7)) by the number of DOFs: AMD's fill grows faster
# than PORD's, which wins from a few hundred thousand DOFs (benchmarks/orderings.py;
# docs/scale.md, "The ordering rule").
AMD, PORD = 0, 4
PORD_FROM_DOFS = 300_000
ORDERING_KEY = "mat_mumps_icntl_7"


def with_ordering(petsc: Mapping[str, object], ndofs: int) -> Mapping[str, object]:
    """A MUMPS factorization's options with the ordering for `ndofs` DOFs.

    AMD below PORD_FROM_DOFS, then PORD, unless the options name one; others unchanged.
    """
    if ORDERING_KEY in petsc or petsc.get("pc_factor_mat_solver_type") != "mumps":
        return petsc
    return {**petsc, ORDERING_KEY: AMD if ndofs < PORD_FROM_DOFS else PORD}


def direct_options(spec: SolverSpec, K: PETSc.Mat) -> Mapping[str, object]:
    """A direct saddle-point solver's options: ordering, on several ranks the analysis."""
    petsc = with_ordering(spec.petsc, K.getSize()[0])
    return with_sequential_analysis(petsc, K.getComm().tompi4py().size)


# GAMG recomputes a kept hierarchy from its products' data when asked to reuse the
# interpolation: then that data must stay (SolverSpec.free_products is ignored).
REUSE_INTERPOLATION = "pc_gamg_reuse_interpolation"


def reuses_interpolation(petsc: Mapping[str, object]) -> bool:
    """Whether the options ask GAMG to reuse its interpolation (PETSc's reading of a bool)."""
    value = petsc.get(REUSE_INTERPOLATION, False)
    return str(value).strip().lower() not in ("0", "false", "no", "off")


def geometric_options(petsc: Mapping[str, object]) -> dict[str, object]:
    """A geometric multigrid's options: GEOMETRIC_MG with the spec's own changes to GAMG's set.

    The keys a user gave (--petsc-option) that the GAMG set lacks or sets otherwise, except
    GAMG's own (pc_type, pc_gamg_*): e.g. the smoother's steps apply to both multigrids.
    """
    own = {
        k: v
        for k, v in petsc.items()
        if GAMG.get(k, _MISSING) != v and not k.startswith(("pc_type", "pc_gamg"))
    }
    return {**GEOMETRIC_MG, **own}


_MISSING = object()


def augmentation(spec: SolverSpec, e_max: float, h: float) -> float:
    """Gamma of A00 = K + gamma B^T B: E_max / h^2 for a fieldsplit (scales as K), else 0."""
    return e_max / h**2 if spec.augmented else 0.0


def make_solver(
    spec: SolverSpec,
    K: PETSc.Mat,
    B: PETSc.Mat,
    f: PETSc.Vec,
    *,
    e_max: float,
    h: float,
    modes: Callable[[], list[PETSc.Vec]],
    node_dofs: np.ndarray,
    reuse: bool = True,
    grid: Callable[[], list[PETSc.Mat]] | None = None,
    tangent: PETSc.Mat | None = None,
) -> LinearSolver:
    """The solver `spec` asks for, on K, B (this rank's rows) and f.

    `modes()`: the rigid-body modes (called only by the solvers that use GAMG on the
    displacements); `node_dofs` (m, 2): the dofs of each multiplier row's active node (the
    condensed solver's pivots); `reuse` False: a throwaway solver for one set; `grid()`: the
    prolongations of the scene's coarser grids, if it has them (a condensed spec with
    `Multigrid.GEOMETRIC` then runs a geometric multigrid). An `auto` spec must be resolved
    first (methods/autosolve.py); here it is its direct path. `tangent`: friction's
    tangential rows (a condensed spec then gives a FrictionCondensedSolver).
    """
    spec = direct_path(spec)
    traits = spec.traits
    if traits.system is System.CONDENSED:
        from ..linalg.condensed import CondensedSolver  # not on the direct path: docs/scale.md

        geometric = spec.multigrid is Multigrid.GEOMETRIC
        levels = grid() if grid is not None and geometric else None
        if reuse and K.getComm().tompi4py().rank == 0:
            how = f"geometric, {len(levels)} coarser levels" if levels else "GAMG (algebraic)"
            log.info("multigrid: %s", how)
        cls: type[CondensedSolver] = CondensedSolver
        extra: dict[str, PETSc.Mat] = {}
        if tangent is not None:
            from ..linalg.condensed_friction import FrictionCondensedSolver

            cls, extra = FrictionCondensedSolver, {"Bt": tangent}
        return cls(
            K,
            B,
            f,
            geometric_options(spec.petsc) if levels else with_ordering(spec.petsc, K.getSize()[0]),
            node_dofs,
            [] if levels or not traits.rigid_modes else modes(),
            rtol=spec.rtol,
            loose_rtol=spec.loose_rtol,
            reuse=reuse,
            free_products=spec.free_products and not reuses_interpolation(spec.petsc),
            interpolations=levels,
            **extra,
        )
    nullspace = None
    if traits.rigid_modes:
        vectors = modes()
        nullspace = near_nullspace(vectors)
        for v in vectors:
            v.destroy()
    direct = traits.factorizes
    return SaddleSolver(
        K,
        B,
        f,
        direct_options(spec, K) if direct else spec.petsc,
        direct=direct,
        gamma=augmentation(spec, e_max, h),
        nullspace=nullspace,
        policy=FactorizationPolicy(reuse) if direct else None,
        fieldsplit=spec.kind is SolverKind.FIELDSPLIT,
        # PETSc then asks the code for the Schur preconditioning matrix: -I/gamma.
        schur_user=spec.schur is SchurPre.USER,
    )


def setup_solver(
    setup: ContactSetup,
    spec: SolverSpec,
    scene: Scene,
    *,
    reuse: bool,
    grid: Callable[[], list[PETSc.Mat]] | None = None,
    tangent: PETSc.Mat | None = None,
) -> LinearSolver:
    """The solver of a contact setup's saddle points (reuse: it keeps its setup across sets).

    `grid`: other multigrid prolongations than the scene's (a benchmark's). The scene's: its
    structured grid's coarser grids, else (a recipe) its remeshes x8, x16, ... (non-nested).
    """
    el = setup.elasticity
    if grid is None and scene.grid is not None:
        grid = partial(grid_interpolations, el.V, el.bcs, scene.grid)
    elif grid is None and scene.can_remesh:
        grid = partial(remesh_interpolations, el.V, scene)
    return make_solver(
        spec,
        el.K,
        setup.B,
        el.f,
        e_max=setup.e_max,
        h=setup.h,
        modes=lambda: rigid_body_modes(el.V, scene),
        node_dofs=setup.node_dofs(),
        reuse=reuse,
        grid=grid,
        tangent=tangent,
    )
