"""The cost of first-touching memory on this machine (docs/scale.md, "Cold memory").

`python benchmarks/cold_memory.py 16`: creates and keeps N arrays of 1 GB (each timed: the
first touch of its pages, then a rewrite), frees them, and creates three more that reuse
the freed pages. On a machine whose free memory is handed back to a hypervisor the first
touch costs seconds per GB; a reuse and a rewrite cost a tenth of a second or less.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

GB = 125_000_000  # float64 entries in 1 GB


def main() -> None:
    """Print the time of each 1 GB first touch, rewrite and reuse."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gb", type=int, nargs="?", default=4, help="GB to keep (default 4)")
    args = parser.parse_args()
    keep = []
    for i in range(args.gb):
        t = time.perf_counter()
        a = np.ones(GB)
        first = time.perf_counter() - t
        keep.append(a)
        t = time.perf_counter()
        a[:] = 2.0
        print(f"GB {i + 1}: first touch {first:.3f} s, rewrite {time.perf_counter() - t:.3f} s")
    del keep, a
    for _ in range(3):
        t = time.perf_counter()
        b = np.ones(GB)
        print(f"reuse of freed pages: {time.perf_counter() - t:.3f} s")
        del b


if __name__ == "__main__":
    main()
