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
from .option_sets import GAMG, MUMPS_LDLT, MUMPS_LU


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
    """Which linear solver handles the saddle points (its traits: `SolverKind.traits`)."""

    DIRECT = "direct"  # a factorization of the whole [[K, B^T], [B, C]] (MUMPS)
    FIELDSPLIT = "fieldsplit"  # PCFIELDSPLIT Schur on A00 = K + gamma B^T B
    CONDENSED = "condensed"  # active multipliers eliminated (D diagonal), CG + multigrid on u
    AUTO = "auto"  # DIRECT unless MUMPS' own estimate does not fit, then CONDENSED (autosolve)

    @property
    def traits(self) -> KindTraits:
        """What the rest of the code asks of this kind (the TRAITS table)."""
        return TRAITS[self]


class System(StrEnum):
    """Which linear system a solver kind solves (4C's SYSTEM: saddlepoint | condensed)."""

    SADDLE = "saddle"  # [[K, B^T], [B, C]] [u; mu] = [f; -g]
    CONDENSED = "condensed"  # the active multipliers eliminated: displacements only (D diagonal)


class Linear(StrEnum):
    """The linear solver of a system: a factorization or a Krylov method (4C's LINEAR_SOLVER)."""

    LU = "lu"
    LDLT = "ldlt"  # symmetric (indefinite) factorization: PETSc's pc_type cholesky
    CG = "cg"
    GMRES = "gmres"  # GMRES or FGMRES

    @property
    def unsymmetric(self) -> bool:
        """Whether it accepts an unsymmetric system (a frictional one is)."""
        return self in (Linear.LU, Linear.GMRES)


# The pc_type of each factorization, and the ksp_types of each Krylov method.
_FACTOR_PC = {Linear.LU: "lu", Linear.LDLT: "cholesky"}
_KRYLOV_KSP = {"cg": Linear.CG, "gmres": Linear.GMRES, "fgmres": Linear.GMRES}


class CoarseStart(StrEnum):
    """When `--predictor auto` starts the loop from a coarser solve (methods/predictor.py)."""

    ROWS = "rows"  # a remeshable scene with more than PROBE_ALL_ROWS multiplier rows
    ALWAYS = "always"  # every remeshable scene (a loop without probes)
    DOFS = "dofs"  # from COARSE_PREDICTOR_DOFS DOFs


@dataclass(frozen=True)
class KindTraits:
    """A solver kind's answers to the questions the methods ask of it.

    `coarse_*` are the coarse predictor's rules (methods/predictor.py, measured in
    docs/scale.md#measured-constants): how much coarser its mesh is (`coarse_factor`; a
    factorization doubles it until the coarse rows are few), how many coarse elements of
    margin its first set gets, and the preset its coarse solve runs (None: the same spec).
    """

    system: System
    linear: frozenset[Linear]  # the linear solvers it accepts
    default_linear: Linear  # a spec's linear solver when it names none
    factorizes: bool  # the whole saddle point factorized: probes exact, release steps
    augmented: bool  # A00 = K + gamma B^T B (a fieldsplit's A00 must be invertible alone)
    rigid_modes: bool  # its multigrid (GAMG) gets the bodies' rigid modes as near-nullspace
    coarse_start: CoarseStart
    coarse_factor: float
    coarse_margin: float
    coarse_solver: str | None = None

    @property
    def needs_diagonal_d(self) -> bool:
        """Whether the multipliers' block D must be diagonal (they are eliminated)."""
        return self.system is System.CONDENSED


