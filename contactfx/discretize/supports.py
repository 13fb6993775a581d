"""Which rigid motions the supports and the contact pairs leave free, body by body.

Each body has three rigid modes (two translations, a rotation about its centroid); in an
axisymmetric model only the axial translation (along y) is rigid: a radial translation or a
rotation strains the revolved body (hoop strain), so each body gets two more fixed rows. A
Dirichlet dof of the body and a contact-surface normal of a pair (taken as bilateral, the
most the contact can hold) each give one linear condition on the modes; the modes in the
null space of all these conditions make K + contact singular, whatever the load. A rigid
obstacle is a body that does not move: its pairs' rows hold the active body alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from ..contact.geometry import nodal_normals
from ..errors import SingularSystemError
from ..linalg.nullspace import orthonormalize
from ..scenes import Body, Model, Scene
from .surfaces import GatheredSurface

# A contact pair as the check needs it: (active body, passive body or None for a rigid
# obstacle, active surface).
Contact = tuple[Body, Body | None, GatheredSurface]


def body_blocks(V: fem.FunctionSpace, cells: np.ndarray) -> np.ndarray:
    """Local dof blocks (nodes, owned and ghost) of the cells `cells` (a body's), sorted.

    A mask over the local blocks, not np.unique: the same sorted blocks without np.unique's
    sort, which dominated the setup of large meshes (measured: docs/scale.md, "Setup").
    """
    im = V.dofmap.index_map
    mask = np.zeros(im.size_local + im.num_ghosts, dtype=bool)
    mask[V.dofmap.list[cells]] = True
    return np.flatnonzero(mask)


def rigid_body_modes(V: fem.FunctionSpace, scene: Scene) -> list[PETSc.Vec]:
    """The three rigid modes of all bodies together (x, y translation, rotation), orthonormal.

    Axisymmetric: the translation along y (the axis) only.

    What aggregation multigrid wants as near-nullspace: an aggregate lies in one body (or
    straddles a contact the condensation couples), so per-body copies of the modes would only
    add zero columns to its tentative prolongator, which GAMG turns into singular coarse
    operators (measured in docs/condensed.md).
    """
    bs = V.dofmap.index_map_bs
    nloc = V.dofmap.index_map.size_local
    comm = V.mesh.comm
    x = V.tabulate_dof_coordinates()[:nloc, :2]
    blocks = body_blocks(V, np.concatenate([scene.body_cells(b) for b in scene.bodies]))
    blocks = blocks[blocks < nloc]
    # Rotate about the centroid: keeps the rotation well scaled against the translations.
    centre = np.array([comm.allreduce(float(x[blocks, d].sum())) for d in (0, 1)])
    centre /= max(comm.allreduce(len(blocks)), 1)
    values = rigid_modes_at(x[blocks], centre, 1.0)  # (n, 2, 3)
    # Axisymmetric: the axial translation is the only rigid mode.
    kept = (1,) if scene.model is Model.AXISYMMETRIC else (0, 1, 2)
    modes: list[PETSc.Vec] = []
    for k in kept:
        v = PETSc.Vec().createMPI((nloc * bs, PETSc.DETERMINE), bsize=bs, comm=comm)
        v.set(0.0)
        v.array[bs * blocks] = values[:, 0, k]
        v.array[bs * blocks + 1] = values[:, 1, k]
        modes.append(v)
    orthonormalize(modes)
    return modes


def rigid_modes_at(x: np.ndarray, centre: np.ndarray, size: float) -> np.ndarray:
    """(n, 2, 3): the x/y values of the translations and the scaled rotation at points x."""
    r = (x - centre) / size
    out = np.zeros((len(x), 2, 3))
    out[:, 0, 0] = 1.0
    out[:, 1, 1] = 1.0
    out[:, 0, 2] = -r[:, 1]
    out[:, 1, 2] = r[:, 0]
    return out


def _body_frames(
    scene: Scene, V: fem.FunctionSpace
) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """Owned blocks of each body, and each body's centroid and size (global)."""
    comm = scene.comm
    nloc = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:nloc, :2]
    owned, centres, sizes = [], [], []
    for body in scene.bodies:
        b = body_blocks(V, scene.body_cells(body))
        b = b[b < nloc]
        owned.append(b)
        n = comm.allreduce(len(b))
        c = np.array([comm.allreduce(float(x[b, d].sum())) for d in (0, 1)]) / max(n, 1)
        lo = np.array(
            [comm.allreduce(float(x[b, d].min(initial=np.inf)), op=MPI.MIN) for d in (0, 1)]
        )
        hi = np.array(
            [comm.allreduce(float(x[b, d].max(initial=-np.inf)), op=MPI.MAX) for d in (0, 1)]
        )
        centres.append(c)
        sizes.append(max(float(np.max(hi - lo)), 1e-300))
    return owned, np.array(centres), np.array(sizes)


