"""Scene meshes: cell type, physical groups, duplicated interface nodes, contact lines, MPI."""

import textwrap
from functools import partial
from pathlib import Path

import dolfinx_solver  # noqa: F401 - orders MPI ahead of the dolfinx bindings
import numpy as np
import pytest
from dolfinx.io.gmsh import MeshData
from dolfinx.mesh import CellType, entities_to_geometry
from mpi4py import MPI

from contactfx.meshes import build_blocks, build_hertz
from contactfx.scenes.gmsh_io import balanced_partitioner, to_dolfinx

NAMES = {"body1", "body2", "contact1", "contact2", "symmetry", "support", "load"}
# (l1, l2, h1, h2, size1, size2, grading1, grading2) of the block scenes
S1 = (10.0, 6.0, 3.0, 3.0, 0.125, 0.125)
S2 = (10.0, 6.0, 3.0, 3.0, 0.08, 0.1)
S4_GRADED = (10.0, 10.0, 3.0, 3.0, 0.12, 0.15, 1.03, 0.97)
HERTZ = {"R": 60.0, "width": 60.0, "height": 60.0, "h_contact": 0.05, "r_refine": 2.0}
TOL = 1e-9


def _mesh(build) -> MeshData:
    """Build a scene serially."""
    return to_dolfinx(MPI.COMM_SELF, build)


@pytest.fixture(scope="module")
def s1() -> MeshData:
    """S1: same material, matching meshes."""
    return _mesh(partial(build_blocks, *S1))


@pytest.fixture(scope="module")
def s2() -> MeshData:
    """S2: non-matching meshes."""
    return _mesh(partial(build_blocks, *S2))


@pytest.fixture(scope="module")
def s4() -> MeshData:
    """S4 geometry with graded (non-uniform) contact meshes."""
    return _mesh(partial(build_blocks, *S4_GRADED))


@pytest.fixture(scope="module")
def hertz() -> MeshData:
    """S5: quarter disc on a block."""
    return _mesh(partial(build_hertz, **HERTZ))


def _cells(md: MeshData, name: str) -> np.ndarray:
    """Return the cells of a dim-2 physical group."""
    return md.cell_tags.find(md.physical_groups[name].tag)


def _facet_points(md: MeshData, name: str) -> np.ndarray:
    """Return the vertex coordinates of the facets of a dim-1 physical group, (n, 2, 2)."""
    facets = md.facet_tags.find(md.physical_groups[name].tag)
    nodes = entities_to_geometry(md.mesh, 1, facets)
    return md.mesh.geometry.x[nodes][:, :, :2]


def _vertices(md: MeshData, cells: np.ndarray) -> set[int]:
    """Return the vertices of the given cells."""
    top = md.mesh.topology
    top.create_connectivity(2, 0)
    c2v = top.connectivity(2, 0)
    return {int(v) for c in cells for v in c2v.links(c)}


def _contact_x(md: MeshData, name: str) -> np.ndarray:
    """Return the sorted distinct x of the nodes of a contact group."""
    return np.unique(np.round(_facet_points(md, name)[:, :, 0].ravel(), 12))


@pytest.mark.parametrize("scene", ["s1", "s2", "s4", "hertz"])
def test_quads_groups_and_duplicated_interface(scene: str, request: pytest.FixtureRequest) -> None:
    md = request.getfixturevalue(scene)
    assert md.mesh.topology.cell_type == CellType.quadrilateral
    assert md.mesh.geometry.x.shape[1] == 3 and np.allclose(md.mesh.geometry.x[:, 2], 0.0)
    assert NAMES <= set(md.physical_groups)
    for name in NAMES:
        assert md.physical_groups[name].dim == (2 if name.startswith("body") else 1)
    b1, b2 = _cells(md, "body1"), _cells(md, "body2")
    assert len(b1) + len(b2) == md.mesh.topology.index_map(2).size_local
    assert not _vertices(md, b1) & _vertices(md, b2)


