"""The condensed solver's first set from the coarse predictor, the former rule against the sharp.

For each case, one condensed solve (`--solver condensed`, predictor auto): the rows of the
former rule's set (every fine node within half a coarse element of a coarse active node) and
of the sharp one (zone edges from the coarse pressures, `contact.zone`), each with how many
rows it has too many (wide) or too few (narrow) against the converged set, and the loop's
sets, CG iterations and the seconds of `solve`. Serial or under mpirun; the code before
issue 33 from `git archive 7828a8d contactfx | tar -x -C /tmp/old`, run from outside the
work tree with PYTHONPATH=/tmp/old (its own rule only):

    python benchmarks/first_set.py [--cases s150,g250,...]

docs/scale.md ("An exact first set") cites its output.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

import contactfx.methods.predictor as predictor
from contactfx import solve
from contactfx.scenes import BLOCK_SCENES, HertzParams, Scene, build_scene, hertz
from contactfx.scenes.scene_file import load_scene_file

SCENES = Path(__file__).resolve().parents[1] / "tests" / "scenes"
# name: (scene kind, size, method, basis); a structured / gmsh Hertz of the 10H family
# (refine H, h_far 10 H), the default gmsh Hertz ("default") and its --refine 0.005, the
# paper's blocks, or a scene file of tests/scenes.
CASES = {
    "s150": ("structured", 0.045, "mortar", "dual"),
    "s250": ("structured", 0.031734, "mortar", "dual"),
    "s250-nts": ("structured", 0.031734, "nts", "standard"),
    "s600": ("structured", 0.02, "mortar", "dual"),
    "s1m": ("structured", 0.015867, "mortar", "dual"),
    "g150-nts": ("gmsh", 0.045, "nts", "standard"),
    "g250": ("gmsh", 0.031734, "mortar", "dual"),
    "g250-nts": ("gmsh", 0.031734, "nts", "standard"),
    "g600-nts": ("gmsh", 0.02, "nts", "standard"),
    "g1m-nts": ("gmsh", 0.015867, "nts", "standard"),
    "default": ("default", 0.0, "mortar", "dual"),
    "default-nts": ("default", 0.0, "nts", "standard"),
    "r005": ("r005", 0.0, "mortar", "dual"),
    "r005-nts": ("r005", 0.0, "nts", "standard"),
    "S1": ("S1", 0.0, "mortar", "dual"),
    "S4": ("S4", 0.0, "mortar", "dual"),
    "axi_punch": ("axi_punch", 0.0, "nts", "standard"),
    "two_cylinders": ("two_cylinders", 0.0, "nts", "standard"),
    "two_cylinders-dual": ("two_cylinders", 0.0, "mortar", "dual"),
    "rotated_hertz": ("rotated_hertz", 0.0, "nts", "standard"),
    "axi_sphere": ("axi_sphere", 0.0, "nts", "standard"),
}


def scene_of(kind: str, size: float) -> Scene:
    """The scene of a case."""
    comm = MPI.COMM_WORLD
    if kind in ("structured", "gmsh"):
        return hertz(HertzParams(refine=size, h_far=10 * size, mesh=kind), comm=comm)
    if kind in ("default", "r005"):
        params = HertzParams() if kind == "default" else HertzParams(refine=0.005)
        return build_scene("hertz", params, comm=comm)
    if kind in BLOCK_SCENES:
        return build_scene("blocks", BLOCK_SCENES[kind], comm=comm)
    return load_scene_file(SCENES / f"{kind}.toml", comm)


def run(name: str) -> str:
    """One case's line."""
    kind, size, method, basis = CASES[name]
    scene = scene_of(kind, size)
    caught: dict[str, predictor.InitialSet] = {}
    # The code before issue 33 (on PYTHONPATH, to compare) has no `initial_set`: its
    # predictor calls coarse_initial_set, spied on instead (no sharp rule to report).
    hook = "initial_set" if hasattr(predictor, "initial_set") else "coarse_initial_set"
    chosen = getattr(predictor, hook)
    former = predictor.coarse_initial_set

    def spy(coarse, *args, **kwargs):  # type: ignore[no-untyped-def]
        caught["former"] = former(coarse, margin=0.5)
        if hook == "initial_set":
            caught["sharp"] = predictor.sharp_initial_set(coarse, args[1])
        return chosen(coarse, *args, **kwargs)

    setattr(predictor, hook, spy)
    try:
        MPI.COMM_WORLD.Barrier()
        t0 = time.perf_counter()
        sol = solve(scene, method, basis=basis, solver="condensed")
        seconds = time.perf_counter() - t0
    finally:
        setattr(predictor, hook, chosen)
    conv = np.asarray(sol.active, dtype=bool)
    words = [f"{name:20s} {sol.dofs:9d} DOFs, converged {int(conv.sum())}"]
    for rule in caught:
        got = np.asarray(caught[rule].active(sol.layout.x), dtype=bool)
        wide, narrow = int((got & ~conv).sum()), int((conv & ~got).sum())
        words.append(f"{rule} {int(got.sum())} (+{wide} -{narrow})")
    sets = [int(h["active"]) for h in sol.history]
    its = [int(h["linear_iterations"]) for h in sol.history]
    words.append(f"sets {sets} CG {its} = {sum(its)}, {seconds:.2f} s")
    return ", ".join(words)


def main() -> None:
    """Print one line per case (rank 0)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES))
    for name in ap.parse_args().cases.split(","):
        line = run(name)
        if MPI.COMM_WORLD.rank == 0:
            print(line, flush=True)


if __name__ == "__main__":
    main()
