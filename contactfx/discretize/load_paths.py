"""Which contact rows can carry load, and so which bodies are held, decided before any solve.

On a free rigid mode m of a body (a mode its Dirichlet supports leave free) equilibrium
K u = f + B^T lam holds exactly whatever the elasticity, since K m = 0 and m vanishes at the
supported dofs:  m . f + (B m) . lam = 0,  lam >= 0.  A row whose lam_i is zero in every
such nonnegative equilibrium carries no load in any solution: it cannot hold a body, however
its gap closes. The rows are B's own rows, so a pair against a rigid obstacle acts along the
obstacle's normal, not along the body's surface normals. Rows on which no free mode acts are
unconstrained by these equations (elasticity decides them) and count as able to carry load.

The rows that can carry load come from one linear program (HiGHS): the equilibria form a
convex cone in (lam, s) (s scales the load), so the rows positive in some equilibrium are
positive together in one, and maximizing sum min(lam_i, 1) over it finds them all at once
(each t_i is 1 or 0 at the optimum, far from HiGHS's feasibility tolerance); a single free
mode (a body free along one direction, the usual case) is decided in closed form. If no
nonnegative lam balances the load, a Farkas certificate (a combination of free modes along
which the load does work and no gap closes) names the bodies that the load pulls away.

Friction: a frictional pair's tangential rows (B_t m) hold too. Their multipliers take either
sign, bounded by Coulomb's |lambda_t| <= mu lambda_n at the same node, so a body pressed on
a floor and pushed sideways by less than mu times the pressing force is held by stick alone;
the program then carries the tangential unknowns with that bound, and a row's tangential
part holds wherever its normal row can carry load (docs/friction.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..contact.geometry import Surface
from ..contact.sparse import CSR
from ..errors import InputError, SingularSystemError
from ..scenes import Body, Scene
from .load_programs import carrying_rows, pulled_away
from .pairs import PairData
from .supports import Holding, _free_motions, body_blocks, rigid_modes_at

# A row's entry below this fraction of the largest is round-off of the geometry (a flat
# edge's normal has a ~1e-17 tangential part); the load on a free mode below this fraction
# of the load scale (sum |m| |f|) is round-off of the assembly (the lifting of a prescribed
# displacement does no work on a rigid mode, up to cancellation).
ROW_RTOL = 1e-9
LOAD_RTOL = 1e-10


@dataclass(frozen=True)
class LoadPaths:
    """The verdict before any solve: which multiplier rows can carry load.

    `rows` (n, 3 nb): B m for each rigid mode m of each body (column 3 k + j: mode j of
    body k), one row per multiplier row in the layout order. `carries` (n,): whether the
    row can be positive in a nonnegative equilibrium of the free rigid modes. `tangent`
    (n, 3 nb): B_t m of the frictional rows (zero on frictionless ones), None without
    friction.
    """

    rows: np.ndarray
    carries: np.ndarray
    tangent: np.ndarray | None = None

    def holding(self, on: np.ndarray) -> np.ndarray:
        """The rows B m that hold the bodies where `on` (n,): normal, and tangential (stick)."""
        if self.tangent is None:
            return self.rows[on]
        return np.vstack([self.rows[on], self.tangent[on]])


def surface_modes(pairs: list[PairData], hold: Holding, ndofs: int) -> CSR:
    """(ndofs, 3 nb) rigid modes of every body at the dofs of the pairs' surfaces."""
    dofs, x, body = [], [], []
    for p in pairs:
        sides: list[tuple[Surface, Body | None]] = [(p.active.surface, p.active_body)]
        if p.passive is not None:
            sides.append((p.passive.surface, p.passive_body))
        for surf, b in sides:
            dofs.append(surf.dofs)
            x.append(surf.x)
            body.append(np.full(surf.n_nodes, hold.index(b)))
    d, xs, k = np.vstack(dofs), np.vstack(x), np.concatenate(body)
    # A node on two surfaces (a passive surface of two pairs) must enter once.
    _, first = np.unique(d[:, 0], return_index=True)
    d, xs, k = d[first], xs[first], k[first]
    vals, rows, cols = [], [], []
    for kb in np.unique(k):
        sel = k == kb
        m = rigid_modes_at(xs[sel], hold.centres[kb], hold.sizes[kb])  # (n, 2, 3)
        for c in (0, 1):
            for j in range(3):
                vals.append(m[:, c, j])
                rows.append(d[sel, c])
                cols.append(np.full(int(sel.sum()), 3 * kb + j))
    return CSR.from_coo(
        np.concatenate(rows),
        np.concatenate(cols),
        np.concatenate(vals),
        (ndofs, 3 * len(hold.bodies)),
    )


