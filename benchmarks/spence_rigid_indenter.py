"""Spence against a frictional solve: a rigid cylinder pressed with mu into a block, step by step.

demos/scenes/spence_indenter.toml (the block of rigid_indenter.toml, E = 7000, nu = 0.3, plane
strain, half model, h = 0.015 on the top; a rigid cylinder R = 200 with mu = 0.3 moved 0.005
down in 15 load steps growing the contact by ~1.1 each) through its own `[[reference]] type =
"spence"`: per step the contact half-width a and the stick half-width c from the statuses, c/a
against spence_stick_ratio(0.3, 0.3) = 0.689, and c - 0.689 a in contact cells. Three variants
show what moves the answer away from Spence's:

- `spence`: the scene as it is (a/R <= 0.0033: the theory's regime);
- `R20`: the cylinder of rigid_indenter.toml (R = 20, moved 0.05 in the same steps: the same
  a, a/R ten times larger, to 0.033);
- `equal`: R = 200 moved in 15 equal steps (the contact grows by 1.48, 1.27, ... 1.04).

    OPENBLAS_NUM_THREADS=1 python benchmarks/spence_rigid_indenter.py \
        --json benchmarks/spence_rigid_indenter.json

(about two minutes on one loaded core: nts, mortar and dual mortar on each variant) prints the
per-step table and writes it; `--table benchmarks/spence_rigid_indenter.json` prints
docs/friction.md's table from the recorded runs.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

from contactfx import SolveRequest, load_scene_file
from contactfx.api import run_scene
from contactfx.scenes import Scene

SCENE = Path(__file__).resolve().parents[1] / "demos" / "scenes" / "spence_indenter.toml"
METHODS = [("nts", "standard"), ("mortar", "standard"), ("mortar", "dual")]


def variant(name: str) -> Scene:
    """The scene of variant `name` (spence, R20, equal)."""
    scene = load_scene_file(SCENE)
    ob = scene.obstacles[0]
    if name == "R20":
        d = tuple(10.0 * v for v in ob.displacement)
        ob = replace(ob, center=(0.0, 20.0), radius=20.0, displacement=(d[0], d[1]))
        return replace(scene, obstacles=(ob,))
    if name == "equal":
        n = len(scene.steps)
        return replace(scene, steps=tuple({"indenter": (k + 1) / n} for k in range(n)))
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
    parser.add_argument("--variants", default="spence,R20,equal")
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
