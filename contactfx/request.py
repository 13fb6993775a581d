"""One solve's request: what the API, the study and the adaptive loop hand to the methods.

A `SolveRequest` names the discretization (nts, sts, mortar) and its basis, the enforcement
(multipliers, penalty, Schwarz), the predictor, the linear solver and the limits. Every rule
that ties these choices together is checked once, in `SolveRequest.__post_init__`: a request
that exists can be run, and nothing downstream checks a combination again.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import NoReturn, TypedDict, Unpack

from .contact import Kernel
from .errors import InputError
from .options import (
    SOLVERS,
    Basis,
    Discretization,
    Enforcement,
    Method,
    Predictor,
    SolverKind,
    SolverSpec,
    solver_spec,
)

# The defaults of a request made from names (SolveRequest.parse, contactfx.solve).
DEFAULT_SOLVER = "auto"
DEFAULT_MAX_ITERATIONS = 50


@dataclass(frozen=True)
class SchwarzOptions:
    """Controls of the Dirichlet-Neumann iteration."""

    relaxation: float = 0.5  # fixed relaxation, and the first step of Aitken's
    aitken: bool = True  # Aitken's dynamic relaxation after the first iteration
    tol: float = 1e-8  # relative change of interface displacement and traction
    max_iterations: int = 100
    divergence: float = 1e8  # stop early once the residual grew by this factor

    def __post_init__(self) -> None:
        if not 0.0 < self.relaxation <= 2.0:
            raise InputError(f"relaxation must lie in (0, 2] (got {self.relaxation})")


class RequestOptions(TypedDict, total=False):
    """The options of a request given by name (`SolveRequest.parse`, `contactfx.solve`)."""

    enforcement: Enforcement | str | None
    solver: SolverSpec | str
    basis: Basis | str
    predictor: Predictor | str
    max_iterations: int
    penalty: float | None
    schwarz: SchwarzOptions | None
    reference_timing: bool
    available_mb: float | None


@dataclass(frozen=True, kw_only=True)
class SolveRequest:
    """A validated solve request: discretization x enforcement, solver and limits.

    Attributes:
        discretization: The contact operator: nts, sts or mortar.
        enforcement: multipliers (saddle points), penalty, or schwarz (mortar only).
        basis: Mortar's multiplier basis: standard or dual (biorthogonal, D diagonal).
        predictor: auto, coarse or none: the first active set of a multiplier method.
        solver: The linear solver (a multiplier method's saddle points; penalty factorizes).
        max_iterations: Limit of the active-set iterations (Schwarz's, without `schwarz`).
        penalty: The penalty's normal stiffness eps (MPa/cm); None: 1e3 E_max / h.
        schwarz: The Schwarz iteration's controls; None: the defaults with max_iterations.
        reference_timing: Also time one fresh solve of the final system (multipliers).
        available_mb: The memory (MB per node) the `auto` solver compares MUMPS' estimate
            with; None: MemAvailable of /proc/meminfo (tests force the choice with it).
    """

    discretization: Discretization = Discretization.MORTAR
    enforcement: Enforcement = Enforcement.MULTIPLIERS
    basis: Basis = Basis.STANDARD
    predictor: Predictor = Predictor.AUTO
    solver: SolverSpec = field(default_factory=lambda: SOLVERS[DEFAULT_SOLVER])
    max_iterations: int = DEFAULT_MAX_ITERATIONS
    penalty: float | None = None
    schwarz: SchwarzOptions | None = None
    reference_timing: bool = False
    available_mb: float | None = None

    def __post_init__(self) -> None:
        """Refuse an impossible combination, one rule per line."""
        if self.solver.kind is SolverKind.AUTO and self.enforcement is not Enforcement.MULTIPLIERS:
            # Penalty and Schwarz factorize with MUMPS: `auto` has nothing to choose there.
            object.__setattr__(self, "solver", direct_path(self.solver))
        enf = self.enforcement
        if self.available_mb is not None and not self.available_mb > 0:
            _refuse(f"the available memory must be positive (got {self.available_mb} MB)")
        if self.max_iterations < 1:
            _refuse(f"max_iterations must be at least 1 (got {self.max_iterations})")
        if self.basis is Basis.DUAL and self.method is not Method.MORTAR:
            _refuse("the dual multiplier basis applies to the mortar method only")
        factorizes = self.solver.traits.factorizes
        if enf is Enforcement.PENALTY and not factorizes:
            _refuse(
                "the penalty method has no multiplier block: it factorizes K + eps B^T W^-1 B "
                f"(use --solver mumps or mumps-lu, not {self.solver.name})"
            )
        if enf is Enforcement.SCHWARZ and not factorizes:
            _refuse("schwarz factorizes each body with MUMPS: the solver option does not apply")
        if enf is Enforcement.SCHWARZ and self.discretization is not Discretization.MORTAR:
            _refuse("schwarz transfers through the mortar matrices: use the mortar discretization")
        if self.penalty is not None and enf is not Enforcement.PENALTY:
            _refuse("--penalty applies to --method penalty only (or --enforcement penalty)")
        if self.penalty is not None and not (math.isfinite(self.penalty) and self.penalty > 0):
            _refuse(f"the penalty parameter must be a positive number (got {self.penalty})")
        if self.schwarz is not None and enf is not Enforcement.SCHWARZ:
            _refuse("Schwarz controls apply to the schwarz enforcement only")
        if (
            self.solver.traits.needs_diagonal_d
            and enf is Enforcement.MULTIPLIERS
            and not self.diagonal
        ):
            _refuse(
                "the condensed solver needs a diagonal D: use --method nts or "
                "--method mortar --basis dual"
            )

    @classmethod
    def parse(
        cls, method: Method | str = Method.MORTAR, **options: Unpack[RequestOptions]
    ) -> SolveRequest:
        """The request named by strings (the CLI's and the Python API's).

        Args:
            method: nts, sts or mortar (a discretization), or penalty / schwarz (aliases of
                mortar with that enforcement).
            options: `RequestOptions`, each defaulting to the request's own default:
                enforcement (None: the method's own), solver (a preset name of `SOLVERS`
                or a SolverSpec; DEFAULT_SOLVER), basis, predictor, max_iterations
                (DEFAULT_MAX_ITERATIONS), penalty, schwarz, reference_timing and
                available_mb (None: MemAvailable).

        Returns:
            The validated request (InputError naming the first rule it breaks).
        """
        unknown = set(options) - set(RequestOptions.__annotations__)
        if unknown:
            _refuse(f"unknown solve option {sorted(unknown)[0]}")
        disc, own = Method.parse(method).pair
        enforcement = options.get("enforcement")
        enf = own if enforcement is None else Enforcement.parse(enforcement)
        if own is not Enforcement.MULTIPLIERS and enf is not own:
            _refuse(f"--method {method} is {own.value} on {disc.value}: drop --enforcement")
        penalty = options.get("penalty")
        return cls(
            discretization=disc,
            enforcement=enf,
            basis=Basis.parse(options.get("basis", Basis.STANDARD)),
            predictor=Predictor.parse(options.get("predictor", Predictor.AUTO)),
            solver=solver_spec(options.get("solver", DEFAULT_SOLVER)),
            max_iterations=options.get("max_iterations", DEFAULT_MAX_ITERATIONS),
            penalty=None if penalty is None else float(penalty),
            schwarz=options.get("schwarz"),
            reference_timing=options.get("reference_timing", False),
            available_mb=options.get("available_mb"),
        )

    @property
    def method(self) -> Method:
        """The method's name in the JSON: the discretization, or penalty / schwarz."""
        if self.enforcement is Enforcement.MULTIPLIERS:
            return Method(self.discretization.value)
        return Method(self.enforcement.value)

    @property
    def label(self) -> str:
        """A name unique per request: the method, or e.g. penalty-nts off the alias table."""
        if self.method.pair == (self.discretization, self.enforcement):
            return self.method.value
        return f"{self.enforcement.value}-{self.discretization.value}"

    @property
    def kernel(self) -> Kernel:
        """The kernel that assembles B and the weighted gap."""
        return self.discretization.kernel

    @property
    def diagonal(self) -> bool:
        """Whether D, the multipliers' block on their own nodes, is diagonal (condensable)."""
        return self.discretization is Discretization.NTS or (
            self.discretization is Discretization.MORTAR and self.basis is Basis.DUAL
        )

    @property
    def schwarz_options(self) -> SchwarzOptions:
        """The Schwarz controls, the defaults with max_iterations if none were given."""
        return self.schwarz or SchwarzOptions(max_iterations=self.max_iterations)


def direct_path(spec: SolverSpec) -> SolverSpec:
    """An `auto` spec's direct path: MUMPS with its options (any other spec: itself).

    `auto` runs it unless MUMPS' memory estimate does not fit (methods/autosolve.py); its
    PETSc options (--petsc-option) are this path's.
    """
    if spec.kind is not SolverKind.AUTO:
        return spec
    return replace(spec, kind=SolverKind.DIRECT, name="mumps")


def _refuse(message: str) -> NoReturn:
    """Raise the one-line InputError of a broken rule."""
    raise InputError(message)
