"""Error measures along the contact line, as reported in the paper-reproduction table."""

from __future__ import annotations

from typing import Any

import numpy as np


def _arrays(itf: dict[str, Any]) -> tuple[np.ndarray, ...]:
    def arr(key: str) -> np.ndarray:
        return np.array([np.nan if v is None else v for v in itf[key]], dtype=float)

    return arr("x"), arr("pressure"), arr("sigma_yy_1"), arr("sigma_yy_2")


def mismatch(itf: dict[str, Any], corner: float, fraction: float = 0.1) -> dict[str, float]:
    """Max |sigma_yy_1 - sigma_yy_2| away from the corner and within `fraction` of it."""
    x, _, s1, s2 = _arrays(itf)
    d = np.abs(s1 - s2)
    near = x >= (1 - fraction) * corner
    ok = np.isfinite(d)
    return {
        "center": float(np.max(d[ok & ~near], initial=0.0)),
        "corner": float(np.max(d[ok & near], initial=0.0)),
    }


def patch_errors(itf: dict[str, Any], p: float) -> dict[str, float]:
    """Max relative deviation from the uniform solution sigma_yy = -p and pressure = p."""
    _, pr, s1, s2 = _arrays(itf)
    return {
        "sigma_yy_1": float(np.nanmax(np.abs(s1 / p + 1))),
        "sigma_yy_2": float(np.nanmax(np.abs(s2 / p + 1))),
        "pressure": float(np.nanmax(np.abs(pr / p - 1))),
    }