def mode_loads(scene: Scene, V: fem.FunctionSpace, f: PETSc.Vec, hold: Holding) -> np.ndarray:
    """(3 nb,) work of the assembled load on each rigid mode, round-off set to exact zero."""
    nloc = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:nloc, :2]
    fa = f.array_r.reshape(-1, 2)[:nloc]
    work = np.zeros(3 * len(hold.bodies))
    scale = 0.0
    for k, body in enumerate(hold.bodies):
        b = body_blocks(V, scene.body_cells(body))
        b = b[b < nloc]
        m = rigid_modes_at(x[b], hold.centres[k], hold.sizes[k])
        work[3 * k : 3 * k + 3] = np.einsum("nc,ncj->j", fa[b], m)
        scale += float(np.einsum("nc,ncj->", np.abs(fa[b]), np.abs(m)))
    work = np.asarray(scene.comm.allreduce(work, op=MPI.SUM))
    scale = scene.comm.allreduce(scale, op=MPI.SUM)
    work[np.abs(work) <= LOAD_RTOL * scale] = 0.0
    return work


def _named(hold: Holding, free: np.ndarray, loose: list[int]) -> list[str]:
    """'name' (every free motion) of each loose body."""
    return [f"'{hold.bodies[k].name}' ({_free_motions(free[:, 3 * k : 3 * k + 3])})" for k in loose]


def advice(pairs: list[PairData], hold: Holding, loose: list[int]) -> str:
    """What to add or check: [[contact]] pairs only if the loose bodies have some."""
    mine = [
        p for p in pairs if {hold.index(p.active_body), hold.index(p.passive_body)} & set(loose)
    ]
    if any(p.passive_body is not None for p in mine):
        return (
            "check that each contact pair ([[contact]] in a scene file, ContactPair in Python) "
            "names two surfaces that touch, or add a support ([[dirichlet]], Dirichlet)"
        )
    return (
        "add a support ([[dirichlet]] in a scene file, Dirichlet in Python) or an obstacle "
        "([[obstacle]], Obstacle) that holds it"
    )


def floating_message(
    pairs: list[PairData], layout_pair: np.ndarray, hold: Holding, paths: LoadPaths
) -> str | None:
    """One line naming the bodies the supports and load-carrying rows leave free, or None."""
    free = hold.free_modes(paths.holding(paths.carries))
    loose = hold.loose(free)
    if not loose:
        return None
    bilateral = set(hold.loose(hold.free_modes(paths.holding(np.ones(len(paths.rows), bool)))))
    when = "before the first solve"
    parts = [
        f"body '{hold.bodies[k].name}' can still move freely after its supports and contacts "
        f"({_free_motions(free[:, 3 * k : 3 * k + 3])}; {when})"
        for k in loose
        if k in bilateral
    ]
    held = [k for k in loose if k not in bilateral]
    if held:
        names = _named(hold, free, held)
        lost = [
            f"{p.index} ({p.pair.active} on {p.pair.passive})"
            for p in pairs
            if {hold.index(p.active_body), hold.index(p.passive_body)} & set(held)
            and not paths.carries[layout_pair == p.index].any()
        ]
        many = len(names) > 1
        s = "s" if len(lost) > 1 else ""
        pairs_text = (
            f": pair{s} {', '.join(lost)} carr{'y' if s else 'ies'} no load" if lost else ""
        )
        parts.append(
            f"bod{'ies' if many else 'y'} {', '.join(names)} {'are' if many else 'is'} held by "
            f"no support and no contact that can carry load ({when}){pairs_text}: "
            f"{'their' if many else 'its'} position is undetermined (K is singular)"
        )
    return "; ".join(parts) + ": " + advice(pairs, hold, loose)


def what_pulls(scene: Scene) -> str:
    """What pulls the bodies apart, as the scene has it: its loads, its thermal strains, both.

    A cooled body between walls has no load to blame: the message names its shrinking.
    """
    strains = [
        f"alpha dT = {b.material.thermal_strain:.3g} in '{b.name}'"
        for b in scene.bodies
        if b.material.thermal_strain
    ]
    if not strains:
        return "the load pulls the bodies apart"
    cooled = all(b.material.thermal_strain <= 0 for b in scene.bodies)
    thermal = f"the thermal strain ({', '.join(strains)}{': it shrinks' if cooled else ''})"
    if scene.loads:
        return f"the load and {thermal} pull the bodies apart"
    return f"{thermal} pulls the bodies apart (no load is applied)"


