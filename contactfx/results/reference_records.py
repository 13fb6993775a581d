"""The records of a run's checks: Hertz, Lame, the patch test, and the probes' values.

Each writes its JSON with `to_json()`; RunSummary (records.py) holds them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True, kw_only=True)
class HertzErrors:
    """One pair against Hertz: fitted and bracketed half-width, p0, L2 error.

    Hertz is never exact for a finite model (a half-space theory, a small against the
    surfaces' radii and the bodies' size): `exact` is False and `a_over_radius` (a over the
    smaller surface radius at the centre) says how far the scene is from the theory.
    """

    pair: int
    s_centre: float  # arc length of the contact centre r is measured from
    a: float | None  # fitted half-width (None if the fit fails)
    a_bracket: tuple[float, float | None]  # last active and first inactive |r|
    a_exact: float
    p0: float
    p0_exact: float
    E_star: float
    P: float
    P_source: str
    l2_error: float
    description: str = "plane-strain Hertz line contact (Johnson 4.2)"
    window: str = "[0, 1.5 a]"  # the interval of the L2 error
    line_load: float | None = None  # a ring's (axisymmetric line contact): P / (2 pi r_c)
    a_over_radius: float = 0.0
    exact: bool = False

    @property
    def validity(self) -> str:
        """Why the reference is approximate, in words."""
        return f"approximate: half-space theory, a / R_min = {self.a_over_radius:.3g}"

    def to_json(self) -> dict[str, Any]:
        """The JSON's `hertz` block."""
        return {
            "pair": self.pair,
            "s_centre": self.s_centre,
            "a": self.a,
            "a_bracket": list(self.a_bracket),
            "a_exact": self.a_exact,
            "p0": self.p0,
            "p0_exact": self.p0_exact,
            "E_star": self.E_star,
            "P": self.P,
            "P_source": self.P_source,
            "l2_error": self.l2_error,
            "l2_window": self.window,
            "reference": self.description,
            **({} if self.line_load is None else {"line_load": self.line_load}),
            "exact": self.exact,
            "validity": self.validity,
            "a_over_radius": self.a_over_radius,
        }


@dataclass(frozen=True, kw_only=True)
class LameErrors:
    """One pair against Lame's shrink-fit pressure (docs/models.md, "Lame")."""

    pair: int
    model: str
    inner: str  # the inner ring's body
    outer: str
    delta: float
    p_mean: float  # the pair's mean contact pressure: sum p_j w_j / sum w_j
    p_exact: float
    error: float  # |p_mean / p_exact - 1|
    active_fraction: float  # active rows / rows of the pair
    exact: bool = True  # False: Lame's is approximate for the scene (validity says why)
    validity: str = ""

    def to_json(self) -> dict[str, Any]:
        """One entry of the JSON's `lame` list."""
        return {
            "pair": self.pair,
            "model": self.model,
            "inner": self.inner,
            "outer": self.outer,
            "delta": self.delta,
            "p_mean": self.p_mean,
            "p_exact": self.p_exact,
            "error": self.error,
            "active_fraction": self.active_fraction,
            "exact": self.exact,
            "validity": self.validity,
        }


@dataclass(frozen=True, kw_only=True)
class ProbeResult:
    """One probe's value (results/probes.py) and where it was read."""

    name: str
    kind: str  # ProbeKind's value
    pair: int
    value: float
    at: tuple[float, float] | None  # the surface point (None for a window's mean)
    s: float | None  # its arc length along the active surface
    window: tuple[float, float] | None  # the arc-length window, if the probe has one
    meaning: str

    def text(self) -> str:
        """One terminal line."""
        where = "" if self.at is None else f" at ({self.at[0]:.6g}, {self.at[1]:.6g})"
        if self.window is not None:
            where += f" in s [{self.window[0]:.6g}, {self.window[1]:.6g}]"
        return f"probe '{self.name}' (pair {self.pair}, {self.kind}): {self.value:.6g}{where}"

    def to_json(self) -> dict[str, Any]:
        """One entry of the JSON's `probes` list."""
        return {
            "name": self.name,
            "type": self.kind,
            "pair": self.pair,
            "value": self.value,
            "at": None if self.at is None else list(self.at),
            "s": self.s,
            "window": None if self.window is None else list(self.window),
            "meaning": self.meaning,
        }


