"""The condensed matrix K + C: PETSc's MatAXPY (different pattern) against the CSR merge.

`condensed_matrix` (contactfx/linalg/elimination.py) inserts C's entries into a copy of K's
local CSR rows and hands PETSc the diagonal and off-diagonal blocks as they are; the former
way (kept here as `axpy_matrix`) assembled C by coordinates and added K to it with
MatAXPY(DIFFERENT_NONZERO_PATTERN). Both are timed in the same process, alternated, on

- `synthetic`: a 2D-like matrix of N DOFs (a grid of nodes, 2 DOFs each, 9-point
  stencil: 18 entries a row), pivots on one grid column (one DOF a node, an E row of 7
  entries like a dual mortar row), or
- `hertz`: the structured Hertz scene's K (dual mortar, the zone x < a active: the pivots of
  the condensed solver's first set).

The two matrices are compared row by row (same pattern, values to 1e-14 of max |K|).

    OPENBLAS_NUM_THREADS=1 mpirun -n 2 python benchmarks/condensed_matrix_merge.py \
        synthetic --dofs 2.6e6 [--repeat 3]
    OPENBLAS_NUM_THREADS=1 mpirun -n 2 python benchmarks/condensed_matrix_merge.py \
        hertz --refine 0.0096 --h-far 0.096 [--repeat 3]

Prints one JSON line (rank 0): the medians of each way's seconds (the slowest rank's),
their ratio, the parts of the merge, the sizes.
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable
from typing import Any, cast

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contactfx.linalg.elimination import PivotRows, condensed_matrix, coupling


def axpy_matrix(
    K: PETSc.Mat, prows: PivotRows, r0: int, piv: np.ndarray, k_diag: PETSc.Vec
) -> PETSc.Mat:
    """The former condensed_matrix: C by coordinates, then MatAXPY and zeroRowsColumns."""
    comm = K.getComm()
    i, j, v = coupling(K, prows, r0, comm.tompi4py())
    A = PETSc.Mat().create(comm)
    A.setSizes(cast(Any, K.getSizes()))
    A.setType(PETSc.Mat.Type.AIJ)
    A.setPreallocationCOO(cast(Any, i.astype(PETSc.IntType)), cast(Any, j.astype(PETSc.IntType)))
    A.setValuesCOO(cast(Any, v.astype(PETSc.ScalarType)), cast(Any, PETSc.InsertMode.ADD_VALUES))
    A.assemble()
    A.axpy(1.0, K, structure=cast(Any, PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN))
    ip: Any = piv.astype(PETSc.IntType)
    A.zeroRowsColumns(ip, diag=1.0)
    diag = A.getDiagonal()
    diag.setValues(ip, cast(Any, k_diag.getValues(ip)))
    diag.assemble()
    A.setDiagonal(diag)
    diag.destroy()
    A.setBlockSize(2)
    A.setOption(cast(PETSc.Mat.Option, PETSc.Mat.Option.SPD), True)
    return A


def grid_matrix(dofs: float, comm: MPI.Comm) -> tuple[PETSc.Mat, PivotRows, np.ndarray, int]:
    """A symmetric 9-point-stencil matrix on an nx x ny grid (2 DOFs a node, rows by node,
    node = iy nx + ix), the pivots on column ix = nx / 2 (x DOF) with E rows reaching the
    next column's nodes iy - 1 .. iy + 1 (both DOFs): (K, prows, piv, nx)."""
    nx = int(np.sqrt(dofs / 2))
    ny = int(dofs / 2 / nx)
    n = 2 * nx * ny
    nodes = nx * ny
    per = nodes // comm.size + np.array([k < nodes % comm.size for k in range(comm.size)])
    n0 = int(per[: comm.rank].sum())
    node = np.arange(n0, n0 + per[comm.rank], dtype=np.int64)
    ix, iy = node % nx, node // nx
    cols_l, ok_l = [], []
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            ok = (ix + dx >= 0) & (ix + dx < nx) & (iy + dy >= 0) & (iy + dy < ny)
            nb = (iy + dy) * nx + ix + dx
            for comp in (0, 1):
                cols_l.append(2 * nb + comp)
                ok_l.append(ok)
    node_cols = np.stack(cols_l, axis=1)  # (nodes, 18), sorted in each row
    node_ok = np.stack(ok_l, axis=1)
    cols = np.repeat(node_cols, 2, axis=0)  # both DOFs of a node: the same columns
    ok = np.repeat(node_ok, 2, axis=0)
    rows = np.repeat(np.arange(2 * n0, 2 * (n0 + per[comm.rank]), dtype=np.int64), 18).reshape(-1, 18)
    vals = np.where(cols == rows, 40.0, -1.0 - 0.1 * ((rows + cols) % 7))  # symmetric
    ptr = np.concatenate([[0], np.cumsum(ok.sum(axis=1))]).astype(PETSc.IntType)
    csr: Any = (ptr, cols[ok].astype(PETSc.IntType), vals[ok])
    del cols, ok, rows, vals
    m = 2 * int(per[comm.rank])
    K = PETSc.Mat().createAIJ(size=((m, n), (m, n)), csr=csr, comm=comm)
    K.assemble()
    r0 = 2 * n0
    x0 = nx // 2
    mine = node[ix == x0]
    prows: PivotRows = {}
    rng = np.random.default_rng(7 + comm.rank)
    for nd in mine:
        yy = nd // nx
        nbrs = [(yy + d) * nx + x0 + 1 for d in (-1, 0, 1) if 0 <= yy + d < ny]
        c = np.sort(np.concatenate([[2 * nd], *[[2 * b, 2 * b + 1] for b in nbrs]]))
        v = np.where(c == 2 * nd, -1.0, -rng.uniform(0.1, 0.5, len(c)))
        prows[int(2 * nd - r0)] = (c.astype(np.int64), v)
    return K, prows, (2 * mine).astype(np.int64), n


