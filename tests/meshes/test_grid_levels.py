"""meshes.grid_levels: the structured Hertz grid's coarser grids and their prolongations.

References are brute force: the grid's own node coordinates (`hertz_grid`) and bilinear
functions of the block's coordinates, which a bilinear prolongation must reproduce.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import scipy.sparse as sp

from contactfx.meshes import grid_geometry, grid_levels, hertz_grid
from contactfx.meshes.grid_levels import grid_patches, kept_lines

ARGS = (60.0, 60.0, 60.0, 0.1, 2.0, 1.0, 0.1)  # R, width, height, h, r_refine, h_far, slope


def _matrix(level) -> sp.csr_matrix:
    shape = (level.n_fine, level.n_coarse)
    return sp.csr_matrix((level.vals, (level.rows, level.cols)), shape=shape)


@pytest.fixture(scope="module")
def grid():
    lines = grid_geometry(*ARGS).lines()
    x, cells, n_block = hertz_grid(*ARGS)
    return lines, x, cells, n_block


def test_patches_number_the_grid_nodes(grid) -> None:
    """Every node of hertz_grid's mesh lies in a patch, and the patches' lines are its cells."""
    lines, x, cells, _ = grid
    patches, n = grid_patches(lines)
    assert n == len(x)
    seen = np.zeros(n, dtype=bool)
    n_cells = 0
    for ids, s, t in patches:
        assert ids.shape == (len(s), len(t))
        seen[ids.ravel()] = True
        n_cells += (len(s) - 1) * (len(t) - 1)
    assert seen.all() and n_cells == len(cells)
    # The block's patch: its lines are the nodes' coordinates.
    block, xs, ys = patches[0]
    np.testing.assert_array_equal(x[block[:, 0], 0], xs)
    np.testing.assert_array_equal(x[block[0, :], 1], ys)


def test_kept_lines() -> None:
    assert kept_lines(4).tolist() == [0, 2, 4]
    assert kept_lines(5).tolist() == [0, 2, 4, 5]
    assert kept_lines(1).tolist() == [0, 1]


def test_prolongation_reproduces_bilinear_functions(grid) -> None:
    """Rows sum to one everywhere (constants), coarse nodes keep their value, and on the
    block (lines = coordinates) a + b x + c y + d x y is interpolated exactly."""
    lines, x, _, _ = grid
    levels = grid_levels(lines, 200)
    assert len(levels) >= 3
    assert levels[-1].n_coarse <= 200 < levels[-2].n_coarse
    P = _matrix(levels[0])
    np.testing.assert_allclose(P.sum(axis=1).A1, 1.0, rtol=0, atol=1e-14)
    # The coarse nodes are the fine nodes on kept lines: a unit row each.
    patches, _ = grid_patches(lines)
    block, xs, ys = patches[0]
    keep = block[np.ix_(kept_lines(len(xs) - 1), kept_lines(len(ys) - 1))].ravel()
    unit = P[keep]
    assert np.all(unit.getnnz(axis=1) == 1) and np.all(unit.data == 1.0)
    coarse_x = x[keep]
    f = lambda p: 1.0 + 2.0 * p[:, 0] - 3.0 * p[:, 1] + 0.5 * p[:, 0] * p[:, 1]  # noqa: E731
    values = np.zeros(levels[0].n_coarse)
    values[unit.indices] = f(coarse_x)
    fine = P[block.ravel()] @ values
    np.testing.assert_allclose(fine, f(x[block.ravel()]), rtol=1e-12, atol=1e-9)


def test_levels_chain(grid) -> None:
    """Each level's coarse grid is the next one's fine grid, and the sizes fall ~4x."""
    lines, *_ = grid
    levels = grid_levels(lines, 200)
    for fine, coarse in itertools.pairwise(levels):
        assert coarse.n_fine == fine.n_coarse
        assert 2.5 <= fine.n_fine / fine.n_coarse <= 4.5
