"""Linear-solver settings shared by everything that builds a KSP.

The presets, PETSc options under a private prefix (removed afterwards), and PETSc's reasons
and errors in words.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from types import MappingProxyType

from petsc4py import PETSc

_PRESETS: dict[str, dict[str, object]] = {
    # MUMPS LU directly on the MatNest (PETSc converts it): the robust reference. PORD
    # ordering: MUMPS' METIS analysis (sequential) took half of a 1M-dof solve, 4.0 of 7.5 s;
    # PORD's took 1.3 s for the same factorization time (4.7 s in all; 13.8 s instead of
    # 18.7 s at 2M dofs, 10.0 s instead of 16.5 s on 2 ranks). benchmarks/README.md.
    "mumps": {
        "ksp_type": "preonly",
        "pc_type": "lu",
        "pc_factor_mat_solver_type": "mumps",
        "mat_mumps_icntl_7": 4,
    },
    # Schur-complement fieldsplit, A00 = K + gamma B^T B factorized by MUMPS, S by Jacobi-GMRES.
    "fieldsplit": {
        "ksp_type": "fgmres",
        "ksp_rtol": 1e-12,
        "ksp_atol": 1e-14,
        "ksp_max_it": 200,
        "pc_type": "fieldsplit",
        "pc_fieldsplit_type": "schur",
        "pc_fieldsplit_schur_fact_type": "full",
        "pc_fieldsplit_schur_precondition": "selfp",
        "fieldsplit_u_ksp_type": "preonly",
        "fieldsplit_u_pc_type": "lu",
        "fieldsplit_u_pc_factor_mat_solver_type": "mumps",
        "fieldsplit_u_mat_mumps_icntl_7": 4,
        "fieldsplit_lambda_ksp_type": "gmres",
        "fieldsplit_lambda_ksp_rtol": 1e-12,
        "fieldsplit_lambda_ksp_max_it": 500,
        "fieldsplit_lambda_pc_type": "jacobi",
    },
    # Iterative path for large meshes: A00 = K + gamma B^T B by one GAMG V-cycle with the
    # rigid-body modes of all bodies as near-nullspace, S by the augmented-Lagrangian diagonal
    # -I/gamma (see `schur_al_diagonal`), whose quality does not depend on the mesh size.
    "fieldsplit-gamg": {
        "ksp_type": "fgmres",
        "ksp_rtol": 1e-10,
        "ksp_max_it": 1000,
        "ksp_gmres_restart": 200,
        "pc_type": "fieldsplit",
        "pc_fieldsplit_type": "schur",
        "pc_fieldsplit_schur_fact_type": "upper",
        "pc_fieldsplit_schur_precondition": "user",
        "fieldsplit_u_ksp_type": "preonly",
        "fieldsplit_u_pc_type": "gamg",
        "fieldsplit_u_pc_gamg_threshold": 0.01,
        "fieldsplit_u_pc_gamg_reuse_interpolation": True,
        # SOR smoothing: stretched cells of graded meshes defeat Chebyshev/Jacobi (measured on
        # the structured Hertz mesh, 115k dofs: 236 outer iterations with it, 50 with SOR).
        "fieldsplit_u_mg_levels_pc_type": "sor",
        "fieldsplit_lambda_ksp_type": "preonly",
        "fieldsplit_lambda_pc_type": "jacobi",
    },
}

# The condensed path (contactfx/condensed.py): the active multipliers eliminated (D diagonal:
# NTS or dual mortar), CG on the SPD displacement system, GAMG with the bodies' rigid modes.
_PRESETS["condensed"] = {
    "contactfx_condensed": True,
    # The solves before the set is stationary only need the signs of gaps and pressures.
    "contactfx_loose_rtol": 1e-4,
    "ksp_type": "cg",
    "ksp_norm_type": "unpreconditioned",
    "ksp_rtol": 1e-9,
    "ksp_max_it": 5000,
    "pc_type": "gamg",
    # GAMG's own smoother (Chebyshev on Jacobi, two sweeps): a fifth of SOR's cost per
    # V-cycle; one level of aggressive coarsening keeps the hierarchy (and its setup) small.
    "pc_gamg_threshold": 0.01,
    "pc_gamg_aggressive_coarsening": 1,
}

# Read-only: a caller that wants to change a preset copies it (dict(SOLVERS[name])).
SOLVERS: Mapping[str, Mapping[str, object]] = MappingProxyType(
    {name: MappingProxyType(opts) for name, opts in _PRESETS.items()}
)

_counter = itertools.count()


class PrefixedOptions:
    """`options` in PETSc's database under a fresh unique prefix, until `remove()`."""

    def __init__(self, options: Mapping[str, object]) -> None:
        self.prefix = f"contactfx_{next(_counter)}_"
        self.keys = list(options)
        db = PETSc.Options()
        for key, value in options.items():
            db[self.prefix + key] = value  # type: ignore[index]  # stub lacks Options.__setitem__

    def remove(self) -> None:
        """Delete this prefix's options from the database."""
        db = PETSc.Options()
        for key in self.keys:
            db.delValue(self.prefix + key)
        self.keys = []


@contextmanager
def petsc_options(options: Mapping[str, object]) -> Iterator[str]:
    """Set `options` under a fresh unique prefix and remove them afterwards."""
    opts = PrefixedOptions(options)
    try:
        yield opts.prefix
    finally:
        opts.remove()


def uses_augmentation(options: Mapping[str, object]) -> bool:
    """True if the options ask for a fieldsplit, whose A00 must be invertible on its own."""
    return options.get("pc_type") == "fieldsplit"


def is_direct(options: Mapping[str, object]) -> bool:
    """True if the options factorize the whole saddle-point matrix (LU or Cholesky)."""
    return options.get("pc_type") in ("lu", "cholesky")


def petsc_error_message(err: PETSc.Error, where: str) -> str:
    """One line from a PETSc error: its code and PETSc's own last message line."""
    lines = [line.removeprefix("[0]").strip() for line in str(err).splitlines()]
    code = err.ierr  # type: ignore[attr-defined]  # set by Error.__init__, missing from the stub
    return f"PETSc error {code} in the {where}: {lines[-1] if len(lines) > 1 else 'no message'}"


def reason_name(reason: int) -> str:
    """PETSc's name of a KSP converged/diverged reason."""
    names = {v: k for k, v in vars(PETSc.KSP.ConvergedReason).items() if isinstance(v, int)}
    return names.get(reason, "unknown")