def _verdict(
    comm: MPI.Comm,
    a: np.ndarray,
    load: np.ndarray,
    at: np.ndarray | None = None,
    mu: np.ndarray | None = None,
) -> tuple[Any, Any]:
    """Rank 0's carrying_rows (and pulled_away where nothing carries), on every rank.

    An exception there (HiGHS refusing its input) is sent to every rank and raised on each,
    so that none waits in the broadcast for a rank that has failed.
    """
    verdict: tuple[Any, Any] = (None, None)
    error = None
    if comm.rank == 0:
        try:
            carries = carrying_rows(a, load, at, mu)
            verdict = (carries, pulled_away(a, load) if carries is None else None)
        except ValueError as exc:
            error = str(exc)
    verdict, error = comm.bcast((verdict, error), root=0)
    if error is not None:
        raise SingularSystemError(
            f"the check of which contacts can hold the bodies failed: {error}"
        )
    return verdict


def load_paths(
    scene: Scene,
    V: fem.FunctionSpace,
    f: PETSc.Vec,
    pairs: list[PairData],
    B: CSR,
    order: np.ndarray,
    layout_pair: np.ndarray,
    hold: Holding,
    friction: tuple[CSR, np.ndarray] | None = None,
) -> LoadPaths:
    """The rows B m of the layout's multiplier rows and which of them can carry load.

    Collective: every rank gets rank 0's verdict. Raises SingularSystemError, naming every
    free motion of each loose body, if the supports and all rows (bilateral) leave a body
    free, if no nonnegative contact force balances the load on the free modes (the load
    pulls the bodies apart), or if the rows that can carry load leave a body free.
    `friction`: the tangential rows B_t (stacked order) and each stacked row's mu.
    """
    modes = surface_modes(pairs, hold, B.shape[1])
    rows = B.rows(order).dense_product(modes)
    rows[np.abs(rows) <= ROW_RTOL * float(np.abs(rows).max(initial=0.0))] = 0.0
    tangent, mu = None, None
    if friction is not None:
        mu = friction[1][order]
        tangent = friction[0].rows(order).dense_product(modes)
        tangent[np.abs(tangent) <= ROW_RTOL * float(np.abs(tangent).max(initial=0.0))] = 0.0
        tangent[mu <= 0] = 0.0
    every = LoadPaths(rows, np.ones(len(rows), dtype=bool), tangent)
    # Free even with every row bilateral: no load can make the system regular.
    message = floating_message(pairs, layout_pair, hold, every)
    if message is not None:
        raise SingularSystemError(message)
    free = hold.free_modes()
    if not free.shape[0]:
        return every
    free[np.abs(free) < 1e-12] = 0.0  # eigh's round-off on the held modes
    a = rows @ free.T
    a[np.abs(a) <= ROW_RTOL * float(np.abs(a).max(initial=0.0))] = 0.0
    at = None
    if tangent is not None:
        at = tangent @ free.T
        at[np.abs(at) <= ROW_RTOL * float(np.abs(at).max(initial=0.0))] = 0.0
    work = mode_loads(scene, V, f, hold)
    if not (np.isfinite(work).all() and np.isfinite(a).all()):
        # inf or nan in the assembled system (a lifting of 0 * inf): no program can decide.
        raise InputError(
            "the assembled load is not a finite number (it overflows double precision): "
            "check the magnitudes of the Young's moduli and the loads (their units)"
        )
    load = free @ work
    load[np.abs(load) <= LOAD_RTOL * float(np.abs(work).sum())] = 0.0
    carries, away = _verdict(scene.comm, a, load, at, mu)
    if carries is None:
        assert away is not None
        motion = (free.T @ away)[None, :]
        motion /= float(np.abs(motion).max())
        loose = hold.loose(motion)
        said = [
            f"body '{hold.bodies[k].name}' is not held by its supports and no contact can push "
            f"against the load ({hold.describe(motion, k)})"
            for k in loose
        ]
        bound = "" if at is None else " (friction holds at most mu times the normal force)"
        raise SingularSystemError(
            f"{'; '.join(said)}; decided before the first solve: {what_pulls(scene)}{bound}"
        )
    paths = LoadPaths(rows, carries, tangent)
    message = floating_message(pairs, layout_pair, hold, paths)
    if message is not None:
        raise SingularSystemError(message)
    return paths
