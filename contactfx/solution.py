"""What a solve produces: the displacement, the multipliers of every pair and what it cost."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from dolfinx import fem

from .contact import ContactOperator
from .coupling import Multipliers
from .elasticity import Elasticity
from .methods import Method
from .pairs import PairData
from .scenes import Scene
from .timers import Timers


@dataclass
class Solution:
    """A solved scene; multiplier arrays are in the global layout order (all pairs)."""

    scene: Scene
    method: Method
    elasticity: Elasticity
    u: fem.Function
    layout: Multipliers
    pressure: np.ndarray  # (n,) contact traction per multiplier node, compression > 0
    gap: np.ndarray  # (n,) normalized gap (weighted gap / weight) at the solution
    active: np.ndarray  # (n,) bool, converged active set
    operator: ContactOperator  # stacked over the pairs (rows: active-surface nodes)
    order: np.ndarray  # layout row i is row order[i] of `operator`
    pairs: list[PairData]
    iterations: int
    # One record per iteration; Schwarz records hold None where a value is undefined.
    history: Sequence[Mapping[str, float | None]] = field(default_factory=list)
    timers: Timers = field(default_factory=Timers)
    info: dict[str, object] = field(default_factory=dict)
    # Post-processing computed once per solution (nodal stresses, interfaces): the summary,
    # the references and the charts all read the same ones.
    cache: dict[object, object] = field(default_factory=dict, init=False, repr=False)

    def rows_of(self, pair: int) -> np.ndarray:
        """Layout rows of contact pair `pair`."""
        return np.flatnonzero(self.layout.pair == pair)
