"""Hertz scene (S5) as a structured graded quad grid (numpy only; loaded by contactfx).

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
from typing import NamedTuple

import numpy as np

# The inner square of the disc's butterfly, as a fraction of R.
_SQUARE = 0.4


def graded_points(length: float, h0: float, r: float, slope: float, h_far: float) -> np.ndarray:
    """Points from 0 to `length`: spacing h0 up to r, then h0 + slope (s - r) up to h_far."""
    h_far = max(h_far, h0)
    s1 = r + (h_far - h0) / slope

    def count(s: float | np.ndarray) -> np.ndarray:
        # Number of cells between 0 and s: the integral of 1 / h(s).
        s = np.asarray(s, dtype=float)
        grow = np.log((h0 + slope * (np.clip(s, r, s1) - r)) / h0) / slope
        return np.minimum(s, r) / h0 + grow + np.maximum(s - s1, 0.0) / h_far

    total = float(count(length))
    n = max(1, round(total))
    target = np.arange(n + 1) * (total / n)
    n_r, n_1 = r / h0, float(count(s1))
    s = np.where(
        target <= n_r,
        target * h0,
        np.where(
            target <= n_1,
            # np.where evaluates every branch: clip so that the uniform part cannot overflow.
            r + h0 * (np.exp(slope * np.minimum(target - n_r, n_1 - n_r)) - 1.0) / slope,
            s1 + (target - n_1) * h_far,
        ),
    )
    s[0], s[-1] = 0.0, length
    return s


def _quads(ids: np.ndarray) -> np.ndarray:
    """Cells of a node grid ids[i, j] in DOLFINx's tensor-product vertex order."""
    corners = [ids[:-1, :-1], ids[1:, :-1], ids[:-1, 1:], ids[1:, 1:]]
    return np.stack(corners, axis=-1).reshape(-1, 4)


class _Lines(NamedTuple):
    """The 1D point distributions and the corner points the grid is built from."""

    xs: np.ndarray  # block columns
    ys: np.ndarray  # block rows
    u: np.ndarray  # disc: along the arc of patch a and along x in the square
    v: np.ndarray  # disc: from the square (0) to the arc (1)
    w: np.ndarray  # disc: along the arc of patch b and along y in the square
    yc: float
    d: float
    a_curves: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
    b_curves: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
    a_corners: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
    b_corners: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]

    def lines(self) -> GridLines:
        """The grid lines alone (what the coarser grids are cut from: meshes/grid_levels.py)."""
        return GridLines(self.xs, self.ys, self.u, self.v, self.w)


def grid_geometry(
    R: float,
    width: float,
    height: float,
    h_contact: float,
    r_refine: float,
    h_far: float,
    slope: float,
) -> _Lines:
    """The 1D point distributions and corner points `hertz_grid`'s mesh is built from."""
    # Block [0, width] x [0, height]: fine at x = 0 along the top.
    xs = graded_points(width, h_contact, r_refine, slope, h_far)
    ys = height - graded_points(height, h_contact, 0.0, slope, h_far)[::-1]
    ys[-1] = height
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
    D, F, G = C + np.array([0.0, -d]), C + np.array([d, -d]), C + np.array([d, 0.0])
    Pb, P45, Pr = (
        C + np.array([0.0, -R]),
        C + R * np.array([math.sqrt(0.5), -math.sqrt(0.5)]),
        C + np.array([R, 0.0]),
    )

    def arc(theta: np.ndarray) -> np.ndarray:
        return C + R * np.column_stack([np.cos(theta), np.sin(theta)])

    line = lambda a, b, s: a + s[:, None] * (b - a)  # noqa: E731
    # Patch a: s = u along D-F (bottom) and the arc to P45 (top), t = v along D-Pb and F-P45.
    a_curves = (
        line(D, F, u),
        arc(-0.5 * math.pi + 0.25 * math.pi * u),
        line(D, Pb, v),
        line(F, P45, v),
    )
    # Patch b: s = w along F-G and the arc from P45 to Pr, t = v along F-P45 and G-Pr.
    b_curves = (
        line(F, G, w),
        arc(-0.25 * math.pi + 0.25 * math.pi * w),
        line(F, P45, v),
        line(G, Pr, v),
    )
    return _Lines(xs, ys, u, v, w, yc, d, a_curves, b_curves, (D, F, Pb, P45), (F, G, P45, Pr))


def _coons(
    bottom: np.ndarray,
    top: np.ndarray,
    left: np.ndarray,
    right: np.ndarray,
    corners: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    S: np.ndarray,
    T: np.ndarray,
) -> np.ndarray:
    # Transfinite interpolation of four boundary curves, S along bottom/top, T along the
    # sides; any shapes that broadcast (the whole patch, or a list of nodes).
    c00, c10, c01, c11 = corners
    edges = (1 - T) * bottom + T * top + (1 - S) * left + S * right
    return edges - ((1 - S) * (1 - T) * c00 + S * (1 - T) * c10 + (1 - S) * T * c01 + S * T * c11)


def hertz_grid(
    R: float,
    width: float,
    height: float,
    h_contact: float,
    r_refine: float,
    h_far: float,
    slope: float,
) -> tuple[np.ndarray, np.ndarray, int]:
    """Node coordinates, quad cells and the number of block cells (which come first)."""
    ln = grid_geometry(R, width, height, h_contact, r_refine, h_far, slope)
    bx, by = np.meshgrid(ln.xs, ln.ys, indexing="ij")
    block_ids = np.arange(bx.size).reshape(bx.shape)
    block_x = np.column_stack([bx.ravel(), by.ravel()])
    block_cells = _quads(block_ids)
    disc_x, disc_cells = _disc(ln)
    x = np.vstack([block_x, disc_x])
    return x, np.vstack([block_cells, disc_cells + len(block_x)]), len(block_cells)


