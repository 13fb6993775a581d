"""Contact pairs of a scene: gathered surfaces, one operator each, stacked into one constraint.

The multipliers of all pairs form one vector: the stacked operator has the rows of pair 0,
then pair 1, ... (before the layout reorders them by owner rank), so the active-set loop and
the saddle-point solver never need to know how many pairs there are.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import fem

from ..contact import ContactOperator, Kernel, Surface, contact_operator
from ..contact.sparse import CSR
from ..scenes import Body, ContactPair, Obstacle, Scene
from .surfaces import GatheredSurface, gather_surface

# A pair with both of its bodies and gathered surfaces: (pair, active body, passive body,
# active surface, passive surface).
GatheredPair = tuple[ContactPair, Body, Body, GatheredSurface, GatheredSurface]


@dataclass(frozen=True)
class PairData:
    """One contact pair with its bodies, gathered surfaces and contact operator.

    A pair against a rigid obstacle (`obstacle` set) has no passive body or surface: its
    `pair.passive` is the obstacle's name, and `motion` ((n_active, 2)) maps the obstacle's
    rigid displacement to the weighted gap (the force on the obstacle is motion^T lambda).
    """

    index: int
    pair: ContactPair
    active_body: Body
    passive_body: Body | None
    active: GatheredSurface
    passive: GatheredSurface | None
    operator: ContactOperator
    first_row: int  # first row of this pair in the stacked operator
    obstacle: Obstacle | None = None
    motion: CSR | None = None
    initial_overlap: float = 0.0  # max over the rows of -gap before the solve (>= 0)

    @property
    def label(self) -> str:
        """How messages name the pair."""
        if self.obstacle is not None:
            return f" of pair {self.index} ({self.pair.active} on obstacle {self.pair.passive})"
        return f" of pair {self.index} ({self.pair.active} on {self.pair.passive})"

    @property
    def overlap_text(self) -> str:
        """What an initial penetration of this pair is called in the error."""
        if self.passive_body is None:
            return f"obstacle '{self.pair.passive}' penetrates body '{self.active_body.name}'"
        return f"bodies '{self.active_body.name}' and '{self.passive_body.name}' overlap"


def gather_pairs(scene: Scene, V: fem.FunctionSpace) -> list[GatheredPair]:
    """Both gathered surfaces and bodies of every pair, in the scene's order."""
    out = []
    for pair in scene.contacts:
        out.append(
            (
                pair,
                scene.body_of_curve(pair.active),
                scene.body_of_curve(pair.passive),
                gather_surface(scene, V, pair.active),
                gather_surface(scene, V, pair.passive),
            )
        )
    return out


def build_pairs(
    gathered: list[GatheredPair],
    kernel: Kernel,
    ndofs: int,
    **kernel_options: object,
) -> list[PairData]:
    """The contact operator `kernel` on every pair."""
    pairs, row = [], 0
    for k, (pair, a_body, p_body, a_surf, p_surf) in enumerate(gathered):
        op = contact_operator(kernel, a_surf.surface, p_surf.surface, ndofs, **kernel_options)
        pairs.append(PairData(k, pair, a_body, p_body, a_surf, p_surf, op, row))
        row += a_surf.surface.n_nodes
    return pairs


def union_surface(parts: list[GatheredSurface]) -> GatheredSurface:
    """The disjoint union of gathered surfaces (node numbers offset part after part)."""
    if len(parts) == 1:
        return parts[0]
    offsets = np.cumsum([0] + [p.surface.n_nodes for p in parts[:-1]])
    surface = Surface(
        x=np.vstack([p.surface.x for p in parts]),
        segments=np.vstack([p.surface.segments + o for p, o in zip(parts, offsets, strict=True)]),
        normals=np.vstack([p.surface.normals for p in parts]),
        dofs=np.vstack([p.surface.dofs for p in parts]),
        axisymmetric=any(p.surface.axisymmetric for p in parts),
    )
    return GatheredSurface(
        surface, np.concatenate([p.owner for p in parts]), np.concatenate([p.gblock for p in parts])
    )


def stack(pairs: list[PairData]) -> tuple[GatheredSurface, ContactOperator, np.ndarray]:
    """The union of the active surfaces, the stacked operator and each row's pair index."""
    ops = [p.operator for p in pairs]
    op = (
        ops[0]
        if len(ops) == 1
        else ContactOperator(
            B=CSR.vstack([o.B for o in ops]),
            gap=np.concatenate([o.gap for o in ops]),
            weights=np.concatenate([o.weights for o in ops]),
        )
    )
    pair_of_row = np.concatenate(
        [np.full(p.active.surface.n_nodes, p.index, dtype=np.int64) for p in pairs]
    )
    return union_surface([p.active for p in pairs]), op, pair_of_row
