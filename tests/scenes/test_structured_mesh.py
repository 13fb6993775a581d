"""The structured Hertz mesh made distributed (each rank its own cells) is `hertz_grid`'s mesh.

`build_hertz_structured` generates each rank's strips of cells and a block of the node
coordinates (`meshes.hertz_grid_part`) and keeps every cell where it was made. The reference
is the whole grid made at once by `hertz_grid` in this process: the same node coordinates
under the same input numbering, the same cells as sets, the same bodies (block cells below
y = height), and the same tagged facets as on one rank; on 1, 2 and 3 ranks.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest
from dolfinx.io.gmsh import MeshData
from dolfinx.mesh import entities_to_geometry
from mpi4py import MPI

from contactfx.meshes import hertz_grid
from contactfx.scenes.structured import build_hertz_structured

# R, width, height, h_contact, r_refine, h_far, slope: 3,645 cells, strongly graded.
ARGS = (60.0, 60.0, 60.0, 0.2, 2.0, 4.0, 0.1)
HERE = Path(__file__).resolve().parent


def build(comm: MPI.Comm) -> MeshData:
    """The scene's structured mesh at ARGS on `comm`."""
    R, width, height, h_contact, r_refine, h_far, slope = ARGS
    return build_hertz_structured(comm, R, width, height, h_contact, r_refine, h_far, slope)[0]


def mesh_arrays(md: MeshData, comm: MPI.Comm) -> dict[str, np.ndarray]:
    """Every rank's cells, nodes and tagged facets gathered, in rank order (collective)."""
    msh = md.mesh
    assert md.cell_tags is not None and md.facet_tags is not None
    tdim = msh.topology.dim
    n = msh.topology.index_map(tdim).size_local
    dofs = msh.geometry.dofmaps[0][:n]
    inputs = np.asarray(msh.geometry.input_global_indices)
    p = msh.geometry.x[dofs][:, :, :2]
    quad = p[:, [0, 1, 3, 2]]  # DOLFINx's tensor-product order -> around the cell
    area = 0.5 * np.abs(
        np.sum(
            quad[..., 0] * np.roll(quad[..., 1], -1, 1)
            - np.roll(quad[..., 0], -1, 1) * quad[..., 1],
            1,
        )
    )
    body = np.zeros(n, dtype=np.int32)
    body[md.cell_tags.indices[md.cell_tags.indices < n]] = md.cell_tags.values[
        md.cell_tags.indices < n
    ]
    nodes = np.arange(msh.geometry.index_map().size_local)
    facets = entities_to_geometry(msh, tdim - 1, md.facet_tags.indices)
    local = {
        "cells": np.sort(inputs[dofs], axis=1),
        "mid": p.mean(axis=1),
        "area": area,
        "body": body,
        "node_index": inputs[nodes],
        "node_x": msh.geometry.x[nodes, :2],
        "facet_tag": md.facet_tags.values,
        "facet_mid": msh.geometry.x[facets][:, :, :2].mean(axis=1),
        "owned": np.array([n]),
    }
    return {k: np.concatenate(comm.allgather(v)) for k, v in local.items()}


def rows(a: np.ndarray) -> np.ndarray:
    """The rows of `a` in lexicographic order."""
    return a[np.lexsort(a.T[::-1])]


def check_against_hertz_grid(got: dict[str, np.ndarray], ranks: int) -> None:
    """`got` (mesh_arrays) is hertz_grid's mesh, split over `ranks` ranks."""
    x, cells, n_block = hertz_grid(*ARGS)
    height = ARGS[2]
    # Every node once, at hertz_grid's coordinates under hertz_grid's numbering.
    order = np.argsort(got["node_index"])
    assert np.array_equal(got["node_index"][order], np.arange(len(x)))
    assert np.array_equal(got["node_x"][order], x)
    # The same cells, as sets of nodes; the same cell midpoints and areas.
    assert np.array_equal(rows(got["cells"]), rows(np.sort(cells, axis=1)))
    p = x[cells]
    quad = p[:, [0, 1, 3, 2]]
    area = 0.5 * np.abs(
        np.sum(
            quad[..., 0] * np.roll(quad[..., 1], -1, 1)
            - np.roll(quad[..., 0], -1, 1) * quad[..., 1],
            1,
        )
    )
    ref = rows(np.column_stack([p.mean(axis=1), area]))
    mine = rows(np.column_stack([got["mid"], got["area"]]))
    assert np.allclose(mine, ref, rtol=0.0, atol=1e-12 * 60.0)
    # Bodies: the block (body 1) lies below y = height, the disc above.
    assert np.array_equal(got["body"], np.where(got["mid"][:, 1] < height, 1, 2))
    assert (got["body"] == 1).sum() == n_block
    # Each rank owns cells of both bodies, equal counts within one cell per body.
    owned = np.split(got["body"], np.cumsum(got["owned"])[:-1])
    assert len(owned) == ranks
    for b in (1, 2):
        counts = [int((o == b).sum()) for o in owned]
        assert min(counts) > 0 and max(counts) - min(counts) <= 1, (b, counts)


def facets(got: dict[str, np.ndarray]) -> np.ndarray:
    """The tagged facets as sorted (tag, midpoint x, midpoint y) rows."""
    return rows(np.column_stack([got["facet_tag"], np.round(got["facet_mid"], 10)]))


@pytest.mark.serial
def test_one_rank_is_hertz_grid() -> None:
    got = mesh_arrays(build(MPI.COMM_SELF), MPI.COMM_SELF)
    check_against_hertz_grid(got, 1)
    tags = set(got["facet_tag"].tolist())
    assert len(tags) == 5, tags  # contact1, contact2, symmetry, support, load


SCRIPT = """
import sys
import numpy as np
from mpi4py import MPI
sys.path.insert(0, {here!r})
from test_structured_mesh import build, mesh_arrays

comm = MPI.COMM_WORLD
got = mesh_arrays(build(comm), comm)
if comm.rank == 0:
    np.savez({out!r}, **got)
"""


@pytest.mark.mpi
@pytest.mark.parametrize("ranks", [2, 3])
def test_ranks_make_hertz_grid(ranks: int, tmp_path: Path, mpi_script) -> None:
    """Each rank made its own cells: together hertz_grid's mesh, and one rank's facet tags."""
    out = tmp_path / "mesh.npz"
    script = tmp_path / "structured.py"
    script.write_text(textwrap.dedent(SCRIPT.format(here=str(HERE), out=str(out))))
    mpi_script(script, ranks=ranks, timeout=120)
    with np.load(out) as data:
        got = {k: data[k] for k in data.files}
    check_against_hertz_grid(got, ranks)
    one = mesh_arrays(build(MPI.COMM_SELF), MPI.COMM_SELF)
    assert np.array_equal(facets(got), facets(one))
