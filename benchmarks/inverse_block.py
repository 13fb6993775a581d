"""A/B of the selected inverse's block size (MUMPS ICNTL(27)) on the probe step.

`python benchmarks/inverse_block.py CASE [BLOCK ...]` solves the Hertz case CASE with mortar,
the blocks alternating in one process (default: contactfx's two, 64 and 256), twice, and
prints the first active-set step (factorization + probes) per block. The comment at
`contactfx.linalg.mumps.LARGE_BLOCK` quotes its numbers.
"""

from __future__ import annotations

import sys

import contactfx.linalg.mumps as mumps
from contactfx import SolveRequest
from contactfx.api import run_case
from contactfx.scenes import HertzParams

CASES = {
    "gmsh-10H-20k": HertzParams(refine=0.074, refine_edge=0.0185, h_far=0.74),
    "gmsh-default-45k": HertzParams(refine=0.0025),
    "gmsh-default-86k": HertzParams(refine=0.00125),
    "structured-10H-300k": HertzParams(mesh="structured", refine=0.02891, h_far=0.2891),
    "structured-default-584k": HertzParams(mesh="structured", refine=0.00125),
}


def main() -> None:
    """Run one case with each block size in turn, twice."""
    name = sys.argv[1]
    blocks = [int(b) for b in sys.argv[2:]] or [64, 256]
    for _ in range(2):
        for block in blocks:
            mumps.inverse_block = lambda n, block=block: block  # the rule, replaced
            _, data = run_case("hertz", CASES[name], SolveRequest.parse("mortar"))
            data = data.to_json()
            first = data["active_set"][0]
            print(
                f"{name} {data['dofs']} dofs, ICNTL(27) {block}: {first['probes']} probes, "
                f"first step {first['solve_time']:.3f} s",
                flush=True,
            )


if __name__ == "__main__":
    main()
