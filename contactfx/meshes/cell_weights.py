"""Bilinear basis weights of points in given quadrilaterals (a non-nested multigrid's rows).

`q1_weights` evaluates, for each point and its cell, the cell's Q1 basis at the point: the
bilinear map pulled back by Newton's method, all points at once. `contains` decides whether
a point lies in its cell without the pull-back. Vertex order is DOLFINx's: the corners are
(0,0), (1,0), (0,1), (1,1) in the reference square. Points outside their cell are
extrapolated (what a coarser mesh's polygon leaves out of a finer mesh's curved boundary).
contactfx meshes are quadrilateral only (scenes/gmsh_checks.py), so triangles are not here.
"""

from __future__ import annotations

import numpy as np

# Newton on the bilinear map: quadratic convergence from the centre for convex cells; a
# point this far outside its cell (reference units) is not extrapolated from it.
NEWTON_STEPS = 8
# Newton converges quadratically: after a step this small (reference units) the error is
# of its square, below round-off.
_SETTLED = 1e-9
FAR_OUTSIDE = 1.0

# The ring of a quadrilateral's corners in DOLFINx's (tensor) order.
_RING = [0, 1, 3, 2]


def q1_weights(points: np.ndarray, corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, 4) bilinear weights of `points` (n, 2) in cells with `corners` (n, 4, 2), and a mask.

    The mask is False where the point's reference coordinates lie more than FAR_OUTSIDE out
    of the reference square (or Newton did not converge): those weights are not to be used.
    """
    ref = _reference(points, corners)
    s, t = ref[:, 0], ref[:, 1]
    w = np.stack([(1 - s) * (1 - t), s * (1 - t), (1 - s) * t, s * t], axis=1)
    with np.errstate(invalid="ignore"):
        ok = (ref > -FAR_OUTSIDE).all(axis=1) & (ref < 1.0 + FAR_OUTSIDE).all(axis=1)
    return w, ok


def contains(points: np.ndarray, corners: np.ndarray, tol: float = 1e-10) -> np.ndarray:
    """(n,) whether each point lies in its convex cell (within `tol` of its size).

    The sign of the cross product with every edge, either orientation; no pull-back.
    """
    c = corners[:, _RING]
    nxt = np.roll(c, -1, axis=1)
    e = nxt - c
    r = points[:, None, :] - c
    cross = e[:, :, 0] * r[:, :, 1] - e[:, :, 1] * r[:, :, 0]
    area = (c[:, :, 0] * nxt[:, :, 1] - c[:, :, 1] * nxt[:, :, 0]).sum(axis=1)
    return (np.sign(area)[:, None] * cross >= -tol * np.abs(area)[:, None]).all(axis=1)


def _reference(points: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Reference coordinates of each point in its cell (NaN where Newton missed it).

    Newton on the points not yet converged only: most settle well before NEWTON_STEPS
    (counts: docs/scale.md, "The gmsh levels' point weights").
    """
    x0, x1, x2, x3 = (corners[:, k] for k in range(4))
    ref = np.full((len(points), 2), 0.5)
    todo = np.arange(len(points))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for _ in range(NEWTON_STEPS):
            a0, a1, a2, a3 = x0[todo], x1[todo], x2[todo], x3[todo]
            s, t = ref[todo, :1], ref[todo, 1:]
            ds = (a1 - a0) * (1 - t) + (a3 - a2) * t  # dx/ds
            dt = (a2 - a0) * (1 - s) + (a3 - a1) * s  # dx/dt
            r = points[todo] - _forward(a0, a1, a2, a3, s, t)
            det = ds[:, 0] * dt[:, 1] - ds[:, 1] * dt[:, 0]
            step = np.stack(
                [
                    (r[:, 0] * dt[:, 1] - r[:, 1] * dt[:, 0]) / det,
                    (ds[:, 0] * r[:, 1] - ds[:, 1] * r[:, 0]) / det,
                ],
                axis=1,
            )
            ref[todo] += step
            # Converged to round-off (reference units), or lost (NaN: the test below).
            todo = todo[~(np.abs(step).max(axis=1) <= _SETTLED)]
            if not len(todo):
                break
        scale = np.linalg.norm(x3 - x0, axis=1) + np.linalg.norm(x2 - x1, axis=1)
        at = _forward(x0, x1, x2, x3, ref[:, :1], ref[:, 1:])
        miss = ~(np.linalg.norm(points - at, axis=1) <= 1e-9 * scale)
    ref[miss] = np.nan
    return ref


def _forward(
    x0: np.ndarray, x1: np.ndarray, x2: np.ndarray, x3: np.ndarray, s: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """The bilinear map of reference coordinates (s, t), each (n, 1), to (n, 2) points."""
    return x0 * (1 - s) * (1 - t) + x1 * s * (1 - t) + x2 * (1 - s) * t + x3 * s * t
