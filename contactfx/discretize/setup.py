"""Prepare a contact problem: assemble K and f, gather every pair, build B, check geometry."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..contact import ContactOperator, Kernel
from ..errors import GeometryError, InputError, SingularSystemError
from ..options import Basis
from ..scenes import Body, Model, Scene
from ..timers import Timers
from .coupling import (
    Multipliers,
    constrained_rows,
    global_dirichlet_dofs,
    multiplier_layout,
    petsc_constraint,
)
from .elasticity import Elasticity, assemble_elasticity
from .load_paths import advice, load_paths, what_pulls
from .obstacles import (
    GatheredObstacle,
    build_obstacle_pairs,
    check_obstacle_geometry,
    gather_obstacles,
    moved,
    node_free_rows,
)
from .pairs import GatheredPair, PairData, build_pairs, gather_pairs, stack
from .supports import Holding, holding
from .surfaces import check_facing
from .tangents import TangentRows, pair_friction, tangent_rows

# An active row whose traction is below this fraction of the largest holds nothing.
HOLDING_RTOL = 1e-9


@dataclass
class ContactSetup:
    """What every contact solver needs before its first solve: K, f, B, gaps, the layout."""

    comm: MPI.Comm
    e_max: float  # the largest Young's modulus (scales gamma, the penalty and c)
    elasticity: Elasticity
    pairs: list[PairData]
    operator: ContactOperator  # stacked over the pairs
    layout: Multipliers
    order: np.ndarray
    B: PETSc.Mat
    g: np.ndarray  # weighted gaps of the rows owned here
    w: np.ndarray  # weights of the rows owned here
    h: float  # median contact weight (about the contact element size)
    needs_contact: list[Body]  # bodies whose supports alone leave a rigid mode free
    holding: Holding  # the bodies' rigid frames and what their supports fix
    row_modes: np.ndarray  # (n, 3 nb) B m of every rigid mode m at every row (global)
    pulls: str = "the load pulls the bodies apart"  # load_paths.what_pulls of the scene
    # Friction (prepare_contact(..., friction=True) with a frictional pair): the tangential
    # rows, and their B_t m at every row (zero on frictionless rows): stick holds bodies too.
    tangent: TangentRows | None = None
    tangent_modes: np.ndarray | None = None

    def normalized_gap(self, u: fem.Function) -> np.ndarray:
        """Nodal gap (weighted gap / weight) of the owned rows at displacement u."""
        y = self.B.createVecLeft()
        self.B.mult(u.x.petsc_vec, y)
        gap = (self.g + y.array_r) / self.w
        y.destroy()
        return gap

    def initial_active(self, tol: float) -> np.ndarray:
        """Touching nodes; in a pair with none that holds a loose body, its closest node(s)."""
        comm = self.comm
        gap = self.g / self.w
        active = gap <= tol
        loose = {b.name for b in self.needs_contact}
        pair_of = self.layout.pair[self.layout.mine]
        for p in self.pairs:
            if not ({b.name for b in (p.active_body, p.passive_body) if b is not None} & loose):
                continue
            rows = pair_of == p.index
            if comm.allreduce(int(active[rows].sum())) == 0:
                gmin = comm.allreduce(float(gap[rows].min(initial=np.inf)), op=MPI.MIN)
                active |= rows & (gap <= gmin + tol)
        return active

    def check_not_floating(self, n_active: int) -> None:
        """Raise SingularSystemError if a body held only by contact has lost every contact."""
        if n_active == 0 and self.needs_contact:
            raise SingularSystemError(
                f"body '{self.needs_contact[0].name}' is not held by its supports alone and no "
                f"node is in contact (empty active set): {self.pulls}"
            )

    def loaded(self, active: np.ndarray, lam: np.ndarray) -> np.ndarray:
        """Rows of `active` (owned) whose traction carries load (above round-off of the largest).

        Only active rows count: penalty's traction -eps g is large and negative elsewhere.
        """
        on = np.asarray(active, dtype=bool)
        big = float(np.max(np.abs(lam[on]), initial=0.0))
        lam_max = self.comm.allreduce(big, op=MPI.MAX)
        return on & (lam > HOLDING_RTOL * lam_max)

    def check_held_by(self, holds: np.ndarray, when: str, detail: np.ndarray | None = None) -> None:
        """Raise SingularSystemError if the rows `holds` (owned) leave a body free.

        A body whose supports leave a rigid mode free must be held by contact rows (taken
        as bilateral). `detail` (owned rows): if the check fails, the bodies named are
        those that `holds & detail` leaves free (e.g. counting only rows that carried load
        in the last solve: a body pressed by nothing is lost too). `when` says which set.
        """
        if not self.needs_contact:
            return
        free, glob = self._free_modes(holds)
        loose = self.holding.loose(free)
        if not loose:
            return
        if detail is not None:
            free, glob = self._free_modes(holds & detail)
            loose = self.holding.loose(free)
        raise SingularSystemError(self._floating_message(loose, free, glob, when))

    def _free_modes(self, holds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(free rigid modes, the global mask) of supports plus the owned rows `holds`."""
        glob = np.zeros(self.layout.size, dtype=bool)
        for idx, vals in self.comm.allgather((self.layout.mine, np.asarray(holds, dtype=bool))):
            glob[idx] = vals
        rows = self.row_modes[glob]
        if self.tangent_modes is not None:  # an active frictional row holds tangentially too
            rows = np.vstack([rows, self.tangent_modes[glob]])
        return self.holding.free_modes(rows), glob

    def _floating_message(
        self, loose: list[int], free: np.ndarray, holds: np.ndarray, when: str
    ) -> str:
        """One line: the loose bodies, their free motion and the pairs that lost contact."""
        hold = self.holding
        names = [f"'{hold.bodies[k].name}' ({hold.describe(free, k)})" for k in loose]
        lost = [
            f"{p.index} ({p.pair.active} on {p.pair.passive})"
            for p in self.pairs
            if {hold.index(p.active_body), hold.index(p.passive_body)} & set(loose)
            and not holds[self.layout.pair == p.index].any()
        ]
        pairs = (
            f": pair{'s' * (len(lost) > 1)} {', '.join(lost)} "
            f"{'carry' if len(lost) > 1 else 'carries'} no load"
            if lost
            else ""
        )
        return (
            f"bod{'ies' if len(names) > 1 else 'y'} {', '.join(names)} "
            f"{'are' if len(names) > 1 else 'is'} held by no support and no contact "
            f"{when}{pairs}: {'their' if len(names) > 1 else 'its'} position is undetermined "
            f"(K is singular); {advice(self.pairs, hold, loose)}"
        )

    def destroy(self) -> None:
        """Free B (K and f belong to the elasticity, which the solution keeps for its fields)."""
        self.B.destroy()

    def node_dofs(self) -> np.ndarray:
        """(m, 2) global dofs (x, y) of the active node of each owned multiplier row."""
        g = np.asarray(self.layout.gblock)[self.layout.mine].astype(np.int64)
        return np.column_stack([2 * g, 2 * g + 1])


