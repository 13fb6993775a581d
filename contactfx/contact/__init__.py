"""Contact discretization kernels (pure numpy/scipy): NTS, STS and segment-based mortar."""

from __future__ import annotations

from collections.abc import Callable

from . import mortar, nts, sts
from .geometry import Surface
from .operator import ContactOperator

__all__ = ["OPERATORS", "ContactOperator", "Surface", "contact_operator"]

OPERATORS: dict[str, Callable[..., ContactOperator]] = {
    "nts": nts.contact_operator,
    "sts": sts.contact_operator,
    "mortar": mortar.contact_operator,
}


def contact_operator(
    method: str, active: Surface, passive: Surface, ndofs: int, **options: object
) -> ContactOperator:
    """Build the contact operator of the named method ("nts", "sts" or "mortar").

    `options` go to the kernel (e.g. the mortar multiplier basis).
    """
    try:
        build = OPERATORS[method]
    except KeyError:
        known = ", ".join(OPERATORS)
        raise ValueError(f"unknown contact method {method!r} (known: {known})") from None
    return build(active, passive, ndofs, **options)
