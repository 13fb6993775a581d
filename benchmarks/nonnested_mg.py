"""A geometric multigrid on gmsh meshes, measured before it is built (serial prototype).

The gmsh Hertz family keeps GAMG (12-15 CG iterations from 100k to 2M DOFs, +25 %): its mesh
has no nested coarser grids. Here the coarser grids are the same scene meshed again with
every size x2, x4, ... (`Scene.remeshed`, down to about 3,000 DOFs), and the prolongation
evaluates a coarse grid's Q1 basis at each finer node: the coarse cell of the same body that
contains it (bounding-box candidates, pulled back), else the nearest one of its body (nodes on
the arc outside the coarser polygon: extrapolated). Dirichlet rows of the finest level are
zero. The condensed solver then runs its PCMG on these levels exactly as on the structured
grid's; one fresh solve of the fixed Hertz zone (dual mortar) to 1e-9, against GAMG
(`condensed-gamg`) on the same system:

    python benchmarks/nonnested_mg.py 100e3 400e3 1e6

Serial only (the point location is a Python loop: seconds per 100k nodes, not timed with the
solves; nor is the remeshing of the coarser grids, printed apart: gmsh's time for them).
docs/scale.md, "Geometric multigrid on the structured grid" cites its output.
"""

from __future__ import annotations

import sys
import time
from typing import Any

import basix
import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)
import numpy as np
import scipy.sparse as sp
from dolfinx import fem, geometry
from mpi4py import MPI
from petsc4py import PETSc

# benchmarks/run.py, next to this script: on sys.path as its folder.
from run import EDGE_RATIO, refine_for

from contactfx.contact import Kernel
from contactfx.discretize.setup import prepare_contact
from contactfx.methods.solvers import setup_solver
from contactfx.options import SOLVERS, Basis
from contactfx.scenes import HertzParams, Scene, hertz
from contactfx.timers import Timers

COMM = MPI.COMM_SELF
COARSEST_DOFS = 3000


def cell_bodies(scene: Scene) -> np.ndarray:
    """The body tag of every cell."""
    cells = scene.mesh.geometry.dofmaps[0]
    body = np.empty(len(cells), dtype=np.int64)
    body[scene.cell_tags.indices] = scene.cell_tags.values
    return body


def node_bodies(scene: Scene) -> np.ndarray:
    """The body tag of every geometry node (the two bodies share no node)."""
    cells = scene.mesh.geometry.dofmaps[0]
    body = np.empty(scene.mesh.geometry.x.shape[0], dtype=np.int64)
    body[cells.ravel()] = np.repeat(cell_bodies(scene), cells.shape[1])
    return body