def assemble_and_gather(scene: Scene, timers: Timers) -> tuple[Elasticity, int, list[GatheredPair]]:
    """Assemble K and f, and gather both surfaces of every contact pair."""
    with timers("assemble"):
        el = assemble_elasticity(scene)
    V = el.V
    ndofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
    with timers("search"):
        gathered = gather_pairs(scene, V)
    return el, ndofs, gathered


def all_pairs(
    gathered: list[GatheredPair],
    obstacles: list[GatheredObstacle],
    kernel: Kernel,
    ndofs: int,
    **kernel_options: object,
) -> list[PairData]:
    """The body pairs, then the obstacle pairs, with their operators of `kernel`."""
    pairs = build_pairs(gathered, kernel, ndofs, **kernel_options)
    row = sum(p.active.surface.n_nodes for p in pairs)
    return pairs + build_obstacle_pairs(obstacles, kernel, ndofs, len(pairs), row, **kernel_options)


def prescribed_gap_shift(
    scene: Scene, el: Elasticity, op: ContactOperator, surface_dofs: np.ndarray
) -> np.ndarray:
    """B[:, D] u_D: the weighted gap that nonzero prescribed displacements add.

    B's Dirichlet columns are removed (K has identity rows there), so a prescribed value on a
    contact surface must enter the gap instead. Zero when every prescribed value is zero.
    """
    V = el.V
    if not any(v != 0.0 for bc in scene.dirichlet for _, v in bc.components()):
        return np.zeros(op.B.shape[0])
    ub = fem.Function(V)
    for bc in el.bcs:
        bc.set(ub.x.array)
    imap = V.dofmap.index_map
    start, nloc = imap.local_range[0], imap.size_local
    dofs = np.unique(surface_dofs.ravel())
    blocks = dofs // 2 - start
    mine = (blocks >= 0) & (blocks < nloc)
    vals = np.zeros(len(dofs))
    vals[mine] = ub.x.array[2 * blocks[mine] + dofs[mine] % 2]
    V.mesh.comm.Allreduce(MPI.IN_PLACE, vals, op=MPI.SUM)
    ud = np.zeros(op.B.shape[1])
    ud[dofs] = vals
    return op.B @ ud


