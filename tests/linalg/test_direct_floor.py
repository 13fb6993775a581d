"""The direct-solve floor: a symmetric default, the condensed path on curved surfaces, and the
selected inverse on several ranks."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, solver_for

from contactfx import load_scene_file, solve
from contactfx.options import SOLVERS, Linear, SolverKind

TWO_CYLINDERS = ROOT / "tests" / "scenes" / "two_cylinders.toml"


@pytest.fixture(scope="module")
def cylinders():
    """Two cylinders (R 40 and 60): a curved passive surface, so dual mortar's D is not diagonal."""
    return load_scene_file(TWO_CYLINDERS)


def test_default_factorizes_symmetrically() -> None:
    """The default `mumps` is MUMPS' LDL^T of the saddle point; LU stays as `mumps-lu`."""
    assert SOLVERS["mumps"].kind is SolverKind.DIRECT
    assert SOLVERS["mumps"].linear is Linear.LDLT and not Linear.LDLT.unsymmetric
    assert SOLVERS["mumps"].petsc["pc_type"] == "cholesky"
    assert SOLVERS["mumps-lu"].linear is Linear.LU and Linear.LU.unsymmetric
    assert SOLVERS["mumps-lu"].petsc["pc_type"] == "lu"


@pytest.mark.parametrize("solver", ["condensed", "condensed-gamg"])
@pytest.mark.parametrize(("method", "basis"), [("mortar", "dual"), ("nts", "standard")])
def test_condensed_on_a_curved_passive_surface(cylinders, method, basis, solver) -> None:
    """Dual mortar on two cylinders couples neighbouring pivots: condensed = MUMPS to 1e-6."""
    ref = solve(cylinders, method, basis=basis, solver="mumps-lu")
    sol = solve(cylinders, method, basis=basis, solver=solver)
    assert np.array_equal(sol.active, ref.active)
    assert np.abs(sol.pressure - ref.pressure).max() <= 1e-6 * np.abs(ref.pressure).max()
    du = np.abs(sol.u.x.array - ref.u.x.array).max()
    assert du <= 1e-6 * np.abs(ref.u.x.array).max()


def test_curved_dual_mortar_pivot_block_is_coupled(cylinders) -> None:
    """The case the coupled elimination exists for: off-diagonal pivot entries above round-off."""
    from contactfx.contact import Kernel
    from contactfx.discretize.setup import prepare_contact
    from contactfx.linalg.elimination import LocalRows
    from contactfx.linalg.pivots import pivots
    from contactfx.options import Basis
    from contactfx.timers import Timers

    setup = prepare_contact(cylinders, Kernel.MORTAR, 1e-6, Timers(), Basis.DUAL)
    rows = LocalRows.of(setup.B, setup.node_dofs())
    n = setup.elasticity.K.getSize()[0]
    r0 = setup.elasticity.K.getOwnershipRange()[0]
    every = np.ones(len(setup.g), dtype=bool)
    assert pivots(rows, every, setup.comm, r0, n).coupled is not None
    setup.destroy()


def test_ordering_rule() -> None:
    """AMD below PORD_FROM_DOFS, PORD from there; an option naming one wins; MUMPS only."""
    from contactfx.methods.solvers import AMD, ORDERING_KEY, PORD, PORD_FROM_DOFS, with_ordering

    mumps = SOLVERS["mumps"].petsc
    assert with_ordering(mumps, PORD_FROM_DOFS - 1)[ORDERING_KEY] == AMD
    assert with_ordering(mumps, PORD_FROM_DOFS)[ORDERING_KEY] == PORD
    assert with_ordering({**mumps, ORDERING_KEY: 5}, 10)[ORDERING_KEY] == 5
    assert ORDERING_KEY not in with_ordering(SOLVERS["condensed"].petsc, 10)


@pytest.mark.parametrize("name", ["mumps", "mumps-lu"])
def test_ordering_reaches_mumps(cylinders, name) -> None:
    """The factorization MUMPS ran used the rule's ordering (ICNTL(7)) on this 8k-DOF scene."""
    from contactfx.discretize.setup import prepare_contact
    from contactfx.methods.active_set import ActiveSetOptions
    from contactfx.methods.solvers import AMD, PORD_FROM_DOFS
    from contactfx.options import Method
    from contactfx.timers import Timers

    setup = prepare_contact(
        cylinders, Method.MORTAR.kernel, ActiveSetOptions().penetration_tol, Timers()
    )
    el = setup.elasticity
    solver = solver_for(setup, name, cylinders)
    try:
        # Every row in contact, as the loop's first step: a nonsingular saddle point.
        solver.solve(setup.g, np.ones(len(setup.layout.mine), dtype=bool), fresh=True)
        factor = solver._ksp.getPC().getFactorMatrix()
        assert el.K.getSize()[0] < PORD_FROM_DOFS
        assert factor.getMumpsIcntl(7) == AMD
    finally:
        solver.destroy()
        setup.destroy()