def prolongation(fine: Scene, coarse: Scene) -> sp.csr_matrix:
    """Scalar Q1 prolongation from the coarse scene's nodes to the fine scene's nodes."""
    xf, body = fine.mesh.geometry.x, node_bodies(fine)
    cm = coarse.mesh
    cmap = cm.geometry.cmaps[0]
    cells, xc = cm.geometry.dofmaps[0], cm.geometry.x
    cbody = cell_bodies(coarse)
    mid = xc[cells].mean(axis=1)
    tree = geometry.bb_tree(cm, cm.topology.dim)
    candidates = geometry.compute_collisions_points(tree, xf)
    q1 = basix.create_element(basix.ElementFamily.P, basix.CellType.quadrilateral, 1)
    rows, cols, vals = [], [], []

    def pulled(i: int, c: int) -> np.ndarray | None:
        try:
            return cmap.pull_back(xf[i : i + 1], xc[cells[c]])
        except RuntimeError:  # Newton did not converge: the point is far outside this cell
            return None

    for i in range(len(xf)):
        found = None
        for c in candidates.links(i):
            X = pulled(i, c) if cbody[c] == body[i] else None
            if X is not None and np.all(X > -1e-10) and np.all(X < 1.0 + 1e-10):
                found = (c, X)
                break
        if found is None:  # outside the coarser polygon: the nearest cell of its body
            same = np.flatnonzero(cbody == body[i])
            c = same[np.argmin(((mid[same] - xf[i]) ** 2).sum(axis=1))]
            X = pulled(i, c)
            if X is None:  # the nearest node of that cell, injected
                k = np.argmin(((xc[cells[c]] - xf[i]) ** 2).sum(axis=1))
                X = np.array([[k % 2, k // 2]], dtype=float)  # Q1 reference vertex k
            found = (c, X)
        c, X = found
        rows += [i] * cells.shape[1]
        cols += list(cells[c])
        vals += list(q1.tabulate(0, X)[0, 0, :, 0])  # basix's Q1 order is the geometry's
    P = sp.csr_matrix((vals, (rows, cols)), shape=(len(xf), len(xc)))
    P.data[np.abs(P.data) < 1e-13] = 0.0
    P.eliminate_zeros()
    return P


def dof_blocks(V: fem.FunctionSpace) -> np.ndarray:
    """The dof block of every geometry node (P1)."""
    msh = V.mesh
    out = np.empty(msh.geometry.x.shape[0], dtype=np.int64)
    out[msh.geometry.dofmaps[0].ravel()] = V.dofmap.list.ravel()
    return out


def vector_prolongation(
    P: sp.csr_matrix, fine: fem.FunctionSpace, coarse: fem.FunctionSpace, fixed: np.ndarray | None
) -> PETSc.Mat:
    """Both displacement components in the spaces' dof numbering; `fixed` rows zero."""
    coo, bf, bc = P.tocoo(), dof_blocks(fine), dof_blocks(coarse)
    r = np.concatenate([2 * bf[coo.row] + k for k in (0, 1)])
    c = np.concatenate([2 * bc[coo.col] + k for k in (0, 1)])
    v = np.concatenate([coo.data, coo.data])
    if fixed is not None:
        v = np.where(fixed[r], 0.0, v)
    M = sp.csr_matrix((v, (r, c)), shape=(2 * P.shape[0], 2 * P.shape[1]))
    M.sort_indices()
    csr: Any = (M.indptr.astype(PETSc.IntType), M.indices.astype(PETSc.IntType), M.data)
    return PETSc.Mat().createAIJ(size=M.shape, csr=csr, comm=PETSc.COMM_SELF)


def run(target: float) -> dict[str, Any]:
    """One size: the levels, then both multigrids on the same fixed set."""
    h = refine_for(target, "gmsh")
    params = HertzParams(refine=h, h_far=10 * h, mesh="gmsh", refine_edge=h / EDGE_RATIO)
    scene = hertz(params, comm=COMM)
    setup = prepare_contact(scene, Kernel.MORTAR, 1e-8, Timers(), Basis.DUAL)
    el = setup.elasticity
    scenes, spaces = [scene], [el.V]
    t0 = time.perf_counter()
    factor = 2.0
    while 2 * scenes[-1].mesh.geometry.x.shape[0] > COARSEST_DOFS:
        coarse = scene.remeshed(factor)
        scenes.append(coarse)
        spaces.append(fem.functionspace(coarse.mesh, ("Lagrange", 1, (2,))))
        factor *= 2.0
    remesh = time.perf_counter() - t0
    fixed = np.zeros(el.K.getSize()[0], dtype=bool)
    for bc in el.bcs:
        fixed[bc.dof_indices()[0]] = True
    t0 = time.perf_counter()
    mats = [
        vector_prolongation(
            prolongation(scenes[k], scenes[k + 1]), spaces[k], spaces[k + 1], None if k else fixed
        )
        for k in range(len(scenes) - 1)
    ]
    out: dict[str, Any] = {
        "dofs": el.K.getSize()[0],
        "levels": [m.getSize()[1] for m in mats],
        "remesh_s": round(remesh, 1),
        "prolongation_s": round(time.perf_counter() - t0, 1),
    }
    zone = setup.layout.x[setup.layout.mine, 0] < scene.params["hertz_exact"]["a"]
    for name in ("condensed", "condensed-gamg"):
        levels = (lambda: [m.copy() for m in mats]) if name == "condensed" else None
        solver = setup_solver(setup, SOLVERS[name], scene, reuse=False, grid=levels)
        t = time.perf_counter()
        res = solver.solve(setup.g, zone)
        out[name] = {"its": res.iterations, "seconds": round(time.perf_counter() - t, 2)}
        solver.destroy()
    for m in mats:
        m.destroy()
    return out


if __name__ == "__main__":
    for arg in sys.argv[1:]:
        print(run(float(arg)), flush=True)
