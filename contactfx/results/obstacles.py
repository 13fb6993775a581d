"""Rigid obstacles in the output: their outlines, from the scene or from the JSON summary."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..contact import Plane
from ..scenes import Obstacle
from ..scenes.model import OBSTACLE_SHAPES


def outline(ob: Obstacle, near: np.ndarray) -> np.ndarray:
    """Points (k, 2) of the obstacle's outline at its reference position, in order.

    A circle is sampled every half degree; a plane is drawn across the projections of the
    points `near` (the body), widened by a quarter of that span on each side.
    """
    shape = ob.geometry
    if isinstance(shape, Plane):
        return shape.outline(near)
    return shape.outline()


def from_summary(entry: dict[str, Any]) -> Obstacle:
    """The Obstacle of a JSON `contacts` entry (its `obstacle` block, results.interface)."""
    block = entry["obstacle"]
    shape = block["shape"]
    params: dict[str, Any] = {key: block[key] for key in OBSTACLE_SHAPES[shape]}
    return Obstacle(
        entry["passive"], shape, entry["active"], displacement=block["displacement"], **params
    )
