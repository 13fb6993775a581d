"""The Schur-complement route (`mumps-schur`): the default's answer from one factorization."""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from contactfx import solve
from contactfx.methods.predictor import use_coarse
from contactfx.options import SOLVERS, Predictor, SolverKind
from contactfx.scenes import BLOCK_SCENES, HertzParams, build_scene, hertz


def _same(scene, method: str) -> None:
    ref = solve(scene, method, solver="mumps")
    sol = solve(scene, method, solver="mumps-schur")
    assert np.array_equal(sol.active, ref.active)
    scale = np.abs(ref.pressure).max()
    assert np.abs(sol.pressure - ref.pressure).max() <= 1e-8 * scale
    u_scale = np.abs(ref.u.x.array).max()
    assert np.abs(sol.u.x.array - ref.u.x.array).max() <= 1e-9 * u_scale
    # One factorization for the whole loop: only the first step factorizes.
    assert [int(h["factorized"]) for h in sol.history] == [1] + [0] * (len(sol.history) - 1)


@pytest.mark.serial
@pytest.mark.parametrize("mesh", ["gmsh", "structured"])
@pytest.mark.parametrize("method", ["nts", "mortar"])
def test_schur_matches_the_default_on_hertz(mesh: str, method: str) -> None:
    """Hertz (body held only by contact, regularized by gamma B^T B): same set, same fields."""
    _same(hertz(HertzParams(mesh=mesh, refine=0.04), comm=MPI.COMM_SELF), method)


@pytest.mark.serial
@pytest.mark.parametrize("name", ["S1", "S2", "S3", "S4"])
def test_schur_matches_the_default_on_blocks(name: str) -> None:
    """The block scenes S1-S4 (mortar)."""
    _same(build_scene("blocks", BLOCK_SCENES[name], comm=MPI.COMM_SELF), "mortar")


@pytest.mark.serial
def test_schur_never_starts_from_the_coarse_solve() -> None:
    """Serially the Schur route has every row's responses: no coarse remesh at any size."""
    spec = SOLVERS["mumps-schur"]
    assert spec.kind is SolverKind.DIRECT_SCHUR and spec.kind.factorizes_saddle
    scene = hertz(HertzParams(refine=0.02), comm=MPI.COMM_SELF)
    assert not use_coarse(Predictor.AUTO, scene, spec)
