"""The summary of a run: sizes, costs, every pair's results and the scene's references.

`summary` builds the RunSummary record (results/records.py) that `run_scene` returns; its
`to_json()` is the JSON of `contactfx solve --json`.
"""

from __future__ import annotations

from ..methods.solution import Solution
from ..options import Method, SolverSpec
from ..request import SolveRequest
from ..scenes import HertzReference, LameReference, UniformStress
from .cattaneo import cattaneo_checks
from .interface import cartesian_interface, contacts_summary
from .lame import lame_summary
from .probes import probe_value
from .pushout import pushout_checks
from .records import (
    ContactSummary,
    EstimateSummary,
    HertzErrors,
    LameErrors,
    MethodExtras,
    PatchErrors,
    ProbeResult,
    RunSummary,
    StepSummary,
)
from .references import hertz_summary, uniform_stress_errors
from .spence import spence_checks

__all__ = [
    "ContactSummary",
    "EstimateSummary",
    "HertzErrors",
    "LameErrors",
    "MethodExtras",
    "PatchErrors",
    "ProbeResult",
    "RunSummary",
    "method_extras",
    "solver_label",
    "summary",
]

# Schwarz factorizes each body with MUMPS, whatever solver the run was given.
SCHWARZ_SOLVER = "mumps (each body)"
SCHWARZ_SOLVES = "mumps (each body factorized once)"


def solver_label(method: Method, spec: SolverSpec) -> str:
    """The label of the linear solver a run used: the spec's name, or Schwarz's own."""
    return SCHWARZ_SOLVER if method is Method.SCHWARZ else spec.name


def method_extras(sol: Solution) -> MethodExtras:
    """What only some methods report: mortar's basis, penalty's stiffness, Schwarz's roles."""
    pen = sol.penalty
    return MethodExtras(
        basis=None if sol.basis.value == "standard" else sol.basis.value,
        penalty=None if pen is None else pen.eps,
        penetration=None if pen is None else pen.penetration,
        condition=None if pen is None else pen.condition,
        schwarz_dirichlet_body=sol.schwarz_dirichlet_body,
        schwarz_solver=None if sol.schwarz_dirichlet_body is None else SCHWARZ_SOLVES,
        reference_linear_iterations=sol.reference_linear_iterations,
    )


def summary(
    sol: Solution,
    times: dict[str, float],
    *,
    request: SolveRequest,
    memory: dict[str, float],
    paper_interface: bool = False,
) -> RunSummary:
    """The summary record of a run (its JSON schema in docs/usage.md).

    Args:
        sol: The solved scene.
        times: Labelled wall-clock seconds of the run.
        request: What was solved and how (the solver's label, the two axes).
        memory: Peak resident memory (MB), summed over the ranks and the largest rank's.
        paper_interface: Also the paper's x-sorted `interface` of pair 0 (sigma_yy of both
            bodies), for scenes with one horizontal contact line (the built-in scenes).

    Returns:
        The RunSummary, with one HertzErrors per Hertz reference and the patch test's errors.
    """
    scene = sol.scene
    refs = scene.references
    patch = [uniform_stress_errors(sol, r) for r in refs if isinstance(r, UniformStress)]
    cattaneo, cattaneo_steps = cattaneo_checks(sol)
    pushout, pushout_steps = pushout_checks(sol)
    spence, spence_steps = spence_checks(sol)
    return RunSummary(
        scene=scene.name,
        method=sol.method,
        params=dict(scene.params),
        ranks=scene.comm.size,
        dofs=sol.dofs,
        multipliers=int(sol.layout.size),
        elements=int(scene.mesh.topology.index_map(2).size_global),
        bodies=tuple(b.name for b in scene.bodies),
        iterations=sol.iterations,
        active_set=sol.history,
        times=times,
        contacts=contacts_summary(sol),
        solver=(
            solver_label(request.method, request.solver)
            if sol.solver_choice is None
            else sol.solver_choice.ran
        ),
        solver_choice=None if sol.solver_choice is None else sol.solver_choice.to_json(),
        discretization=request.discretization,
        enforcement=request.enforcement,
        memory=memory,
        units=scene.units,
        active_nodes=int(sol.active.sum()),
        extras=method_extras(sol),
        interface=cartesian_interface(sol) if paper_interface else None,
        hertz=tuple(hertz_summary(sol, r) for r in refs if isinstance(r, HertzReference)),
        # The last uniform stress wins, as one `patch` block holds one.
        patch=patch[-1] if patch else None,
        lame=tuple(lame_summary(sol, r) for r in refs if isinstance(r, LameReference)),
        cattaneo=cattaneo,
        pushout=pushout,
        spence=spence,
        probes=tuple(probe_value(sol, p) for p in scene.probes),
        steps=tuple(
            StepSummary(s.iterations, contacts_summary(s), c, po, sp)
            for s, c, po, sp in zip(
                sol.steps, cattaneo_steps, pushout_steps, spence_steps, strict=True
            )
        ),
    )
