"""Rigid-body modes: of each body (support checks) and the near-nullspace GAMG needs."""

from __future__ import annotations

import numpy as np
from dolfinx import fem
from petsc4py import PETSc

from .scenes import Scene
from .supports import body_blocks


def rigid_body_modes(V: fem.FunctionSpace, scene: Scene, per_body: bool = True) -> list[PETSc.Vec]:
    """Three modes (x and y translation, rotation) per body, each zero outside its body.

    The vectors are orthonormalized: they span the kernel of each body's unconstrained
    stiffness matrix separately. `per_body=False` gives the three rigid modes of all bodies
    together, which is what aggregation multigrid wants: an aggregate lies in one body (or
    straddles a contact the condensation couples), so per-body copies add only zero columns
    to its tentative prolongator, which GAMG turns into singular coarse operators.
    """
    imap = V.dofmap.index_map
    bs = V.dofmap.index_map_bs
    nloc = imap.size_local
    comm = V.mesh.comm
    x = V.tabulate_dof_coordinates()[:nloc, :2]
    groups = [body_blocks(scene, V, body) for body in scene.bodies]
    if not per_body:
        groups = [np.unique(np.concatenate(groups))]
    modes: list[PETSc.Vec] = []
    for blocks in groups:
        blocks = blocks[blocks < nloc]
        # Rotate about the body's centroid: keeps the rotation mode well scaled against the
        # translations before orthonormalization.
        count = comm.allreduce(len(blocks))
        centre = np.array([comm.allreduce(float(x[blocks, d].sum())) for d in (0, 1)])
        centre /= max(count, 1)
        xb = x[blocks] - centre
        arrays = np.zeros((3, nloc * bs))
        arrays[0, bs * blocks] = 1.0
        arrays[1, bs * blocks + 1] = 1.0
        arrays[2, bs * blocks] = -xb[:, 1]
        arrays[2, bs * blocks + 1] = xb[:, 0]
        for a in arrays:
            v = PETSc.Vec().createMPI((nloc * bs, PETSc.DETERMINE), bsize=bs, comm=comm)
            v.array[:] = a
            modes.append(v)
    orthonormalize(modes)
    return modes


def orthonormalize(vectors: list[PETSc.Vec]) -> None:
    """Modified Gram-Schmidt in place (twice, for round-off)."""
    for _ in range(2):
        for i, v in enumerate(vectors):
            for w in vectors[:i]:
                v.axpy(-v.dot(w), w)
            v.normalize()


def near_nullspace(V: fem.FunctionSpace, scene: Scene) -> PETSc.NullSpace:
    """The rigid-body modes of all bodies together as a PETSc near-nullspace (for GAMG)."""
    modes = rigid_body_modes(V, scene, per_body=False)
    nsp = PETSc.NullSpace().create(vectors=modes, comm=V.mesh.comm)
    for v in modes:
        v.destroy()
    return nsp
