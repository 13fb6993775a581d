"""The choices a user makes, as typed values: discretization, enforcement, basis, solver.

A `SolverSpec` says which linear solver runs (`kind`), the PETSc options it is configured
with (PETSc keys only) and the tolerances the code itself applies. Nothing infers the kind
from the PETSc options: a spec whose options contradict its kind is refused when it is made.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from enum import StrEnum
from types import MappingProxyType
from typing import Self

from .contact import Kernel
from .errors import InputError
from .option_sets import GAMG, GEOMETRIC_MG, MUMPS_LDLT, MUMPS_LU


def _unknown(enum: type[StrEnum], value: object, what: str) -> InputError:
    """The error for a value that is not a member of `enum`, naming the choices."""
    choices = ", ".join(m.value for m in enum)
    return InputError(f"unknown {what} '{value}' (choose {choices})")


_WHAT = {"Basis": "multiplier basis"}  # in the errors; otherwise the class name


class _Choice(StrEnum):
    """A user's choice by name: `parse` refuses other names, listing the members."""

    @classmethod
    def parse(cls, value: Self | str) -> Self:
        """The member named `value`."""
        try:
            return cls(value)
        except ValueError:
            raise _unknown(cls, value, _WHAT.get(cls.__name__, cls.__name__.lower())) from None


class Discretization(_Choice):
    """The discrete contact operator (B, weighted gap): which kernel builds it."""

    NTS = "nts"
    STS = "sts"
    MORTAR = "mortar"

    @property
    def kernel(self) -> Kernel:
        """The kernel of contactfx/contact that assembles this discretization."""
        return _KERNELS[self]


_KERNELS: Mapping[Discretization, Kernel] = MappingProxyType(
    {
        Discretization.NTS: Kernel.NTS,
        Discretization.STS: Kernel.STS,
        Discretization.MORTAR: Kernel.MORTAR,
    }
)


class Enforcement(_Choice):
    """How the contact constraint is enforced on a discretization."""

    MULTIPLIERS = "multipliers"  # Lagrange multipliers: saddle points in an active-set loop
    PENALTY = "penalty"  # a normal stiffness on the penetrating rows, no multipliers
    SCHWARZ = "schwarz"  # Dirichlet-Neumann iteration between the two bodies


class Method(_Choice):
    """The names of --method: a discretization, or an alias of a (discretization, enforcement).

    The JSON key "method" holds these names; `pair` is the alias table.
    """

    NTS = "nts"
    STS = "sts"
    MORTAR = "mortar"
    PENALTY = "penalty"
    SCHWARZ = "schwarz"

    @property
    def pair(self) -> tuple[Discretization, Enforcement]:
        """The discretization and the enforcement this name stands for."""
        return _ALIASES[self]

    @property
    def kernel(self) -> Kernel:
        """The discrete contact operator (B, weighted gap) this method is built on."""
        return self.pair[0].kernel

    @property
    def has_multipliers(self) -> bool:
        """Whether the method solves saddle points with Lagrange multipliers."""
        return self.pair[1] is Enforcement.MULTIPLIERS


_ALIASES: Mapping[Method, tuple[Discretization, Enforcement]] = MappingProxyType(
    {
        Method.NTS: (Discretization.NTS, Enforcement.MULTIPLIERS),
        Method.STS: (Discretization.STS, Enforcement.MULTIPLIERS),
        Method.MORTAR: (Discretization.MORTAR, Enforcement.MULTIPLIERS),
        # Penalty and Schwarz as they always ran: on the mortar operator.
        Method.PENALTY: (Discretization.MORTAR, Enforcement.PENALTY),
        Method.SCHWARZ: (Discretization.MORTAR, Enforcement.SCHWARZ),
    }
)


class Basis(_Choice):
    """Mortar multiplier bases: the shape functions N_j, or the biorthogonal (dual) ones."""

    STANDARD = "standard"
    DUAL = "dual"


class Predictor(_Choice):
    """Where the active-set loop starts: a coarser solve of the same scene, or not."""

    AUTO = "auto"  # the policy of methods/predictor.py decides
    COARSE = "coarse"
    NONE = "none"


