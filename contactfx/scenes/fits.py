"""Thermal strains and interference fits as scene data: their checks, and the Lame reference.

Plain numbers only (no mesh): scenes/model.py's Material and ContactPair call the checks,
results/references.py evaluates the Lame reference (docs/models.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError

# |alpha| per degree and |alpha dT| beyond which the input is out of range.
ALPHA_MAX = 1e-2
THERMAL_STRAIN_MAX = 0.1


def _finite(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def check_thermal(alpha: float | None, dT: float | None, where: str) -> None:
    """InputError unless alpha and dT come together, finite, with a small thermal strain."""
    if (alpha is None) != (dT is None):
        given, missing = ("alpha", "dT") if dT is None else ("dT", "alpha")
        raise InputError(
            f"{where}: {given} needs {missing} (a thermal strain is alpha dT: give both)"
        )
    if alpha is None or dT is None:
        return
    for key, value in (("alpha", alpha), ("dT", dT)):
        if not _finite(value):
            raise InputError(f"{where}: {key} must be a finite number (got {value!r})")
    if not abs(alpha) < ALPHA_MAX:
        raise InputError(
            f"{where}: the expansion coefficient must satisfy |alpha| < {ALPHA_MAX:g} per "
            f"degree (got alpha = {alpha})"
        )
    if not abs(alpha * dT) < THERMAL_STRAIN_MAX:
        raise InputError(
            f"{where}: the thermal strain alpha dT = {alpha * dT:.3g} is not small "
            f"(|alpha dT| < {THERMAL_STRAIN_MAX:g}: contactfx is a small-strain code)"
        )


def check_friction(value: object, where: str) -> float:
    """The pair's Coulomb coefficient as stored: a finite number >= 0 (InputError otherwise)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not _finite(value):
        raise InputError(f"{where}: mu must be a number >= 0 (got {value!r})")
    if value < 0:
        raise InputError(f"{where}: mu must be a number >= 0, 0 for frictionless (got {value!r})")
    return float(value)


def check_interference(value: bool | float, where: str) -> bool | float:
    """The pair's interference as stored: a bool, or D > 0 as a float (InputError otherwise)."""
    if isinstance(value, bool):
        return value
    if not (_finite(value) and value > 0):
        raise InputError(
            f"{where}: interference must be true, false or a number > 0 (got {value!r})"
        )
    return float(value)


@dataclass(frozen=True)
class LameReference:
    """Lame's shrink fit of two concentric rings on one pair (any model; axisymmetric: open ends).

    The inner ring a..b, the outer ring b..c, both centred at `center`; `delta` the radial
    interference (None: the pair's `interference = D`). Which body is the inner ring is read
    from the pair's geometry (the active surface's normal points away from the centre or
    towards it). The JSON compares the pair's mean contact pressure with Lame's (docs/models.md).
    """

    a: float
    b: float
    c: float
    delta: float | None = None
    pair: int = 0
    center: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        values = (self.a, self.b, self.c) + (() if self.delta is None else (self.delta,))
        if not all(math.isfinite(v) for v in values):
            raise InputError("lame reference: a, b, c and delta must be finite numbers")
        if not 0 <= self.a < self.b < self.c:
            raise InputError(
                f"lame reference: the radii must satisfy 0 <= a < b < c "
                f"(got a = {self.a}, b = {self.b}, c = {self.c})"
            )
        if self.delta is not None and not self.delta > 0:
            raise InputError(f"lame reference: delta must be > 0 (got {self.delta})")


@dataclass(frozen=True)
class PushoutReference:
    """A press fit pushed out (axisymmetric): Coulomb's law on the whole interface.

    At each load step the pair's axial force (total over the turn) against mu times its
    normal force N = sum_j w_j lambda_n,j (the contact pressure integrated over the revolved
    interface, total over the turn as well): their ratio reaches 1 in full slip, where every
    contact node slips with `|shear| = mu p`. `mu` None takes the pair's. With the rings' radii
    (a, b, c; `delta` None: the pair's `interference = D`) the first step, the fit before the
    push, is compared with Lame's open-ended cylinder and its plane-strain value
    (docs/friction_verification.md, "The push-out of a press fit").
    """

    pair: int = 0
    mu: float | None = None
    rings: tuple[float, float, float] | None = None
    delta: float | None = None

    def __post_init__(self) -> None:
        where = f"pushout reference (pair {self.pair})"
        if self.mu is not None and not (_finite(self.mu) and self.mu > 0):
            raise InputError(f"{where}: mu must be a number > 0 (got {self.mu!r})")
        if self.rings is None:
            if self.delta is not None:
                raise InputError(f"{where}: delta is Lame's: give the rings' a, b and c with it")
            return
        a, b, c = self.rings
        if not all(_finite(v) for v in self.rings) or not 0 <= a < b < c:
            raise InputError(
                f"{where}: the rings' radii must satisfy 0 <= a < b < c (got a = {a}, b = {b}, "
                f"c = {c})"
            )
        if self.delta is not None and not (_finite(self.delta) and self.delta > 0):
            raise InputError(f"{where}: delta must be > 0 (got {self.delta!r})")
