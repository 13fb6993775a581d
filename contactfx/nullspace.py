"""Rigid-body modes of each body: the near-nullspace that GAMG needs for elasticity."""

from __future__ import annotations

import numpy as np
from dolfinx import fem
from petsc4py import PETSc

from .scenes import Scene
from .supports import body_blocks


def rigid_body_modes(V: fem.FunctionSpace, scene: Scene) -> list[PETSc.Vec]:
    """Three modes per body (x and y translation, rotation), each zero outside its body.

    The vectors are orthonormalized: they span the kernel of each body's unconstrained
    stiffness matrix separately, which is what aggregation multigrid must interpolate exactly.
    """
    imap = V.dofmap.index_map
    bs = V.dofmap.index_map_bs
    nloc = imap.size_local
    comm = V.mesh.comm
    x = V.tabulate_dof_coordinates()[:nloc, :2]
    modes: list[PETSc.Vec] = []
    for body in scene.bodies:
        blocks = body_blocks(scene, V, body)
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
    """The rigid-body modes of every body as a PETSc near-nullspace (for GAMG)."""
    modes = rigid_body_modes(V, scene)
    nsp = PETSc.NullSpace().create(vectors=modes, comm=V.mesh.comm)
    for v in modes:
        v.destroy()
    return nsp