class SolverKind(StrEnum):
    """Which linear solver handles the saddle points."""

    DIRECT = "direct"  # a factorization of the whole [[K, B^T], [B, C]] (MUMPS)
    FIELDSPLIT = "fieldsplit"  # PCFIELDSPLIT Schur on A00 = K + gamma B^T B
    CONDENSED = "condensed"  # active multipliers eliminated (D diagonal), CG + multigrid on u
    CONDENSED_DIRECT = "condensed-direct"  # the same system factorized (Cholesky)
    # One MUMPS factorization of K + gamma B^T B with every multiplier row as its Schur
    # variables; each active set a dense solve on that block (serial; linalg/schur.py).
    DIRECT_SCHUR = "direct-schur"
    AUTO = "auto"  # DIRECT unless MUMPS' own estimate does not fit, then CONDENSED (autosolve)

    @property
    def factorizes_saddle(self) -> bool:
        """Whether a MUMPS factorization of the whole saddle point answers (probes exact)."""
        return self in (SolverKind.DIRECT, SolverKind.DIRECT_SCHUR)

    @property
    def augmented(self) -> bool:
        """Whether A00 = K + gamma B^T B (a fieldsplit's A00 must be invertible alone)."""
        return self is SolverKind.FIELDSPLIT

    @property
    def condensed(self) -> bool:
        """Whether the multipliers are eliminated (the displacement-only SPD system)."""
        return self in (SolverKind.CONDENSED, SolverKind.CONDENSED_DIRECT)


class SchurPre(StrEnum):
    """A Schur-complement fieldsplit's preconditioning matrix for S."""

    SELFP = "selfp"  # PETSc's A11 - A10 inv(diag(A00)) A01
    USER = "user"  # the code supplies the augmented-Lagrangian diagonal -I/gamma


SCHUR_KEY = "pc_fieldsplit_schur_precondition"


@dataclass(frozen=True)
class LowRank:
    """MUMPS' block low-rank factorization of a direct saddle point from `from_dofs` DOFs.

    CNTL(7) = `tolerance`, ICNTL(35) = `variant`: the factors are approximate, so every solve
    on them is GMRES to full-rank accuracy (linalg/saddle.py: APPROX_RTOL).
    """

    from_dofs: int = 0
    tolerance: float = 1e-8
    variant: int = 2  # ICNTL(35): 1 automatic, 2 factors and solve compressed, 3 factors only


