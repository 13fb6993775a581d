"""Contact discretization kernels (pure numpy/scipy): NTS, STS and segment-based mortar."""

from __future__ import annotations

from collections.abc import Callable
from enum import StrEnum

from . import mortar, nts, sts
from .geometry import Surface
from .operator import ContactOperator, overlap_tolerance

__all__ = [
    "OPERATORS",
    "ContactOperator",
    "Kernel",
    "Surface",
    "contact_operator",
    "overlap_tolerance",
]


class Kernel(StrEnum):
    """The discrete contact operators: node-to-surface, surface-to-surface (Gauss), mortar."""

    NTS = "nts"
    STS = "sts"
    MORTAR = "mortar"


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
