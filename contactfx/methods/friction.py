"""Which frictional scenes can be solved: a pair with mu > 0 is refused in one line until then.

Coulomb friction is chosen per contact pair (`ContactPair.mu`). Its building blocks (the
complementarity rows of contact/friction.py, the tangential rows of the nts and mortar
kernels, the references of results/friction_references.py) are in; no solver path carries the
tangential multipliers yet (docs/friction.md), so a frictional pair is refused rather than
solved frictionless. With every mu = 0 nothing here changes the model.
"""

from __future__ import annotations

from ..errors import InputError
from ..request import SolveRequest
from ..scenes import Scene


def frictional_pairs(scene: Scene) -> list[int]:
    """Indices (into `scene.contacts`) of the pairs with mu > 0."""
    return [k for k, pair in enumerate(scene.contacts) if pair.mu > 0.0]


def refuse_friction(scene: Scene, request: SolveRequest) -> None:
    """InputError naming the first frictional pair: no method solves friction yet."""
    pairs = frictional_pairs(scene)
    if not pairs:
        return
    k = pairs[0]
    pair = scene.contacts[k]
    raise InputError(
        f"contact {k} ('{pair.active}' on '{pair.passive}') has mu = {pair.mu:g}: Coulomb "
        f"friction is not solved yet by any method ({request.discretization.value} with "
        f"{request.enforcement.value} included); set mu = 0 for frictionless contact"
    )
