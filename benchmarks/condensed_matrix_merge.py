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

The two matrices are compared (same pattern; the values relative to max |K|'s row sum): row
by row below 3e7 entries a rank, else by their entry counts and products with a random
vector (to keep one matrix at a time in memory beside K).

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

from contactfx.linalg import elimination
from contactfx.linalg.elimination import PivotRows, condensed_matrix, coupling

PARTS = ["coupling", "_to_owners", "add_entries", "decouple", "assemble_blocks"]
SPENT: dict[str, list[float]] = {}


def _timing(name: str) -> None:
    """Replace elimination.<name> by a wrapper adding its seconds to SPENT[name][-1]."""
    f = getattr(elimination, name)

    def wrapped(*args: Any, **kwargs: Any) -> Any:
        t = time.perf_counter()
        out = f(*args, **kwargs)
        SPENT[name][-1] += time.perf_counter() - t
        return out

    setattr(elimination, name, wrapped)


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
    cols_l, ok_l = [], []  # per node: 9 neighbours x 2 DOFs
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            ok = (ix + dx >= 0) & (ix + dx < nx) & (iy + dy >= 0) & (iy + dy < ny)
            nb = (iy + dy) * nx + ix + dx
            for comp in (0, 1):
                cols_l.append(2 * nb + comp)
                ok_l.append(ok)
    node_cols = np.stack(cols_l, axis=1).astype(PETSc.IntType)  # sorted in each row
    node_ok = np.stack(ok_l, axis=1)
    del cols_l, ok_l
    counts = np.repeat(node_ok.sum(axis=1), 2)  # both DOFs of a node: the same columns
    ptr = np.concatenate([[0], np.cumsum(counts)]).astype(PETSc.IntType)
    cols = node_cols[node_ok]
    node_ptr = np.concatenate([[0], np.cumsum(node_ok.sum(axis=1))])
    del node_cols, node_ok
    # Row 2k and 2k + 1 repeat node k's columns.
    seg = np.repeat(node_ptr[:-1], 2)
    cols = cols[_segment_positions(seg, counts)]
    rows = np.repeat(np.arange(2 * n0, 2 * (n0 + per[comm.rank]), dtype=PETSc.IntType), counts)
    vals = -1.0 - 0.1 * ((rows.astype(np.int64) + cols) % 7)  # symmetric
    vals[rows == cols] = 40.0
    del rows
    csr: Any = (ptr, cols, vals)
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


KEEP: list[Any] = []  # the scene and the setup: K's communicator lives with the mesh


def hertz_problem(
    refine: float, h_far: float, comm: MPI.Comm
) -> tuple[PETSc.Mat, PivotRows, np.ndarray, int]:
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
    KEEP.extend([scene, setup])
    return K, pv.e_rows, pv.dofs, K.getSize()[0]


def _segment_positions(starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """start, start + 1, ..., start + length - 1 for each segment, in order."""
    offsets = np.cumsum(lengths) - lengths
    return np.repeat(starts - offsets, lengths) + np.arange(int(lengths.sum()))


def timed(f: Callable[[], PETSc.Mat], comm: MPI.Comm) -> tuple[float, PETSc.Mat]:
    """The slowest rank's seconds of f() (started together)."""
    comm.Barrier()
    t = time.perf_counter()
    A = f()
    dt = time.perf_counter() - t
    return float(comm.allreduce(dt, op=MPI.MAX)), A


def compared(
    old: PETSc.Mat, new: Callable[[], PETSc.Mat], scale: float, full: bool, comm: MPI.Comm
) -> tuple[float, PETSc.Mat, bool, float]:
    """Time new() with `old` destroyed first (one matrix at a time in memory), compared to
    it: (seconds, new matrix, same pattern, max |difference| / scale). full: the local CSR
    rows entry by entry; else the entry counts and the products with a random vector."""
    x = old.createVecRight()
    x.setRandom()
    y = old.createVecLeft()
    old.mult(x, y)
    nz = old.getInfo()["nz_used"]
    rows = old.getValuesCSR() if full else None
    old.destroy()
    seconds, A = timed(new, comm)
    if rows is not None:
        a = A.getValuesCSR()
        pattern = bool(np.array_equal(a[0], rows[0]) and np.array_equal(a[1], rows[1]))
        diff = float(np.abs(a[2] - rows[2]).max(initial=0.0)) / scale if pattern else np.inf
    else:
        pattern = A.getInfo()["nz_used"] == nz
        z = A.createVecLeft()
        A.mult(x, z)
        z.axpy(-1.0, y)
        diff = z.norm(PETSc.NormType.INFINITY) / (scale * x.norm(PETSc.NormType.INFINITY))
        z.destroy()
    for v in (x, y):
        v.destroy()
    return seconds, A, bool(comm.allreduce(pattern, op=MPI.LAND)), comm.allreduce(diff, op=MPI.MAX)


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
    for name in PARTS:
        _timing(name)
        SPENT[name] = []
    full = comm.allreduce(K.getInfo()["nz_used"], op=MPI.MAX) < 3e7
    for _ in range(args.repeat):
        t_csr, rows = timed(lambda: K.getValuesCSR(), comm)  # type: ignore[arg-type,return-value]
        del rows  # one matrix at a time beside K
        t_old, A = timed(lambda: axpy_matrix(K, prows, r0, piv, diag), comm)
        for name in PARTS:
            SPENT[name].append(0.0)
        t_new, B, ok, err = compared(
            A, lambda: condensed_matrix(K, prows, r0, piv, diag), scale, full, comm
        )
        B.destroy()
        old.append(t_old)
        new.append(t_new)
        csr.append(t_csr)
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
        "merge_parts_s": {  # this rank's medians (the merge's total is the slowest rank's)
            k: round(float(np.median(v)), 3) for k, v in SPENT.items()
        },
        "axpy_all": [round(x, 3) for x in old],
        "merge_all": [round(x, 3) for x in new],
        "same_pattern": ok,
        "compared": "entries" if full else "products",
        "max_diff_rel": err,
    }
    if args.problem == "hertz":
        out.update(refine=args.refine, h_far=args.h_far)
    if comm.rank == 0:
        print(json.dumps(out), flush=True)


if __name__ == "__main__":
    main()
