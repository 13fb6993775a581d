"""The contact pressure along a pair's surface: its L2 norms and its peak's growth.

The pressure goal (adapt/goal.py) compares two solutions' pressures in L2
(`pressure_difference`, exact for piecewise-linear curves; with friction the shear too,
`shear_parts`) and judges whether the pressure
is singular from its peak (`window_peak`) over successive refinements (`singular_growth`).
"""

from __future__ import annotations

import itertools

import numpy as np

from ..methods.solution import PairView, Solution
from ..scenes import Model

# A pair's pressure is singular when its peak grows like h^-lambda, lambda at least this, over
# two successive refinements of the contact cells: a rigid flat punch's 1/sqrt edge has
# lambda = 1/2, a sharp elastic corner (a hub's edge on a shaft) a smaller one, a bounded
# peak (Hertz) tends to 0. One refinement is not enough to judge: a node that falls beside
# the end of a passive surface can jump by orders of magnitude on one mesh and not the next.
SINGULAR_EXPONENT = 0.15
# The smallest refinement of the peak's segments that gives an exponent (h ratio).
MIN_REFINEMENT = 1.2
# The peak is the mean pressure over this many segments (`window_peak`).
WINDOW = 4


def pressure_curve(pv: PairView, pressure: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(s, p, x): the pair's multipliers along its surface's arc length, sorted, and x.

    x is each node's x coordinate: the radius of an axisymmetric model.
    """
    s_all = pv.arc[0]
    p = pv.nodal(pressure)
    keep = np.isfinite(s_all)
    order = np.argsort(s_all[keep], kind="stable")
    x = pv.active.surface.x[:, 0]
    return s_all[keep][order], p[keep][order], x[keep][order]


def _l2_pl(s: np.ndarray, v: np.ndarray, r: np.ndarray | None = None) -> float:
    """L2 norm of the piecewise-linear v at sorted abscissae s, exactly.

    With r (piecewise linear too: an axisymmetric surface's radius) weighted by r.
    """
    h = np.diff(s)
    a, b = v[:-1], v[1:]
    if r is None:
        return float(np.sqrt(np.sum(h * (a * a + a * b + b * b) / 3.0)))
    ra, rb = r[:-1], r[1:]
    w = a * a * (3 * ra + rb) / 12 + a * b * (ra + rb) / 6 + b * b * (ra + 3 * rb) / 12
    return float(np.sqrt(np.sum(h * w)))


def pressure_difference(
    coarse: tuple[np.ndarray, ...], fine: tuple[np.ndarray, ...], radial: bool = False
) -> tuple[float, float]:
    """(||p_c - p_f||_L2, ||p_f||_L2) of two piecewise-linear pressures along arc length.

    Both are evaluated on the union of their nodes, where the difference is again piecewise
    linear, so the integral is exact. `radial` (an axisymmetric model, curves (s, p, x)):
    the L2 norm over the revolved surface, weighted by the radius x, as the Hertz
    reference's error is.
    """
    s = np.union1d(coarse[0], fine[0])
    pc = np.interp(s, coarse[0], coarse[1], left=0.0, right=0.0)
    pf = np.interp(s, fine[0], fine[1], left=0.0, right=0.0)
    r = np.interp(s, fine[0], fine[2]) if radial else None
    return _l2_pl(s, pc - pf, r), _l2_pl(s, pf, r)


def pair_peak(pv: PairView, pressure: np.ndarray) -> tuple[float, float]:
    """(peak, h) of the pair's pressure along its surface (`window_peak`)."""
    s, p, _ = pressure_curve(pv, pressure)
    return window_peak(s, p)


def window_peak(s: np.ndarray, p: np.ndarray, m: int = WINDOW) -> tuple[float, float]:
    """(peak, h): the largest mean pressure over m consecutive segments, and their mean length.

    `s` sorted arc lengths, `p` the nodal pressures (piecewise linear between them). The
    load over a few cells, not a node's value: a node that takes its neighbour's load (the
    on/off pattern beside the end of a passive surface or at a corner) moves load inside the
    window, and a single spike counts 1/m. A singular edge's mean over m cells grows like
    its field at m cells' distance, h^-lambda; a bounded one tends to a constant.
    """
    n = len(s) - 1
    if n < 1:
        return 0.0, 0.0
    m = min(m, n)
    load = np.concatenate([[0.0], np.cumsum(np.diff(s) * 0.5 * (p[:-1] + p[1:]))])
    length = s[m:] - s[:-m]
    mean = (load[m:] - load[:-m]) / np.maximum(length, 1e-300)
    i = int(np.argmax(mean))
    return float(mean[i]), float(length[i] / m)


def peak_exponent(coarse: tuple[float, float], fine: tuple[float, float]) -> float:
    """The exponent lambda of peak ~ h^-lambda between two meshes' (peak, h).

    0 where the peak's segment was not refined (or a peak is 0).
    """
    (p0, h0), (p1, h1) = coarse, fine
    if p0 <= 0 or p1 <= 0 or h1 <= 0 or h0 < MIN_REFINEMENT * h1:
        return 0.0
    return float(np.log(p1 / p0) / np.log(h0 / h1))


def singular_growth(peaks: list[tuple[float, float]]) -> list[float] | None:
    """The exponents between successive meshes' (peak, h) if each is at least SINGULAR_EXPONENT.

    `peaks` from the coarsest mesh on; None (bounded) unless there are two refinements or more
    and the peak grew like a singularity's over every one of them.
    """
    exponents = [peak_exponent(a, b) for a, b in itertools.pairwise(peaks)]
    if len(exponents) < 2 or min(exponents) < SINGULAR_EXPONENT:
        return None
    return exponents


def shear_parts(sol: Solution, ref: Solution, q: float) -> dict[str, float]:
    """Per frictional pair: the shear's relative L2 difference / (1 - q), as the pressure's."""
    if sol.friction is None or ref.friction is None:
        return {}
    out = {}
    for pv, pr in zip(sol.pairs, ref.pairs, strict=True):
        if not np.any(sol.friction.mu[pv.rows] > 0):
            continue
        d, n = pressure_difference(
            pressure_curve(pv, sol.friction.shear),
            pressure_curve(pr, ref.friction.shear),
            radial=sol.scene.model is Model.AXISYMMETRIC,
        )
        out[pv.label] = d / n / (1.0 - q) if n > 0 else 0.0
    return out
