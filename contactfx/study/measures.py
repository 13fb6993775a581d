"""What a study measures per run: the contact element size, errors against a reference, rates.

Every number here comes from gathered data (the summary's lists, the gathered contact
surfaces), identical on all ranks, so a study on 2 ranks reports what a serial one does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from ..contact.geometry import arc_length
from ..discretize.surfaces import GatheredSurface
from ..methods.solution import Solution
from ..results.records import HertzErrors, RunSummary

# Relative errors below this are round-off (e.g. mortar on a patch test): a rate fitted
# through them would be the slope of noise, so such points are left out of the fit.
ROUND_OFF = 1e-8


def fit_rate(h: list[float] | np.ndarray, err: list[float | None] | np.ndarray) -> float | None:
    """Least-squares slope of log(err) against log(h); None with fewer than 2 usable points.

    Usable: h > 0 and a finite err above ROUND_OFF (err ~ C h^rate gives `rate`).
    """
    x = np.asarray(h, dtype=float)
    y = np.asarray([np.nan if e is None else abs(e) for e in err], dtype=float)
    ok = np.isfinite(x) & np.isfinite(y) & (x > 0) & (y > ROUND_OFF)
    if np.count_nonzero(ok) < 2 or np.ptp(np.log(x[ok])) == 0:
        return None
    return float(np.polyfit(np.log(x[ok]), np.log(y[ok]), 1)[0])


def contact_size(summary: RunSummary) -> float | None:
    """Median length of the active-surface elements with pressure at both ends (all pairs).

    Read off the summary's interface lists (nodes sorted by arc length s); if no element
    carries pressure, the median of all of the active surfaces' elements.
    """
    carrying, every = [], []
    for c in summary.contacts:
        itf = c.interface
        s = np.asarray(itf["s"], dtype=float)
        act = np.asarray(itf["active"], dtype=bool)
        ds = np.diff(s)
        # Consecutive polylines continue s: their junction is a zero-length step, no element.
        real = ds > 0
        every.append(ds[real])
        carrying.append(ds[real & act[1:] & act[:-1]])
    for group in (carrying, every):
        vals = np.concatenate(group) if group else np.zeros(0)
        if vals.size:
            return float(np.median(vals))
    return None


def _rel(value: float | None, exact: float) -> float | None:
    return None if value is None else abs(value / exact - 1.0)


def _half_width(h: HertzErrors) -> float | None:
    """The fitted half-width, else the middle of the bracket (demo_hertz.py's rule)."""
    if h.a is not None:
        return float(h.a)
    lo, hi = h.a_bracket
    return 0.5 * (lo + (hi if hi is not None else lo)) if lo else None


def hertz_errors(summary: RunSummary) -> dict[str, float | None]:
    """l2 (relative L2 of the pressure), a and p0 (relative errors) against Hertz.

    With several Hertz pairs: the worst pair under l2, a, p0, and each pair's as l2_pair<k>...
    """
    pairs = summary.hertz
    if not pairs:
        raise ValueError(f"run of {summary.scene} has no Hertz reference")
    per = [
        {
            "l2": float(h.l2_error),
            "a": _rel(_half_width(h), h.a_exact),
            "p0": _rel(h.p0, h.p0_exact),
        }
        for h in pairs
    ]
    out: dict[str, float | None] = {}
    for name in ("l2", "a", "p0"):
        vals = [p[name] for p in per]
        out[name] = None if None in vals else max(vals)  # type: ignore[type-var]
    if len(per) > 1:
        for h, p in zip(pairs, per, strict=True):
            out.update({f"{k}_pair{h.pair}": v for k, v in p.items()})
    return out


def cattaneo_study_errors(summary: RunSummary) -> dict[str, float | None]:
    """Shear (relative L2 of the shear) and stick (|c / c_exact - 1|) against Cattaneo-Mindlin.

    The last load step's; with several Cattaneo pairs the worst. stick is None in full slip
    (c_exact = 0: no stick zone to measure).
    """
    pairs = summary.cattaneo
    if not pairs:
        raise ValueError(f"run of {summary.scene} has no Cattaneo reference")
    sticks = [_rel(c.c, c.c_exact) if c.c_exact > 0 else None for c in pairs]
    return {
        "shear": max(float(c.shear_l2) for c in pairs),
        "stick": None if None in sticks else max(sticks),  # type: ignore[type-var]
    }


def patch_error(summary: RunSummary) -> dict[str, float | None]:
    """stress: the patch test's max stress/pressure error relative to the exact uniform stress."""
    if summary.patch is None:
        raise ValueError(f"run of {summary.scene} has no uniform-stress reference")
    return {"stress": float(summary.patch.max)}


@dataclass(frozen=True)
class Profiles:
    """What self-convergence compares, as functions of arc length s along each surface.

    pressure: per pair, (s, pressure) at the multipliers; displacement: per pair and side
    (active, then passive), (s, u (n, 2)) at the surface nodes.
    """

    pressure: list[tuple[np.ndarray, np.ndarray]]
    displacement: list[tuple[np.ndarray, np.ndarray]]


def surface_displacement(sol: Solution, side: GatheredSurface) -> np.ndarray:
    """The displacement (n, 2) at every node of a gathered surface, on all ranks."""
    imap = sol.fields.V.dofmap.index_map
    lo, hi = imap.local_range
    mine = (side.gblock >= lo) & (side.gblock < hi)
    u = np.zeros((len(side.gblock), 2))
    u[mine] = sol.u.x.array.reshape(-1, 2)[side.gblock[mine] - lo]
    # Exactly one rank contributes each node, so the sum is exact and rank-independent.
    sol.scene.comm.Allreduce(MPI.IN_PLACE, u, op=MPI.SUM)
    return u


def profiles(sol: Solution, summary: RunSummary) -> Profiles:
    """The pressure and displacement profiles of a solved scene."""
    pressure = []
    for c in summary.contacts:
        itf = c.interface
        pressure.append(
            (np.asarray(itf["s"], dtype=float), np.asarray(itf["pressure"], dtype=float))
        )
    disp = []
    for pd in sol.pairs:
        for side in (pd.active, pd.passive):
            if side is None:  # a rigid obstacle: no displacement field of its own
                continue
            s = arc_length(side.surface)[0]
            order = np.argsort(s, kind="stable")
            disp.append((s[order], surface_displacement(sol, side)[order]))
    return Profiles(pressure, disp)


def l2_difference(
    s: np.ndarray, v: np.ndarray, s_ref: np.ndarray, v_ref: np.ndarray
) -> tuple[float, float]:
    """(integral of |v - v_ref|^2, integral of |v_ref|^2) over the reference's s range.

    Both are piecewise linear in s (the FE trace); on the union of their nodes the difference
    is linear per interval, so the integrals are exact.
    """
    v = np.asarray(v, dtype=float).reshape(len(s), -1)
    v_ref = np.asarray(v_ref, dtype=float).reshape(len(s_ref), -1)
    lo, hi = float(s_ref[0]), float(s_ref[-1])
    grid = np.unique(np.concatenate([s_ref, np.clip(s, lo, hi)]))
    # Coarse polylines on curved surfaces are a little shorter: np.interp holds the end value.
    a = np.column_stack([np.interp(grid, s, v[:, c]) for c in range(v.shape[1])])
    b = np.column_stack([np.interp(grid, s_ref, v_ref[:, c]) for c in range(v.shape[1])])

    def integral(d: np.ndarray) -> float:
        d0, d1 = d[:-1], d[1:]
        return float(np.sum(np.diff(grid) * np.sum(d0 * d0 + d0 * d1 + d1 * d1, axis=1)) / 3)

    return integral(a - b), integral(b)


def self_errors(run: Profiles, ref: Profiles) -> dict[str, float | None]:
    """Relative L2 (in s) differences from the reference: pressure and displacement.

    Summed over all pairs (pressure) and all contact surfaces, both sides (displacement);
    with several pairs also each pair's pressure as pressure_pair<k>.
    """
    out: dict[str, float | None] = {}
    parts = [l2_difference(*r, *q) for r, q in zip(run.pressure, ref.pressure, strict=True)]
    out["pressure"] = _ratio(parts)
    disp = [l2_difference(*r, *q) for r, q in zip(run.displacement, ref.displacement, strict=True)]
    out["displacement"] = _ratio(disp)
    if len(parts) > 1:
        out.update({f"pressure_pair{k}": _ratio([p]) for k, p in enumerate(parts)})
    return out


def _ratio(parts: list[tuple[float, float]]) -> float | None:
    err, norm = sum(p[0] for p in parts), sum(p[1] for p in parts)
    return float(np.sqrt(err / norm)) if norm > 0 else None
