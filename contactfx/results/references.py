"""Analytic references: Hertz contact, the patch test's uniform stress, Lame's shrink fit.

Hertz is the plane line contact (a cylinder, force per unit thickness) in plane strain and
plane stress (E* from the model's effective moduli: E/(1 - nu^2) in plane strain, E in plane
stress), and in an axisymmetric model the point contact of a sphere (3D, total force), whose
L2 error weights the pressure by r (the integral over the contact disc), or a ring's line
contact (`contact = "line"`: the line load is the total force over 2 pi r_c).

Hertz, for one pair: half-width, peak and the L2 error of the pressure. The distance r from
the contact centre is measured along the active surface's tangent at the centre (the
tangent-plane coordinate of Hertz's theory). A sphere's centre is on the axis (r is the
radius); for a half model (`symmetric`) the centre is the end of the active surface nearest
the pressure peak; otherwise the pressure's own centre along the arc length: the first
moment of the piecewise-linear pressure (`pressure_centre`).

Each record says whether its reference is exact for the scene (the patch test's uniform
stress; Lame's rings in a plane model, results/lame.py) or approximate (Hertz's half-space
theory).
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from ..contact.geometry import Surface
from ..errors import InputError
from ..methods.solution import Solution
from ..scenes import (
    HertzContact,
    HertzReference,
    Material,
    Model,
    Scene,
    UniformStress,
)
from .interface import curve_radius, pair_forces, pair_interface, report_frame, resolve
from .lame import lame_pressure as lame_pressure  # where tests and scripts found it
from .records import HertzErrors, PatchErrors
from .stress import body_vertex_stress


def exact_pressure(x: np.ndarray, a: float, p0: float) -> np.ndarray:
    """Plane-strain Hertz pressure p0 sqrt(1 - x^2/a^2) inside |x| < a, zero outside."""
    return p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))


def fit_half_width(x: np.ndarray, p: np.ndarray) -> float | None:
    """Least-squares fit of p^2 = p0^2 (1 - x^2/a^2); returns a."""
    A = np.column_stack([np.ones_like(x), x**2])
    (c0, c1), *_ = np.linalg.lstsq(A, p**2, rcond=None)
    return float(np.sqrt(-c0 / c1)) if c1 < 0 < c0 else None


def pressure_centre(s: np.ndarray, p: np.ndarray) -> float:
    """Centre of the piecewise-linear pressure: integral of p s ds / integral of p ds.

    Integrated exactly segment by segment (s sorted; negative values count as 0). A mean of
    the nodes' s weighted by their pressures would lean towards the side with more nodes.
    """
    order = np.argsort(s, kind="stable")
    s, w = s[order], np.clip(p[order], 0.0, None)
    h, s0, s1, w0, w1 = np.diff(s), s[:-1], s[1:], w[:-1], w[1:]
    mass = float(np.sum(h * (w0 + w1))) / 2.0
    if mass <= 0.0:
        return float(s[np.argmax(w)]) if s.size else 0.0
    return float(np.sum(h * (w0 * (2 * s0 + s1) + w1 * (s0 + 2 * s1)))) / (6.0 * mass)


def l2_error(
    x: np.ndarray,
    p: np.ndarray,
    a: float,
    p0: float,
    samples: int = 40001,
    both_sides: bool = False,
    radial: bool = False,
) -> float:
    """Relative L2 error over [0, 1.5 a] (or [-1.5 a, 1.5 a]) of the piecewise-linear pressure.

    `radial`: weighted by |x| (axisymmetric: the integral over the contact disc, r dr).
    """
    xs = np.linspace(-1.5 * a if both_sides else 0.0, 1.5 * a, samples)
    ph = np.interp(xs, x, p, left=0.0, right=0.0)
    pe = exact_pressure(xs, a, p0)
    w = np.abs(xs) if radial else 1.0
    return float(np.sqrt(np.trapezoid(w * (ph - pe) ** 2, xs) / np.trapezoid(w * pe**2, xs)))


def effective_modulus(mats: list[Material], model: Model) -> float:
    """E* = 1 / sum (1 - nu^2)/E (plane strain, axisymmetric); 1 / sum 1/E in plane stress."""
    if model is Model.PLANE_STRESS:
        return 1.0 / sum(1.0 / m.E for m in mats)
    return 1.0 / sum((1 - m.nu**2) / m.E for m in mats)


def hertz_values(
    e_star: float, R: float, P: float, contact: HertzContact | Model
) -> dict[str, float]:
    """E*, a and p0 of Hertz's contact under the load P.

    Line (a cylinder, P per unit length): a = sqrt(4 P R/(pi E*)), p0 = 2 P/(pi a).
    Point (a sphere, P the total force): a = (3 P R/(4 E*))^(1/3), p0 = 3 P/(2 pi a^2).
    A model stands for its default contact (axisymmetric: the point).
    """
    if isinstance(contact, Model):
        contact = HertzContact.POINT if contact is Model.AXISYMMETRIC else HertzContact.LINE
    if contact is HertzContact.POINT:
        a = (3 * P * R / (4 * e_star)) ** (1.0 / 3.0)
        return {"E_star": e_star, "a": a, "p0": 3 * P / (2 * math.pi * a * a)}
    a = math.sqrt(4 * P * R / (math.pi * e_star))
    return {"E_star": e_star, "a": a, "p0": 2 * P / (math.pi * a)}


def reference_values(scene: Scene, ref: HertzReference, P: float) -> dict[str, float]:
    """E*, a and p0 of the pair's materials under the load P (`hertz_values`).

    A rigid obstacle (pair index len(contacts) + i) is infinitely stiff: it adds nothing.
    """
    if ref.pair >= len(scene.contacts):
        groups = [scene.obstacles[ref.pair - len(scene.contacts)].surface]
    else:
        groups = [scene.contacts[ref.pair].active, scene.contacts[ref.pair].passive]
    mats = [scene.body_of_curve(g).material for g in groups]
    return hertz_values(effective_modulus(mats, scene.model), ref.R, P, ref.contact_in(scene.model))


def centre_mode(ref: HertzReference, model: Model) -> str:
    """Where the contact centre is: "axis" (a sphere), "end" (a half model) or "moment"."""
    if ref.contact_in(model) is HertzContact.POINT:
        return "axis"
    return "end" if ref.symmetric else "moment"


def computed_load(sol: Solution, ref: HertzReference, tangent: np.ndarray) -> float:
    """The pair's load: its contact force along the normal at the centre (x2 if halved).

    `tangent` is the active surface's tangent at the contact centre. Axisymmetric: the force
    is already the total over the turn (the half section is the whole body).
    """
    force = pair_forces(sol, ref.pair)[0]
    normal = np.array([-tangent[1], tangent[0]])
    halved = centre_mode(ref, sol.scene.model) == "end"
    return float(abs(force @ normal) * (2.0 if halved else 1.0))


def axis_node(surf: Surface, s_all: np.ndarray, pair: int) -> int:
    """The active surface's node on the axis (x = 0): a sphere's contact centre.

    InputError if the surface does not reach the axis (a ring's contact is a line).
    """
    ok = np.isfinite(s_all)
    extent = float(np.ptp(surf.x[ok], axis=0).max()) if ok.any() else 0.0
    node = int(np.argmin(np.where(ok, np.abs(surf.x[:, 0]), np.inf)))
    if abs(surf.x[node, 0]) > 1e-6 * max(extent, 1e-300):
        raise InputError(
            f"hertz reference (pair {pair}): a sphere's contact centre is on the axis, but "
            f"the pair's active surface stops at r = {surf.x[node, 0]:.4g} (a ring's "
            'contact: give contact = "line")'
        )
    return node


def centre_distance(
    sol: Solution, ref: HertzReference
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """(r, pressure, active, tc, sc) of the pair's multipliers, r signed along the centre's tangent.

    tc is that tangent (unit), sc the centre's arc length s along the active surface. A
    sphere (axisymmetric): r is the radius x, tc the radial direction (1, 0).
    """
    pv = sol.pairs[ref.pair]
    rows = pv.rows
    surf = pv.active.surface
    node = pv.nodes
    s_all, t_all = pv.arc
    s, p = s_all[node], sol.pressure[rows]
    order = np.argsort(s, kind="stable")
    s, p, node, act = s[order], p[order], node[order], sol.active[rows][order]
    mode = centre_mode(ref, sol.scene.model)
    if mode == "axis":
        centre_node = axis_node(surf, s_all, ref.pair)
        return surf.x[node, 0].copy(), p, act, np.array([1.0, 0.0]), float(s_all[centre_node])
    if mode == "end":
        peak = s[int(np.argmax(p))]
        ends = np.array([np.nanmin(s_all), np.nanmax(s_all)])
        centre_node = int(np.nanargmin(np.abs(s_all - ends[np.argmin(np.abs(ends - peak))])))
        xc, tc, sc = surf.x[centre_node], t_all[centre_node], float(s_all[centre_node])
    else:
        sc = pressure_centre(s, p)
        xc = np.array([np.interp(sc, s, surf.x[node, d]) for d in (0, 1)])
        tc = np.array([np.interp(sc, s, t_all[node, d]) for d in (0, 1)])
        tc /= np.linalg.norm(tc)
    r = (surf.x[node] - xc) @ tc
    if mode == "end" and np.any(p > 0) and np.median(r[p > 0]) < 0:
        r = -r  # the centre is the end of largest s: measure into the surface
    return r, p, act, tc, sc


def hertz_summary(sol: Solution, ref: HertzReference | None = None) -> HertzErrors:
    """The pair's errors against Hertz: fitted and bracketed half-width, p0 and the L2 error."""
    if ref is None:
        ref = next(r for r in sol.scene.references if isinstance(r, HertzReference))
    scene = sol.scene
    contact = ref.contact_in(scene.model)
    r, p, act, tc, sc = centre_distance(sol, ref)
    load = ref.P if ref.P is not None else computed_load(sol, ref, tc)
    xc = centre_point(sol, ref, sc)
    line_load = None
    if contact is HertzContact.LINE and scene.model is Model.AXISYMMETRIC:
        line_load = load / (2.0 * math.pi * xc[0])  # the total over the turn, per length
    exact = reference_values(scene, ref, load if line_load is None else line_load)
    radius = surface_radius(sol, ref, xc)
    order = np.argsort(r, kind="stable")
    r, p, act = r[order], p[order], act[order]
    ra = np.abs(r[act])
    last = float(ra.max()) if ra.size else 0.0
    beyond = np.abs(r[(~act) & (np.abs(r) > last)])
    return HertzErrors(
        pair=ref.pair,
        s_centre=sc,
        a=fit_half_width(r[act], p[act]),
        a_bracket=(last, float(beyond.min()) if beyond.size else None),
        a_exact=exact["a"],
        p0=float(p.max()),
        p0_exact=exact["p0"],
        E_star=exact["E_star"],
        P=load,
        P_source="given" if ref.P is not None else "computed (the pair's contact force)",
        l2_error=l2_error(
            r,
            p,
            exact["a"],
            exact["p0"],
            both_sides=centre_mode(ref, scene.model) == "moment",
            radial=contact is HertzContact.POINT,
        ),
        description=hertz_description(contact, scene.model),
        window=HERTZ_WINDOWS[centre_mode(ref, scene.model)],
        line_load=line_load,
        a_over_radius=exact["a"] / radius,
    )


# The interval of the L2 error, by where the centre is (centre_mode).
HERTZ_WINDOWS = {
    "axis": "[0, 1.5 a] of the radius (the contact disc, weighted by r)",
    "end": "[0, 1.5 a] (half model)",
    "moment": "[-1.5 a, 1.5 a] (full model)",
}


def hertz_description(contact: HertzContact, model: Model) -> str:
    """What the Hertz reference is in this model, in words (terminal, JSON, study)."""
    if contact is HertzContact.POINT:
        return "Hertz point contact of a sphere (Johnson 3.4; axisymmetric, P the total force)"
    if model is Model.AXISYMMETRIC:
        return (
            "Hertz line contact of a ring (Johnson 4.2 on a torus section; axisymmetric, "
            "the line load P / (2 pi r_c))"
        )
    return f"{model.value.replace('_', '-')} Hertz line contact (Johnson 4.2)"


def centre_point(sol: Solution, ref: HertzReference, sc: float) -> np.ndarray:
    """The contact centre's point: on the active surface at arc length sc."""
    pv = sol.pairs[ref.pair]
    s_all = pv.arc[0]
    ok = np.flatnonzero(np.isfinite(s_all))
    order = ok[np.argsort(s_all[ok], kind="stable")]
    x = pv.active.surface.x
    return np.array([np.interp(sc, s_all[order], x[order, d]) for d in (0, 1)])


def surface_radius(sol: Solution, ref: HertzReference, xc: np.ndarray) -> float:
    """The smaller radius of the two surfaces at the contact centre (inf if both are flat).

    Hertz's theory holds for a small against it (and against the bodies' size): a / R_min
    is the record's measure of how approximate the reference is.
    """
    pv = sol.pairs[ref.pair]
    radii = [curve_radius(pv.active.surface, xc)]
    if pv.passive is not None:
        radii.append(curve_radius(pv.passive.surface, xc))
    elif pv.obstacle is not None and pv.obstacle.radius is not None:
        radii.append(float(pv.obstacle.radius))
    return min(radii)


def _max_error(values: list[float | None], exact: np.ndarray, scale: float) -> float:
    """Max |value - exact| / scale over the values that exist."""
    v = np.array([np.nan if a is None else a for a in values], dtype=float)
    return float(np.nanmax(np.abs(v - exact), initial=0.0) / scale)


def uniform_stress_errors(sol: Solution, ref: UniformStress) -> PatchErrors:
    """Patch test against a uniform stress: max errors relative to the largest abs(ref_ij)."""
    sigma = np.asarray(ref.sigma, dtype=float)
    comm = sol.scene.comm
    scale = float(np.abs(sigma).max())
    bodies = {
        name: comm.allreduce(float(np.max(np.abs(v - sigma), initial=0.0)), op=MPI.MAX) / scale
        for name, v in body_vertex_stress(sol).items()
    }
    pairs = []
    for k, pv in enumerate(sol.pairs):
        itf = pair_interface(sol, k)
        order = np.argsort(pv.s, kind="stable")
        n, nu, tau = (v[order] for v in report_frame(pv))
        sig = np.broadcast_to(sigma, (len(nu), 2, 2))
        # The exact values of the columns: each side's traction in the contact frame.
        nn_a, nt_a = resolve(sig, n, nu, tau)
        nn_p, nt_p = resolve(sig, nu, nu, tau)
        exact = {"nn_active": nn_a, "nn_passive": nn_p, "nt_active": nt_a, "nt_passive": nt_p}
        sides = ("active",) if pv.obstacle is not None else ("active", "passive")
        shear = {}
        fr = sol.friction
        if "shear" in itf and fr is not None and np.any(fr.mu[pv.rows] > 0):
            # The frictional multiplier: the traction on the active body (sigma nu, nu out of
            # it) is -shear along t = (-nu_y, nu_x) (results/interface.py's convention). A
            # frictionless pair carries none, whatever the uniform stress's shear.
            traction = np.einsum("kij,kj->ki", sig, nu)
            exact_shear = -(traction[:, 0] * -nu[:, 1] + traction[:, 1] * nu[:, 0])
            shear["shear"] = _max_error(itf["shear"], exact_shear, scale)
        pairs.append(
            {
                **shear,
                "pressure": _max_error(itf["pressure"], -nn_p, scale),
                **{
                    f"sigma_{kind}_{side}": _max_error(
                        itf[f"sigma_{kind}_{side}"], exact[f"{kind}_{side}"], scale
                    )
                    for kind in ("nn", "nt")
                    for side in sides
                },
            }
        )
    return PatchErrors(
        sigma=ref.sigma,
        bodies=bodies,
        pairs=tuple(pairs),
        max=max([*bodies.values(), *(v for p in pairs for v in p.values())]),
    )