# A factorization probes the fine band (selected inverse entries): a band twice as wide costs
# it less than the coarse solve saves at x16, and a generous margin costs it nothing ("Coarse
# factor", "Coarse predictor"). The condensed loop pays a whole solve per ring of nodes it
# adds or releases: a sharper prediction (1/16 of the DOFs, half a coarse element) pays for
# itself, and its coarse set is a guess that MUMPS finds fastest ("Direct predictor").
_DIRECT = KindTraits(
    System.SADDLE,
    frozenset((Linear.LDLT, Linear.LU)),
    Linear.LDLT,
    factorizes=True,
    augmented=False,
    rigid_modes=False,
    coarse_start=CoarseStart.ROWS,
    coarse_factor=16.0,
    coarse_margin=1.5,
)
TRAITS: Mapping[SolverKind, KindTraits] = MappingProxyType(
    {
        SolverKind.DIRECT: _DIRECT,
        SolverKind.AUTO: _DIRECT,  # its direct path; it is resolved before the loop
        SolverKind.FIELDSPLIT: KindTraits(
            System.SADDLE,
            frozenset((Linear.GMRES,)),
            Linear.GMRES,
            factorizes=False,
            augmented=True,
            rigid_modes=True,
            coarse_start=CoarseStart.DOFS,
            coarse_factor=8.0,
            coarse_margin=1.5,
        ),
        SolverKind.CONDENSED: KindTraits(
            System.CONDENSED,
            frozenset((Linear.CG, Linear.GMRES)),
            Linear.CG,
            factorizes=False,
            augmented=False,
            rigid_modes=True,
            coarse_start=CoarseStart.ALWAYS,
            coarse_factor=4.0,
            coarse_margin=0.5,
            coarse_solver="mumps",
        ),
    }
)


class Multigrid(StrEnum):
    """A condensed solver's multigrid on the displacements."""

    GAMG = "gamg"  # PETSc's algebraic multigrid, the bodies' rigid modes as near-nullspace
    # The scene's coarser meshes: a structured grid's own (Scene.grid), else its remeshes (a
    # recipe), with the option set GEOMETRIC_MG; GAMG where the scene has neither.
    GEOMETRIC = "geometric"


class SchurPre(StrEnum):
    """A Schur-complement fieldsplit's preconditioning matrix for S."""

    SELFP = "selfp"  # PETSc's A11 - A10 inv(diag(A00)) A01
    USER = "user"  # the code supplies the augmented-Lagrangian diagonal -I/gamma


SCHUR_KEY = "pc_fieldsplit_schur_precondition"


