"""The typed records of a run that the layers above read; each writes its JSON with `to_json()`.

`RunSummary` is what `run_scene` returns beside the Solution: the CLI, the writers, the
study and the adaptive loop read its attributes. Its `to_json()` is the schema of
`contactfx solve --json` (docs/usage.md), the one place that schema is written.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..options import Discretization, Enforcement, Method
from ..scenes import Obstacle, Units
from .obstacles import obstacle_json
from .reference_records import CattaneoCheck as CattaneoCheck
from .reference_records import HertzErrors as HertzErrors
from .reference_records import LameErrors as LameErrors
from .reference_records import PatchErrors as PatchErrors
from .reference_records import ProbeResult as ProbeResult
from .reference_records import PushoutCheck as PushoutCheck
from .reference_records import PushoutSummary as PushoutSummary
from .reference_records import SpenceCheck as SpenceCheck

# The JSON's `estimate.norm`: what the relative values are relative to.
ESTIMATE_NORM = (
    "energy: sqrt(int sigma(u_h) : eps(u_h)); every value above but "
    "absolute relative to it; pressure: the contact pressure's L2 error estimate "
    "relative to ||p_h||_L2 (results/pressure_estimate.py)"
)


@dataclass(frozen=True, kw_only=True)
class ContactSummary:
    """One contact pair's results: its names, forces, counts and interface columns.

    `force` is the sum of the pair's nodal forces. In an axisymmetric scene these are totals
    over the turn, and the x sum is no force (the radial forces of a body of revolution
    cancel): the records give the axial force (y, total over the turn) and the radial
    pressure's resultant per radian, int p n_r r ds (twice it is the force that splits the
    ring across a diametral plane: for a fit of radius b and length L, 2 p b L). The x
    component of `force` is then written as null (docs/models.md, "Forces").
    """

    active: str
    passive: str
    active_body: str
    passive_body: str  # an obstacle pair names the obstacle here too
    force: tuple[float, float]  # on the active body
    force_passive: tuple[float, float]
    balance: float  # |force + force_passive| / |force|
    multipliers: int
    active_nodes: int
    # INTERFACE_FIELDS columns (None where not finite) and `active`, sorted by s.
    interface: dict[str, list[Any]]
    obstacle: Obstacle | None = None
    initial_overlap: float = 0.0  # max over the pair's nodes of -gap before the solve
    axisymmetric: bool = False
    fit: bool = False  # the pair is an interference fit

    @property
    def axial_force(self) -> float:
        """Axisymmetric: the force along the axis on the active body, total over the turn."""
        return self.force[1]

    @property
    def radial_per_radian(self) -> float:
        """Axisymmetric: the radial pressure's resultant per radian on the active body."""
        return self.force[0] / (2.0 * math.pi)

    @property
    def magnitude(self) -> float:
        """The size of `force` in a plane model; that of `axial_force` in an axisymmetric one."""
        return abs(self.axial_force) if self.axisymmetric else float(np.hypot(*self.force))

    @property
    def components(self) -> tuple[float, float]:
        """The two force components that exist, named by `component_names`."""
        return (self.radial_per_radian, self.axial_force) if self.axisymmetric else self.force

    @property
    def component_names(self) -> tuple[str, str]:
        """Plane: (x, y); axisymmetric: the radial resultant per radian and the axial force."""
        return ("radial_per_radian", "axial") if self.axisymmetric else ("x", "y")

    def force_text(self) -> str:
        """The pair's forces for the terminal (axisymmetric: the components that exist)."""
        tail = f"balance {self.balance:.1e}, {self.active_nodes} active nodes"
        if not self.axisymmetric:
            return f"force ({self.force[0]:.6g}, {self.force[1]:.6g}), {tail}"
        text = (
            f"axial force {self.axial_force:.6g} (total over the turn), radial resultant "
            f"{self.radial_per_radian:.6g} per radian"
        )
        # A frictional fit's shear carries an axial force (its interface has statuses).
        if self.fit and self.force[0] != 0.0 and "status" not in self.interface:
            share = abs(self.axial_force / self.force[0])
            text += (
                f" (a fit's axial force is {100 * share:.2g} % of its radial load: none "
                "on a frictionless cylinder, the rest is the discretization's)"
            )
        return f"{text}, {tail}"

    def to_json(self) -> dict[str, Any]:
        """The pair's entry of the JSON's `contacts` list."""
        force: list[float | None] = list(self.force)
        force_passive: list[float | None] = list(self.force_passive)
        if self.axisymmetric:
            force[0] = force_passive[0] = None  # no radial force: see the class docstring
        out: dict[str, Any] = {
            "active": self.active,
            "passive": self.passive,
            "active_body": self.active_body,
            "passive_body": self.passive_body,
            "force": force,
            "force_passive": force_passive,
            "balance": self.balance,
            "multipliers": self.multipliers,
            "active_nodes": self.active_nodes,
            "initial_overlap": self.initial_overlap,
            "interface": self.interface,
        }
        if self.axisymmetric:
            out["axial_force"] = self.axial_force
            out["radial_force_per_radian"] = self.radial_per_radian
        if self.obstacle is not None:
            out["obstacle"] = obstacle_json(self.obstacle)
        return out


