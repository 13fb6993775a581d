"""The condensed loop's loose solves from a warm start: CG iterations and final accuracy.

For each WARM_REDUCTION (the least reduction of a warm-started loose solve's own residual;
`linalg/condensed.py`; 1e-4 reproduces the rule before issue 33, which reduced it by the
loose tolerance itself) and final tolerance, the whole condensed loop on small Hertz scenes,
with the coarse predictor (`auto`) and without it (`none`): CG iterations per active-set
step, and the largest pressure and displacement differences from MUMPS' saddle-point answer
(an independent solver of the same equations; same active set asked). One process, serial:

    python benchmarks/warm_reduction.py [--warm 1e-4,1e-2,1e-1] [--rtol 1e-9,1e-10]

docs/scale.md ("Release steps") cites its output.
"""

from __future__ import annotations

import argparse
from dataclasses import replace

import numpy as np
from mpi4py import MPI

import contactfx.linalg.condensed as condensed
from contactfx import solve
from contactfx.options import SOLVERS
from contactfx.scenes import HertzParams, Scene, build_scene, hertz


def cases() -> list[tuple[str, Scene, str, str]]:
    """(name, scene, method, basis): the default gmsh Hertz and two structured ones."""
    comm = MPI.COMM_SELF
    s50 = hertz(HertzParams(refine=0.08, h_far=0.8, mesh="structured"), comm=comm)
    s100 = hertz(HertzParams(refine=0.054156, h_far=0.54156, mesh="structured"), comm=comm)
    return [
        ("gmsh default, nts", build_scene("hertz", HertzParams(), comm=comm), "nts", "standard"),
        ("structured 50k, nts", s50, "nts", "standard"),
        ("structured 50k, dual", s50, "mortar", "dual"),
        ("structured 100k, dual", s100, "mortar", "dual"),
    ]


def main() -> None:
    """Print one line per (scene, predictor, WARM_REDUCTION, final rtol)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--warm", default="1e-4,1e-2,1e-1")
    ap.add_argument("--rtol", default="1e-9,1e-10")
    args = ap.parse_args()
    warms = [float(w) for w in args.warm.split(",")]
    rtols = [float(r) for r in args.rtol.split(",")]
    for name, scene, method, basis in cases():
        ref = solve(scene, method, basis=basis, solver="mumps")
        p_scale = np.abs(ref.pressure).max()
        u_scale = np.abs(ref.u.x.array).max()
        for warm in warms:
            condensed.WARM_REDUCTION = warm
            for rtol in rtols:
                spec = replace(SOLVERS["condensed"], rtol=rtol)
                for predictor in ("auto", "none"):
                    sol = solve(scene, method, basis=basis, solver=spec, predictor=predictor)
                    its = [int(h["linear_iterations"]) for h in sol.history]
                    dp = np.abs(sol.pressure - ref.pressure).max() / p_scale
                    du = np.abs(sol.u.x.array - ref.u.x.array).max() / u_scale
                    same = np.array_equal(sol.active, ref.active)
                    print(
                        f"{name:22s} {predictor:4s} warm {warm:.0e} rtol {rtol:.0e}: "
                        f"same set {same}, pressure {dp:.1e}, u {du:.1e}, "
                        f"CG its {its} = {sum(its)}",
                        flush=True,
                    )


if __name__ == "__main__":
    main()
