"""Hertz scene (S5) on a structured graded quad mesh, built directly in DOLFINx (no gmsh).

gmsh's frontal quad mesher with Blossom recombination takes about 45 s for 470k elements on
this machine class, too slow for the 1-2 million dof benchmarks. This mesh is a tensor
product of 1D graded point distributions: the block is one patch; the quarter disc is a
"butterfly" of three patches (a square around the centre and two transfinite patches along
the arc), so every cell is a proper quad. Sizes grow from `h_contact` over the first
`r_refine` cm of the contact surfaces at `slope` up to `h_far`; scaling all three sizes by
1/k multiplies the number of cells by about k^2 with the same cell shapes, which is what a
scaling study needs. Far from the contact the cells are stretched (up to h_far/h_contact).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import basix.ufl
import numpy as np
import ufl
from dolfinx import mesh as dmesh
from mpi4py import MPI

from contactfx.errors import InputError

if TYPE_CHECKING:
    from contactfx.scenes import HertzParams, Scene

# Physical groups, numbered like the gmsh scene's names (the numbers themselves are free).
TAGS = {"body1": 1, "body2": 2, "contact1": 3, "contact2": 4, "symmetry": 5, "support": 6,
        "load": 7}
# The inner square of the disc's butterfly, as a fraction of R.
_SQUARE = 0.4


@dataclass(frozen=True)
class StructuredMesh:
    """A distributed mesh with its cell and facet tags (names in `physical_groups`)."""

    mesh: dmesh.Mesh
    cell_tags: dmesh.MeshTags
    facet_tags: dmesh.MeshTags
    physical_groups: dict[str, int]


def graded_points(length: float, h0: float, r: float, slope: float, h_far: float) -> np.ndarray:
    """Points from 0 to `length`: spacing h0 up to r, then h0 + slope (s - r) up to h_far."""
    h_far = max(h_far, h0)
    s1 = r + (h_far - h0) / slope

    def count(s: np.ndarray) -> np.ndarray:
        # Number of cells between 0 and s: the integral of 1 / h(s).
        s = np.asarray(s, dtype=float)
        grow = np.log((h0 + slope * (np.clip(s, r, s1) - r)) / h0) / slope
        return np.minimum(s, r) / h0 + grow + np.maximum(s - s1, 0.0) / h_far

    total = float(count(length))
    n = max(1, round(total))
    target = np.arange(n + 1) * (total / n)
    n_r, n_1 = r / h0, float(count(s1))
    s = np.where(target <= n_r, target * h0,
                 np.where(target <= n_1,
                          r + h0 * (np.exp(slope * (target - n_r)) - 1.0) / slope,
                          s1 + (target - n_1) * h_far))
    s[0], s[-1] = 0.0, length
    return s


def _quads(ids: np.ndarray) -> np.ndarray:
    """Cells of a node grid ids[i, j] in DOLFINx's tensor-product vertex order."""
    corners = [ids[:-1, :-1], ids[1:, :-1], ids[:-1, 1:], ids[1:, 1:]]
    return np.stack(corners, axis=-1).reshape(-1, 4)


