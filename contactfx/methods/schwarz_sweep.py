"""One Dirichlet-Neumann sweep of the Schwarz method: the two body solves and their data."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import numpy as np
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

if TYPE_CHECKING:
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

from ..contact import ContactOperator
from ..discretize.coupling import Multipliers
from ..discretize.elasticity import Elasticity
from ..discretize.supports import body_blocks
from ..discretize.surfaces import GatheredSurface
from ..errors import MeshError, SolverError
from ..scenes import Body, ContactPair, Scene


@dataclass(frozen=True)
class Roles:
    """Which body takes Neumann (1) and which Dirichlet (2) data, and their surfaces."""

    pair: ContactPair
    body_a: Body  # the pair's active and passive bodies
    body_p: Body
    surf_act: GatheredSurface
    surf_pas: GatheredSurface
    dirichlet: Body
    surf1: GatheredSurface  # the Neumann body's contact surface
    surf2: GatheredSurface  # the Dirichlet body's contact surface
    bodies: tuple[Body, Body]  # (Neumann, Dirichlet)


@dataclass(frozen=True)
class Transfer:
    """The mortar transfer (slave: the Dirichlet body) and the reported operator."""

    keep: np.ndarray  # slave rows with overlap
    D: sp.csc_matrix
    M: sp.csr_matrix
    D_lu: spla.SuperLU
    wgap: np.ndarray  # weighted initial gap D y2 - M y1
    op: ContactOperator  # the pair's own mortar operator (active side), for the report
    layout: Multipliers
    order: np.ndarray


class BodySolver:
    """One body's block of K, factorized once by MUMPS, solved on full-size vectors."""

    def __init__(self, K: PETSc.Mat, dofs: PETSc.IS, dirichlet: np.ndarray | None) -> None:
        self.dofs = dofs
        self.A = K.createSubMatrix(dofs, dofs)
        if dirichlet is not None:
            # Collective: every rank calls it, with its own (possibly empty) rows.
            # The stub asks for a Sequence; petsc4py takes an integer array.
            self.A.zeroRowsColumns(dirichlet.astype(PETSc.IntType), diag=1.0)  # type: ignore[arg-type]
        self.ksp = PETSc.KSP().create(K.getComm())
        self.ksp.setOperators(self.A)
        self.ksp.setType("preonly")
        pc = self.ksp.getPC()
        pc.setType("lu")
        pc.setFactorSolverType("mumps")
        self.ksp.setUp()
        self.x = self.A.createVecRight()

    def solve(self, rhs: PETSc.Vec, out: PETSc.Vec) -> None:
        """Solve with this body's part of the full vector `rhs`; write it into `out`."""
        b = rhs.getSubVector(self.dofs)
        self.ksp.solve(b, self.x)
        rhs.restoreSubVector(self.dofs, b)
        reason = cast(int, self.ksp.getConvergedReason())  # an int; the stub says the enum class
        if reason <= 0 or not np.isfinite(self.x.norm()):
            raise SolverError(f"body solve (MUMPS) failed: PETSc reason {reason}")
        o = out.getSubVector(self.dofs)
        self.x.copy(o)
        out.restoreSubVector(self.dofs, o)

    def destroy(self) -> None:
        """Free the factorization and the matrix."""
        for obj in (self.ksp, self.A, self.x):
            obj.destroy()