@dataclass(frozen=True)
class SolverSpec:
    """A linear solver: its kind, its PETSc options and the tolerances the code applies.

    `petsc` holds PETSc keys only (no leading dash). `rtol` is the final relative tolerance
    of an iterative solver (the condensed solver's CG); `loose_rtol` the relative reduction
    the condensed loop's solves stop at before the set is stationary (None: solve to rtol).
    `schur` is a fieldsplit's Schur preconditioner; its PETSc option is derived from it.
    """

    kind: SolverKind
    petsc: Mapping[str, object] = field(default_factory=dict)
    rtol: float = 1e-9
    loose_rtol: float | None = None
    name: str = "custom"
    schur: SchurPre | None = None
    free_products: bool = False  # GAMG's setup frees its products' data (methods/solvers.py)
    low_rank: LowRank | None = None  # a direct solver's BLR factorization (methods/solvers.py)
    # A condensed solver's options where the scene has coarser grids: the structured grid's
    # own (Scene.grid) or its remeshes (a recipe): a geometric multigrid; None: `petsc`
    # (GAMG) on every mesh, also where the scene has neither.
    geometric: Mapping[str, object] | None = None

    def __post_init__(self) -> None:
        self._check()
        petsc = dict(self.petsc)
        if self.schur is not None:
            petsc[SCHUR_KEY] = self.schur.value
        object.__setattr__(self, "petsc", MappingProxyType(petsc))

    def _check(self) -> None:
        """Refuse PETSc options that contradict the kind or the Schur preconditioner."""
        given = self.petsc.get(SCHUR_KEY)
        if given is not None and (self.schur is None or str(given) != self.schur.value):
            raise InputError(
                f"solver '{self.name}': PETSc option {SCHUR_KEY}={given} contradicts its "
                f"Schur preconditioner ({self.schur.value if self.schur else 'none'})"
            )
        if self.schur is not None and self.kind is not SolverKind.FIELDSPLIT:
            raise InputError(f"solver '{self.name}': a Schur preconditioner needs a fieldsplit")
        pc = self.petsc.get("pc_type")
        bad = {
            SolverKind.DIRECT: pc not in ("lu", "cholesky"),
            SolverKind.FIELDSPLIT: pc != "fieldsplit",
            SolverKind.CONDENSED: pc in ("fieldsplit", "lu", "cholesky"),
            SolverKind.CONDENSED_DIRECT: pc not in ("lu", "cholesky"),
            SolverKind.DIRECT_SCHUR: pc not in ("lu", "cholesky"),
        }[SolverKind.DIRECT if self.kind is SolverKind.AUTO else self.kind]
        if bad:
            fix = {
                SolverKind.DIRECT: "a direct solver factorizes (pc_type lu or cholesky)",
                SolverKind.FIELDSPLIT: "a fieldsplit solver needs pc_type fieldsplit",
                SolverKind.CONDENSED: "it preconditions by multigrid (condensed-direct factorizes)",
            }.get(self.kind, "it factorizes (pc_type cholesky or lu)")
            raise InputError(
                f"solver '{self.name}' ({self.kind.value}): PETSc option pc_type={pc} "
                f"contradicts it: {fix}; choose the solver with --solver instead"
            )
        if self.low_rank is not None and not 0.0 < self.low_rank.tolerance < 1.0:
            raise InputError(f"solver '{self.name}': the low-rank tolerance must lie in (0, 1)")
        if not (0.0 < self.rtol < 1.0) or (
            self.loose_rtol is not None and not 0.0 < self.loose_rtol < 1.0
        ):
            raise InputError(f"solver '{self.name}': tolerances must lie in (0, 1)")

    @property
    def augmented(self) -> bool:
        """Whether A00 = K + gamma B^T B."""
        return self.kind.augmented

    def with_petsc(self, items: Iterable[str]) -> SolverSpec:
        """The spec with PETSc options KEY=VALUE added (checked against the kind).

        For the condensed solver `ksp_rtol` is the tolerance the code applies itself (its
        final solves), so it sets `rtol` rather than a PETSc option that would be overridden;
        for a fieldsplit pc_fieldsplit_schur_precondition sets `schur`.
        """
        petsc = dict(self.petsc)
        geometric = None if self.geometric is None else dict(self.geometric)
        rtol, schur = self.rtol, self.schur
        for item in items:
            key, sep, value = item.partition("=")
            key = key.strip().lstrip("-")
            if not sep or not key:
                raise InputError(f"--petsc-option expects KEY=VALUE, got '{item}'")
            if self.kind.condensed and key == "ksp_rtol":
                try:
                    rtol = float(value)
                except ValueError:
                    raise InputError(f"--petsc-option {item}: not a number") from None
                continue
            if key == SCHUR_KEY and self.kind is SolverKind.FIELDSPLIT:
                # The choice is a field of the spec (the code supplies the "user" matrix).
                try:
                    schur = SchurPre(value)
                except ValueError:
                    raise _unknown(SchurPre, value, SCHUR_KEY) from None
            petsc[key] = value
            if geometric is not None and not key.startswith(("pc_type", "pc_gamg")):
                geometric[key] = value  # e.g. the smoother's steps: both multigrids
        if self.kind is SolverKind.FIELDSPLIT:
            petsc.pop(SCHUR_KEY, None)
        return replace(self, petsc=petsc, rtol=rtol, schur=schur, geometric=geometric)


# Multipliers eliminated (D diagonal: NTS or dual mortar), CG on the SPD displacement system,
# GAMG (two levels of aggressive coarsening) with the bodies' rigid modes, or a geometric
# multigrid where the mesh is a structured grid; the loop's solves only need signs
# (loose_rtol, docs/condensed.md).
CONDENSED = SolverSpec(
    SolverKind.CONDENSED,
    GAMG,
    rtol=1e-9,
    loose_rtol=1e-4,
    name="condensed",
    free_products=True,  # never reused: docs/scale.md, "Memory of the condensed path"
    geometric=GEOMETRIC_MG,
)

