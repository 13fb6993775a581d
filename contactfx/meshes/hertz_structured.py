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
    D, F, G = C + np.array([0.0, -d]), C + np.array([d, -d]), C + np.array([d, 0.0])
    Pb, P45, Pr = (
        C + np.array([0.0, -R]),
        C + R * np.array([math.sqrt(0.5), -math.sqrt(0.5)]),
        C + np.array([R, 0.0]),
    )

    def arc(theta: np.ndarray) -> np.ndarray:
        return C + R * np.column_stack([np.cos(theta), np.sin(theta)])

    def coons(
        bottom: np.ndarray,
        top: np.ndarray,
        left: np.ndarray,
        right: np.ndarray,
        corners: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
        s: np.ndarray,
        t: np.ndarray,
    ) -> np.ndarray:
        # Transfinite interpolation of four boundary curves, s along bottom/top, t along sides.
        S, T = s[:, None, None], t[None, :, None]
        c00, c10, c01, c11 = corners
        edges = (
            (1 - T) * bottom[:, None] + T * top[:, None] + (1 - S) * left[None] + S * right[None]
        )
        return edges - (
            (1 - S) * (1 - T) * c00 + S * (1 - T) * c10 + (1 - S) * T * c01 + S * T * c11
        )

    line = lambda a, b, s: a + s[:, None] * (b - a)  # noqa: E731
    pa = coons(
        line(D, F, u),
        arc(-0.5 * math.pi + 0.25 * math.pi * u),
        line(D, Pb, v),
        line(F, P45, v),
        (D, F, Pb, P45),
        u,
        v,
    )
    pb = coons(
        line(F, G, w),
        arc(-0.25 * math.pi + 0.25 * math.pi * w),
        line(F, P45, v),
        line(G, Pr, v),
        (F, G, P45, Pr),
        w,
        v,
    )
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
