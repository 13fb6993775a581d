"""Linear basis weights of points in given cells (a non-nested multigrid's prolongation rows).

`p1_weights` evaluates, for each point and its cell, the cell's P1 (triangle) or Q1
(quadrilateral) basis at the point: barycentric coordinates, or the bilinear map pulled back
by Newton's method, all points at once. Vertex order is DOLFINx's: a quadrilateral's corners
are (0,0), (1,0), (0,1), (1,1) in its reference square. Points outside their cell are
extrapolated (what a coarser mesh's polygon leaves out of a finer mesh's curved boundary).
"""

from __future__ import annotations

import numpy as np

# Newton on the bilinear map: quadratic convergence from the centre for convex cells; a
# point this far outside its cell (reference units) is not extrapolated from it.
NEWTON_STEPS = 8
FAR_OUTSIDE = 1.0


def p1_weights(points: np.ndarray, corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, nv) basis weights of `points` (n, 2) in cells with `corners` (n, nv, 2), and a mask.

    nv = 3: a triangle's barycentric coordinates; nv = 4: a quadrilateral's bilinear basis.
    The mask is False where the point's reference coordinates lie more than FAR_OUTSIDE out
    of the reference cell (or Newton did not converge): those weights are not to be used.
    """
    nv = corners.shape[1]
    if nv == 3:
        ref = _triangle_reference(points, corners)
    elif nv == 4:
        ref = _quad_reference(points, corners)
    else:
        raise ValueError(f"cells of {nv} vertices: only triangles and quadrilaterals")
    s, t = ref[:, 0], ref[:, 1]
    if nv == 3:
        w = np.stack([1.0 - s - t, s, t], axis=1)
    else:
        w = np.stack([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t], axis=1)
    lo = -FAR_OUTSIDE
    ok = np.isfinite(ref).all(axis=1) & (ref > lo).all(axis=1) & (ref < 1.0 - lo).all(axis=1)
    if nv == 3:
        ok &= s + t < 1.0 - lo
    return w, ok


def contains(points: np.ndarray, corners: np.ndarray, tol: float = 1e-10) -> np.ndarray:
    """(n,) whether each point lies in its convex cell (within `tol` of its size).

    The sign of the cross product with every edge, either orientation; no pull-back.
    """
    nv = corners.shape[1]
    ring = [0, 1, 2] if nv == 3 else [0, 1, 3, 2]  # DOLFINx's quadrilateral: tensor order
    c = corners[:, ring]
    e = np.roll(c, -1, axis=1) - c
    r = points[:, None, :] - c
    cross = e[:, :, 0] * r[:, :, 1] - e[:, :, 1] * r[:, :, 0]
    area = (c[:, :, 0] * np.roll(c, -1, axis=1)[:, :, 1]).sum(axis=1) - (
        c[:, :, 1] * np.roll(c, -1, axis=1)[:, :, 0]
    ).sum(axis=1)
    scale = tol * np.abs(area)
    return (np.sign(area)[:, None] * cross >= -scale[:, None]).all(axis=1)


def _triangle_reference(points: np.ndarray, corners: np.ndarray) -> np.ndarray:
    a = corners[:, 1] - corners[:, 0]
    b = corners[:, 2] - corners[:, 0]
    r = points - corners[:, 0]
    det = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (r[:, 0] * b[:, 1] - r[:, 1] * b[:, 0]) / det
        t = (a[:, 0] * r[:, 1] - a[:, 1] * r[:, 0]) / det
    return np.stack([s, t], axis=1)


def _quad_reference(points: np.ndarray, corners: np.ndarray) -> np.ndarray:
    x0, x1, x2, x3 = (corners[:, k] for k in range(4))
    ref = np.full((len(points), 2), 0.5)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for _ in range(NEWTON_STEPS):
            s, t = ref[:, :1], ref[:, 1:]
            x = x0 * (1 - s) * (1 - t) + x1 * s * (1 - t) + x2 * (1 - s) * t + x3 * s * t
            ds = (x1 - x0) * (1 - t) + (x3 - x2) * t  # dx/ds
            dt = (x2 - x0) * (1 - s) + (x3 - x1) * s  # dx/dt
            r = points - x
            det = ds[:, 0] * dt[:, 1] - ds[:, 1] * dt[:, 0]
            ref[:, 0] += (r[:, 0] * dt[:, 1] - r[:, 1] * dt[:, 0]) / det
            ref[:, 1] += (ds[:, 0] * r[:, 1] - ds[:, 1] * r[:, 0]) / det
        s, t = ref[:, :1], ref[:, 1:]
        x = x0 * (1 - s) * (1 - t) + x1 * s * (1 - t) + x2 * (1 - s) * t + x3 * s * t
        scale = np.linalg.norm(x3 - x0, axis=1) + np.linalg.norm(x2 - x1, axis=1)
        miss = np.linalg.norm(points - x, axis=1) > 1e-9 * scale
    ref[miss] = np.nan
    return ref
