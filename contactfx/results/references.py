"""Analytic references: Hertz contact, the patch test's uniform stress, Lame's shrink fit.

Hertz is the plane line contact (a cylinder, force per unit thickness) in plane strain and
plane stress (E* from the model's effective moduli: E/(1 - nu^2) in plane strain, E in plane
stress), and the point contact of a sphere (3D, total force) in an axisymmetric model, whose
L2 error weights the pressure by r (the integral over the contact disc).

Hertz, for one pair: half-width, peak and the L2 error of the pressure. The distance r from
the contact centre is measured along the active surface's tangent at the centre (the
tangent-plane coordinate of Hertz's theory). For a half model (`symmetric`) the centre is the
end of the active surface nearest the pressure peak; otherwise the pressure's own centre along
the arc length: the first moment of the piecewise-linear pressure (`pressure_centre`).
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from ..errors import InputError
from ..methods.solution import Solution
from ..scenes import HertzReference, LameReference, Material, Model, Scene, UniformStress
from .interface import pair_forces, pair_interface, report_frame, resolve
from .records import HertzErrors, LameErrors, PatchErrors
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


def hertz_values(e_star: float, R: float, P: float, model: Model) -> dict[str, float]:
    """E*, a and p0 of Hertz's contact under the load P.

    Cylinder (plane models, P per unit thickness): a = sqrt(4 P R/(pi E*)), p0 = 2 P/(pi a).
    Sphere (axisymmetric, P the total force): a = (3 P R/(4 E*))^(1/3), p0 = 3 P/(2 pi a^2).
    """
    if model is Model.AXISYMMETRIC:
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
    return hertz_values(effective_modulus(mats, scene.model), ref.R, P, scene.model)


def computed_load(sol: Solution, ref: HertzReference, tangent: np.ndarray) -> float:
    """The pair's load: its contact force along the normal at the centre (x2 if halved).

    `tangent` is the active surface's tangent at the contact centre. Axisymmetric: the force
    is already the total over the turn (the half section is the whole body).
    """
    force = pair_forces(sol, ref.pair)[0]
    normal = np.array([-tangent[1], tangent[0]])
    halved = ref.symmetric and sol.scene.model is not Model.AXISYMMETRIC
    return float(abs(force @ normal) * (2.0 if halved else 1.0))


def centre_distance(
    sol: Solution, ref: HertzReference
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """(r, pressure, active, tc, sc) of the pair's multipliers, r signed along the centre's tangent.

    tc is that tangent (unit), sc the centre's arc length s along the active surface.
    """
    pv = sol.pairs[ref.pair]
    rows = pv.rows
    surf = pv.active.surface
    node = pv.nodes
    s_all, t_all = pv.arc
    s, p = s_all[node], sol.pressure[rows]
    order = np.argsort(s, kind="stable")
    s, p, node, act = s[order], p[order], node[order], sol.active[rows][order]
    if ref.symmetric:
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
    if ref.symmetric and np.any(p > 0) and np.median(r[p > 0]) < 0:
        r = -r  # the centre is the end of largest s: measure into the surface
    return r, p, act, tc, sc


def hertz_summary(sol: Solution, ref: HertzReference | None = None) -> HertzErrors:
    """The pair's errors against Hertz: fitted and bracketed half-width, p0 and the L2 error."""
    if ref is None:
        ref = next(r for r in sol.scene.references if isinstance(r, HertzReference))
    r, p, act, tc, sc = centre_distance(sol, ref)
    load = ref.P if ref.P is not None else computed_load(sol, ref, tc)
    exact = reference_values(sol.scene, ref, load)
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
            both_sides=not ref.symmetric,
            radial=sol.scene.model is Model.AXISYMMETRIC,
        ),
    )


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
        pairs.append(
            {
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
    nu -> nu/(1 - nu).
    """
    if model is Model.AXISYMMETRIC:
        raise InputError("lame reference: the shrink fit of rings is plane strain or plane stress")

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
    # The active surface's outward normal points away from the centre on the inner ring.
    radial = float(np.mean(np.einsum("kd,kd->k", pv.n, pv.x - np.asarray(ref.center))))
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
    )
