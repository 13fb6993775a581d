"""Probes as scene data: a value read off one pair's solution (results/probes.py reads it).

Plain numbers only (no mesh), like fits.py's Lame reference: scenes/model.py's Scene holds
them, scene_file.py reads `[[probe]]` tables into them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

from ..errors import InputError


class ProbeKind(StrEnum):
    """What a probe reads off a pair (docs/scenes.md, "Probes")."""

    PRESSURE = "pressure"  # the pressure at the surface point nearest `at`
    MEAN_PRESSURE = "mean_pressure"  # the mean pressure between `start` and `end`
    PEAK_SIGMA_NN = "peak_sigma_nn"  # the largest compression -sigma_nn of the FE stress


@dataclass(frozen=True)
class Probe:
    """A value read off one pair's solution: printed on the terminal, written to the JSON.

    `pressure`: the multipliers' pressure (piecewise linear along the active surface) at the
    surface point nearest `at`. `mean_pressure`: its mean between the surface points nearest
    `start` and `end` (over the revolved surface in an axisymmetric scene: weighted by r).
    `peak_sigma_nn`: the largest -sigma_nn of `side`'s FE stress (`active` or `passive`) at
    the pair's nodes, between `start` and `end` if given (the edge peak of a punch or a fit),
    and where it is. Points are (x, y) of the undeformed mesh.
    """

    kind: ProbeKind
    pair: int = 0
    at: tuple[float, float] | None = None
    start: tuple[float, float] | None = None
    end: tuple[float, float] | None = None
    side: str = "active"
    name: str = ""

    def __post_init__(self) -> None:
        try:
            object.__setattr__(self, "kind", ProbeKind(self.kind))
        except ValueError:
            choices = ", ".join(k.value for k in ProbeKind)
            raise InputError(f"probe: unknown type {self.kind!r} (choose {choices})") from None
        where = f"probe '{self.label}'"
        window = (self.start is None, self.end is None)
        if self.kind is ProbeKind.PRESSURE and (self.at is None or window != (True, True)):
            raise InputError(f"{where}: type 'pressure' takes `at` = [x, y] (and no start, end)")
        if self.kind is ProbeKind.MEAN_PRESSURE and (self.at is not None or any(window)):
            raise InputError(f"{where}: type 'mean_pressure' takes start and end (and no at)")
        if self.kind is ProbeKind.PEAK_SIGMA_NN and (self.at is not None or len(set(window)) > 1):
            raise InputError(f"{where}: type 'peak_sigma_nn' takes start and end, or neither")
        if self.side not in ("active", "passive"):
            raise InputError(f"{where}: side must be 'active' or 'passive' (got {self.side!r})")
        for key in ("at", "start", "end"):
            v = getattr(self, key)
            if v is not None and not all(math.isfinite(float(c)) for c in v):
                raise InputError(f"{where}: {key} must be finite")

    @property
    def label(self) -> str:
        """The probe's name, or its kind and pair."""
        return self.name or f"{self.kind.value} on pair {self.pair}"
