"""Memory and time of the condensed solver's setup, per phase and per multigrid level.

One process (or `mpirun -n 2`): Hertz on the structured mesh (`--refine H --h-far 10H`),
dual mortar, the zone x < a active (a fixed set). Builds the condensed matrix, sets up the
`condensed` preset's KSP (GAMG + ICC(0)) with the extra PETSc options given, solves once
from zero to 1e-9, and prints the heap bytes in use (glibc's mallinfo2) added by the
condensed matrix and by the setup on this rank, the setup and solve seconds, the CG
iterations and each level's operator, prolongator and ICC factor entries.

    python benchmarks/condensed_memory.py --refine 0.0155 [KEY=VALUE ...]
    PETSC_OPTIONS=-mat_product_clear mpirun -n 2 python benchmarks/condensed_memory.py ...

Unprefixed PETSc options (what GAMG's products read, e.g. mat_product_clear, matptap_via) go
through PETSC_OPTIONS; KEY=VALUE pairs are added to the preset's (prefixed) options.
"""

from __future__ import annotations

import argparse
import ctypes
import time
from typing import Any, cast

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contactfx.contact import Kernel
from contactfx.discretize.setup import prepare_contact
from contactfx.discretize.supports import rigid_body_modes
from contactfx.linalg.elimination import LocalRows, condensed_matrix
from contactfx.linalg.nullspace import orthonormalize
from contactfx.linalg.petsc_options import PrefixedOptions
from contactfx.linalg.pivots import pivots
from contactfx.options import SOLVERS, Basis
from contactfx.scenes import HertzParams, hertz
from contactfx.timers import Timers


class _MallInfo2(ctypes.Structure):
    _fields_ = [
        (name, ctypes.c_size_t)
        for name in (
            "arena", "ordblks", "smblks", "hblks", "hblkhd",
            "usmblks", "fsmblks", "uordblks", "fordblks", "keepcost",
        )
    ]  # fmt: skip


_LIBC = ctypes.CDLL("libc.so.6")
_LIBC.mallinfo2.restype = _MallInfo2


def in_use_mb() -> float:
    """Heap bytes in use (small blocks and mapped ones), MB."""
    info = _LIBC.mallinfo2()
    return (info.uordblks + info.hblkhd) / 2**20


def mat_mb(M: PETSc.Mat) -> tuple[float, float]:
    """(entries, MB) of an AIJ-like matrix: 12 bytes an entry and 4 a row."""
    nz = float(M.getInfo()["nz_allocated"])
    return nz, (nz * 12 + M.getSize()[0] * 4) / 2**20


def main() -> None:
    """Set up and solve once; print the phases' memory and each level (rank 0's view)."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--refine", type=float, default=0.0155, help="h at the contact (cm)")
    ap.add_argument("options", nargs="*", help="extra PETSc options KEY=VALUE")
    args = ap.parse_args()
    extra = dict(item.split("=", 1) for item in args.options)
    comm = MPI.COMM_WORLD
    scene = hertz(HertzParams(refine=args.refine, h_far=10 * args.refine, mesh="structured"))
    setup = prepare_contact(scene, Kernel.MORTAR, 1e-8, Timers(), Basis.DUAL)
    K, f = setup.elasticity.K, setup.elasticity.f
    active = setup.layout.x[setup.layout.mine, 0] < scene.params["hertz_exact"]["a"]
    r0 = K.getOwnershipRange()[0]
    n = K.getSize()[0]
    pv = pivots(LocalRows.of(setup.B, setup.node_dofs()), active, comm, r0, n)
    ip: Any = pv.dofs.astype(PETSc.IntType)
    m0, t0 = in_use_mb(), time.perf_counter()
    A = condensed_matrix(K, pv.e_rows, r0, pv.dofs, K.getDiagonal())
    m1, t1 = in_use_mb(), time.perf_counter()
    modes = rigid_body_modes(setup.elasticity.V, scene)
    for m in modes:
        m.setValues(ip, cast(Any, np.zeros(len(ip))))
        m.assemble()
    orthonormalize(modes)
    A.setNearNullSpace(PETSc.NullSpace().create(vectors=modes, comm=K.getComm()))
    opts = PrefixedOptions({**SOLVERS["condensed"].petsc, **extra})
    ksp = PETSc.KSP().create(K.getComm())
    ksp.setOptionsPrefix(opts.prefix)
    b = f.copy()
    b.setValues(ip, cast(Any, np.zeros(len(ip))))
    b.assemble()
    x = b.duplicate()
    x.set(0.0)
    m2, t2 = in_use_mb(), time.perf_counter()
    with opts.inserted():
        ksp.setOperators(A)
        ksp.setFromOptions()
        ksp.setTolerances(rtol=1e-9)
        ksp.setUp()
        m3, t3 = in_use_mb(), time.perf_counter()
        ksp.solve(b, x)
    t4 = time.perf_counter()
    if comm.rank == 0:
        print(
            f"{n} DOFs, {comm.size} rank(s), options {extra}: condensed matrix {t1 - t0:.2f} s "
            f"+{m1 - m0:.0f} MB; setup {t3 - t2:.2f} s +{m3 - m2:.0f} MB (rank 0); "
            f"solve {t4 - t3:.2f} s, {ksp.getIterationNumber()} CG its",
            flush=True,
        )
    pc = ksp.getPC()
    for level in range(pc.getMGLevels() - 1, -1, -1):
        smoother = pc.getMGSmoother(level)
        nz, mb = mat_mb(smoother.getOperators()[0])
        line = f"  level {level}: {nz:.0f} entries ({mb:.0f} MB)"
        if level > 0:
            line += " P {:.0f} entries ({:.0f} MB)".format(*mat_mb(pc.getMGInterpolation(level)))
        if smoother.getPC().getType() == "bjacobi":
            sub = smoother.getPC().getBJacobiSubKSP()[0].getPC()
            if sub.getType() == "icc":
                line += f" ICC {sub.getFactorMatrix().getInfo()['nz_allocated']:.0f} entries"
        if comm.rank == 0:
            print(line, flush=True)


if __name__ == "__main__":
    main()
