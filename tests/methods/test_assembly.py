"""discretize.elasticity's PETSc assembly equals dolfinx.fem.petsc's, bit for bit.

petsc_matrix / petsc_vector replace dolfinx.fem.petsc's assemble_matrix, assemble_vector and
apply_lifting (whose import builds a cffi parser: docs/scale.md, "Time to the first
answer"). Reference: dolfinx.fem.petsc itself, on a square with a nonzero prescribed
displacement (the lifting moves f), serial and on 2 ranks (ghost rows and columns).
"""

from __future__ import annotations

from pathlib import Path

import pytest

CASE = """
import numpy as np
import dolfinx_solver  # noqa: F401
import dolfinx.fem.petsc
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI
from petsc4py import PETSc

from contactfx.discretize.elasticity import petsc_matrix, petsc_vector

comm = MPI.COMM_WORLD
msh = mesh.create_unit_square(comm, 7, 5, mesh.CellType.quadrilateral)
V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
x = ufl.SpatialCoordinate(msh)
eps = lambda w: ufl.sym(ufl.grad(w))  # noqa: E731
a = fem.form(ufl.inner(2.0 * eps(u) + ufl.tr(eps(u)) * ufl.Identity(2), eps(v)) * ufl.dx)
L = fem.form(ufl.inner(ufl.as_vector([x[1], 1.0 + x[0] ** 2]), v) * ufl.dx)
left = mesh.locate_entities_boundary(msh, 1, lambda p: np.isclose(p[0], 0.0))
ub = fem.Function(V)
ub.interpolate(lambda p: np.stack([0.1 + 0 * p[0], 0.02 * p[1]]))
bcs = [fem.dirichletbc(ub, fem.locate_dofs_topological(V, 1, left))]

K_ref = dolfinx.fem.petsc.assemble_matrix(a, bcs=bcs)
K_ref.assemble()
f_ref = dolfinx.fem.petsc.assemble_vector(L)
dolfinx.fem.petsc.apply_lifting(f_ref, [a], bcs=[bcs])
K = petsc_matrix(a, bcs)
K.assemble()
f = petsc_vector(L, a, bcs)
for vec in (f_ref, f):
    vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
dolfinx.fem.petsc.set_bc(f_ref, bcs)
for bc in bcs:
    bc.set(f.array_w, None, 1.0)

ia, ja, va = K_ref.getValuesCSR()
ib, jb, vb = K.getValuesCSR()
assert np.array_equal(ia, ib) and np.array_equal(ja, jb), comm.rank
assert np.array_equal(va, vb), (comm.rank, np.abs(va - vb).max())
assert np.array_equal(f_ref.array_r, f.array_r), (comm.rank, np.abs(f_ref.array - f.array).max())
assert np.abs(f.array_r).max() > 0
print("OK", comm.rank, flush=True)
"""


def test_assembly_is_dolfinx_petsc_bit_for_bit(tmp_path: Path) -> None:
    exec(compile(CASE, "assembly_case", "exec"), {"__name__": "assembly_case"})


@pytest.mark.mpi
def test_assembly_is_dolfinx_petsc_bit_for_bit_on_two_ranks(tmp_path: Path, mpi_script) -> None:
    script = tmp_path / "assembly_case.py"
    script.write_text(CASE)
    run = mpi_script(script, timeout=180)
    assert run.stdout.count("OK") == 2, run.stdout