def _dirichlet_rows(
    scene: Scene,
    V: fem.FunctionSpace,
    bc_dofs: np.ndarray,
    owned: list[np.ndarray],
    centres: np.ndarray,
    sizes: np.ndarray,
) -> np.ndarray:
    """One row per owned Dirichlet dof (all ranks' rows gathered): the modes it fixes."""
    nloc = V.dofmap.index_map.size_local
    x = V.tabulate_dof_coordinates()[:nloc, :2]
    nb = len(scene.bodies)
    dofs = bc_dofs[bc_dofs < 2 * nloc]
    rows = []
    for k, b in enumerate(owned):
        here = dofs[np.isin(dofs // 2, b)]
        if not here.size:
            continue
        m = rigid_modes_at(x[here // 2], centres[k], sizes[k])
        r = np.zeros((len(here), 3 * nb))
        r[:, 3 * k : 3 * k + 3] = m[np.arange(len(here)), here % 2]
        rows.append(r)
    local = np.vstack(rows) if rows else np.zeros((0, 3 * nb))
    return np.vstack(scene.comm.allgather(local))


def _free_modes(rows: np.ndarray, ncols: int) -> np.ndarray:
    """Orthonormal basis (k, ncols) of the modes that every row leaves free."""
    if rows.shape[0] == 0:
        return np.eye(ncols)
    # Duplicate rows (many nodes of one straight edge) add nothing: an SVD of the Gram
    # matrix keeps this cheap however many rows there are.
    gram = rows.T @ rows
    w, v = np.linalg.eigh(gram)
    return v[:, w <= 1e-10 * max(float(w.max()), 1e-300)].T


def _free_motions(part: np.ndarray) -> str:
    """The rigid motions of one body that its part (k, 3) of the free modes spans."""
    _, sv, vt = np.linalg.svd(part, full_matrices=False)
    span = vt[sv > 1e-6 * max(float(sv.max(initial=0.0)), 1e-300)]
    axes = ("translation along x", "translation along y", "rotation")
    names = [
        name for name, e in zip(axes, np.eye(3), strict=True) if np.linalg.norm(span @ e) > 0.999
    ]
    return ", ".join(names) if names else _describe(span[0])


def _describe(mode: np.ndarray) -> str:
    if abs(mode[2]) >= np.hypot(mode[0], mode[1]):
        return "rotation"
    d = mode[:2] / np.hypot(mode[0], mode[1])
    if abs(d[0]) > 0.999:
        return "translation along x"
    if abs(d[1]) > 0.999:
        return "translation along y"
    return f"translation along ({d[0]:.3g}, {d[1]:.3g})"


@dataclass(frozen=True)
class Holding:
    """The bodies' rigid frames and the conditions their supports put on the rigid modes.

    Column 3 k + m of a row is mode m of body k; `dirichlet` holds one row per Dirichlet
    dof (gathered from every rank). Contact rows come from `contact_rows`.
    """

    bodies: tuple[Body, ...]
    centres: np.ndarray  # (nb, 2)
    sizes: np.ndarray  # (nb,)
    dirichlet: np.ndarray  # (k, 3 nb)

    def index(self, body: Body | None) -> int:
        """Column block of `body`; -1 for a rigid obstacle (None: fixed, no modes of its own)."""
        if body is None:
            return -1
        return next(k for k, b in enumerate(self.bodies) if b.name == body.name)

    def contact_rows(
        self, x: np.ndarray, n: np.ndarray, active: np.ndarray, passive: np.ndarray
    ) -> np.ndarray:
        """Rows n . (m_active - m_passive) at points x with normals n (bilateral contact).

        `active`, `passive`: the body index of each point's two sides (-1: a rigid obstacle,
        which holds like a fixed body).
        """
        nb = len(self.bodies)
        rows = np.zeros((len(x), 3 * nb))
        for k in range(nb):
            for side, sign in ((active, 1.0), (passive, -1.0)):
                sel = np.flatnonzero(side == k)
                if sel.size:
                    m = rigid_modes_at(x[sel], self.centres[k], self.sizes[k])
                    cols = slice(3 * k, 3 * k + 3)
                    rows[sel, cols] += sign * np.einsum("nd,ndm->nm", n[sel], m)
        return rows

    def free_modes(self, contact: np.ndarray | None = None) -> np.ndarray:
        """Orthonormal basis of the modes the supports (and `contact` rows) leave free."""
        rows = self.dirichlet if contact is None else np.vstack([self.dirichlet, contact])
        return _free_modes(rows, 3 * len(self.bodies))

    def loose(self, free: np.ndarray) -> list[int]:
        """Indices of the bodies that take part in a free mode."""
        return [
            k
            for k in range(len(self.bodies))
            if free.size and np.abs(free[:, 3 * k : 3 * k + 3]).max() > 1e-6
        ]

    def needs_contact(self) -> list[Body]:
        """The bodies whose supports alone leave a rigid mode free."""
        return [self.bodies[k] for k in self.loose(self.free_modes())]

    def describe(self, free: np.ndarray, k: int) -> str:
        """The free motion of body k (its largest part in the free modes)."""
        part = free[:, 3 * k : 3 * k + 3]
        return _describe(free[int(np.argmax(np.linalg.norm(part, axis=1))), 3 * k : 3 * k + 3])


def holding(scene: Scene, V: fem.FunctionSpace, bc_dofs: np.ndarray) -> Holding:
    """The rigid frames of the scene's bodies and the rows of their Dirichlet conditions."""
    owned, centres, sizes = _body_frames(scene, V)
    rows_d = _dirichlet_rows(scene, V, bc_dofs, owned, centres, sizes)
    if scene.model is Model.AXISYMMETRIC:
        nb = len(scene.bodies)
        fixed = np.eye(3 * nb)[[3 * k + m for k in range(nb) for m in (0, 2)]]
        rows_d = np.vstack([rows_d, fixed])
    return Holding(tuple(scene.bodies), centres, sizes, rows_d)


def check_held(
    scene: Scene,
    V: fem.FunctionSpace,
    bc_dofs: np.ndarray,
    pairs: list[Contact],
    hold: Holding | None = None,
) -> list[Body]:
    """Raise SingularSystemError if a body can move freely; return those needing contact.

    Contacts count as bilateral here (the most they can hold); whether the converged
    active set still holds every body is checked after the loop (setup.check_held_by).
    """
    hold = hold or holding(scene, V, bc_dofs)
    rows = []
    for active_body, passive_body, active in pairs:
        surf = active.surface
        a = np.full(surf.n_nodes, hold.index(active_body))
        q = np.full(surf.n_nodes, hold.index(passive_body))
        rows.append(hold.contact_rows(surf.x, nodal_normals(surf), a, q))
    free = hold.free_modes(np.vstack(rows))
    if free.shape[0]:
        # The free space, not one basis vector of it: eigh's basis of a degenerate null
        # space is arbitrary (it changed with the LAPACK build), and so was the body named.
        k = hold.loose(free)[0]
        raise SingularSystemError(
            f"body '{scene.bodies[k].name}' can still move freely after its supports and "
            f"contacts ({_free_motions(free[:, 3 * k : 3 * k + 3])}): add a support "
            "([[dirichlet]] in a scene file, Dirichlet in Python) or a contact pair that holds it"
        )
    return hold.needs_contact()
