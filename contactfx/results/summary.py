"""The JSON summary of a run: sizes, costs, every pair's results and the scene's references."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..methods.solution import Solution
from ..scenes import HertzReference, UniformStress
from .interface import cartesian_interface, contacts_summary
from .references import hertz_summary, uniform_stress_errors


def reference_results(sol: Solution) -> dict[str, Any]:
    """Errors against each analytic reference the scene carries (keys `hertz`, `patch`)."""
    hertz = [hertz_summary(sol, r) for r in sol.scene.references if isinstance(r, HertzReference)]
    out: dict[str, Any] = {}
    if hertz:
        out["hertz"] = hertz[0]
        if len(hertz) > 1:
            out["hertz_pairs"] = hertz
    for r in sol.scene.references:
        if isinstance(r, UniformStress):
            out["patch"] = {
                "sigma": [list(row) for row in r.sigma],
                **uniform_stress_errors(sol, np.asarray(r.sigma, dtype=float)),
            }
    return out


def method_results(sol: Solution) -> dict[str, Any]:
    """What only some methods report: mortar's basis, penalty's stiffness, Schwarz's roles."""
    out: dict[str, Any] = {}
    if sol.basis.value != "standard":
        out["basis"] = sol.basis.value
    if sol.penalty is not None:
        out["penalty"] = sol.penalty.eps
        out["penetration"] = sol.penalty.penetration
        if sol.penalty.condition is not None:
            out["condition"] = sol.penalty.condition
    if sol.schwarz_dirichlet_body is not None:
        out["schwarz"] = {
            "dirichlet_body": sol.schwarz_dirichlet_body,
            "solver": "mumps (each body factorized once)",
        }
    if sol.reference_linear_iterations is not None:
        out["reference_linear_iterations"] = sol.reference_linear_iterations
    return out


def summary(
    sol: Solution,
    times: dict[str, float],
    extra: dict[str, Any] | None = None,
    *,
    paper_interface: bool = False,
) -> dict[str, Any]:
    """The JSON-ready summary of a run (schema in README).

    `paper_interface`: also the paper's x-sorted `interface` of pair 0 (sigma_yy of
    both bodies), for scenes with one horizontal contact line (the built-in scenes).
    """
    scene = sol.scene
    contacts = contacts_summary(sol)
    data: dict[str, Any] = {
        "scene": scene.name,
        "method": sol.method.value,
        "params": dict(scene.params),
        "ranks": scene.comm.size,
        "dofs": sol.dofs,
        "multipliers": int(sol.layout.size),
        "elements": int(scene.mesh.topology.index_map(2).size_global),
        "bodies": [b.name for b in scene.bodies],
        "iterations": sol.iterations,
        "active_set": sol.history,
        "times": times,
        # Magnitude of the first pair's force: the paper's scenes have one pair.
        "contact_force": float(np.linalg.norm(contacts[0]["force"])),
        "active_nodes": int(sol.active.sum()),
        "contacts": contacts,
        **method_results(sol),
    }
    if paper_interface:
        data["interface"] = cartesian_interface(sol)
    data.update(reference_results(sol))
    data.update(extra or {})
    return data