def prepare_contact(
    scene: Scene,
    kernel: Kernel,
    penetration_tol: float,
    timers: Timers,
    basis: Basis = Basis.STANDARD,
    frame: str = "passive",
    friction: bool = False,
) -> ContactSetup:
    """Assemble K and f, build every pair's operator and B, and check the geometry.

    frame: the rows' normals, the passive surface's or (friction, pairs between bodies) the
    bisector of both surfaces' (contact/operator.bisector_normals). friction: also the
    tangential rows of the frictional pairs, which hold bodies in the free-body check.
    """
    comm = scene.comm
    el, ndofs, gathered = assemble_and_gather(scene, timers)
    V = el.V
    dual = basis is Basis.DUAL
    with timers("search"):
        obstacles = gather_obstacles(scene, V)
    with timers("contact"):
        framed: dict[str, object] = {} if frame == "passive" else {"frame": frame}
        pairs = all_pairs(
            gathered, obstacles, kernel, ndofs, **({"basis": basis} if dual else {}), **framed
        )
        for p in pairs:
            if p.passive is None:
                check_obstacle_geometry(p)
                continue
            if not p.operator.overlapping.any():
                raise GeometryError(
                    f"contact pair {p.index}: the active surface "
                    f"'{p.pair.active}' does not overlap the passive surface "
                    f"'{p.pair.passive}'"
                )
            check_facing(p.active.surface, p.passive.surface, p.operator, p.label)
        active_union, op, pair_of_row = stack(pairs)
        shift = prescribed_gap_shift(
            scene,
            el,
            op,
            np.vstack(
                [active_union.surface.dofs]
                + [p.passive.surface.dofs for p in pairs if p.passive is not None]
            ),
        )
        if np.any(shift):
            op = ContactOperator(op.B, op.gap + shift, op.weights)
        dirichlet = global_dirichlet_dofs(V, el.bc_dofs)
        usable = constrained_rows(op, dirichlet) & node_free_rows(
            op, active_union.surface.dofs, pairs, dirichlet
        )
        layout, order = multiplier_layout(comm, active_union, op, pair_of_row, usable)
        B = petsc_constraint(V, op, order, layout, dirichlet)
    w_all = layout.weights
    g_all = op.gap[order] / w_all
    if dual:
        # A dual (sign-changing) weighting averages the gap with negative weights: check
        # for overlap with the standard, positive weights (geometry, not the multipliers).
        std = stack(all_pairs(gathered, obstacles, kernel, ndofs, **framed))[1]
        g_all = (std.gap[order] + shift[order]) / std.weights[order]
    h = contact_size(w_all, layout.x, scene.model)
    pairs = check_overlaps(pairs, layout, g_all, penetration_tol * h)
    fit = np.concatenate(
        [np.full(p.active.surface.n_nodes, p.pair.prescribed_overlap) for p in pairs]
    )
    if np.any(fit):
        # interference = D: the gap g becomes g - D (weighted: g_w - D w).
        op = ContactOperator(op.B, op.gap - fit * op.weights, op.weights)
    # Checked at their reference positions, the obstacles now take their prescribed motion.
    op = moved(op, pairs)
    hold = holding(scene, V, el.bc_dofs)
    # Before any solve: a body that only rows carrying no load could hold floats, whatever
    # round-off the singular solve would show (decided from statics, see load_paths).
    mu = pair_friction(pairs)
    tangent = None
    if friction and np.any(mu > 0):
        tangent = tangent_rows(pairs, kernel, basis, frame, ndofs)
    friction_rows = None if tangent is None else (tangent.B, mu)
    paths = load_paths(scene, V, el.f, pairs, op.B, order, layout.pair, hold, friction_rows)
    mine = layout.mine
    return ContactSetup(
        comm,
        scene.e_max,
        el,
        pairs,
        op,
        layout,
        order,
        B,
        op.gap[order][mine],
        w_all[mine],
        h,
        hold.needs_contact(),
        hold,
        paths.rows,
        what_pulls(scene),
        tangent,
        paths.tangent,
    )


