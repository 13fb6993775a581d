"""The structured Hertz grid's partition: made per rank (`hertz_grid_part`) against the strips
of the former partitioner (`body_strips` on the whole grid's cell midpoints), for P parts.

Per P, serially on the whole grid (`hertz_grid`, accurate family `--refine H --h-far 10H`):
each body's cells per part (min-max); the contact facets of each body (x <= R/4, the tagged
contact lines): how many parts hold them and the most on one part; the facets cut between
parts; the most neighbours of a part.

    python benchmarks/structured_partition.py [H] [--parts 2,4,8,16,64,256]

docs/scale.md ("Setup") cites its output.
"""

from __future__ import annotations

import argparse

import numpy as np

from contactfx.meshes import hertz_grid, hertz_grid_part
from contactfx.scenes.partition import body_strips

R = WIDTH = HEIGHT = 60.0


def quality(cells: np.ndarray, x: np.ndarray, n_block: int, dest: np.ndarray, P: int) -> dict:
    """Balance, contact facets per part, cut facets and neighbours of the partition `dest`."""
    body = (np.arange(len(cells)) >= n_block).astype(int)
    edges = cells[:, [0, 1, 1, 3, 3, 2, 2, 0]].reshape(-1, 2)
    owner = np.repeat(np.arange(len(cells)), 4)
    key = np.sort(edges, axis=1) @ np.array([len(x), 1])
    order = np.argsort(key, kind="stable")
    key, owner, edges = key[order], owner[order], edges[order]
    twice = np.flatnonzero(key[1:] == key[:-1])  # interior facets: cells owner[k], owner[k + 1]
    a, b = dest[owner[twice]], dest[owner[twice + 1]]
    cut = a != b
    neighbours = max(len(set(b[cut & (a == p)]) | set(a[cut & (b == p)])) for p in range(P))
    once = np.ones(len(key), dtype=bool)
    once[twice] = once[twice + 1] = False
    ex = edges[once]
    mid = x[ex].mean(axis=1)
    in_block = body[owner[once]] == 0
    top = in_block & (x[ex][:, :, 1] == HEIGHT).all(axis=1)
    radius = np.hypot(x[ex][:, :, 0], x[ex][:, :, 1] - HEIGHT - R)
    arc = ~in_block & (np.abs(radius - R) <= 1e-10 * R).all(axis=1)
    near = mid[:, 0] <= R / 4
    contact = [np.bincount(dest[owner[once][m & near]], minlength=P) for m in (top, arc)]
    counts = [np.bincount(dest[body == k], minlength=P) for k in (0, 1)]
    return {
        "cells": [f"{c.min()}-{c.max()}" for c in counts],
        "contact": [f"{c.sum()} on {(c > 0).sum()} parts, <= {c.max()}" for c in contact],
        "cut": int(cut.sum()),
        "neighbours": neighbours,
    }


def main() -> None:
    """Both partitions for each P."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("h", nargs="?", type=float, default=0.0384)
    ap.add_argument("--parts", default="2,4,8,16,64,256")
    args = ap.parse_args()
    grid = (R, WIDTH, HEIGHT, args.h, 2.0, 10 * args.h, 0.1)
    x, cells, n_block = hertz_grid(*grid)
    print(f"{2 * len(x)} DOFs, {len(cells)} cells ({n_block} in the block)")
    index = {c: k for k, c in enumerate(map(tuple, np.sort(cells, axis=1).tolist()))}
    for P in map(int, args.parts.split(",")):
        strips = np.zeros(len(cells), dtype=np.int64)
        mid = x[cells].mean(axis=1)
        body_strips(strips, (np.arange(len(cells)) >= n_block).astype(int), mid, P)
        made = np.zeros(len(cells), dtype=np.int64)
        for p in range(P):
            part = hertz_grid_part(*grid, p, P)
            made[[index[c] for c in map(tuple, np.sort(part.cells, axis=1).tolist())]] = p
        for name, dest in (("strips (before)", strips), ("per rank (now)", made)):
            print(P, name, quality(cells, x, n_block, dest, P), flush=True)


if __name__ == "__main__":
    main()
