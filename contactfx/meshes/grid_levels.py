"""The structured Hertz grid's coarser grids and their interpolations (numpy only).

Every patch of `hertz_grid`'s mesh (the block, the disc's patches a, b and the square) is a
tensor product of 1D point distributions. Keeping every second line of each (and the last)
gives a coarser grid of the same patches whose nodes are nodes of the finer one; a finer
node's value is interpolated bilinearly in the patch's line parameters from the corners of
the coarser cell it lies in. Shared patch edges use the same lines on both sides, so a node
on them gets the same weights from either patch. These are the prolongations of a geometric
multigrid: on the accurate family's cells (aspect up to 10) its iterations stay flat where
GAMG's aggregation grows; on far more stretched cells both degrade (coarsening every line in
both directions): docs/scale.md, "Geometric multigrid on the structured grid".
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .hertz_structured import GridLines, disc_ids

# (node numbers of the patch's tensor grid, line parameters along its first and second axis)
Patch = tuple[np.ndarray, np.ndarray, np.ndarray]


class Level(NamedTuple):
    """A prolongation from `n_coarse` coarser nodes to `n_fine` nodes, as coordinates."""

    rows: np.ndarray
    cols: np.ndarray
    vals: np.ndarray
    n_fine: int
    n_coarse: int
    fine_of: np.ndarray  # (n_coarse,) the finer node each coarser node is


def grid_patches(lines: GridLines) -> tuple[list[Patch], int]:
    """The patches of `hertz_grid`'s node numbering (block first, then the disc) and the count."""
    nx, ny = len(lines.xs) - 1, len(lines.ys) - 1
    block = np.arange((nx + 1) * (ny + 1)).reshape(nx + 1, ny + 1)
    ida, idb, ids, n = disc_ids(len(lines.u) - 1, len(lines.v) - 1, len(lines.w) - 1)
    off = block.size
    patches = [
        (block, lines.xs, lines.ys),
        (ida + off, lines.u, lines.v),
        (idb + off, lines.w, lines.v),
        (ids + off, lines.u, lines.w),
    ]
    return patches, off + n


def kept_lines(n: int) -> np.ndarray:
    """Lines 0, 2, 4, ... of n + 1 lines, and the last one."""
    keep = np.arange(0, n + 1, 2)
    return keep if keep[-1] == n else np.append(keep, n)


def coarsen(patches: list[Patch], n_fine: int) -> tuple[Level, list[Patch]]:
    """The prolongation to these patches' nodes from their every-second-line grid, and it."""
    chosen = [ids[np.ix_(kept_lines(len(s) - 1), kept_lines(len(t) - 1))] for ids, s, t in patches]
    coarse = np.zeros(n_fine, dtype=bool)
    for c in chosen:
        coarse[c.ravel()] = True
    number = np.cumsum(coarse) - 1  # coarse numbers in the finer numbering's order
    rows, cols, vals = [], [], []
    done = np.zeros(n_fine, dtype=bool)
    out: list[Patch] = []
    for (ids, s, t), c in zip(patches, chosen, strict=True):
        si, ti = kept_lines(len(s) - 1), kept_lines(len(t) - 1)
        cids = number[c]
        out.append((cids, s[si], t[ti]))
        (ki, ws), (kj, wt) = _cell_weights(s, si), _cell_weights(t, ti)
        new = ~done[ids]  # a node on an edge shared with an earlier patch has its row
        done[ids] = True
        for a in (0, 1):
            for b in (0, 1):
                w = np.outer(ws if a else 1.0 - ws, wt if b else 1.0 - wt)
                m = new & (w > 0.0)
                rows.append(ids[m])
                cols.append(cids[np.ix_(ki + a, kj + b)][m])
                vals.append(w[m])
    level = Level(
        np.concatenate(rows),
        np.concatenate(cols),
        np.concatenate(vals),
        n_fine,
        int(coarse.sum()),
        np.flatnonzero(coarse),
    )
    return level, out


def _cell_weights(s: np.ndarray, kept: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    # For every line: the coarse interval it lies in and its linear weight towards the end.
    k = np.clip(np.searchsorted(kept, np.arange(len(s)), side="right") - 1, 0, len(kept) - 2)
    lo, hi = s[kept[k]], s[kept[k + 1]]
    return k, (s - lo) / (hi - lo)


def grid_levels(lines: GridLines, coarsest: int) -> list[Level]:
    """Prolongations from the finest grid down until a grid has at most `coarsest` nodes.

    Finest first; stops early where a patch has fewer than 3 lines left.
    """
    patches, n = grid_patches(lines)
    levels: list[Level] = []
    while n > coarsest and min(min(len(s), len(t)) for _, s, t in patches) >= 3:
        level, patches = coarsen(patches, n)
        levels.append(level)
        n = level.n_coarse
    return levels