@dataclass(frozen=True)
class SolverSpec:
    """A linear solver: its kind, its PETSc options and the tolerances the code applies.

    `petsc` holds PETSc keys only (no leading dash). `linear` is the linear solver of the
    kind's system (None: the kind's default); a factorization's pc_type is derived from it.
    `rtol` is the final relative tolerance of an iterative solver (the condensed solver's
    CG); `loose_rtol` the relative reduction the condensed loop's solves stop at before the
    set is stationary (None: solve to rtol). `schur` is a fieldsplit's Schur preconditioner;
    its PETSc option is derived from it.
    """

    kind: SolverKind
    petsc: Mapping[str, object] = field(default_factory=dict)
    rtol: float = 1e-9
    loose_rtol: float | None = None
    name: str = "custom"
    schur: SchurPre | None = None
    linear: Linear | None = None
    free_products: bool = False  # GAMG's setup frees its products' data (methods/solvers.py)
    multigrid: Multigrid | None = None  # a condensed solver's (None there: GAMG)

    def __post_init__(self) -> None:
        if self.linear is None:
            object.__setattr__(self, "linear", self.traits.default_linear)
        if self.multigrid is None and self.system is System.CONDENSED:
            object.__setattr__(self, "multigrid", Multigrid.GAMG)
        self._check()
        petsc = dict(self.petsc)
        if self.schur is not None:
            petsc[SCHUR_KEY] = self.schur.value
        object.__setattr__(self, "petsc", MappingProxyType(petsc))

    @property
    def traits(self) -> KindTraits:
        """The kind's traits (the TRAITS table)."""
        return TRAITS[self.kind]

    @property
    def system(self) -> System:
        """The linear system this solver solves: the saddle point or the condensed one."""
        return self.traits.system

    def _check(self) -> None:
        """Refuse PETSc options that contradict the kind, the linear solver or the Schur pre."""
        given = self.petsc.get(SCHUR_KEY)
        if given is not None and (self.schur is None or str(given) != self.schur.value):
            raise InputError(
                f"solver '{self.name}': PETSc option {SCHUR_KEY}={given} contradicts its "
                f"Schur preconditioner ({self.schur.value if self.schur else 'none'})"
            )
        if self.schur is not None and self.kind is not SolverKind.FIELDSPLIT:
            raise InputError(f"solver '{self.name}': a Schur preconditioner needs a fieldsplit")
        if self.multigrid is not None and self.system is not System.CONDENSED:
            raise InputError(f"solver '{self.name}': a multigrid choice needs the condensed system")
        traits, pc = self.traits, self.petsc.get("pc_type")
        factorizes = traits.factorizes
        bad = {
            SolverKind.FIELDSPLIT: pc != "fieldsplit",
            SolverKind.CONDENSED: pc in ("fieldsplit", "lu", "cholesky"),
        }.get(self.kind, pc not in ("lu", "cholesky"))
        if bad:
            fix = {
                SolverKind.FIELDSPLIT: "a fieldsplit solver needs pc_type fieldsplit",
                SolverKind.CONDENSED: "it preconditions by multigrid",
            }.get(self.kind, "a direct solver factorizes (pc_type lu or cholesky)")
            raise InputError(
                f"solver '{self.name}' ({self.kind.value}): PETSc option pc_type={pc} "
                f"contradicts it: {fix}; choose the solver with --solver instead"
            )
        assert self.linear is not None
        if self.linear not in traits.linear:
            accepted = ", ".join(sorted(m.value for m in traits.linear))
            raise InputError(
                f"solver '{self.name}' ({self.kind.value}): linear solver {self.linear.value} "
                f"does not apply (choose {accepted})"
            )
        if factorizes and pc != _FACTOR_PC[self.linear]:
            raise InputError(
                f"solver '{self.name}': PETSc option pc_type={pc} contradicts its linear solver "
                f"({self.linear.value}: pc_type {_FACTOR_PC[self.linear]})"
            )
        if not (0.0 < self.rtol < 1.0) or (
            self.loose_rtol is not None and not 0.0 < self.loose_rtol < 1.0
        ):
            raise InputError(f"solver '{self.name}': tolerances must lie in (0, 1)")

    @property
    def augmented(self) -> bool:
        """Whether A00 = K + gamma B^T B."""
        return self.traits.augmented

    def with_petsc(self, items: Iterable[str]) -> SolverSpec:
        """The spec with PETSc options KEY=VALUE added (checked against the kind).

        For the condensed solver `ksp_rtol` is the tolerance the code applies itself (its
        final solves), so it sets `rtol` rather than a PETSc option that would be overridden;
        for a fieldsplit pc_fieldsplit_schur_precondition sets `schur`; a factorization's
        pc_type (lu, cholesky) and a Krylov solver's ksp_type (cg, gmres) set `linear`.
        """
        petsc = dict(self.petsc)
        rtol, schur, linear = self.rtol, self.schur, self.linear
        factorizes = self.traits.factorizes
        for item in items:
            key, sep, value = item.partition("=")
            key = key.strip().lstrip("-")
            if not sep or not key:
                raise InputError(f"--petsc-option expects KEY=VALUE, got '{item}'")
            if self.system is System.CONDENSED and key == "ksp_rtol":
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
            if factorizes and key == "pc_type":
                linear = {"lu": Linear.LU, "cholesky": Linear.LDLT}.get(value, linear)
            if not factorizes and key == "ksp_type":
                linear = _KRYLOV_KSP.get(value, linear)
            petsc[key] = value
        if self.kind is SolverKind.FIELDSPLIT:
            petsc.pop(SCHUR_KEY, None)
        return replace(self, petsc=petsc, rtol=rtol, schur=schur, linear=linear)


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
    multigrid=Multigrid.GEOMETRIC,
)

SOLVERS: Mapping[str, SolverSpec] = MappingProxyType(
    {
        "auto": SolverSpec(SolverKind.AUTO, MUMPS_LDLT, name="auto"),  # docs/scale.md
        "mumps": SolverSpec(SolverKind.DIRECT, MUMPS_LDLT, name="mumps"),
        "mumps-lu": SolverSpec(SolverKind.DIRECT, MUMPS_LU, name="mumps-lu", linear=Linear.LU),
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
        "condensed-gamg": replace(CONDENSED, name="condensed-gamg", multigrid=Multigrid.GAMG),
    }
)


def solver_spec(solver: SolverSpec | str) -> SolverSpec:
    """A named preset (InputError listing them if unknown), or the spec itself."""
    if isinstance(solver, SolverSpec):
        return solver
    if solver not in SOLVERS:
        raise InputError(f"unknown solver '{solver}' (choose {', '.join(SOLVERS)})")
    return SOLVERS[solver]