@dataclass(frozen=True, kw_only=True)
class PatchErrors:
    """The patch test: max errors relative to the largest exact stress component."""

    sigma: tuple[tuple[float, float], tuple[float, float]]  # the exact uniform stress
    bodies: dict[str, float]
    pairs: tuple[dict[str, float], ...]  # pressure and sigma_* columns per pair
    max: float

    def to_json(self) -> dict[str, Any]:
        """The JSON's `patch` block."""
        return {
            "sigma": [list(row) for row in self.sigma],
            "bodies": self.bodies,
            "pairs": list(self.pairs),
            "max": self.max,
        }


# Above this first-step shear (L2, relative to mu p's), the approach slipped: Cattaneo-Mindlin
# (a slip-free approach) no longer describes the push. Mirrored bodies on non-matching
# meshes stay well below it (docs/friction_verification.md, "Cattaneo-Mindlin: measured").
APPROACH_SHEAR_MAX = 0.05
# Below this Q/(mu P) the closed-form shear is about 0 and an error relative to it says nothing.
SMALL_PUSH = 0.05


@dataclass(frozen=True, kw_only=True)
class CattaneoCheck:
    """One frictional pair at one load step against Cattaneo-Mindlin (line contact)."""

    pair: int
    P: float  # the pair's normal force (sum of the pressure multipliers)
    Q: float  # its tangential force (sum of the shear multipliers, taken positive)
    mu: float
    E_star: float
    a_exact: float
    c_exact: float
    c: float  # the stick half-width read from the statuses
    h: float  # the contact cell (median node spacing over the active nodes)
    shear_l2: float  # relative L2 error of the shear against the closed form
    slip_law: float  # max over slip nodes of ||shear| - mu p| / (mu p0)
    shear_ratio: float  # this step's shear L2 over mu p's (well defined where Q ~ 0)
    approach_shear: float | None = None  # step 1's shear_ratio (None: one step)
    # Relative L2 error of the pressure against Hertz's under P (Cattaneo-Mindlin's pressure).
    pressure_l2: float | None = None

    @property
    def c_error_cells(self) -> float:
        """|c - c_exact| in contact cells."""
        return abs(self.c - self.c_exact) / self.h if self.h > 0 else float("inf")

    @property
    def warning(self) -> str | None:
        """Why the reference does not describe the run, or None."""
        if self.approach_shear is None:
            return (
                "one load step: the load path is not resolved, while Cattaneo-Mindlin "
                "presses first without slip, then pushes (give [[step]] tables: press, then push)"
            )
        if self.approach_shear > APPROACH_SHEAR_MAX:
            return (
                f"the approach slipped: step 1's shear is {100 * self.approach_shear:.3g} % of "
                f"mu p (L2, above {100 * APPROACH_SHEAR_MAX:g} %), and Cattaneo-Mindlin assumes "
                "none (mirrored bodies or a frictionless approach)"
            )
        return None

    def text(self) -> str:
        """One terminal line (where Q ~ 0 the shear is read against mu p: no closed form's)."""
        if self.Q < SMALL_PUSH * self.mu * self.P:
            return (
                f"Cattaneo-Mindlin, pair {self.pair}: no push yet (Q/(mu P) = "
                f"{self.Q / (self.mu * self.P):.2g}), a = {self.a_exact:.4g}, shear "
                f"{100 * self.shear_ratio:.3g} % of mu p (L2), c = {self.c:.4g}"
            )
        return (
            f"Cattaneo-Mindlin, pair {self.pair}: c = {self.c:.4g} (exact {self.c_exact:.4g}, "
            f"{self.c_error_cells:.2f} cells), a = {self.a_exact:.4g}, Q/(mu P) = "
            f"{self.Q / (self.mu * self.P):.3g}, shear L2 error {100 * self.shear_l2:.2f} %, "
            f"slip law {self.slip_law:.1e}"
        )

    def to_json(self) -> dict[str, Any]:
        """The JSON's `cattaneo` entry."""
        return {
            "pair": self.pair,
            "P": self.P,
            "Q": self.Q,
            "mu": self.mu,
            "E_star": self.E_star,
            "a_exact": self.a_exact,
            "c_exact": self.c_exact,
            "c": self.c,
            "h": self.h,
            "c_error_cells": self.c_error_cells,
            "shear_l2": self.shear_l2,
            "pressure_l2": self.pressure_l2,
            "slip_law": self.slip_law,
            "shear_ratio": self.shear_ratio,
            "approach_shear": self.approach_shear,
            "warning": self.warning,
            "reference": "Cattaneo-Mindlin line contact, similar materials (Johnson 7.1)",
        }


