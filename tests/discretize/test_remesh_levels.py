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
    several: the default x8 leaves one at this size)."""
    mp = pytest.MonkeyPatch()
    mp.setattr(remesh_mg, "FIRST_FACTOR", 2.0)
    scene = hertz(
        HertzParams(refine=0.1, h_far=1.0, refine_edge=0.025, mesh="gmsh"), comm=MPI.COMM_SELF
    )
    setup = prepare_contact(scene, Method.MORTAR.kernel, 1e-8, Timers(), Basis.DUAL)
    el = setup.elasticity
    mats = remesh_mg.remesh_interpolations(el.V, el.bcs, scene)
    mp.undo()
    yield scene, el, [_scipy(m) for m in mats]
    for m in mats:
        m.destroy()


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


def test_levels_coarsen(levels) -> None:
    """Two or more levels, each the scene remeshed x2 more coarsely, with fewer than 0.6 of
    the nodes of the level before."""
    scene, el, mats = levels
    assert len(mats) >= 2
    n_fine = el.V.dofmap.index_map.size_local * 2
    sizes = [n_fine] + [m.shape[1] for m in mats]
    assert [m.shape[0] for m in mats] == sizes[:-1]
    assert all(b < 0.6 * a for a, b in itertools.pairwise(sizes))
    for k, m in enumerate(mats):
        assert m.shape[1] == 2 * scene.remeshed(2.0 ** (k + 1)).mesh.geometry.x.shape[0]


def test_prolongations_reproduce_each_bodys_affine_function(levels) -> None:
    """P f_coarse = f_fine for a different affine function per body, at every row but the
    Dirichlet ones (zero rows) on the finest level; the other rows sum to one."""
    scene, el, mats = levels
    n = el.V.dofmap.index_map.size_local
    x_fine = el.V.tabulate_dof_coordinates()[:n, :2]
    node_block = np.empty(scene.mesh.geometry.x.shape[0], dtype=np.int64)
    node_block[scene.mesh.geometry.dofmaps[0].ravel()] = el.V.dofmap.list.ravel()
    body_fine = np.empty(n, dtype=np.int64)
    body_fine[node_block] = _bodies(scene)
    fixed = np.zeros(2 * n, dtype=bool)
    for bc in el.bcs:
        fixed[bc.dof_indices()[0]] = True
    assert fixed.any()
    fine_x, fine_body = x_fine, body_fine
    for k, P in enumerate(mats):
        coarse = scene.remeshed(2.0 ** (k + 1))
        cx, cbody = coarse.mesh.geometry.x[:, :2], _bodies(coarse)
        got = P @ _interleaved(cx, cbody)
        want = _interleaved(fine_x, fine_body)
        free = ~fixed if k == 0 else np.ones(len(want), dtype=bool)
        assert np.abs(got - want)[free].max() < 1e-9 * np.abs(want).max()
        sums = np.asarray(P.sum(axis=1)).ravel()  # a row's weights: on its component's columns
        assert np.abs(sums[free] - 1.0).max() < 1e-12
        if k == 0:
            assert np.abs(P[fixed]).sum() == 0.0
        fine_x, fine_body = cx, cbody


def test_the_default_levels_start_at_x8(levels) -> None:
    """By default the first coarser mesh is the scene remeshed x8 (FIRST_FACTOR), then x16...
    down to the coarsest size; here, 8k nodes, x8 is already under it: one level."""
    scene, el, _ = levels
    mats = remesh_mg.remesh_interpolations(el.V, el.bcs, scene)
    try:
        assert remesh_mg.FIRST_FACTOR == 8.0
        coarse = scene.remeshed(8.0).mesh.geometry.x.shape[0]
        assert coarse <= remesh_mg.COARSEST_NODES < el.V.dofmap.index_map.size_local
        assert [m.getSize()[1] for m in mats] == [2 * coarse]
    finally:
        for m in mats:
            m.destroy()
