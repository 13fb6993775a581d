"""Lame's shrink fit as a reference: the rings' contact pressure against the pair's mean.

Exact for rings in the plane models; in an axisymmetric model the open-ended long cylinder
(plane stress's formula), which the ends of a finite cylinder depart from: the record says
which (docs/models.md, "Lame").
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..methods.solution import Solution
from ..scenes import LameReference, Model
from .records import LameErrors


def lame_pressure(
    a: float,
    b: float,
    c: float,
    delta: float,
    inner: tuple[float, float],
    outer: tuple[float, float],
    model: Model,
) -> float:
    """Lame's shrink-fit contact pressure of rings a..b (inner) and b..c (outer).

    Plane stress (Shigley's Mechanical Engineering Design, sec. 3-16, "Press and Shrink
    Fits"; Lame's thick cylinder, Timoshenko & Goodier, ch. 4):
    p = delta / (b [(1/E_o)((c^2 + b^2)/(c^2 - b^2) + nu_o)
                    + (1/E_i)((b^2 + a^2)/(b^2 - a^2) - nu_i)]),
    `inner` and `outer` the (E, nu) of the rings; plane strain by E -> E/(1 - nu^2),
    nu -> nu/(1 - nu). Axisymmetric: an open-ended long cylinder (sigma_z = 0 away from the
    ends, each body free to shorten): plane stress's formula.
    """

    def plane(E: float, nu: float) -> tuple[float, float]:
        return (E / (1 - nu**2), nu / (1 - nu)) if model is Model.PLANE_STRAIN else (E, nu)

    (Ei, nui), (Eo, nuo) = plane(*inner), plane(*outer)
    compliance = ((c**2 + b**2) / (c**2 - b**2) + nuo) / Eo
    compliance += ((b**2 + a**2) / (b**2 - a**2) - nui) / Ei
    return delta / (b * compliance)


def lame_summary(sol: Solution, ref: LameReference) -> LameErrors:
    """The pair's mean contact pressure against Lame's (InputError if the pair is no fit)."""
    scene = sol.scene
    if ref.pair >= len(scene.contacts):
        raise InputError(f"lame reference: pair {ref.pair} is not a [[contact]] pair")
    pair = scene.contacts[ref.pair]
    delta = ref.delta if ref.delta is not None else pair.prescribed_overlap
    if not delta > 0:
        raise InputError(
            f"lame reference: give delta (pair {ref.pair} has no interference = D to take it from)"
        )
    pv = sol.pairs[ref.pair]
    # The active surface's outward normal points away from the centre (the axis) on the
    # inner ring.
    axi = scene.model is Model.AXISYMMETRIC
    outward = pv.n[:, 0] if axi else np.einsum("kd,kd->k", pv.n, pv.x - np.asarray(ref.center))
    radial = float(np.mean(outward))
    assert pv.passive_body is not None  # a [[contact]] pair joins two bodies
    inner, outer = (
        (pv.active_body, pv.passive_body) if radial > 0 else (pv.passive_body, pv.active_body)
    )
    w = sol.layout.weights[pv.rows]
    p_mean = float(np.sum(sol.pressure[pv.rows] * w) / np.sum(w))
    exact = lame_pressure(
        ref.a,
        ref.b,
        ref.c,
        delta,
        (inner.material.E, inner.material.nu),
        (outer.material.E, outer.material.nu),
        scene.model,
    )
    return LameErrors(
        pair=ref.pair,
        model=scene.model.value,
        inner=inner.name,
        outer=outer.name,
        delta=delta,
        p_mean=p_mean,
        p_exact=exact,
        error=abs(p_mean / exact - 1.0),
        active_fraction=float(np.mean(sol.active[pv.rows])) if len(pv.rows) else 0.0,
        exact=not axi,
        validity=LAME_VALIDITY[scene.model],
    )


# What Lame's rings are in each model: exact in the plane models, not at a cylinder's ends.
LAME_VALIDITY = {
    Model.PLANE_STRAIN: "exact: rings in plane strain (a long hub held at its ends)",
    Model.PLANE_STRESS: "exact: thin rings in plane stress",
    Model.AXISYMMETRIC: "approximate: an open-ended long cylinder, plane stress away from "
    "the ends (the mean over the interface includes the ends' effect)",
}
