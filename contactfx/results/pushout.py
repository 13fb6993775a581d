"""A press fit pushed out (`[[reference]] type = "pushout"`): axial force against mu N.

At each load step the pair's axial force (results/interface.pair_forces, total over the
turn) against mu times its normal force, N = sum_j w_j lambda_n,j (the pressure integrated
over the revolved interface: the axisymmetric weights hold 2 pi r), the stick and slip
counts, and on the slip nodes Coulomb's |shear| = mu p. The first step, the fit before the
push, against Lame's rings where the reference gives them (results/lame.py).
"""

from __future__ import annotations

import numpy as np

from ..contact.friction import Status
from ..methods.solution import Solution
from ..scenes import Model, PushoutReference
from .interface import pair_forces
from .lame import lame_pressure
from .reference_records import PushoutCheck, PushoutFit, PushoutSummary


def _mu(sol: Solution, ref: PushoutReference) -> float:
    return ref.mu if ref.mu is not None else sol.scene.contacts[ref.pair].mu


def pushout_check(sol: Solution, ref: PushoutReference) -> PushoutCheck:
    """The pair at `sol`'s step: |axial| / (mu N), the statuses and the slip law."""
    fr = sol.friction
    assert fr is not None  # checks.py refuses a frictionless pair
    mu = _mu(sol, ref)
    pv = sol.pairs[ref.pair]
    rows = pv.rows
    w = sol.layout.weights[rows]
    p, q, status = sol.pressure[rows], fr.shear[rows], fr.status[rows]
    touching = status != Status.OPEN
    axial = float(pair_forces(sol, ref.pair)[0][1])
    slip = status == Status.SLIP
    p_max = float(p.max(initial=0.0))
    law = None
    if slip.any() and p_max > 0:
        law = float(np.max(np.abs(np.abs(q[slip]) - mu * p[slip]))) / (mu * p_max)
    return PushoutCheck(
        pair=ref.pair,
        mu=mu,
        axial=axial,
        normal=float(w @ p),
        stick=int(np.sum(status == Status.STICK)),
        slip=int(slip.sum()),
        open=int(np.sum(status == Status.OPEN)),
        slip_law=law,
        taper=float(np.abs(pv.n[touching, 1]).max(initial=0.0)),
    )


def pushout_fit(sol: Solution, ref: PushoutReference) -> PushoutFit | None:
    """The fit's mean pressure (`sol`: the first step) against Lame's two limits, or None."""
    if ref.rings is None:
        return None
    a, b, c = ref.rings
    delta = ref.delta if ref.delta is not None else sol.scene.contacts[ref.pair].prescribed_overlap
    pv = sol.pairs[ref.pair]
    assert pv.passive_body is not None  # a [[contact]] pair joins two bodies
    # The inner ring: the body whose contact surface faces away from the axis.
    outward = float(np.mean(pv.n[:, 0])) > 0
    inner, outer = (
        (pv.active_body, pv.passive_body) if outward else (pv.passive_body, pv.active_body)
    )
    rings = ((inner.material.E, inner.material.nu), (outer.material.E, outer.material.nu))
    w = sol.layout.weights[pv.rows]
    return PushoutFit(
        p_mean=float(w @ sol.pressure[pv.rows] / w.sum()),
        open_ended=lame_pressure(a, b, c, delta, *rings, Model.AXISYMMETRIC),
        plane_strain=lame_pressure(a, b, c, delta, *rings, Model.PLANE_STRAIN),
        delta=delta,
    )


def pushout_checks(
    sol: Solution,
) -> tuple[tuple[PushoutSummary, ...], list[tuple[PushoutCheck, ...]]]:
    """Every push-out reference over the run, and each step's checks (checks.py: steps >= 2)."""
    refs = [r for r in sol.scene.references if isinstance(r, PushoutReference)]
    if not refs:
        return (), [() for _ in sol.steps]
    per_step = [tuple(pushout_check(s, r) for r in refs) for s in sol.steps]
    runs = tuple(
        PushoutSummary(steps=tuple(step[k] for step in per_step), fit=pushout_fit(sol.steps[0], r))
        for k, r in enumerate(refs)
    )
    return runs, per_step