class OwnedNodes:
    """The nodes of a gathered surface owned by this rank, and their local unrolled dofs."""

    def __init__(self, gs: GatheredSurface, V: fem.FunctionSpace) -> None:
        comm = V.mesh.comm
        start = V.dofmap.index_map.local_range[0]
        self.comm = comm
        self.n = gs.surface.n_nodes
        self.mine = np.flatnonzero(gs.owner == comm.rank)
        self.block = (gs.gblock[self.mine] - start).astype(np.int64)

    def read(self, arr: np.ndarray, comp: int = 1) -> np.ndarray:
        """Component `comp` at every surface node, replicated on all ranks."""
        out = np.zeros(self.n)
        out[self.mine] = arr[2 * self.block + comp]
        # Each node has one owner, so the sum is exact and the same on every rank.
        self.comm.Allreduce(MPI.IN_PLACE, out, op=MPI.SUM)
        return out

    def dofs(self, nodes: np.ndarray, comp: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """(positions among `nodes` owned here, their local unrolled dofs of component comp)."""
        owned = np.isin(nodes, self.mine)
        idx = np.searchsorted(self.mine, nodes[owned])
        return np.flatnonzero(owned), 2 * self.block[idx] + comp


def body_dofs(el: Elasticity, scene: Scene, body: Body) -> np.ndarray:
    """Owned local unrolled dofs (both components) of `body`."""
    V = el.V
    nloc = V.dofmap.index_map.size_local
    blocks = body_blocks(V, scene.body_cells(body))
    blocks = blocks[blocks < nloc].astype(np.int64)
    return np.sort(np.concatenate([2 * blocks, 2 * blocks + 1]))


def _owned_global(V: fem.FunctionSpace, local: np.ndarray) -> np.ndarray:
    return (local + 2 * V.dofmap.index_map.local_range[0]).astype(PETSc.IntType)


class Sweep:
    """One Dirichlet-Neumann sweep: B2 with prescribed interface u_y, B1 with its reaction.

    Each body's block of K is factorized once (MUMPS); a sweep is two back-substitutions.
    """

    def __init__(
        self, scene: Scene, el: Elasticity, r: Roles, tr: Transfer, u: fem.Function
    ) -> None:
        comm, V = scene.comm, el.V
        self.el, self.tr, self.comm = el, tr, comm
        self.nodes1, self.nodes2 = OwnedNodes(r.surf1, V), OwnedNodes(r.surf2, V)
        dofs = [body_dofs(el, scene, b) for b in r.bodies]
        if comm.allreduce(int(np.intersect1d(dofs[0], dofs[1]).size)):
            raise MeshError(
                f"bodies '{r.bodies[0].name}' and '{r.bodies[1].name}' share nodes: contact "
                "needs duplicated interface nodes"
            )
        self.pos_d, self.dof_d = self.nodes2.dofs(tr.keep)  # B2 Dirichlet dofs (u_y), owned
        self.pos_n, self.dof_n = self.nodes1.dofs(np.arange(self.nodes1.n))  # B1 Neumann dofs
        self.uvec = u.x.petsc_vec
        self.rhs, self.tmp = el.f.duplicate(), el.f.duplicate()
        # The stub asks for a Sequence; petsc4py takes an integer array.
        self.iss = [
            PETSc.IS().createGeneral(_owned_global(V, d), comm=comm)  # type: ignore[arg-type]
            for d in dofs
        ]
        # Where B2's Dirichlet dofs sit in its own block's numbering.
        tmp = self.tmp
        tmp.set(0.0)
        tmp.array[self.dof_d] = 1.0
        sub = tmp.getSubVector(self.iss[1])
        rows2 = np.flatnonzero(sub.array_r == 1.0) + sub.getOwnershipRange()[0]
        tmp.restoreSubVector(self.iss[1], sub)
        self.solver1 = BodySolver(el.K, self.iss[0], None)
        self.solver2 = BodySolver(el.K, self.iss[1], rows2)

    def step(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(mortar traction on B2, B1's interface u_y) after prescribing u_y = d on B2."""
        el, tr, rhs, tmp, f = self.el, self.tr, self.rhs, self.tmp, self.el.f
        # B2, Dirichlet: lift the prescribed u_y into the right-hand side.
        tmp.set(0.0)
        tmp.array[self.dof_d] = d[self.pos_d]
        el.K.mult(tmp, rhs)
        rhs.aypx(-1.0, f)
        rhs.array[self.dof_d] = d[self.pos_d]
        self.solver2.solve(rhs, self.uvec)
        # Reaction of B1 on B2 at the interface, then the mortar traction.
        el.K.mult(self.uvec, tmp)
        tmp.axpy(-1.0, f)
        lam = tr.D_lu.solve(self.nodes2.read(tmp.array_r)[tr.keep])
        # B1, Neumann: the opposite force, spread by M^T onto B1's nodes.
        force1 = -(tr.M.T @ lam)
        f.copy(rhs)
        rhs.array[self.dof_n] += force1[self.pos_n]
        self.solver1.solve(rhs, self.uvec)
        return lam, self.nodes1.read(self.uvec.array_r)

    def destroy(self) -> None:
        """Free the factorizations and work vectors."""
        self.solver1.destroy()
        self.solver2.destroy()
        for obj in (*self.iss, self.rhs, self.tmp):
            obj.destroy()
