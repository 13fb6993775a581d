"""What DOLFINx itself takes to mesh and assemble a plain tensor grid of the same size.

    OPENBLAS_NUM_THREADS=1 mpirun -n 2 python benchmarks/dolfinx_floor.py [DOFS] [--out F]

A unit square of quadrilaterals with DOFS / 2 nodes (default 10.46M DOFs, the large default
command's count), each rank passing its own strip of cells to `create_mesh` with cells kept
on their rank (what the structured Hertz grid does), then the vector P1 space, the plane
strain elasticity matrix (DOLFINx's create_matrix + assemble_matrix) and one product with
it. No contact, no multigrid: the part of the large command's time that is DOLFINx's own
work, the lower bound of our mesh and assembly phases. Prints one JSON line (seconds, the
slowest rank's) and appends it to F if given. benchmarks/README.md ("The floor") cites it.
"""

from __future__ import annotations

import argparse
import json
import resource
import time

import basix.ufl
import dolfinx_solver  # noqa: F401  (before dolfinx)
import numpy as np
import ufl
from dolfinx import fem
from dolfinx import mesh as dmesh
from dolfinx.fem.petsc import assemble_matrix
from mpi4py import MPI

from contactfx.scenes.gmsh_io import stay_on_rank


def strip(n: int, rank: int, size: int) -> tuple[np.ndarray, np.ndarray]:
    """This rank's cells (global node numbers) and all nodes of an n x n cell grid."""
    lo, hi = rank * n // size, (rank + 1) * n // size  # cell columns
    i, j = np.meshgrid(np.arange(lo, hi), np.arange(n), indexing="ij")
    v0 = (i * (n + 1) + j).ravel()
    cells = np.stack([v0, v0 + n + 1, v0 + 1, v0 + n + 2], axis=1)  # DOLFINx quad order
    nodes = (
        np.arange(lo * (n + 1), (hi + 1) * (n + 1))
        if rank == size - 1
        else np.arange(lo * (n + 1), hi * (n + 1))
    )
    x = np.stack([nodes // (n + 1), nodes % (n + 1)], axis=1) / n
    return cells.astype(np.int64), x


def main() -> None:
    """Time the phases and print them."""
    ap = argparse.ArgumentParser()
    ap.add_argument("dofs", nargs="?", type=float, default=10.46e6)
    ap.add_argument("--out")
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    n = int(np.sqrt(args.dofs / 2) + 0.5) - 1
    t = {}
    comm.Barrier()
    t0 = time.perf_counter()
    cells, x = strip(n, comm.rank, comm.size)
    element = ufl.Mesh(basix.ufl.element("Lagrange", "quadrilateral", 1, shape=(2,)))
    msh = dmesh.create_mesh(comm, cells, element, x, partitioner=stay_on_rank)
    comm.Barrier()
    t["mesh"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    lam, mu = 1.0, 1.0
    eps = ufl.sym(ufl.grad(u))
    sig = 2 * mu * eps + lam * ufl.tr(eps) * ufl.Identity(2)
    a = fem.form(ufl.inner(sig, ufl.sym(ufl.grad(v))) * ufl.dx)
    K = assemble_matrix(a)
    K.assemble()
    comm.Barrier()
    t["assembly"] = time.perf_counter() - t0
    x_, y_ = K.createVecs()
    x_.set(1.0)
    t0 = time.perf_counter()
    K.mult(x_, y_)
    t["matvec"] = time.perf_counter() - t0
    ndofs = V.dofmap.index_map.size_global * 2
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    slow = {k: comm.allreduce(val, op=MPI.MAX) for k, val in t.items()}
    peak_sum = comm.allreduce(peak)
    if comm.rank == 0:
        row = {
            "dofs": ndofs,
            "ranks": comm.size,
            **{f"{k}_s": round(v, 3) for k, v in slow.items()},
            "peak_mb": round(peak_sum),
        }
        print(json.dumps(row))
        if args.out:
            with open(args.out, "a") as f:
                f.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
