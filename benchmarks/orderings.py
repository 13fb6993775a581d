"""MUMPS' fill-reducing orderings (ICNTL(7)) on the final Hertz saddle point, both meshers.

`python benchmarks/orderings.py [--sizes gmsh:0.074,structured:0.02891,...] [--repeats R]`
meshes each case once, then for each ordering in turn solves it with mortar and the default
solver (MUMPS LDL^T) with `--reference-timing`: a fresh LDL^T and a fresh LU of the final
system with that ordering, after the contact solve in the same process (warm). The orderings
take turns (R rounds), so none is always the first. Prints one line per solve and a median
table; the comment at `contactfx.methods.solvers.PORD_FROM_DOFS` and docs/scale.md cite it.
"""

from __future__ import annotations

import argparse
import statistics
import time

from mpi4py import MPI

from contactfx import SolveRequest
from contactfx.api import run_scene
from contactfx.options import solver_spec
from contactfx.scenes import HertzParams
from contactfx.scenes.builtin import build_scene

ORDERINGS = {0: "AMD", 3: "SCOTCH", 4: "PORD", 5: "METIS", 6: "QAMD"}
# --refine H (gmsh also --refine-edge H/4) with --h-far 10H: 20k, 80k, 300k (and 1.2M) DOFs.
DEFAULT_SIZES = (
    "gmsh:0.074,gmsh:0.0368,gmsh:0.0183,structured:0.112,structured:0.0578,structured:0.0289,"
    "structured:0.01445"
)


def params(mesher: str, h: float) -> HertzParams:
    """The sweep's 10H family at cell size h."""
    edge = h / 4 if mesher == "gmsh" else 0.0
    return HertzParams(mesh=mesher, refine=h, refine_edge=edge, h_far=10 * h)


def main() -> None:
    """Run the sweep and print the per-ordering medians."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default=DEFAULT_SIZES)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--orderings", default=",".join(str(k) for k in ORDERINGS))
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    orderings = [int(k) for k in args.orderings.split(",")]
    rows = []
    for item in args.sizes.split(","):
        mesher, h = item.split(":")
        scene = build_scene("hertz", params(mesher, float(h)), comm=comm)
        times: dict[int, dict[str, list[float]]] = {k: {} for k in orderings}
        dofs = 0
        for r in range(args.repeats):
            order = orderings[r % len(orderings) :] + orderings[: r % len(orderings)]
            for k in order:
                spec = solver_spec("mumps").with_petsc([f"mat_mumps_icntl_7={k}"])
                t0 = time.perf_counter()
                _, data = run_scene(
                    scene, SolveRequest.parse("mortar", solver=spec, reference_timing=True)
                )
                data = data.to_json()
                t = data["times"]
                dofs = data["dofs"]
                got = {
                    "solve": t["solve"],
                    "ldlt": t["reference_ldlt"],
                    "lu": t["reference_lu"],
                }
                for key, val in got.items():
                    times[k].setdefault(key, []).append(val)
                if comm.rank == 0:
                    print(
                        f"{mesher} {dofs} {ORDERINGS.get(k, k)}: contact solve "
                        f"{got['solve']:.3f} s, LDL^T {got['ldlt']:.3f} s, LU {got['lu']:.3f} s "
                        f"({time.perf_counter() - t0:.1f} s)",
                        flush=True,
                    )
        for k in orderings:
            med = {key: statistics.median(v) for key, v in times[k].items()}
            rows.append((mesher, dofs, ORDERINGS.get(k, str(k)), med))
    if comm.rank == 0:
        print("\n| mesh | dofs | ordering | contact solve (s) | fresh LDL^T (s) | fresh LU (s) |")
        print("|---|---|---|---|---|---|")
        for mesher, dofs, name, med in rows:
            print(
                f"| {mesher} | {dofs:,} | {name} | {med['solve']:.3f} | {med['ldlt']:.3f} "
                f"| {med['lu']:.3f} |"
            )


if __name__ == "__main__":
    main()