@pytest.mark.parametrize("scene,args", [("s1", S1), ("s2", S2), ("s4", S4_GRADED)])
def test_block_lines(scene: str, args: tuple, request: pytest.FixtureRequest) -> None:
    md = request.getfixturevalue(scene)
    l1, l2, h1, h2 = args[:4]
    c1, c2 = _facet_points(md, "contact1"), _facet_points(md, "contact2")
    assert np.allclose(c1[:, :, 1], h1, atol=TOL) and np.allclose(c2[:, :, 1], h1, atol=TOL)
    assert np.isclose(c1[:, :, 0].min(), 0) and np.isclose(c1[:, :, 0].max(), l1 / 2)
    assert np.isclose(c2[:, :, 0].min(), 0) and np.isclose(c2[:, :, 0].max(), l2 / 2)
    # B2's corner is a node of B1's contact edge
    assert np.any(np.isclose(_contact_x(md, "contact1"), l2 / 2, atol=TOL))
    assert np.allclose(_facet_points(md, "symmetry")[:, :, 0], 0.0, atol=TOL)
    assert np.allclose(_facet_points(md, "support")[:, :, 1], 0.0, atol=TOL)
    assert np.allclose(_facet_points(md, "load")[:, :, 1], h1 + h2, atol=TOL)


def test_s1_counts_and_matching_contact_nodes(s1: MeshData) -> None:
    assert len(_cells(s1, "body1")) == (5 / 0.125) * (3 / 0.125) == 960
    assert len(_cells(s1, "body2")) == (3 / 0.125) * (3 / 0.125) == 576
    x1, x2 = _contact_x(s1, "contact1"), _contact_x(s1, "contact2")
    assert np.allclose(x1[x1 <= 3.0 + TOL], x2, atol=TOL)
    assert np.allclose(np.diff(x1), 0.125)


def test_s2_non_matching_counts(s2: MeshData) -> None:
    # round(3/0.08) = 38 (half to even) + round(2/0.08) = 25 columns, 38 rows; 30 x 30
    assert len(_cells(s2, "body1")) == (38 + 25) * 38
    assert len(_cells(s2, "body2")) == 30 * 30


def test_grading_makes_contact_spacing_non_uniform(s4: MeshData) -> None:
    # the count still comes from length / size: round(5 / 0.12) = 42, round(5 / 0.15) = 33
    for name, ratio, n in (("contact1", S4_GRADED[6], 42), ("contact2", S4_GRADED[7], 33)):
        dx = np.diff(_contact_x(s4, name))
        assert len(dx) == n
        assert np.allclose(dx[1:] / dx[:-1], ratio)


def test_hertz_lines_and_refinement(hertz: MeshData) -> None:
    R, height, hc = HERTZ["R"], HERTZ["height"], HERTZ["h_contact"]
    yc, extent = height + R, R / 4
    n_cells = len(_cells(hertz, "body1")) + len(_cells(hertz, "body2"))
    assert n_cells < 5000
    c1, c2 = _facet_points(hertz, "contact1"), _facet_points(hertz, "contact2")
    assert np.allclose(c1[:, :, 1], height, atol=TOL)
    assert np.isclose(c1[:, :, 0].min(), 0) and np.isclose(c1[:, :, 0].max(), extent)
    assert np.allclose(np.hypot(c2[:, :, 0], c2[:, :, 1] - yc), R, atol=1e-8)
    assert np.isclose(c2[:, :, 0].min(), 0) and np.isclose(c2[:, :, 0].max(), extent)
    assert np.allclose(_facet_points(hertz, "symmetry")[:, :, 0], 0.0, atol=TOL)
    assert np.allclose(_facet_points(hertz, "support")[:, :, 1], 0.0, atol=TOL)
    load = _facet_points(hertz, "load")
    assert np.allclose(load[:, :, 1], yc) and np.isclose(load[:, :, 0].max(), R)
    for name in ("contact1", "contact2"):
        x = _contact_x(hertz, name)
        near = np.diff(x)[x[1:] <= HERTZ["r_refine"]]
        assert 0.7 * hc < near.min() and near.max() < 1.3 * hc
        assert np.diff(x).max() > 10 * hc  # coarse away from the contact zone