def contact_size(w: np.ndarray, x: np.ndarray, model: Model) -> float:
    """The median contact weight: about the contact element size (a length).

    Axisymmetric weights are int N_j 2 pi r ds: divided by 2 pi r_j (rows off the axis).
    """
    if model is Model.AXISYMMETRIC:
        off = x[:, 0] > 0
        if off.any():
            return float(np.median(w[off] / (2 * np.pi * x[off, 0])))
    return float(np.median(w))


def check_overlaps(
    pairs: list[PairData], layout: Multipliers, g_all: np.ndarray, tol: float
) -> list[PairData]:
    """The pairs with their initial overlaps, once the drawn gaps `g_all` are checked.

    A pair drawn overlapping beyond `tol` is a GeometryError, unless it is an interference
    fit drawn so (`interference = true`), which must overlap beyond `tol` (InputError if
    not). The initial overlap is max(0, max -g) over the pair's rows before the solve, with
    the prescribed overlap D of `interference = D` included.
    """
    out = []
    for p in pairs:
        rows = np.flatnonzero(layout.pair == p.index)
        j = rows[int(np.argmin(g_all[rows]))]
        drawn = -float(g_all[j])
        if p.pair.interference is True:
            if drawn <= tol:
                raise InputError(
                    f"contact pair {p.index} ({p.pair.active} on {p.pair.passive}) has "
                    f"interference = true but its bodies do not overlap as drawn (largest "
                    f"overlap {max(drawn, 0.0):.3e}, tolerance {tol:.1e}): draw the fit "
                    "overlapping, or give interference = D (a number > 0) for bodies drawn "
                    "touching"
                )
        elif drawn > tol:
            raise GeometryError(
                f"{p.overlap_text}: initial penetration {drawn:.3e} at ("
                f"{layout.x[j, 0]:.4g}, {layout.x[j, 1]:.4g}) exceeds the "
                f"tolerance {tol:.1e}"
                + (
                    " (interference = D prescribes an overlap of bodies drawn touching; "
                    "for a fit drawn overlapping give interference = true)"
                    if p.pair.prescribed_overlap
                    else ""
                )
            )
        overlap = max(0.0, drawn + p.pair.prescribed_overlap)
        out.append(replace(p, initial_overlap=overlap))
    return out
