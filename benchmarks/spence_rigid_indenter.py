"""Spence against a frictional solve: a rigid cylinder pressed with mu into a block, step by step.

demos/scenes/spence_indenter.toml (a block 100 x 100, E = 7000, nu = 0.3, plane strain, half
model, h = 0.015 on the top; a rigid cylinder R = 200 with mu = 0.3 moved 0.007 down in 28 load
steps growing the contact by ~1.05 each) through its own `[[reference]] type = "spence"`: per
step the contact half-width a and the stick half-width c from the statuses, c/a against
spence_stick_ratio(0.3, 0.3) = 0.689, and c - 0.689 a in contact cells. Variants show what
moves the answer away from Spence's:

- `spence`: the scene as it is (a/R <= 0.0034, a/H <= 0.007: the theory's regime);
- `steps1.1`: 15 steps growing the contact by ~1.1 each (factors 1.1^(2 (k - 15)));
- `equal`: 28 equal steps of the approach (the contact grows by 1.41, 1.22, ... 1.02);
- `R20`: R = 20, moved 0.07 in the scene's steps (the same a, a/R ten times larger, to 0.034);
- `block20`: the 20 x 20 block of rigid_indenter.toml (meshes/rigid_block.geo), moved 0.005
  (the same a, a/H up to 0.034).

    OPENBLAS_NUM_THREADS=1 python benchmarks/spence_rigid_indenter.py \
        --json benchmarks/spence_rigid_indenter.json

(about five minutes on the shared 2-core machine: nts, mortar and dual mortar on each variant)
prints the per-step tables and writes them; `--table benchmarks/spence_rigid_indenter.json`
prints them from the recorded runs.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

from contactfx import SolveRequest, load_scene_file
from contactfx.api import run_scene
from contactfx.scenes import Scene

SCENE = Path(__file__).resolve().parents[1] / "demos" / "scenes" / "spence_indenter.toml"
METHODS = [("nts", "standard"), ("mortar", "standard"), ("mortar", "dual")]


def variant(name: str) -> Scene:
    """The scene of variant `name` (spence, steps1.1, equal, R20, block20)."""
    text = SCENE.read_text().replace('"../../meshes/', f'"{SCENE.parents[2] / "meshes"}/')
    if name == "block20":
        text = text.replace("spence_block.geo", "rigid_block.geo")
        text = text.replace("displacement = [0.0, -0.007]", "displacement = [0.0, -0.005]")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "spence.toml"
        path.write_text(text)
        scene = load_scene_file(path)
    n = len(scene.steps)
    if name == "steps1.1":
        return replace(scene, steps=tuple({"indenter": 1.1 ** (2 * (k - 14))} for k in range(15)))
    if name == "equal":
        return replace(scene, steps=tuple({"indenter": (k + 1) / n} for k in range(n)))
    if name == "R20":
        ob = scene.obstacles[0]
        d = tuple(10.0 * v for v in ob.displacement)
        ob = replace(ob, center=(0.0, 20.0), radius=20.0, displacement=(d[0], d[1]))
        return replace(scene, obstacles=(ob,))
    return scene


def measure(name: str, method: str, basis: str) -> list[dict[str, float]]:
    """Each step's Spence check (a, c, h, c/a, offset in cells, a/R) and its iterations."""
    _, run = run_scene(variant(name), SolveRequest.parse(method, basis=basis))
    rows = []
    for step in run.steps:
        c = step.spence[0]
        rows.append(
            {
                "a": c.a,
                "c": c.c,
                "h": c.h,
                "ratio": c.ratio,
                "ratio_exact": c.ratio_exact,
                "offset_cells": c.offset_cells,
                "a_over_R": c.a / c.R,
                "iterations": step.iterations,
            }
        )
    return rows


def table(results: dict[str, dict[str, list[dict[str, float]]]]) -> None:
    """Per variant: one row per step, c/a and the offset in cells per method."""
    for name, runs in results.items():
        labels = list(runs)
        print(f"\n{name}: " + ", ".join(labels))
        print("| step | a/h | a/R | " + " | ".join(f"{m} c/a (cells)" for m in labels) + " |")
        print("|---|---|---|" + "---|" * len(labels))
        first = runs[labels[0]]
        for k in range(len(first)):
            cells = " | ".join(
                f"{runs[m][k]['ratio']:.3f} ({runs[m][k]['offset_cells']:+.2f})" for m in labels
            )
            r = first[k]
            print(f"| {k + 1} | {r['a'] / r['h']:.1f} | {r['a_over_R']:.4f} | {cells} |")
        for m in labels:
            later = [abs(r["offset_cells"]) for r in runs[m][1:]]
            its = [int(r["iterations"]) for r in runs[m]]
            print(f"{m}: largest |offset| after step 1 {max(later):.2f} cells, iterations {its}")


def main() -> None:
    """Run every variant and method (or print the recorded table)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, help="write the runs here")
    parser.add_argument("--table", type=Path, help="print the table of a recorded JSON")
    parser.add_argument("--variants", default="spence,steps1.1,equal,R20,block20")
    args = parser.parse_args()
    if args.table is not None:
        table(json.loads(args.table.read_text())["results"])
        return
    results: dict[str, dict[str, list[dict[str, float]]]] = {}
    for name in args.variants.split(","):
        results[name] = {}
        for method, basis in METHODS:
            label = method if basis == "standard" else f"{method}-{basis}"
            results[name][label] = measure(name, method, basis)
            print(f"{name} {label} done", file=sys.stderr)
    table(results)
    if args.json is not None:
        args.json.write_text(json.dumps({"scene": str(SCENE.name), "results": results}, indent=1))


if __name__ == "__main__":
    main()
