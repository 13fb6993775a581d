"""Cattaneo-Mindlin on mirrored meshes: a convergence table for mortar and nts.

tests/scenes/cattaneo_mirrored.toml: two identical half-cylinders (R = 1, E = 1000, nu = 0.3,
mu = 0.3), the lower mesh the upper one's mirror image node for node, pressed by a rigid flat
face (a = 0.0996), then pushed (Q / mu P = 0.62). Each size factor scales every element size
of the .geo (h = 0.0005 on the contact at factor 1, a/h = 200). Per run: DOFs, a/h, the
stick half-width's offset from c in contact cells (signed: negative is narrower), the shear's
relative L2 error (`cattaneo_errors`, the scene's own `[[reference]] type = "cattaneo"`), the
slip law on the slip nodes, step 1's shear (the locked-in shear the mirror removes), the
interpolation floor (the L2 error of the closed form's own nodal values, interpolated as the
computed shear is), the solve's wall time and the Newton (active-set) iterations per step.
The table of docs/friction_verification.md (about four minutes on one core; the machine was shared):

    OPENBLAS_NUM_THREADS=1 python benchmarks/cattaneo_mirrored.py \
        --factors 4 2 1 0.7 --json benchmarks/cattaneo_mirrored.json
    python benchmarks/cattaneo_mirrored.py --table benchmarks/cattaneo_mirrored.json
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from contactfx import solve
from contactfx.results.cattaneo import cattaneo_checks
from contactfx.results.friction_references import cattaneo_errors, cattaneo_mindlin
from contactfx.results.references import centre_distance
from contactfx.scenes import CattaneoReference, HertzReference
from contactfx.scenes.scene_file import load_scene_file

SCENE = Path(__file__).resolve().parents[1] / "tests" / "scenes" / "cattaneo_mirrored.toml"


def run(factor: float, method: str) -> dict[str, Any]:
    """One solve of the scene at `factor` with `method`, and its Cattaneo-Mindlin errors."""
    scene = load_scene_file(SCENE, size_factor=factor)
    t0 = time.perf_counter()
    sol = solve(scene, method)
    wall = time.perf_counter() - t0
    (chk,) = cattaneo_checks(sol)[0]
    (ref,) = [r for r in scene.references if isinstance(r, CattaneoReference)]
    cm = cattaneo_mindlin(chk.P, min(chk.Q, chk.mu * chk.P), chk.mu, ref.R, chk.E_star)
    r, p, _, _, _ = centre_distance(sol, HertzReference(ref.pair, ref.R))
    floor = cattaneo_errors(cm, r, cm.shear(r), p, np.zeros(r.size, dtype=bool)).shear_l2
    return {
        "factor": factor,
        "method": method,
        "dofs": sol.dofs,
        "h": chk.h,
        "a": chk.a_exact,
        "a_over_h": chk.a_exact / chk.h,
        "Q_over_muP": chk.Q / (chk.mu * chk.P),
        "c_exact": chk.c_exact,
        "c": chk.c,
        "c_offset_cells": (chk.c - chk.c_exact) / chk.h,
        "shear_l2": chk.shear_l2,
        "interpolation_floor": floor,
        "slip_law": chk.slip_law,
        "approach_shear": chk.approach_shear,
        "iterations": [s.iterations for s in sol.steps],
        "wall_s": wall,
    }


def table(rows: list[dict[str, Any]]) -> str:
    """The markdown table of docs/friction_verification.md."""
    head = (
        "| method | size factor | DOFs | $a/h$ | stick half-width $-\\, c$ | shear $L^2$ error "
        "| interpolation floor | slip law | step 1 shear | iterations | time |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|\n"
    )
    lines = [
        f"| {r['method']} | {r['factor']:g} | {r['dofs']} | {r['a_over_h']:.0f} "
        f"| {r['c_offset_cells']:+.2f} cells | {100 * r['shear_l2']:.2f} % "
        f"| {100 * r['interpolation_floor']:.2f} % | {r['slip_law']:.0e} "
        f"| {100 * r['approach_shear']:.2f} % | {' + '.join(map(str, r['iterations']))} "
        f"| {r['wall_s']:.1f} s |"
        for r in rows
    ]
    return head + "\n".join(lines)


def main() -> None:
    """Run the factors (or print a recorded table)."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--factors", type=float, nargs="+", default=[4.0, 2.0, 1.0])
    ap.add_argument("--methods", nargs="+", default=["mortar", "nts"])
    ap.add_argument("--json", type=Path, help="write the runs here")
    ap.add_argument("--table", type=Path, help="print the table of a recorded JSON and stop")
    args = ap.parse_args()
    if args.table is not None:
        print(table(json.loads(args.table.read_text())["runs"]))
        return
    rows = []
    for factor in args.factors:
        for method in args.methods:
            rows.append(run(factor, method))
            print(table(rows[-1:]).splitlines()[-1], flush=True)
    if args.json is not None:
        args.json.write_text(json.dumps({"scene": str(SCENE.name), "runs": rows}, indent=1) + "\n")
    print(table(rows))


if __name__ == "__main__":
    main()