SOLVERS: Mapping[str, SolverSpec] = MappingProxyType(
    {
        "auto": SolverSpec(SolverKind.AUTO, MUMPS_LDLT, name="auto"),  # docs/scale.md
        "mumps": SolverSpec(SolverKind.DIRECT, MUMPS_LDLT, name="mumps"),
        "mumps-lu": SolverSpec(SolverKind.DIRECT, MUMPS_LU, name="mumps-lu"),
        # Opt-in: MUMPS' block low-rank LDL^T, every solve refined by GMRES to full-rank
        # accuracy (docs/scale.md, "Block low-rank factorization").
        "mumps-blr": SolverSpec(
            SolverKind.DIRECT, MUMPS_LDLT, name="mumps-blr", low_rank=LowRank()
        ),
        # Opt-in (docs/scale.md, "The Schur route, measured"): MUMPS' Schur complement of
        # every multiplier row, one factorization, each set a dense solve. Serial only: on
        # several ranks the `mumps` path runs instead.
        "mumps-schur": SolverSpec(SolverKind.DIRECT_SCHUR, MUMPS_LDLT, name="mumps-schur"),
        # Schur fieldsplit, A00 = K + gamma B^T B factorized by MUMPS, S by Jacobi-GMRES.
        "fieldsplit": SolverSpec(
            SolverKind.FIELDSPLIT,
            {
                "ksp_type": "fgmres",
                "ksp_rtol": 1e-12,
                "ksp_atol": 1e-14,
                "ksp_max_it": 200,
                "pc_type": "fieldsplit",
                "pc_fieldsplit_type": "schur",
                "pc_fieldsplit_schur_fact_type": "full",
                "fieldsplit_u_ksp_type": "preonly",
                "fieldsplit_u_pc_type": "lu",
                "fieldsplit_u_pc_factor_mat_solver_type": "mumps",
                "fieldsplit_u_mat_mumps_icntl_7": 4,
                "fieldsplit_lambda_ksp_type": "gmres",
                "fieldsplit_lambda_ksp_rtol": 1e-12,
                "fieldsplit_lambda_ksp_max_it": 500,
                "fieldsplit_lambda_pc_type": "jacobi",
            },
            name="fieldsplit",
            schur=SchurPre.SELFP,
        ),
        # A00 by one GAMG V-cycle with the bodies' rigid modes as near-nullspace, S by the
        # augmented-Lagrangian diagonal -I/gamma (linalg/saddle.py: schur_al_diagonal).
        "fieldsplit-gamg": SolverSpec(
            SolverKind.FIELDSPLIT,
            {
                "ksp_type": "fgmres",
                "ksp_rtol": 1e-10,
                "ksp_max_it": 1000,
                "ksp_gmres_restart": 200,
                "pc_type": "fieldsplit",
                "pc_fieldsplit_type": "schur",
                "pc_fieldsplit_schur_fact_type": "upper",
                "fieldsplit_u_ksp_type": "preonly",
                "fieldsplit_u_pc_type": "gamg",
                "fieldsplit_u_pc_gamg_threshold": 0.01,
                "fieldsplit_u_pc_gamg_reuse_interpolation": True,
                "fieldsplit_u_mg_levels_pc_type": "sor",  # stretched cells: docs/scale.md
                "fieldsplit_lambda_ksp_type": "preonly",
                "fieldsplit_lambda_pc_type": "jacobi",
            },
            name="fieldsplit-gamg",
            schur=SchurPre.USER,
        ),
        "condensed": CONDENSED,
        # The same with GAMG on every mesh (the structured grid's levels unused).
        "condensed-gamg": replace(CONDENSED, name="condensed-gamg", geometric=None),
        # The same condensed system factorized: MUMPS Cholesky (SPD, SYM=1). Later sets run CG
        # preconditioned by the kept factorization (a low-rank change: a few iterations)
        # until the pivots have moved too far (linalg/condensed.py).
        "condensed-direct": SolverSpec(
            SolverKind.CONDENSED_DIRECT,
            {
                "ksp_type": "cg",
                "ksp_norm_type": "unpreconditioned",
                "ksp_max_it": 500,
                "pc_type": "cholesky",
                "pc_factor_mat_solver_type": "mumps",
            },
            rtol=1e-9,
            loose_rtol=1e-4,
            name="condensed-direct",
        ),
    }
)


def solver_spec(solver: SolverSpec | str) -> SolverSpec:
    """A named preset (InputError listing them if unknown), or the spec itself."""
    if isinstance(solver, SolverSpec):
        return solver
    if solver not in SOLVERS:
        raise InputError(f"unknown solver '{solver}' (choose {', '.join(SOLVERS)})")
    return SOLVERS[solver]
