"""Contact discretization kernels (pure numpy/scipy): NTS, STS and segment-based mortar.

Against a body (`contact_operator`) or a rigid obstacle (`rigid_operator`: rigid.py,
rigid_kernels.py).
"""

from __future__ import annotations

from collections.abc import Callable
from enum import StrEnum

from . import mortar, nts, sts
from .geometry import Surface
from .operator import ContactOperator, overlap_tolerance
from .rigid import Circle, Plane, Polyline, RigidShape
from .rigid_kernels import RigidOperator, rigid_operator

__all__ = [
    "OPERATORS",
    "Circle",
    "ContactOperator",
    "Kernel",
    "Plane",
    "Polyline",
    "RigidOperator",
    "RigidShape",
    "Surface",
    "contact_operator",
    "overlap_tolerance",
    "rigid_operator",
]


class Kernel(StrEnum):
    """The discrete contact operators: node-to-surface, surface-to-surface (Gauss), mortar."""

    NTS = "nts"
    STS = "sts"
    MORTAR = "mortar"


#: The contact operator of each kernel: contact_operator(kernel, ...) dispatches here.
OPERATORS: dict[Kernel, Callable[..., ContactOperator]] = {
    Kernel.NTS: nts.contact_operator,
    Kernel.STS: sts.contact_operator,
    Kernel.MORTAR: mortar.contact_operator,
}


def contact_operator(
    kernel: Kernel, active: Surface, passive: Surface, ndofs: int, **options: object
) -> ContactOperator:
    """Build the contact operator of `kernel`; `options` go to it (e.g. mortar's basis)."""
    return OPERATORS[Kernel(kernel)](active, passive, ndofs, **options)
