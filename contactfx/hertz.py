"""Hertz (S5) post-processing: half-width, peak pressure, L2 error of the pressure profile."""

from __future__ import annotations

import numpy as np

from .problem import Solution


def exact_pressure(x: np.ndarray, a: float, p0: float) -> np.ndarray:
    """Plane-strain Hertz pressure p0 sqrt(1 - x^2/a^2) inside |x| < a, zero outside."""
    return p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))


def fit_half_width(x: np.ndarray, p: np.ndarray) -> float | None:
    """Least-squares fit of p^2 = p0^2 (1 - x^2/a^2); returns a."""
    A = np.column_stack([np.ones_like(x), x**2])
    (c0, c1), *_ = np.linalg.lstsq(A, p**2, rcond=None)
    return float(np.sqrt(-c0 / c1)) if c1 < 0 < c0 else None


def l2_error(x: np.ndarray, p: np.ndarray, a: float, p0: float, samples: int = 40001) -> float:
    """Relative L2 error over [0, 1.5 a] of the piecewise-linear nodal pressure."""
    xs = np.linspace(0.0, 1.5 * a, samples)
    ph = np.interp(xs, x, p, right=0.0)
    pe = exact_pressure(xs, a, p0)
    return float(np.sqrt(np.trapezoid((ph - pe) ** 2, xs) / np.trapezoid(pe**2, xs)))


def hertz_summary(sol: Solution) -> dict[str, object]:
    """The `hertz` block of the JSON: fitted and bracketed half-width, p0 and the L2 error."""
    exact = sol.scene.extra["hertz_exact"]
    order = np.argsort(sol.layout.x[:, 0])
    x, p, act = sol.layout.x[order, 0], sol.pressure[order], sol.active[order]
    xa = x[act]
    last = float(xa.max()) if xa.size else 0.0
    beyond = x[(~act) & (x > last)]
    return {
        "a": fit_half_width(xa, p[act]),
        "a_bracket": [last, float(beyond.min()) if beyond.size else None],
        "a_exact": exact["a"],
        "p0": float(p.max()),
        "p0_exact": exact["p0"],
        "E_star": exact["E_star"],
        "l2_error": l2_error(x, p, exact["a"], exact["p0"]),
    }
