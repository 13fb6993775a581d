"""Near-nullspaces for PETSc's algebraic multigrid from given vectors (the rigid modes)."""

from __future__ import annotations

from petsc4py import PETSc


def orthonormalize(vectors: list[PETSc.Vec]) -> None:
    """Modified Gram-Schmidt in place (twice, for round-off)."""
    for _ in range(2):
        for i, v in enumerate(vectors):
            for w in vectors[:i]:
                v.axpy(-v.dot(w), w)
            v.normalize()


def near_nullspace(modes: list[PETSc.Vec]) -> PETSc.NullSpace:
    """The vectors `modes` (orthonormal) as a PETSc near-nullspace for GAMG."""
    return PETSc.NullSpace().create(vectors=modes, comm=modes[0].getComm())