@dataclass(frozen=True, kw_only=True)
class EstimateSummary:
    """The error estimate, relative to the energy norm (pressure: to ||p_h||_L2)."""

    total: float
    contact: float
    bulk: float
    terms: dict[str, float]
    absolute: float
    energy_norm: float
    pressure: float | None
    # The goal's two-level estimate (adapt/goal.py GoalRecord.to_json: goal, goal_estimate,
    # goal_parts, ...), or None if none was asked for.
    goal: dict[str, Any] | None = None

    def to_json(self) -> dict[str, Any]:
        """The JSON's `estimate` block."""
        return {
            "total": self.total,
            "contact": self.contact,
            "bulk": self.bulk,
            "terms": self.terms,
            "absolute": self.absolute,
            "energy_norm": self.energy_norm,
            "pressure": self.pressure,
            "norm": ESTIMATE_NORM,
            **(self.goal or {}),
        }


@dataclass(frozen=True, kw_only=True)
class MethodExtras:
    """What only some methods report (None where the method has none)."""

    basis: str | None = None  # mortar's basis, when not standard
    penalty: float | None = None  # penalty's stiffness
    penetration: float | None = None
    condition: dict[str, float] | None = None  # CG + Jacobi estimate, if asked for
    schwarz_dirichlet_body: str | None = None
    schwarz_solver: str | None = None
    reference_linear_iterations: int | None = None

    def to_json(self) -> dict[str, Any]:
        """The keys these give in the JSON, in its order."""
        out: dict[str, Any] = {}
        if self.basis is not None:
            out["basis"] = self.basis
        if self.penalty is not None:
            out["penalty"] = self.penalty
            out["penetration"] = self.penetration
            if self.condition is not None:
                out["condition"] = self.condition
        if self.schwarz_dirichlet_body is not None:
            out["schwarz"] = {
                "dirichlet_body": self.schwarz_dirichlet_body,
                "solver": self.schwarz_solver,
            }
        if self.reference_linear_iterations is not None:
            out["reference_linear_iterations"] = self.reference_linear_iterations
        return out


@dataclass(frozen=True)
class StepSummary:
    """One load step of a run: its iterations and every pair's results at its end."""

    iterations: int
    contacts: tuple[ContactSummary, ...]
    cattaneo: tuple[CattaneoCheck, ...] = ()  # one per Cattaneo reference
    pushout: tuple[PushoutCheck, ...] = ()  # one per push-out reference
    spence: tuple[SpenceCheck, ...] = ()  # one per Spence reference

    def to_json(self) -> dict[str, Any]:
        """The step's entry of the JSON's `steps`."""
        out: dict[str, Any] = {
            "iterations": self.iterations,
            "contacts": [c.to_json() for c in self.contacts],
        }
        if self.cattaneo:
            out["cattaneo"] = [c.to_json() for c in self.cattaneo]
        if self.pushout:
            out["pushout"] = [c.to_json() for c in self.pushout]
        if self.spence:
            out["spence"] = [c.to_json() for c in self.spence]
        return out