def hertz_grid(R: float, width: float, height: float, h_contact: float, r_refine: float,
               h_far: float, slope: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Node coordinates, quad cells and the number of block cells (which come first)."""
    # Block [0, width] x [0, height]: fine at x = 0 along the top.
    xs = graded_points(width, h_contact, r_refine, slope, h_far)
    ys = height - graded_points(height, h_contact, 0.0, slope, h_far)[::-1]
    ys[-1] = height
    bx, by = np.meshgrid(xs, ys, indexing="ij")
    block_ids = np.arange(bx.size).reshape(bx.shape)
    block_x = np.column_stack([bx.ravel(), by.ravel()])
    block_cells = _quads(block_ids)

    # Quarter disc: centre C, bottom point Pb (the contact point), P45 on the arc, Pr right.
    yc = height + R
    d = _SQUARE * R
    su = graded_points(0.25 * math.pi * R, h_contact, r_refine, slope, h_far)
    u = su / su[-1]
    v = 1.0 - graded_points(R - d, h_contact, 0.0, slope, h_far)[::-1] / (R - d)
    v[0], v[-1] = 0.0, 1.0
    nw = max(1, math.ceil(0.25 * math.pi * R / h_far))
    w = np.linspace(0.0, 1.0, nw + 1)
    C = np.array([0.0, yc])
    D, F, G = C + [0.0, -d], C + [d, -d], C + [d, 0.0]
    Pb, P45, Pr = C + [0.0, -R], C + R * np.array([math.sqrt(0.5), -math.sqrt(0.5)]), C + [R, 0.0]

    def arc(theta: np.ndarray) -> np.ndarray:
        return C + R * np.column_stack([np.cos(theta), np.sin(theta)])

    def coons(bottom, top, left, right, corners, s, t):
        # Transfinite interpolation of four boundary curves, s along bottom/top, t along sides.
        S, T = s[:, None, None], t[None, :, None]
        c00, c10, c01, c11 = corners
        edges = ((1 - T) * bottom[:, None] + T * top[:, None]
                 + (1 - S) * left[None] + S * right[None])
        return edges - ((1 - S) * (1 - T) * c00 + S * (1 - T) * c10 + (1 - S) * T * c01
                        + S * T * c11)

    line = lambda a, b, s: a + s[:, None] * (b - a)  # noqa: E731
    pa = coons(line(D, F, u), arc(-0.5 * math.pi + 0.25 * math.pi * u), line(D, Pb, v),
               line(F, P45, v), (D, F, Pb, P45), u, v)
    pb = coons(line(F, G, w), arc(-0.25 * math.pi + 0.25 * math.pi * w), line(F, P45, v),
               line(G, Pr, v), (F, G, P45, Pr), w, v)
    nu, nv = len(u) - 1, len(v) - 1
    ida = np.arange((nu + 1) * (nv + 1)).reshape(nu + 1, nv + 1)
    n = ida.size
    idb = np.empty((nw + 1, nv + 1), dtype=np.int64)
    idb[0] = ida[nu]
    idb[1:] = n + np.arange(nw * (nv + 1)).reshape(nw, nv + 1)
    n += nw * (nv + 1)
    ids = np.empty((nu + 1, nw + 1), dtype=np.int64)
    ids[:, 0] = ida[:, 0]
    ids[nu, :] = idb[:, 0]
    ids[:nu, 1:] = n + np.arange(nu * nw).reshape(nu, nw)
    n += nu * nw
    disc_x = np.empty((n, 2))
    disc_x[ida] = pa
    disc_x[idb] = pb
    sq = np.stack(np.meshgrid(u * d, yc - d + w * d, indexing="ij"), axis=-1)
    disc_x[ids[:nu, 1:]] = sq[:nu, 1:]
    # Boundary lines exactly on x = 0 and y = yc: the facet classification tests equality.
    disc_x[ida[0], 0] = 0.0
    disc_x[ids[0], 0] = 0.0
    disc_x[ids[:, nw], 1] = yc
    disc_x[idb[nw], 1] = yc
    disc_cells = np.vstack([_quads(ida), _quads(idb), _quads(ids)]) + len(block_x)
    x = np.vstack([block_x, disc_x])
    return x, np.vstack([block_cells, disc_cells]), len(block_cells)


def build_hertz_structured(comm: MPI.Comm, R: float, width: float, height: float,
                           h_contact: float, r_refine: float, h_far: float | None = None,
                           slope: float = 0.1, contact_extent: float | None = None,
                           partitioner: Callable | None = None) -> StructuredMesh:
    """The Hertz half model (quarter disc on a block) as a distributed structured quad mesh."""
    h_far = R / 6.0 if h_far is None else h_far
    extent = min(width, R / 4.0) if contact_extent is None else contact_extent
    if min(R, width, height, h_contact, h_far, slope) <= 0.0 or r_refine < 0.0:
        raise InputError("radius, block size, mesh sizes and slope must be positive")
    if not 0.0 < extent < min(width, R):
        raise InputError(f"contact_extent={extent} must lie in (0, min(width, R))")
    if comm.rank == 0:
        x, cells, n_block = hertz_grid(R, width, height, h_contact, r_refine, h_far, slope)
    else:
        x, cells, n_block = np.zeros((0, 2)), np.zeros((0, 4), dtype=np.int64), 0
    n_block = comm.bcast(n_block, root=0)
    element = ufl.Mesh(basix.ufl.element("Lagrange", "quadrilateral", 1, shape=(2,)))
    if partitioner is None:
        from meshes import balanced_partitioner

        partitioner = balanced_partitioner(np.column_stack([x, np.zeros(len(x))]))
    msh = dmesh.create_mesh(comm, cells, element, x, partitioner=partitioner)
    tdim = msh.topology.dim
    ncells = msh.topology.index_map(tdim).size_local + msh.topology.index_map(tdim).num_ghosts
    body = np.where(np.asarray(msh.topology.original_cell_index)[:ncells] < n_block, 1, 2)
    cell_tags = dmesh.meshtags(msh, tdim, np.arange(ncells, dtype=np.int32),
                               body.astype(np.int32))
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets = dmesh.exterior_facet_indices(msh.topology)
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    fbody = body[f2c.array[f2c.offsets[facets]]]
    xf = msh.geometry.x[dmesh.entities_to_geometry(msh, tdim - 1, facets)][:, :, :2]
    both = lambda cond: cond.all(axis=1)  # noqa: E731
    yc = height + R
    mid_x = xf[:, :, 0].mean(axis=1)
    on_arc = np.abs(np.hypot(xf[:, :, 0], xf[:, :, 1] - yc) - R) <= 1e-10 * R
    values = np.zeros(len(facets), dtype=np.int32)
    rules = [
        (fbody == 1, both(xf[:, :, 1] == height) & (mid_x <= extent), "contact1"),
        (fbody == 2, both(on_arc) & (mid_x <= extent), "contact2"),
        (fbody > 0, both(xf[:, :, 0] == 0.0), "symmetry"),
        (fbody == 1, both(xf[:, :, 1] == 0.0), "support"),
        (fbody == 2, both(xf[:, :, 1] == yc), "load"),
    ]
    for in_body, cond, name in rules:
        values[(values == 0) & in_body & cond] = TAGS[name]
    keep = values > 0
    order = np.argsort(facets[keep])
    facet_tags = dmesh.meshtags(msh, tdim - 1, facets[keep][order].astype(np.int32),
                                values[keep][order])
    return StructuredMesh(msh, cell_tags, facet_tags, dict(TAGS))


def hertz_structured_scene(params: HertzParams, comm: MPI.Comm = MPI.COMM_WORLD,
                           h_far: float | None = None, slope: float = 0.1,
                           active: int = 2) -> Scene:
    """A contactfx Scene of `params` (HertzParams) on the structured mesh (refine = h_contact)."""
    from dataclasses import replace

    from contactfx.scenes import Material, Scene, hertz_exact, validate

    validate(params)
    exact = hertz_exact(params)
    if params.r_refine == 0.0:
        params = replace(params, r_refine=round(1.4 * exact["a"], 6))
    data = build_hertz_structured(comm, params.R, params.width, params.height, params.refine,
                                  params.r_refine, h_far, slope)
    materials = (Material(params.E1, params.nu1), Material(params.E2, params.nu2))
    extra = {"hertz_exact": exact, "mesh": "structured", "h_far": h_far, "slope": slope}
    return Scene("hertz", params, data.mesh, data.cell_tags, data.facet_tags,
                 data.physical_groups, materials, params.P / (2 * params.R), active, extra)
