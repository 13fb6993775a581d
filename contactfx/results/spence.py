"""Spence's stick ratio on a user's rigid cylinder, step by step (`[[reference]] type = "spence"`).

A rigid circle obstacle pressed with friction into a plane-strain body: per load step the
contact and stick half-widths read from the statuses (each edge halfway between the last node
of the zone and the next one), against c/a = spence_stick_ratio(mu, nu), computed once per
(mu, nu). The coordinate across the contact is measured along the active surface's tangent
from the pressure's centre, or from the symmetry line's end of a half model (as for Hertz).
"""

from __future__ import annotations

from functools import cache

import numpy as np

from ..contact.friction import Status
from ..methods.solution import Solution
from ..scenes import HertzReference, SpenceReference
from .friction_references import spence_stick_ratio
from .reference_records import SpenceCheck
from .references import centre_distance


@cache
def _ratio(mu: float, nu: float) -> float:
    return spence_stick_ratio(mu, nu)


def zone_half_width(r: np.ndarray, inside: np.ndarray, half: bool) -> float:
    """The half-width of the zone of nodes `inside` (r sorted, across the contact).

    Each edge lies halfway between the zone's last node and the next one out. A half model
    (`half`, r >= 0 from the symmetry line) measures from r = 0; a full one halves the span.
    """
    idx = np.flatnonzero(inside)
    if idx.size == 0:
        return 0.0
    lo, hi = int(idx[0]), int(idx[-1])
    right = 0.5 * (r[hi] + r[hi + 1]) if hi + 1 < len(r) else float(r[hi])
    if half:
        return float(right)
    left = 0.5 * (r[lo] + r[lo - 1]) if lo > 0 else float(r[lo])
    return float(0.5 * (right - left))


def spence_check(sol: Solution, ref: SpenceReference, step: int) -> SpenceCheck:
    """The obstacle pair at `sol`'s load step (numbered from 1) against Spence's c/a."""
    scene = sol.scene
    ob = scene.obstacles[ref.pair - len(scene.contacts)]
    assert ob.radius is not None and sol.friction is not None  # checks.py refused others
    mu = ob.mu if ref.mu is None else ref.mu
    nu = scene.body_of_curve(ob.surface).material.nu
    pv = sol.pairs[ref.pair]
    r, _, _, _, _ = centre_distance(sol, HertzReference(ref.pair, ob.radius, None, ref.symmetric))
    order = np.argsort(pv.arc[0][pv.nodes], kind="stable")
    status = sol.friction.status[pv.rows][order]
    across = np.argsort(r, kind="stable")
    r, status = r[across], status[across]
    act = status != Status.OPEN
    ra = r[act]  # sorted; signed, so a full model's mirror nodes do not pair up at 0
    h = float(np.median(np.diff(ra))) if ra.size > 1 else 0.0
    return SpenceCheck(
        pair=ref.pair,
        mu=mu,
        nu=nu,
        R=float(ob.radius),
        ratio_exact=_ratio(mu, nu),
        a=zone_half_width(r, act, ref.symmetric),
        c=zone_half_width(r, status == Status.STICK, ref.symmetric),
        h=h,
        step=step,
    )


def spence_checks(
    sol: Solution,
) -> tuple[tuple[SpenceCheck, ...], list[tuple[SpenceCheck, ...]]]:
    """Every Spence reference at the last step and at each step (empty without steps)."""
    refs = [r for r in sol.scene.references if isinstance(r, SpenceReference)]
    if not refs:
        return (), [() for _ in sol.steps]
    per_step = [tuple(spence_check(s, r, k) for r in refs) for k, s in enumerate(sol.steps, 1)]
    last = per_step[-1] if per_step else tuple(spence_check(sol, r, 1) for r in refs)
    return last, per_step