@dataclass(frozen=True, kw_only=True)
class RunSummary:
    """One run: sizes, iterations, costs, every pair's results and the references' errors."""

    scene: str
    method: Method
    params: dict[str, Any]
    ranks: int
    dofs: int
    multipliers: int
    elements: int
    bodies: tuple[str, ...]
    iterations: int
    active_set: list[Any]  # the active-set (or Schwarz) history, step by step
    times: dict[str, float]
    contacts: tuple[ContactSummary, ...]
    solver: str  # the label of the linear solver that ran
    solver_choice: dict[str, Any] | None = None  # `auto`: what it ran and why
    discretization: Discretization
    enforcement: Enforcement
    memory: dict[str, float]
    units: Units = field(default_factory=Units)  # labels for pictures; not in the JSON
    active_nodes: int
    extras: MethodExtras = MethodExtras()
    interface: dict[str, list[float | None]] | None = None  # the paper's view of pair 0
    hertz: tuple[HertzErrors, ...] = ()  # one per Hertz reference
    patch: PatchErrors | None = None
    estimate: EstimateSummary | None = None
    lame: tuple[LameErrors, ...] = ()  # one per Lame reference
    cattaneo: tuple[CattaneoCheck, ...] = ()  # one per Cattaneo reference (the last step)
    pushout: tuple[PushoutSummary, ...] = ()  # one per push-out reference
    spence: tuple[SpenceCheck, ...] = ()  # one per Spence reference (the last step)
    probes: tuple[ProbeResult, ...] = ()  # one per probe of the scene
    steps: tuple[StepSummary, ...] = ()  # one per [[step]] (none without steps)

    @property
    def contact_force(self) -> float:
        """Magnitude of the first pair's force (axisymmetric: its axial force's)."""
        return self.contacts[0].magnitude

    def with_estimate(self, estimate: EstimateSummary) -> RunSummary:
        """The same summary with the error estimate attached."""
        return replace(self, estimate=estimate)

    def with_times(self, **seconds: float) -> RunSummary:
        """The same summary with these times replaced (e.g. a mesh timed elsewhere)."""
        return replace(self, times={**self.times, **seconds})

    def to_json(self) -> dict[str, Any]:
        """The JSON summary of `contactfx solve --json` (schema in docs/usage.md)."""
        out: dict[str, Any] = {
            "scene": self.scene,
            "method": self.method.value,
            "params": self.params,
            "ranks": self.ranks,
            "dofs": self.dofs,
            "multipliers": self.multipliers,
            "elements": self.elements,
            "bodies": list(self.bodies),
            "iterations": self.iterations,
            "active_set": self.active_set,
            "times": self.times,
            "contact_force": self.contact_force,
            "active_nodes": self.active_nodes,
            "contacts": [c.to_json() for c in self.contacts],
            **self.extras.to_json(),
        }
        if self.interface is not None:
            out["interface"] = self.interface
        if self.hertz:
            out["hertz"] = self.hertz[0].to_json()
            if len(self.hertz) > 1:
                out["hertz_pairs"] = [h.to_json() for h in self.hertz]
        if self.patch is not None:
            out["patch"] = self.patch.to_json()
        if self.lame:
            out["lame"] = [r.to_json() for r in self.lame]
        if self.cattaneo:
            out["cattaneo"] = [r.to_json() for r in self.cattaneo]
        if self.pushout:
            out["pushout"] = [r.to_json() for r in self.pushout]
        if self.spence:
            out["spence"] = [r.to_json() for r in self.spence]
        if self.probes:
            out["probes"] = [p.to_json() for p in self.probes]
        if self.steps:
            out["steps"] = [s.to_json() for s in self.steps]
        out["solver"] = self.solver
        if self.solver_choice is not None:
            out["solver_choice"] = self.solver_choice
        out["discretization"] = self.discretization.value
        out["enforcement"] = self.enforcement.value
        out["memory"] = self.memory
        if self.estimate is not None:
            out["estimate"] = self.estimate.to_json()
        return out