# A push-out: the active surface's normal may lean this far from radial (round-off of a
# cylinder), and in full slip the ratio and the slip law must hold to this: far above the
# multipliers' round-off, far below any real violation (docs/friction_verification.md).
CYLINDER_TOL = 1e-6
COULOMB_TOL = 1e-6


@dataclass(frozen=True, kw_only=True)
class PushoutCheck:
    """One press fit at one load step: its axial force against mu times its normal force.

    Both forces are totals over the turn (the summary's `axial_force` convention): N is the
    contact pressure integrated over the revolved interface, sum_j w_j lambda_n,j.
    """

    pair: int
    mu: float
    axial: float  # the axial force on the active body (the shaft), total over the turn
    normal: float  # N, total over the turn
    stick: int
    slip: int
    open: int
    slip_law: float | None  # max over slip nodes of ||shear| - mu p| / (mu max p); None: none
    taper: float = 0.0  # max |n_axial| of the active surface over the contact nodes

    @property
    def warning(self) -> str | None:
        """Why the reference does not describe the pair, or where Coulomb's law fails."""
        if self.taper > CYLINDER_TOL:
            return (
                f"the interface is not a cylinder (its normal's axial part reaches "
                f"{self.taper:.2g}): the pressure has an axial force, and axial = mu N holds "
                "only on a cylinder"
            )
        if self.full_slip and not (
            abs(self.ratio - 1.0) <= COULOMB_TOL and (self.slip_law or 0.0) <= COULOMB_TOL
        ):
            return (
                f"full slip, but axial / (mu N) = {self.ratio:.6g} and the slip law's largest "
                f"violation is {self.slip_law:.2g} (both 1 and 0 to {COULOMB_TOL:g} expected)"
            )
        return None

    @property
    def ratio(self) -> float:
        """|axial| / (mu N): 1 in full slip."""
        return abs(self.axial) / (self.mu * self.normal) if self.normal > 0 else 0.0

    @property
    def full_slip(self) -> bool:
        """Every contact node slips."""
        return self.stick == 0 and self.slip > 0

    def text(self) -> str:
        """One terminal line."""
        law = "" if self.slip_law is None else f", slip law {self.slip_law:.1e}"
        state = "full slip" if self.full_slip else ("stick" if self.slip == 0 else "partial slip")
        text = (
            f"push-out, pair {self.pair}: axial / (mu N) = {self.ratio:.4f} ({state}: "
            f"{self.stick} stick, {self.slip} slip), axial {self.axial:.6g}, N {self.normal:.6g} "
            f"(totals over the turn){law}"
        )
        return text if self.warning is None else f"{text}; warning: {self.warning}"

    def to_json(self) -> dict[str, Any]:
        """The entry of a step's `pushout` list."""
        return {
            "pair": self.pair,
            "mu": self.mu,
            "axial_force": self.axial,
            "normal_force": self.normal,
            "ratio": self.ratio,
            "stick": self.stick,
            "slip": self.slip,
            "open": self.open,
            "full_slip": self.full_slip,
            "slip_law": self.slip_law,
            "taper": self.taper,
            "warning": self.warning,
        }


@dataclass(frozen=True, kw_only=True)
class PushoutFit:
    """The fit before the push (step 1) against Lame's rings, open-ended and in plane strain.

    Lame's open-ended cylinder (plane stress, sigma_z = 0: shaft and hub free to change
    length, which a frictionless fit meets) is the reference the error is taken against;
    plane strain (eps_z = 0) is the value above it: stick friction holds the axial strains
    the fit's Poisson effect would slide by and raises the pressure towards it (a bonded fit
    stays below: shaft and hub share one axial strain, not zero; docs/friction_verification.md).
    """

    p_mean: float  # sum p_j w_j / sum w_j at step 1
    open_ended: float  # Lame, plane stress (sigma_z = 0)
    plane_strain: float  # Lame, eps_z = 0
    delta: float

    @property
    def error(self) -> float:
        """p_mean / open_ended - 1."""
        return self.p_mean / self.open_ended - 1.0

    @property
    def between(self) -> bool:
        """The fit's pressure lies between the two limits."""
        return (
            min(self.open_ended, self.plane_strain)
            <= self.p_mean
            <= max(self.open_ended, self.plane_strain)
        )

    def to_json(self) -> dict[str, Any]:
        """The `fit` block of a `pushout` entry."""
        return {
            "p_mean": self.p_mean,
            "lame_open_ended": self.open_ended,
            "lame_plane_strain": self.plane_strain,
            "error": self.error,
            "between": self.between,
            "delta": self.delta,
        }


