"""Probes: values read off one pair's solution (`[[probe]]` in a scene file, Scene.probes).

The pressure is the multipliers' piecewise-linear pressure along the active surface's arc
length s; a point is taken to the active surface's closest point, a window to the arc
between the closest points of its ends. The mean over a window is over the revolved surface
in an axisymmetric scene (weighted by the radius). The peak of sigma_nn reads the interface
columns (results/interface.py): the largest compression -sigma_nn of one side's FE stress at
the pair's multiplier nodes.
"""

from __future__ import annotations

import numpy as np

from ..contact.search import project
from ..errors import InputError
from ..methods.solution import PairView, Solution
from ..scenes import Model, Probe, ProbeKind
from .interface import pair_interface
from .records import ProbeResult


def surface_s(pv: PairView, point: tuple[float, float]) -> tuple[float, np.ndarray]:
    """(s, x): the arc length and the point of the active surface closest to `point`."""
    surf = pv.active.surface
    s_all = pv.arc[0]
    seg, xi, _ = project(np.asarray([point], dtype=float), surf)
    a, b = surf.segments[int(seg[0])]
    t = float(xi[0])
    return (1 - t) * float(s_all[a]) + t * float(s_all[b]), (1 - t) * surf.x[a] + t * surf.x[b]


def pressure_along(sol: Solution, pv: PairView) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(s, p, r) of the pair's multipliers sorted by s; r the radius x of each node."""
    s, p, x = pv.s, sol.pressure[pv.rows], pv.x[:, 0]
    order = np.argsort(s, kind="stable")
    return s[order], p[order], x[order]


def window_mean(s: np.ndarray, p: np.ndarray, w: np.ndarray, s0: float, s1: float) -> float:
    """The mean of p weighted by w over [s0, s1], both piecewise linear (Simpson: exact)."""
    lo, hi = min(s0, s1), max(s0, s1)
    knots = np.unique(np.concatenate([[lo, hi], s[(s > lo) & (s < hi)]]))
    if len(knots) < 2:
        return float(np.interp(lo, s, p))
    mid = 0.5 * (knots[:-1] + knots[1:])
    h = np.diff(knots)

    def integral(f: np.ndarray, fm: np.ndarray) -> float:
        return float(np.sum(h * (f[:-1] + 4 * fm + f[1:])) / 6.0)

    pk, pm = np.interp(knots, s, p), np.interp(mid, s, p)
    wk, wm = np.interp(knots, s, w), np.interp(mid, s, w)
    return integral(pk * wk, pm * wm) / integral(wk, wm)


def probe_value(sol: Solution, probe: Probe) -> ProbeResult:
    """The probe's value and where it was read (collective: the interface columns)."""
    if not 0 <= probe.pair < len(sol.pairs):
        raise InputError(f"probe '{probe.label}': pair {probe.pair} does not exist")
    pv = sol.pairs[probe.pair]
    s, p, r = pressure_along(sol, pv)
    window = None
    if probe.start is not None and probe.end is not None:
        (s0, _), (s1, _) = surface_s(pv, probe.start), surface_s(pv, probe.end)
        window = (min(s0, s1), max(s0, s1))
    if probe.kind is ProbeKind.PRESSURE:
        assert probe.at is not None  # Probe checks its keys
        sa, xa = surface_s(pv, probe.at)
        value, where = float(np.interp(sa, s, p)), (float(xa[0]), float(xa[1]), sa)
        meaning = "the contact pressure at the surface point nearest `at`"
    elif probe.kind is ProbeKind.MEAN_PRESSURE:
        assert window is not None
        axi = sol.scene.model is Model.AXISYMMETRIC
        value = window_mean(s, p, r if axi else np.ones_like(s), *window)
        where = None
        meaning = "the mean contact pressure over the window" + (
            " (over the revolved surface: weighted by r)" if axi else ""
        )
    else:
        itf = pair_interface(sol, probe.pair)
        col = np.array([np.nan if v is None else v for v in itf[f"sigma_nn_{probe.side}"]])
        ss = np.asarray(itf["s"], dtype=float)
        inside = np.isfinite(col) & (
            True if window is None else (ss >= window[0] - 1e-12) & (ss <= window[1] + 1e-12)
        )
        if not inside.any():
            raise InputError(f"probe '{probe.label}': no {probe.side} stress in its window")
        k = int(np.flatnonzero(inside)[np.argmax(-col[inside])])
        value = float(-col[k])
        where = (float(itf["x"][k]), float(itf["y"][k]), float(ss[k]))
        meaning = f"the largest compression -sigma_nn of the {probe.side} body's FE stress"
    return ProbeResult(
        name=probe.label,
        kind=probe.kind.value,
        pair=probe.pair,
        value=value,
        at=None if where is None else where[:2],
        s=None if where is None else where[2],
        window=window,
        meaning=meaning,
    )
