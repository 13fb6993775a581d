"""discretize.remesh_mg: a gmsh scene's coarser remeshes as a multigrid's prolongations.

References are brute force: the coarse meshes' own node coordinates and affine functions,
a different one per body, which a linear prolongation must reproduce at every finer node
(inside a coarse cell or extrapolated from the nearest one) if, and only if, each row
interpolates from coarse nodes of its own body.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import scipy.sparse as sp
from mpi4py import MPI

from contactfx.discretize import remesh_mg
from contactfx.discretize.setup import prepare_contact
from contactfx.options import Basis, Method
from contactfx.scenes import HertzParams, hertz
from contactfx.timers import Timers


@pytest.fixture(scope="module")
def levels():
    """A small gmsh Hertz mesh and its levels with the first remesh x2 (so that there are
    several: the default first factor leaves one at this size)."""
    mp = pytest.MonkeyPatch()
    mp.setattr(remesh_mg, "FIRST_FACTOR", 2.0)
    scene = hertz(
        HertzParams(refine=0.1, h_far=1.0, refine_edge=0.025, mesh="gmsh"), comm=MPI.COMM_SELF
    )
    setup = prepare_contact(scene, Method.MORTAR.kernel, 1e-8, Timers(), Basis.DUAL)
    el = setup.elasticity
    out = remesh_mg.remesh_levels(el.V, scene)
    mp.undo()
    yield scene, el, out
    for level in out:
        level.P.destroy()


def _scipy(m) -> sp.csr_matrix:
    indptr, indices, data = m.getValuesCSR()
    return sp.csr_matrix((data, indices, indptr), shape=m.getSize())


def _bodies(scene) -> np.ndarray:
    """The body index of every geometry node of the scene's mesh (bodies share no node)."""
    nodes = scene.mesh.geometry.dofmaps[0]
    out = np.full(scene.mesh.geometry.x.shape[0], -1)
    for i, b in enumerate(scene.bodies):
        out[nodes[scene.body_cells(b)].ravel()] = i
    return out


AFFINE = np.array([[0.3, -1.7, 2.5], [-4.0, 0.6, 1.1]])  # a + b x + c y, per body


def _interleaved(x: np.ndarray, body: np.ndarray) -> np.ndarray:
    """Both components of the bodies' affine functions at points x (y component: 2f)."""
    a, b, c = AFFINE[body].T
    f = a + b * x[:, 0] + c * x[:, 1]
    return np.stack([f, 2.0 * f], axis=1).ravel()


def test_levels_are_the_remeshes(levels) -> None:
    """Two or more levels; level k's nodes are nodes of the scene remeshed 2^(k+1) times
    coarser, each with that mesh's body, fewer than 0.6 of the level before; none is an
    empty column (a singular coarse operator)."""
    scene, el, out = levels
    assert len(out) >= 2
    sizes = [el.V.dofmap.index_map.size_local] + [len(level.x) for level in out]
    assert all(b < 0.6 * a for a, b in itertools.pairwise(sizes))
    for k, level in enumerate(out):
        P = _scipy(level.P)
        assert P.shape == (2 * sizes[k], 2 * sizes[k + 1])
        assert (np.abs(P).sum(axis=0) > 0).all()
        mesh = scene.remeshed(2.0 ** (k + 1))
        # Keyed by position and body: the two bodies each have a node where they touch.
        cx, cb = np.round(mesh.mesh.geometry.x[:, :2], 12), _bodies(mesh)
        index = {(*p, b): i for i, (p, b) in enumerate(zip(cx, cb, strict=True))}
        keys = zip(np.round(level.x, 12), level.body, strict=True)
        where = [index[(*p, b)] for p, b in keys]  # KeyError: not a node of that body there
        assert len(set(where)) == len(where)


def test_prolongations_reproduce_each_bodys_affine_function(levels) -> None:
    """P f_coarse = f_fine for a different affine function per body, at every row (Dirichlet
    rows too: they keep their weights); rows sum to one."""
    scene, el, out = levels
    n = el.V.dofmap.index_map.size_local
    fine_x = el.V.tabulate_dof_coordinates()[:n, :2]
    node_block = np.empty(scene.mesh.geometry.x.shape[0], dtype=np.int64)
    node_block[scene.mesh.geometry.dofmaps[0].ravel()] = el.V.dofmap.list.ravel()
    fine_body = np.empty(n, dtype=np.int64)
    fine_body[node_block] = _bodies(scene)
    for level in out:
        P = _scipy(level.P)
        want = _interleaved(fine_x, fine_body)
        got = P @ _interleaved(level.x, level.body)
        assert np.abs(got - want).max() < 1e-9 * np.abs(want).max()
        assert np.abs(np.asarray(P.sum(axis=1)).ravel() - 1.0).max() < 1e-12
        fine_x, fine_body = level.x, level.body


def test_the_default_levels_start_at_the_first_factor(levels) -> None:
    """By default the first coarser mesh is the scene remeshed FIRST_FACTOR times coarser,
    then twice that... down to the coarsest size; on this 8k-node mesh the first is already
    under it: one level."""
    scene, el, _ = levels
    out = remesh_mg.remesh_levels(el.V, scene)
    try:
        coarse = scene.remeshed(remesh_mg.FIRST_FACTOR).mesh.geometry.x.shape[0]
        assert coarse <= remesh_mg.COARSEST_NODES < el.V.dofmap.index_map.size_local
        assert len(out) == 1 and len(out[0].x) <= coarse
    finally:
        for level in out:
            level.P.destroy()


def test_no_empty_coarse_column_on_the_default_mesh() -> None:
    """The default Hertz mesh (nodes held by the edge sizes: its remeshes keep most of them)
    has coarse nodes no finer node interpolates from; they are dropped, so every column of
    every level carries weight (else PCMG's Galerkin operator is singular and CG breaks
    down: DIVERGED_INDEFINITE_PC)."""
    scene = hertz(HertzParams(), comm=MPI.COMM_SELF)
    setup = prepare_contact(scene, Method.NTS.kernel, 1e-8, Timers())
    out = remesh_mg.remesh_levels(setup.elasticity.V, scene)
    assert out
    for level in out:
        P = _scipy(level.P)
        assert (np.abs(P).sum(axis=0) > 0).all()
        assert len(level.x) < scene.remeshed(remesh_mg.FIRST_FACTOR).mesh.geometry.x.shape[0]
        level.P.destroy()
