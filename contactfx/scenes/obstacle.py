"""A rigid obstacle as scene data: an analytic curve (circle, plane, polyline) a body may touch."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from enum import StrEnum
from functools import cached_property
from types import MappingProxyType

from ..contact.rigid import Circle, Plane, Polyline, RigidShape
from ..errors import InputError
from .fits import check_friction


class Shape(StrEnum):
    """The shape of a rigid obstacle (its parameters: OBSTACLE_SHAPES)."""

    CIRCLE = "circle"
    PLANE = "plane"
    POLYLINE = "polyline"


# The parameters each obstacle shape takes (besides name, shape, surface and displacement).
OBSTACLE_SHAPES: Mapping[Shape, tuple[str, ...]] = MappingProxyType(
    {
        Shape.CIRCLE: ("center", "radius"),
        Shape.PLANE: ("point", "normal"),
        Shape.POLYLINE: ("points",),
    }
)


@dataclass(frozen=True)
class Obstacle:
    """A rigid obstacle: an analytic curve that the body's curve group `surface` may touch.

    `shape` "circle" (`center`, `radius`; the body outside), "plane" (`point`, `normal` from
    the obstacle towards the body) or "polyline" (`points` in order, the obstacle on the left,
    the body on the right; closed if the last point repeats the first). `displacement` is the
    obstacle's prescribed rigid motion (`name` names it in load steps). `mu`: Coulomb's friction
    coefficient against the body (0, the default: frictionless, the model unchanged).
    InputError at once for a bad shape or parameter.
    """

    name: str
    shape: Shape  # or its name: "circle", "plane", "polyline"
    surface: str
    center: tuple[float, float] | None = None
    radius: float | None = None
    point: tuple[float, float] | None = None
    normal: tuple[float, float] | None = None
    points: tuple[tuple[float, float], ...] | None = None
    displacement: tuple[float, float] = (0.0, 0.0)
    mu: float = 0.0

    def __post_init__(self) -> None:
        where = f"obstacle '{self.name}'"
        if not isinstance(self.name, str) or not self.name:
            raise InputError("obstacle: name must be a non-empty string")
        if self.shape not in OBSTACLE_SHAPES:
            raise InputError(
                f"{where}: unknown shape {self.shape!r} (choose {', '.join(OBSTACLE_SHAPES)})"
            )
        object.__setattr__(self, "shape", Shape(self.shape))
        object.__setattr__(self, "mu", check_friction(self.mu, where))
        takes = OBSTACLE_SHAPES[self.shape]
        for key in ("center", "radius", "point", "normal", "points"):
            given = getattr(self, key) is not None
            if given != (key in takes):
                need = " and ".join(takes)
                raise InputError(
                    f"{where}: a {self.shape} takes {need}"
                    + (f", not {key}" if given else f" (missing {key})")
                )
        try:
            # Plain numbers in tuples: the obstacle stays hashable and prints as given.
            for key in ("center", "point", "normal", "displacement"):
                value = getattr(self, key)
                if value is not None:
                    object.__setattr__(self, key, tuple(float(v) for v in value))
            if self.points is not None:
                points = tuple(tuple(float(v) for v in p) for p in self.points)
                object.__setattr__(self, "points", points)
            if self.radius is not None:
                object.__setattr__(self, "radius", float(self.radius))
            if len(self.displacement) != 2 or not all(map(math.isfinite, self.displacement)):
                raise ValueError("displacement must be two finite numbers [ux, uy]")
            self.geometry  # noqa: B018  (builds and checks the shape once)
        except (ValueError, TypeError) as exc:
            raise InputError(f"{where}: {exc}") from None

    @cached_property
    def geometry(self) -> RigidShape:
        """The exact shape (contact.rigid) at the obstacle's reference position."""
        if self.shape is Shape.CIRCLE:
            assert self.center is not None and self.radius is not None  # checked above
            return Circle(self.center, self.radius)
        if self.shape is Shape.PLANE:
            assert self.point is not None and self.normal is not None
            return Plane(self.point, self.normal)
        assert self.points is not None
        return Polyline(self.points)
