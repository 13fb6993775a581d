"""Rigid obstacles in the output: their outlines, from the scene, and their JSON block."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..contact import Plane
from ..scenes import Obstacle
from ..scenes.obstacle import OBSTACLE_SHAPES


def outline(ob: Obstacle, near: np.ndarray) -> np.ndarray:
    """Points (k, 2) of the obstacle's outline at its reference position, in order.

    A circle is sampled every half degree; a plane is drawn across the projections of the
    points `near` (the body), widened by a quarter of that span on each side.
    """
    shape = ob.geometry
    if isinstance(shape, Plane):
        return shape.outline(near)
    return shape.outline()


def obstacle_json(ob: Obstacle) -> dict[str, Any]:
    """An obstacle as the JSON gives it: its shape, parameters and prescribed displacement."""
    params = {key: getattr(ob, key) for key in OBSTACLE_SHAPES[ob.shape]}
    if ob.points is not None:
        params["points"] = [list(p) for p in ob.points]
    return {
        "shape": ob.shape,
        **{k: list(v) if isinstance(v, tuple) else v for k, v in params.items()},
        "displacement": list(ob.displacement),
    }
