"""Alternating Dirichlet-Neumann (Schwarz) iteration between the two bodies, mortar transfer.

The body held only by contact (D) takes the Dirichlet data: its interface normal
displacement is prescribed, which fixes its rigid motion along the normal, so its subproblem
is well posed whatever the iterate. The body held by its supports (N) takes the Neumann
data: the interface force D exerts on it. The transfer uses the mortar matrices of the pair
(slave D, master N): u2_n = D^-1 (M u1_n - g~) and, for the traction lambda = D^-1 R2 of
B2's reaction R2, the force on B1 is -M^T lambda, so no force is lost across non-matching
meshes. The fixed point satisfies exactly the equations of the mortar Lagrange-multiplier
method with D active (full contact): the iteration is an independent solver for them.

Longer than ~300 lines because the body solvers, the owned-node bookkeeping and the
iteration share one transfer setup; split, each part would need all of it passed in.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import cast

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from .contact import contact_operator
from .contact.mortar import mortar_matrices
from .coupling import multiplier_layout
from .elasticity import Elasticity
from .errors import ConvergenceError, GeometryError, InputError, MeshError, SolverError
from .methods import Method
from .pairs import PairData
from .prepare import assemble_and_gather
from .scenes import Body, Scene
from .solution import Solution
from .supports import body_blocks, check_held
from .surfaces import GatheredSurface
from .timers import Timers

log = logging.getLogger("contactfx")

# Largest angle (as |1 - |n_y||) between a contact-segment normal and the vertical: the
# Dirichlet condition is set on u_y, which is the normal component only on a flat interface.
_FLAT_TOL = 1e-10


@dataclass(frozen=True)
class SchwarzOptions:
    """Controls of the Dirichlet-Neumann iteration."""

    relaxation: float = 0.5  # fixed relaxation, and the first step of Aitken's
    aitken: bool = True  # Aitken's dynamic relaxation after the first iteration
    tol: float = 1e-8  # relative change of interface displacement and traction
    max_iterations: int = 100
    divergence: float = 1e8  # stop early once the residual grew by this factor


class _BodySolver:
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


class _OwnedNodes:
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
    blocks = body_blocks(scene, V, body)
    blocks = blocks[blocks < nloc].astype(np.int64)
    return np.sort(np.concatenate([2 * blocks, 2 * blocks + 1]))


def _owned_global(V: fem.FunctionSpace, local: np.ndarray) -> np.ndarray:
    return (local + 2 * V.dofmap.index_map.local_range[0]).astype(PETSc.IntType)


def _check_flat(s1: GatheredSurface, s2: GatheredSurface) -> None:
    """Raise unless both contact lines are horizontal and face each other."""
    sign = float(np.sign(s1.surface.normals[0, 1]))
    for gs, sg in ((s1, sign), (s2, -sign)):
        ny = gs.surface.normals[:, 1]
        if sg == 0.0 or np.any(np.abs(sg * ny - 1.0) > _FLAT_TOL):
            raise InputError(
                "schwarz supports one straight horizontal contact line in full "
                "contact (it iterates on u_y): use nts, sts or mortar here"
            )


def _norm(D: sp.csr_matrix, v: np.ndarray) -> float:
    """Discrete L2 norm on the interface, sqrt(v^T D v)."""
    return float(np.sqrt(max(v @ (D @ v), 0.0)))


def _failed(history: list[dict[str, float | None]], message: str) -> ConvergenceError:
    """The error to raise, carrying the iteration history (for charts of failed runs)."""
    err = ConvergenceError(message)
    err.history = history
    return err


def solve_schwarz(
    scene: Scene, options: SchwarzOptions = SchwarzOptions(), timers: Timers | None = None
) -> Solution:
    """Solve a two-body full-contact scene by the relaxed Dirichlet-Neumann iteration.

    Body N (held by its supports) takes Neumann data, body D (held only by the contact)
    Dirichlet data; the contact line must be straight, horizontal and closed everywhere.
    """
    if len(scene.bodies) != 2 or len(scene.contacts) != 1:
        raise InputError(
            f"schwarz supports two bodies with one contact pair (this scene has "
            f"{len(scene.bodies)} bodies and {len(scene.contacts)} pairs): use "
            "nts, sts or mortar"
        )
    if not 0.0 < options.relaxation <= 2.0:
        raise InputError(f"relaxation must lie in (0, 2] (got {options.relaxation})")
    timers = timers or Timers()
    comm = scene.mesh.comm
    el, ndofs, gathered = assemble_and_gather(scene, timers)
    V = el.V
    pair, body_a, body_p, surf_act, surf_pas = gathered[0]
    loose = check_held(scene, V, el.bc_dofs, [(body_a, body_p, surf_act)])
    if len(loose) != 1:
        raise InputError(
            "schwarz needs one body held by its supports and one held only by "
            f"the contact ({'both are' if loose else 'neither is'} free): use "
            "nts, sts or mortar"
        )
    dirichlet_body = loose[0]
    # surf1/surf2: the Neumann and the Dirichlet body's contact surfaces.
    if dirichlet_body == body_a:
        surf1, surf2, bodies = surf_pas, surf_act, (body_p, body_a)
    else:
        surf1, surf2, bodies = surf_act, surf_pas, (body_a, body_p)
    _check_flat(surf1, surf2)
    with timers("contact"):
        # Transfer pair: D (the Dirichlet body) is the mortar slave, whatever the active side.
        op2 = contact_operator(Method.MORTAR.operator, surf2.surface, surf1.surface, ndofs)
        D_all, M_all = mortar_matrices(surf2.surface, surf1.surface)
        keep = np.flatnonzero(op2.weights > 1e-12 * max(float(op2.weights.max(initial=0)), 1e-300))
        if keep.size == 0:
            raise GeometryError(
                f"the contact surfaces '{pair.active}' and '{pair.passive}' do not overlap"
            )
        D = D_all[keep][:, keep].tocsc()
        M = M_all[keep].tocsr()
        D_lu = spla.splu(D)
        y1, y2 = surf1.surface.x[:, 1], surf2.surface.x[:, 1]
        wgap = D @ y2[keep] - M @ y1
        h = float(np.median(op2.weights[keep]))
        if np.max(np.abs(wgap / op2.weights[keep])) > 1e-6 * h:
            raise InputError(
                "schwarz supports full-contact scenes only: the bodies do not "
                "touch along the whole contact line (non-zero initial gap)"
            )
        # The reported multipliers live on the pair's active body, as for the other methods.
        if dirichlet_body == body_a:
            surf_a, op = surf2, op2
        else:
            surf_a = surf1
            op = contact_operator(Method.MORTAR.operator, surf1.surface, surf2.surface, ndofs)
        layout, order = multiplier_layout(comm, surf_a, op)

    nodes1, nodes2 = _OwnedNodes(surf1, V), _OwnedNodes(surf2, V)
    dofs = [body_dofs(el, scene, b) for b in bodies]
    if comm.allreduce(int(np.intersect1d(dofs[0], dofs[1]).size)):
        raise MeshError(
            f"bodies '{bodies[0].name}' and '{bodies[1].name}' share nodes: contact "
            "needs duplicated interface nodes"
        )
    pos_d, dof_d = nodes2.dofs(keep)  # B2 Dirichlet dofs (u_y), owned here
    pos_n, dof_n = nodes1.dofs(np.arange(nodes1.n))  # B1 Neumann dofs (f_y), owned here

    u = fem.Function(V, name="u")
    uvec = u.x.petsc_vec
    f = el.f
    rhs, tmp = f.duplicate(), f.duplicate()
    history: list[dict[str, float | None]] = []
    # The stub asks for a Sequence; petsc4py takes an integer array.
    iss = [PETSc.IS().createGeneral(_owned_global(V, d), comm=comm) for d in dofs]  # type: ignore[arg-type]
    t_solve = time.perf_counter()
    with timers("solve"), timers("factorize"):
        # Where B2's Dirichlet dofs sit in its own block's numbering.
        tmp.set(0.0)
        tmp.array[dof_d] = 1.0
        sub = tmp.getSubVector(iss[1])
        rows2 = np.flatnonzero(sub.array_r == 1.0) + sub.getOwnershipRange()[0]
        tmp.restoreSubVector(iss[1], sub)
        solver1 = _BodySolver(el.K, iss[0], None)
        solver2 = _BodySolver(el.K, iss[1], rows2)
    d = np.zeros(keep.size)  # B2's interface u_y, the iterated quantity
    lam_prev = None
    r_prev, omega = None, options.relaxation
    r_first = None
    try:
        for it in range(1, options.max_iterations + 1):
            t0 = time.perf_counter()
            with timers("solve"):
                # B2, Dirichlet: lift the prescribed u_y into the right-hand side.
                tmp.set(0.0)
                tmp.array[dof_d] = d[pos_d]
                el.K.mult(tmp, rhs)
                rhs.aypx(-1.0, f)
                rhs.array[dof_d] = d[pos_d]
                solver2.solve(rhs, uvec)
                # Reaction of B1 on B2 at the interface, then the mortar traction.
                el.K.mult(uvec, tmp)
                tmp.axpy(-1.0, f)
                R2 = nodes2.read(tmp.array_r)[keep]
                lam = D_lu.solve(R2)
                # B1, Neumann: the opposite force, spread by M^T onto B1's nodes.
                force1 = -(M.T @ lam)
                f.copy(rhs)
                rhs.array[dof_n] += force1[pos_n]
                solver1.solve(rhs, uvec)
                u1 = nodes1.read(uvec.array_r)
            target = D_lu.solve(M @ u1 - wgap)
            r = target - d
            e_u = _norm(D, r) / max(_norm(D, target), 1e-300)
            e_t = (
                np.inf
                if lam_prev is None
                else _norm(D, lam - lam_prev) / max(_norm(D, lam), 1e-300)
            )
            if it > 1 and options.aitken:
                dr = r - r_prev
                omega = -omega * float(r_prev @ (D @ dr)) / max(float(dr @ (D @ dr)), 1e-300)
            history.append(
                {
                    "iteration": it,
                    "residual": e_u,
                    "traction_change": None if lam_prev is None else e_t,
                    "relaxation": omega,
                    "solve_time": time.perf_counter() - t0,
                }
            )
            if comm.rank == 0:
                log.info(
                    "schwarz %3d: interface residual %.3e, traction change %.3e, relaxation %.4f",
                    it,
                    e_u,
                    e_t,
                    omega,
                )
            r_abs = _norm(D, r)
            r_first = r_first or max(r_abs, 1e-300)
            if max(e_u, e_t) < options.tol:
                break
            if not np.isfinite(r_abs) or r_abs > options.divergence * r_first:
                raise _failed(
                    history,
                    f"schwarz iteration diverged at iteration {it}: "
                    f"interface residual grew by {r_abs / r_first:.1e} (relaxation "
                    f"{omega:.3g}, Aitken {'on' if options.aitken else 'off'})",
                )
            d = d + omega * r
            r_prev, lam_prev = r, lam
        else:
            raise _failed(
                history,
                f"schwarz iteration did not converge in "
                f"{options.max_iterations} iterations: interface residual {e_u:.2e}, "
                f"traction change {e_t:.2e} > tol {options.tol:.0e} (relaxation "
                f"{omega:.3g}, Aitken {'on' if options.aitken else 'off'})",
            )
    finally:
        solver1.destroy()
        solver2.destroy()
        for obj in (*iss, rhs, tmp):
            obj.destroy()
    u.x.scatter_forward()
    if comm.rank == 0:
        log.info(
            "schwarz converged in %d iterations, %.3f s",
            len(history),
            time.perf_counter() - t_solve,
        )

    lam2 = np.zeros(surf2.surface.n_nodes)
    lam2[keep] = lam
    if dirichlet_body == body_a:
        pressure = lam2[order]
    else:
        # Same force on B1's nodes, expressed as the traction of B1's own mortar multipliers.
        Da, _ = mortar_matrices(surf1.surface, surf2.surface)
        force = M.T @ lam
        pressure = spla.spsolve(Da[order][:, order].tocsc(), force[order])
        pressure = np.atleast_1d(pressure)
    if np.any(pressure < -1e-8 * np.abs(pressure).max(initial=0.0)) and comm.rank == 0:
        log.warning(
            "schwarz: tensile contact traction (min %.3g MPa): the full-contact "
            "assumption does not hold for this scene",
            pressure.min(),
        )
    # Gap at the solution through the reported operator (both components of both surfaces).
    ufull = np.zeros(ndofs)
    for gs, nodes in ((surf1, nodes1), (surf2, nodes2)):
        for comp in (0, 1):
            ufull[gs.surface.dofs[:, comp]] = nodes.read(u.x.array, comp)
    gap = (op.gap + op.B @ ufull)[order] / layout.weights
    pd = PairData(0, pair, body_a, body_p, surf_act, surf_pas, op, 0)
    return Solution(
        scene,
        Method.SCHWARZ,
        el,
        u,
        layout,
        pressure=pressure,
        gap=gap,
        active=np.ones(layout.size, dtype=bool),
        operator=op,
        order=order,
        pairs=[pd],
        iterations=len(history),
        history=history,
        timers=timers,
        info={
            "schwarz": {
                "dirichlet_body": dirichlet_body.name,
                "solver": "mumps (each body factorized once)",
            }
        },
    )
