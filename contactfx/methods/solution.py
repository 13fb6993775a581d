"""What a solve produces: the displacement, the multipliers of every pair and what it cost."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from ..contact.friction import FrictionResult
from ..contact.geometry import arc_length, nodal_normals
from ..contact.search import project
from ..contact.sparse import CSR
from ..discretize.coupling import Multipliers
from ..discretize.pairs import PairData
from ..discretize.setup import ContactSetup
from ..discretize.surfaces import GatheredSurface
from ..options import Basis, Method
from ..scenes import Body, ContactPair, Obstacle, Scene
from ..timers import Timers
from .solver_choice import SolverChoice

# One record per active-set (or Schwarz) iteration; None where a value is undefined.
History = list[dict[str, float | None]]


@dataclass(frozen=True)
class Fields:
    """The solved displacement and the material fields the stresses need."""

    V: fem.FunctionSpace
    u: fem.Function
    E: fem.Function
    nu: fem.Function


@dataclass
class PairView:
    """One contact pair of a solution: its surfaces, multiplier rows and their geometry.

    `data` is the pair as the setup built it (its bodies, gathered surfaces, obstacle and
    initial overlap; read through the properties below). Row i of `B` is the pair's
    multiplier row `rows[i]` (layout order): the weighted gap's linearization, whose
    transpose spreads the multipliers into nodal forces. Against a rigid obstacle
    (`obstacle` set) there is no passive body or surface; row i of `motion` is the same
    row's derivative by the obstacle's displacement (its force: motion^T lambda).
    """

    data: PairData
    rows: np.ndarray  # layout rows of the pair's multipliers
    gblock: np.ndarray  # global node (dof block) of each of those rows
    B: CSR
    motion: CSR | None = None  # `data.motion`'s rows in the order of `rows`

    @property
    def index(self) -> int:
        """The pair's index in the scene."""
        return self.data.index

    @property
    def pair(self) -> ContactPair:
        """The scene's pair (its curve groups, interference)."""
        return self.data.pair

    @property
    def active_body(self) -> Body:
        """The body of the active (multiplier) surface."""
        return self.data.active_body

    @property
    def passive_body(self) -> Body | None:
        """The body of the passive surface; None against an obstacle."""
        return self.data.passive_body

    @property
    def active(self) -> GatheredSurface:
        """The gathered active surface."""
        return self.data.active

    @property
    def passive(self) -> GatheredSurface | None:
        """The gathered passive surface; None against an obstacle."""
        return self.data.passive

    @property
    def obstacle(self) -> Obstacle | None:
        """The rigid obstacle of the pair, if any."""
        return self.data.obstacle

    @property
    def initial_overlap(self) -> float:
        """Max over the pair's rows of -gap before the solve (>= 0)."""
        return self.data.initial_overlap

    @property
    def label(self) -> str:
        """How messages name the pair."""
        return f"pair {self.index} ({self.pair.active} on {self.pair.passive})"

    @cached_property
    def nodes(self) -> np.ndarray:
        """The active-surface node of each multiplier row."""
        return np.searchsorted(self.active.gblock, self.gblock)

    def nodal(self, values: np.ndarray) -> np.ndarray:
        """`values` (one per multiplier row, e.g. the pressure) on every active-surface node.

        0 on the nodes without a row of this pair.
        """
        out = np.zeros(self.active.surface.n_nodes)
        out[self.nodes] = values[self.rows]
        return out

    @cached_property
    def arc(self) -> tuple[np.ndarray, np.ndarray]:
        """(s, t): arc length and unit tangent at every node of the active surface."""
        return arc_length(self.active.surface)

    @property
    def s(self) -> np.ndarray:
        """Arc length of each multiplier row's node."""
        return self.arc[0][self.nodes]

    @property
    def t(self) -> np.ndarray:
        """Unit tangent (direction of increasing s) at each multiplier row's node."""
        return self.arc[1][self.nodes]

    @cached_property
    def n(self) -> np.ndarray:
        """Outward normal of the active surface at each multiplier row's node."""
        return nodal_normals(self.active.surface)[self.nodes]

    @property
    def x(self) -> np.ndarray:
        """Coordinates of each multiplier row's node."""
        return self.active.surface.x[self.nodes]

    @cached_property
    def frame(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(nu, tau, found): the contact frame at each multiplier row's node.

        nu is the passive surface's normal at the node's projection, turned to point out of
        the active body: the direction the multiplier acts along (every kernel measures the
        gap along the passive normal). tau is perpendicular to it, along increasing s.
        Where the node projects beyond the passive surface's end (found False), the active
        surface's own normal and tangent. Against a rigid obstacle: its exact outward normal
        at the closest point, turned the same way.
        """
        if self.passive is None:
            assert self.obstacle is not None  # a pair without a passive body has an obstacle
            closest = self.obstacle.geometry.closest(self.x)
            found, normal = closest.found, closest.normal
        else:
            seg, _, found = project(self.x, self.passive.surface)
            normal = self.passive.surface.normals[seg]
        nu = np.where(found[:, None], -normal, self.n)
        t = self.t
        tau = t - np.einsum("ki,ki->k", t, nu)[:, None] * nu
        tau /= np.linalg.norm(tau, axis=1)[:, None]
        return nu, tau, found


@dataclass
class PenaltyResult:
    """What the penalty method adds: its stiffness and the penetration it leaves."""

    eps: float  # normal stiffness (MPa/cm)
    penetration: float  # largest penetration (cm)
    condition: dict[str, float] | None = None  # CG + Jacobi Lanczos estimate, if asked for


@dataclass
class Cache:
    """Post-processing computed once per solution, shared by the summary and the charts.

    `stress`: (global node, x, sigma) by curve group; `interface`: the JSON block by pair.
    """

    stress: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = field(default_factory=dict)
    interface: dict[int, dict[str, Any]] = field(default_factory=dict)


@dataclass
class Solution:
    """A solved scene; multiplier arrays are in the global layout order (all pairs)."""

    scene: Scene
    method: Method
    fields: Fields
    layout: Multipliers
    pressure: np.ndarray  # (n,) contact traction per multiplier node, compression > 0
    gap: np.ndarray  # (n,) normalized gap (weighted gap / weight) at the solution
    active: np.ndarray  # (n,) bool, converged active set
    pairs: list[PairView]
    history: History = field(default_factory=list)
    timers: Timers = field(default_factory=Timers)
    basis: Basis = Basis.STANDARD
    penalty: PenaltyResult | None = None
    schwarz_dirichlet_body: str | None = None  # Schwarz: the body that took Dirichlet data
    reference_linear_iterations: int | None = None  # of the fresh solve (reference timing)
    solver_choice: SolverChoice | None = None  # what the `auto` solver ran and why
    cache: Cache = field(default_factory=Cache, repr=False)
    friction: FrictionResult | None = None  # the tangential side where some pair has mu > 0
    steps: list[Solution] = field(default_factory=list, repr=False)  # each load step's

    @property
    def iterations(self) -> int:
        """Outer iterations (active-set or Schwarz) the solve took."""
        return len(self.history)

    @property
    def u(self) -> fem.Function:
        """The displacement."""
        return self.fields.u

    @property
    def dofs(self) -> int:
        """Displacement dofs of the whole mesh."""
        imap = self.fields.V.dofmap.index_map
        return imap.size_global * self.fields.V.dofmap.index_map_bs


def gather_all(comm: MPI.Comm, local: np.ndarray) -> np.ndarray:
    """Concatenate every rank's rows (in rank order), on every rank."""
    return np.concatenate(comm.allgather(np.asarray(local)))


def pair_views(
    setup_pairs: list[PairData], layout: Multipliers, B: CSR, order: np.ndarray
) -> list[PairView]:
    """One PairView per pair: its layout rows and their rows of the stacked operator B."""
    out = []
    for p in setup_pairs:
        rows = np.flatnonzero(layout.pair == p.index)
        view = PairView(
            p,
            rows,
            layout.gblock[rows],
            B.rows(order[rows]),
            None if p.motion is None else p.motion.rows(order[rows] - p.first_row),
        )
        out.append(view)
    return out


def finish(
    setup: ContactSetup,
    method: Method,
    scene: Scene,
    u: fem.Function,
    pressure: np.ndarray,
    gap: np.ndarray,
    active: np.ndarray,
    history: History,
    timers: Timers,
) -> Solution:
    """Gather the owned rows of a converged loop into a Solution."""
    comm = setup.comm
    el = setup.elasticity
    return Solution(
        scene,
        method,
        Fields(el.V, u, el.E, el.nu),
        setup.layout,
        pressure=gather_all(comm, np.where(active, pressure, 0.0)),
        gap=gather_all(comm, gap),
        active=gather_all(comm, active),
        pairs=pair_views(setup.pairs, setup.layout, setup.operator.B, setup.order),
        history=history,
        timers=timers,
    )