def hertz_problem(refine: float, h_far: float, comm: MPI.Comm) -> tuple[PETSc.Mat, PivotRows, np.ndarray, int]:
    """The structured Hertz scene's K and the pivots of the zone x < a (dual mortar)."""
    from contactfx.contact import Kernel
    from contactfx.discretize.setup import prepare_contact
    from contactfx.linalg.elimination import LocalRows
    from contactfx.linalg.pivots import pivots
    from contactfx.options import Basis
    from contactfx.scenes import HertzParams, hertz
    from contactfx.timers import Timers

    scene = hertz(HertzParams(refine=refine, h_far=h_far, mesh="structured"), comm=comm)
    setup = prepare_contact(scene, Kernel.MORTAR, 1e-8, Timers(), Basis.DUAL)
    K = setup.elasticity.K
    active = setup.layout.x[setup.layout.mine, 0] < scene.params["hertz_exact"]["a"]
    r0 = K.getOwnershipRange()[0]
    pv = pivots(LocalRows.of(setup.B, setup.node_dofs()), active, comm, r0, K.getSize()[0])
    return K, pv.e_rows, pv.dofs, K.getSize()[0]


def timed(f: Callable[[], PETSc.Mat], comm: MPI.Comm) -> tuple[float, PETSc.Mat]:
    """The slowest rank's seconds of f() (started together)."""
    comm.Barrier()
    t = time.perf_counter()
    A = f()
    dt = time.perf_counter() - t
    return float(comm.allreduce(dt, op=MPI.MAX)), A


def same(A: PETSc.Mat, B: PETSc.Mat, scale: float, comm: MPI.Comm) -> tuple[bool, float]:
    """(same local pattern on every rank, max |A - B| / scale)."""
    a, b = A.getValuesCSR(), B.getValuesCSR()
    pattern = bool(np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]))
    diff = float(np.abs(a[2] - b[2]).max()) / scale if pattern else np.inf
    return bool(comm.allreduce(pattern, op=MPI.LAND)), float(comm.allreduce(diff, op=MPI.MAX))


def main() -> None:
    """Build the problem, time both ways alternated, compare them, print JSON."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("problem", choices=["synthetic", "hertz"])
    ap.add_argument("--dofs", type=float, default=2.6e6, help="synthetic: the DOFs")
    ap.add_argument("--refine", type=float, default=0.0096, help="hertz: h at the contact")
    ap.add_argument("--h-far", type=float, default=0.096, help="hertz: h far away")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    t = time.perf_counter()
    if args.problem == "synthetic":
        K, prows, piv, n = grid_matrix(args.dofs, comm)
    else:
        K, prows, piv, n = hertz_problem(args.refine, args.h_far, comm)
    build = time.perf_counter() - t
    r0 = K.getOwnershipRange()[0]
    diag = K.getDiagonal()
    scale = K.norm(PETSc.NormType.INFINITY)
    old: list[float] = []
    new: list[float] = []
    csr: list[float] = []
    ok, err = True, 0.0
    for _ in range(args.repeat):
        t_old, A = timed(lambda: axpy_matrix(K, prows, r0, piv, diag), comm)
        t_new, B = timed(lambda: condensed_matrix(K, prows, r0, piv, diag), comm)
        t_csr, _ = timed(lambda: K.getValuesCSR(), comm)  # type: ignore[arg-type,return-value]
        old.append(t_old)
        new.append(t_new)
        csr.append(t_csr)
        ok, err = same(A, B, scale, comm)
        A.destroy()
        B.destroy()
    n_piv = comm.allreduce(len(piv))
    out = {
        "problem": args.problem,
        "dofs": n,
        "pivots": n_piv,
        "ranks": comm.size,
        "nnz": K.getInfo(PETSc.Mat.InfoType.GLOBAL_SUM)["nz_used"],
        "build_s": round(build, 2),
        "axpy_s": round(float(np.median(old)), 3),
        "merge_s": round(float(np.median(new)), 3),
        "ratio": round(float(np.median(old)) / float(np.median(new)), 2),
        "get_values_csr_s": round(float(np.median(csr)), 3),
        "axpy_all": [round(x, 3) for x in old],
        "merge_all": [round(x, 3) for x in new],
        "same_pattern": ok,
        "max_diff_rel": err,
    }
    if args.problem == "hertz":
        out.update(refine=args.refine, h_far=args.h_far)
    if comm.rank == 0:
        print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