MPI_SCRIPT = """
import dolfinx_solver  # noqa: F401
import numpy as np
from functools import partial
from mpi4py import MPI
from contactfx.scenes.gmsh_io import balanced_partitioner, to_dolfinx
from contactfx.meshes import build_blocks

comm = MPI.COMM_WORLD
md = to_dolfinx(comm, partial(build_blocks, {args}), balanced_partitioner())
owned = md.mesh.topology.index_map(2).size_local
x = md.mesh.geometry.x
dofs = md.mesh.geometry.dofmaps[0]
counts, spans = [], []
for body in ("body1", "body2"):
    cells = md.cell_tags.find(md.physical_groups[body].tag)
    cells = cells[cells < owned]
    mid = x[dofs[cells], 0].mean(axis=1)
    counts.append(len(cells))
    spans.append((mid.min(), mid.max()))
assert comm.size == 2 and min(counts) > 0, (comm.rank, counts)
assert comm.allreduce(np.array(counts)).tolist() == [960, 576]
# strips by x within each body: rank 0 holds the left part
spans = comm.allgather(spans)
assert all(spans[0][b][1] < spans[1][b][0] for b in range(2)), spans
print("OK", comm.rank, counts, flush=True)
"""


@pytest.mark.mpi
def test_balanced_partition_under_mpirun(tmp_path: Path, mpi_script) -> None:
    script = tmp_path / "partition.py"
    script.write_text(textwrap.dedent(MPI_SCRIPT.format(args=", ".join(map(str, S1)))))
    run = mpi_script(script, timeout=120)
    assert run.stdout.count("OK") == 2, run.stdout


def test_balanced_partitioner_serial_is_identity() -> None:
    md = to_dolfinx(MPI.COMM_SELF, partial(build_blocks, *S1), balanced_partitioner())
    assert md.mesh.topology.index_map(2).size_local == 960 + 576


# (R, width, height, h_contact, r_refine, h_far, slope): the scene's proportions, and two
# whose arc and top nodes do not round onto the boundary lines (hertz_grid sets them there).
GRIDS = [
    (60.0, 60.0, 60.0, 0.1, 2.0, 1.0, 0.1),
    (0.37, 1.3, 0.55, 0.004, 0.01, 0.03, 0.3),
    (0.53, 1.3, 0.37, 0.006, 0.02, 0.04, 0.3),
]


@pytest.mark.parametrize("grid", GRIDS)
@pytest.mark.parametrize("nparts", [1, 2, 3, 7])
def test_grid_parts_make_hertz_grid(grid: tuple, nparts: int) -> None:
    """The parts' node blocks, in part order, are hertz_grid's nodes bit for bit; their cells
    are hertz_grid's cells, each once, block cells first; one part is hertz_grid itself."""
    from contactfx.meshes import hertz_grid, hertz_grid_part

    x, cells, n_block = hertz_grid(*grid)
    parts = [hertz_grid_part(*grid, k, nparts) for k in range(nparts)]
    assert [p.first_node for p in parts] == list(np.cumsum([0] + [len(p.x) for p in parts])[:-1])
    assert np.array_equal(np.vstack([p.x for p in parts]), x)
    mine = np.vstack([p.cells for p in parts])
    assert np.array_equal(mine[np.lexsort(mine.T[::-1])], cells[np.lexsort(cells.T[::-1])])
    n_block_nodes = cells[:n_block].max() + 1
    for p in parts:
        assert (p.cells[: p.n_block] < n_block_nodes).all()
        assert (p.cells[p.n_block :] >= n_block_nodes).all()
    if nparts == 1:
        assert np.array_equal(parts[0].cells, cells) and parts[0].n_block == n_block


@pytest.mark.parametrize("nparts", [2, 3, 16])
def test_grid_parts_are_strips_of_each_body(nparts: int) -> None:
    """Each body's parts are the partitioner's strips by x (body_strips on hertz_grid's cell
    midpoints), the block's and the disc's, as equal as counts allow (within one cell)."""
    from contactfx.meshes import hertz_grid, hertz_grid_part
    from contactfx.scenes.gmsh_io import body_strips

    grid = GRIDS[0]
    x, cells, n_block = hertz_grid(*grid)
    mid = x[cells].mean(axis=1)
    strips = np.zeros(len(cells), dtype=np.int32)
    body_strips(strips, (np.arange(len(cells)) >= n_block).astype(int), mid, nparts)
    index = {tuple(c): k for k, c in enumerate(np.sort(cells, axis=1).tolist())}
    disc = []
    for k in range(nparts):
        p = hertz_grid_part(*grid, k, nparts)
        made = [index[tuple(c)] for c in np.sort(p.cells, axis=1).tolist()]
        assert np.array_equal(np.sort(made), np.flatnonzero(strips == k))
        assert (np.asarray(made[: p.n_block]) < n_block).all()
        disc.append(len(p.cells) - p.n_block)
    assert max(disc) - min(disc) <= 1 and min(disc) > 0