def _disc(ln: _Lines) -> tuple[np.ndarray, np.ndarray]:
    """The quarter disc's node coordinates and cells, numbered from 0 (patch a, b, square)."""
    u, v, w, yc, d = ln.u, ln.v, ln.w, ln.yc, ln.d

    def patch(
        curves: tuple[np.ndarray, ...],
        corners: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
        s: np.ndarray,
    ) -> np.ndarray:
        bottom, top, left, right = curves
        return _coons(
            bottom[:, None], top[:, None], left[None], right[None], corners,
            s[:, None, None], v[None, :, None],
        )  # fmt: skip

    pa = patch(ln.a_curves, ln.a_corners, u)
    pb = patch(ln.b_curves, ln.b_corners, w)
    ida, idb, ids, n = disc_ids(len(u) - 1, len(v) - 1, len(w) - 1)
    nu, nw = len(u) - 1, len(w) - 1
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
    return disc_x, np.vstack([_quads(ida), _quads(idb), _quads(ids)])


def disc_ids(nu: int, nv: int, nw: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Node numbers of the disc's patches a (u, v), b (w, v), the square (u, w); their count.

    b shares a's edge u = 1, the square shares a's and b's edges v = 0.
    """
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
    return ida, idb, ids, n + nu * nw


class GridLines(NamedTuple):
    """The grid lines of `hertz_grid`: block columns xs and rows ys, the disc's u, v, w."""

    xs: np.ndarray
    ys: np.ndarray
    u: np.ndarray
    v: np.ndarray
    w: np.ndarray


class GridPart(NamedTuple):
    """One rank's share of `hertz_grid`: its cells and a block of the node coordinates.

    Nodes keep `hertz_grid`'s numbering; `x` holds the coordinates of nodes `first_node`,
    `first_node + 1`, ... and `cells` refer to nodes by that numbering (they may lie in
    another part's block). The first `n_block` cells are block cells.
    """

    x: np.ndarray
    first_node: int
    cells: np.ndarray
    n_block: int


def _strip(n: int, part: int, nparts: int) -> np.ndarray:
    # Item k goes to part (k nparts) // n: the equal-count strips of scenes/gmsh_io.py.
    return np.arange(-(-part * n // nparts), -(-(part + 1) * n // nparts))


def _node_block(n: int, part: int, nparts: int) -> tuple[int, int]:
    # DOLFINx's own split of n input nodes over the ranks (the first n % nparts get one
    # more): create_mesh first sends every input node to the rank of this split.
    q, r = divmod(n, nparts)
    lo = part * q + min(part, r)
    return lo, lo + q + (part < r)


def hertz_grid_part(
    R: float,
    width: float,
    height: float,
    h_contact: float,
    r_refine: float,
    h_far: float,
    slope: float,
    part: int,
    nparts: int,
) -> GridPart:
    """Part `part` of `nparts` of `hertz_grid`'s mesh, made without the rest of the grid.

    The cells of each body are cut into `nparts` equal-count strips by cell midpoint x (then
    y), the very strips `scenes.gmsh_io.body_strips` gives. Each part makes its cells and
    the coordinates of one block of nodes; it holds the block's cells and nodes of its own
    only, the disc's nodes whole (to cut the disc by x). With `nparts == 1`, `hertz_grid`'s
    arrays.
    """
    ln = grid_geometry(R, width, height, h_contact, r_refine, h_far, slope)
    nx, ny = len(ln.xs) - 1, len(ln.ys) - 1
    n_bx = (nx + 1) * (ny + 1)  # block nodes; the disc's follow
    # Block cells k = (column i, row j), column by column: the strips by x (then y).
    i, j = np.divmod(_strip(nx * ny, part, nparts), ny)
    corners = [(i + a) * (ny + 1) + j + b for b in (0, 1) for a in (0, 1)]
    block_cells = np.column_stack(corners)
    # The disc: the partitioner's strips by cell midpoint x (then y) too. Other cuts (swept
    # around the centre: fewer cut facets at many parts) cost the ICC(0)-smoothed multigrid
    # of the condensed path iterations on 2 ranks (docs/scale.md, "Setup"); this needs the
    # disc's nodes on every part, about half the grid's coordinates.
    xd, all_disc = _disc(ln)
    mid = xd[all_disc].mean(axis=1)
    order = np.lexsort((mid[:, 1], mid[:, 0]))
    disc_cells = all_disc[np.sort(order[_strip(len(all_disc), part, nparts)])]
    lo, hi = _node_block(n_bx + len(xd), part, nparts)

    def block_rows(i: np.ndarray) -> np.ndarray:
        return np.stack(np.broadcast_arrays(ln.xs[i][:, None], ln.ys[None, :]), axis=-1)

    x = np.vstack(
        [
            _rows(lo, min(hi, n_bx), ny + 1, block_rows),
            xd[max(lo, n_bx) - n_bx : max(hi - n_bx, 0)],
        ]
    )
    return GridPart(x, lo, np.vstack([block_cells, disc_cells + n_bx]), len(block_cells))


def _rows(lo: int, hi: int, width: int, fill: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    # Items lo .. hi - 1 of a row-major (rows, width) node grid whose rows `fill` makes.
    if hi <= lo:
        return np.empty((0, 2))
    r0 = lo // width
    grid = fill(np.arange(r0, (hi - 1) // width + 1)).reshape(-1, 2)
    return grid[lo - r0 * width : hi - r0 * width]
