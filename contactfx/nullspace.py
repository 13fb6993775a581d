"""The rigid-body modes of all bodies: the near-nullspace GAMG needs for elasticity."""

from __future__ import annotations

import numpy as np
from dolfinx import fem
from petsc4py import PETSc

from .scenes import Scene
from .supports import body_blocks, rigid_modes_at


def rigid_body_modes(V: fem.FunctionSpace, scene: Scene) -> list[PETSc.Vec]:
    """The three rigid modes of all bodies together (x, y translation, rotation), orthonormal.

    What aggregation multigrid wants as near-nullspace: an aggregate lies in one body (or
    straddles a contact the condensation couples), so per-body copies of the modes would only
    add zero columns to its tentative prolongator, which GAMG turns into singular coarse
    operators (measured in docs/condensed.md).
    """
    bs = V.dofmap.index_map_bs
    nloc = V.dofmap.index_map.size_local
    comm = V.mesh.comm
    x = V.tabulate_dof_coordinates()[:nloc, :2]
    blocks = np.unique(np.concatenate([body_blocks(scene, V, b) for b in scene.bodies]))
    blocks = blocks[blocks < nloc]
    # Rotate about the centroid: keeps the rotation well scaled against the translations.
    centre = np.array([comm.allreduce(float(x[blocks, d].sum())) for d in (0, 1)])
    centre /= max(comm.allreduce(len(blocks)), 1)
    values = rigid_modes_at(x[blocks], centre, 1.0)  # (n, 2, 3)
    modes: list[PETSc.Vec] = []
    for k in range(3):
        v = PETSc.Vec().createMPI((nloc * bs, PETSc.DETERMINE), bsize=bs, comm=comm)
        v.set(0.0)
        v.array[bs * blocks] = values[:, 0, k]
        v.array[bs * blocks + 1] = values[:, 1, k]
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
    modes = rigid_body_modes(V, scene)
    nsp = PETSc.NullSpace().create(vectors=modes, comm=V.mesh.comm)
    for v in modes:
        v.destroy()
    return nsp
