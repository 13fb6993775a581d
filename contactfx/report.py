"""The JSON summary of a run: sizes, costs, every pair's results and the scene's references."""

from __future__ import annotations

from typing import Any

import numpy as np

from .hertz import hertz_summary
from .postprocess import cartesian_interface, contacts_summary, uniform_stress_errors
from .scenes import HertzReference, UniformStress
from .solution import Solution


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


def summary(
    sol: Solution, times: dict[str, float], extra: dict[str, Any] | None = None
) -> dict[str, Any]:
    """The JSON-ready summary of a run (schema in README)."""
    scene = sol.scene
    V = sol.elasticity.V
    contacts = contacts_summary(sol)
    data: dict[str, Any] = {
        "scene": scene.name,
        "method": sol.method.value,
        "params": scene.params_dict(),
        "ranks": scene.comm.size,
        "dofs": V.dofmap.index_map.size_global * V.dofmap.index_map_bs,
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
        **sol.info,
    }
    if scene.cartesian_interface:
        data["interface"] = cartesian_interface(sol)
    data.update(reference_results(sol))
    data.update(extra or {})
    return data
