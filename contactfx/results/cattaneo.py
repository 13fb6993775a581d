"""Cattaneo-Mindlin on a user's frictional pair, step by step (`[[reference]] type = "cattaneo"`).

The closed form (results/friction_references.py) under the pair's own forces: P and Q the sums
of its pressure and shear multipliers, E* of its two bodies, mu the reference's or the pair's.
The coordinate across the contact is measured along the active surface's tangent from the
pressure's centre (as for Hertz, results/references.py).
"""

from __future__ import annotations

import numpy as np

from ..contact.friction import Status
from ..methods.solution import Solution
from ..scenes import CattaneoReference, HertzReference
from .friction_references import cattaneo_errors, cattaneo_mindlin
from .reference_records import CattaneoCheck
from .references import centre_distance, effective_modulus


def _shear_ratio(sol: Solution, ref: CattaneoReference, mu: float) -> float:
    """The pair's shear L2 over mu times its pressure's (nodal, weighted by the multipliers')."""
    assert sol.friction is not None
    rows = sol.pairs[ref.pair].rows
    w = sol.layout.weights[rows]
    q, p = sol.friction.shear[rows], sol.pressure[rows]
    norm = mu * float(np.sqrt(w @ p**2))
    return float(np.sqrt(w @ q**2)) / norm if norm > 0 else 0.0


def cattaneo_check(
    sol: Solution, ref: CattaneoReference, approach: Solution | None
) -> CattaneoCheck:
    """The pair at `sol`'s step against Cattaneo-Mindlin; `approach` the first step (or None)."""
    scene = sol.scene
    pair = scene.contacts[ref.pair]
    mu = ref.mu if ref.mu is not None else pair.mu
    fr = sol.friction
    assert fr is not None  # checks.py refuses a frictionless pair
    pv = sol.pairs[ref.pair]
    rows = pv.rows
    w = sol.layout.weights[rows]
    P = float(w @ sol.pressure[rows])
    # centre_distance orders the rows by arc length: the shear and statuses alike.
    r, p, act, _, _ = centre_distance(sol, HertzReference(ref.pair, ref.R))
    order = np.argsort(pv.arc[0][pv.nodes], kind="stable")
    q, status = fr.shear[rows][order], fr.status[rows][order]
    Q = float(w[order] @ q)
    if Q < 0:  # the push's sense: the closed form's shear is positive
        q, Q = -q, -Q
    mats = [scene.body_of_curve(g).material for g in (pair.active, pair.passive)]
    e_star = effective_modulus(mats, scene.model)
    # Round-off may carry Q a hair past mu P in full slip (c = 0 there).
    cm = cattaneo_mindlin(P, min(Q, mu * P), mu, ref.R, e_star)
    err = cattaneo_errors(cm, r, q, p, status == Status.STICK)
    ra = np.sort(r[act])
    h = float(np.median(np.diff(ra))) if ra.size > 1 else 0.0
    return CattaneoCheck(
        pair=ref.pair,
        P=P,
        Q=Q,
        mu=mu,
        E_star=e_star,
        a_exact=cm.a,
        c_exact=cm.c,
        c=err.c,
        h=h,
        shear_l2=err.shear_l2,
        slip_law=err.slip_law,
        shear_ratio=_shear_ratio(sol, ref, mu),
        approach_shear=None if approach is None else _shear_ratio(approach, ref, mu),
        pressure_l2=err.pressure_l2,
    )


def cattaneo_checks(
    sol: Solution,
) -> tuple[tuple[CattaneoCheck, ...], list[tuple[CattaneoCheck, ...]]]:
    """Every Cattaneo reference at the last step and at each step (empty without steps)."""
    refs = [r for r in sol.scene.references if isinstance(r, CattaneoReference)]
    if not refs:
        return (), [() for _ in sol.steps]
    approach = sol.steps[0] if len(sol.steps) > 1 else None
    per_step = [tuple(cattaneo_check(s, r, approach) for r in refs) for s in sol.steps]
    return tuple(cattaneo_check(sol, r, approach) for r in refs), per_step