@dataclass(frozen=True, kw_only=True)
class PushoutSummary:
    """A push-out reference over the run: each step's check, and the fit against Lame."""

    steps: tuple[PushoutCheck, ...]
    fit: PushoutFit | None = None

    def lines(self) -> list[str]:
        """The terminal lines: the fit, the last step, the ratio's course."""
        out = []
        if self.fit is not None:
            f = self.fit
            out.append(
                f"push-out fit (step 1): mean pressure {f.p_mean:.6g}, Lame open-ended "
                f"{f.open_ended:.6g} ({100 * f.error:+.2f} %), plane strain {f.plane_strain:.6g}"
            )
        last = self.steps[-1]
        ratios = ", ".join(f"{c.ratio:.3f}" for c in self.steps)
        out.append(last.text())
        out.append(f"  axial / (mu N) by step: {ratios}")
        return out

    def to_json(self) -> dict[str, Any]:
        """One entry of the JSON's `pushout` list (the last step's, with the ratios and fit)."""
        last = self.steps[-1]
        return {
            **last.to_json(),
            "ratios": [c.ratio for c in self.steps],
            "first_full_slip_step": next(
                (k + 1 for k, c in enumerate(self.steps) if c.full_slip), None
            ),
            "fit": None if self.fit is None else self.fit.to_json(),
            "reference": "Coulomb: in full slip the axial force is mu times the normal force",
        }


# Spence's analysis is the limit a/R -> 0: beyond this a/R the cylinder's tilt across the
# contact moves the stick edge out by more than a cell or so (measured in
# docs/friction_verification.md, Spence, "Finite a/R").
SPENCE_AR_MAX = 0.02


@dataclass(frozen=True, kw_only=True)
class SpenceCheck:
    """A rigid cylinder pressed with friction, at one load step, against Spence's c/a."""

    pair: int
    mu: float
    nu: float
    R: float
    ratio_exact: float  # Spence's c/a (spence_stick_ratio(mu, nu))
    a: float  # the contact half-width read from the statuses (edge halfway to the open node)
    c: float  # the stick half-width read from the statuses (edge halfway to the slip node)
    h: float  # the contact cell (median node spacing over the contact nodes)
    step: int  # the load step (1: the first, a single step from zero)

    @property
    def ratio(self) -> float:
        """The computed c/a (0 without contact)."""
        return self.c / self.a if self.a > 0 else 0.0

    @property
    def offset_cells(self) -> float:
        """C - (c/a)_Spence a in contact cells (signed: positive, a stick zone too wide)."""
        return (self.c - self.ratio_exact * self.a) / self.h if self.h > 0 else float("inf")

    @property
    def warning(self) -> str | None:
        """Why Spence's c/a does not describe this step, or None."""
        if self.step == 1:
            return (
                "step 1 loads from zero in one step (the whole contact forms at once), while "
                "Spence's c/a is that of a load grown in small steps: compare the later steps"
            )
        if self.a / self.R > SPENCE_AR_MAX:
            return (
                f"a/R = {self.a / self.R:.3g} is above {SPENCE_AR_MAX:g}: Spence's analysis is "
                "the limit a/R -> 0 (the cylinder's tilt across the contact adds to the slip)"
            )
        return None

    def text(self) -> str:
        """One terminal line."""
        return (
            f"Spence, pair {self.pair}: c/a = {self.ratio:.4f} (Spence {self.ratio_exact:.4f}, "
            f"c off by {self.offset_cells:+.2f} cells), a = {self.a:.4g} "
            f"({self.a / self.h:.1f} cells), a/R = {self.a / self.R:.2g}"
        )

    def to_json(self) -> dict[str, Any]:
        """The JSON's `spence` entry."""
        return {
            "pair": self.pair,
            "mu": self.mu,
            "nu": self.nu,
            "R": self.R,
            "ratio_exact": self.ratio_exact,
            "ratio": self.ratio,
            "a": self.a,
            "c": self.c,
            "h": self.h,
            "offset_cells": self.offset_cells,
            "warning": self.warning,
            "reference": "Spence (1975) self-similar stick ratio, rigid cylinder, plane strain",
        }
