"""Effectivity of the goal estimates (contactfx/adapt/goal.py) on the built-in Hertz scene.

For each mesh: the exact relative L2 pressure error (hertz_summary), the pressure indicator
of adapt/pressure_estimate.py, and the two-level pressure estimate (contact cells halved),
with the raw difference so that other rates can be tried afterwards; with --energy also the
two-level energy estimate (every cell halved) against an overkill solution (every cell
quartered) and the residual estimate. Meshes: ungraded starts (one size along the contact,
--h-far elsewhere, no edge refinement) and the levels of the adaptive loop from the first.

    python benchmarks/goal_effectivity.py --refine 0.4,0.2,0.1,0.05 --adapt-levels 4 \
        --json benchmarks/goal_effectivity.json
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

from contactfx.adapt.estimate import estimate
from contactfx.adapt.goal import Goal, goal_estimate, refined_field
from contactfx.adapt.loop import adapt
from contactfx.adapt.records import AdaptOptions
from contactfx.adapt.true_error import energy_error
from contactfx.api import solve
from contactfx.methods.solution import Solution
from contactfx.request import SolveRequest
from contactfx.results.references import hertz_summary
from contactfx.scenes import HertzParams, hertz, load_scene_file


def measure(
    sol: Solution, seconds: float, energy: bool, label: str, reaches: list[float]
) -> dict[str, Any]:
    """One mesh's row: exact error, the indicator, the goal estimates and their costs."""
    est = estimate(sol)
    exact = hertz_summary(sol).l2_error
    g = goal_estimate(sol, Goal.PRESSURE, reach=reaches[0])
    diff = g.relative * (1.0 - 2.0**-g.rate)
    row: dict[str, Any] = {
        "mesh": label,
        "dofs": sol.dofs,
        "solve_s": seconds,
        "exact_l2": exact,
        "indicator": est.pressure.relative if est.pressure else None,
        "indicator_eff": (est.pressure.relative / exact) if est.pressure else None,
        "two_level": g.relative,
        "two_level_eff": g.relative / exact,
        "difference": diff,
        "eff_r1": diff / 0.5 / exact,
        "eff_r2": diff / 0.75 / exact,
        "refined_exact_l2": hertz_summary(g.reference).l2_error,
        "refined_dofs": g.dofs,
        "refined_s": g.seconds,
        "energy_residual": est.relative,
    }
    for reach in reaches[1:]:
        v = goal_estimate(sol, Goal.PRESSURE, reach=reach)
        row[f"reach_{reach:g}"] = {
            "two_level_eff": v.relative / exact,
            "refined_exact_l2": hertz_summary(v.reference).l2_error,
            "refined_dofs": v.dofs,
            "refined_s": v.seconds,
        }
    if energy:
        ge = goal_estimate(sol, Goal.ENERGY)
        t0 = time.perf_counter()
        over = solve(sol.scene.remeshed_to(refined_field(sol, far=0.25, near=0.25)), sol.method)
        true = sol.scene.comm.bcast(energy_error(sol, over), root=0)["relative"]
        row |= {
            "energy_true": true,
            "overkill_dofs": over.dofs,
            "overkill_s": time.perf_counter() - t0,
            "energy_two_level": ge.relative,
            "energy_two_level_eff": ge.relative / true,
            "energy_ratio": ge.parts["ratio"],
            "energy_r1_eff": ge.parts["difference"] / 0.75**0.5 / true,
            "energy_residual_eff": est.relative / true,
            "energy_refined_dofs": ge.dofs,
            "energy_refined_s": ge.seconds,
        }
    print(
        f"{label}: {row['dofs']} DOFs, exact {100 * exact:.3g} %, indicator eff "
        f"{row['indicator_eff']:.2f}, two-level eff {row['two_level_eff']:.2f} "
        f"(r=1 {row['eff_r1']:.2f}, r=2 {row['eff_r2']:.2f}), cost x "
        f"{row['refined_s'] / seconds:.2f}"
        + "".join(
            f", reach {k[6:]} eff {v['two_level_eff']:.2f}"
            for k, v in row.items()
            if k.startswith("reach_")
        )
        + (
            f", energy eff {row['energy_two_level_eff']:.2f} (r=1 {row['energy_r1_eff']:.2f})"
            if energy
            else ""
        ),
        flush=True,
    )
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--refine", default="0.4,0.2,0.1,0.05", help="contact sizes of the starts")
    ap.add_argument("--h-far", type=float, default=10.0)
    ap.add_argument("--slope", type=float, default=0.3)
    ap.add_argument("--adapt-from", type=float, default=2.0, help="contact size of the start")
    ap.add_argument("--adapt-h-far", type=float, default=2.0)
    ap.add_argument("--adapt-levels", type=int, default=4)
    ap.add_argument("--max-dofs", type=int, default=30000)
    ap.add_argument("--pressure-tol", type=float, default=0.0005)
    ap.add_argument(
        "--energy-max-dofs",
        type=int,
        default=0,
        help="also the energy goal on meshes up to this many DOFs (its overkill: x 16)",
    )
    ap.add_argument("--reach", default="0.5,0,1", help="pressure refined regions (zone lengths)")
    ap.add_argument("--file", default="", help="a scene file with a Hertz reference, too")
    ap.add_argument("--factors", default="1,0.5", help="its mesh sizes times these")
    ap.add_argument("--json", default="benchmarks/goal_effectivity.json")
    args = ap.parse_args()
    rows = []
    reaches = [float(v) for v in args.reach.split(",")]
    for r in (float(v) for v in args.refine.split(",") if v and v != "none"):
        params = HertzParams(refine=r, h_far=args.h_far, refine_edge=0.0, slope=args.slope)
        t0 = time.perf_counter()
        sol = solve(hertz(params), "mortar")
        rows.append(
            measure(
                sol,
                time.perf_counter() - t0,
                sol.dofs <= args.energy_max_dofs,
                f"start refine {r:g}",
                reaches,
            )
        )
    for f in (float(v) for v in args.factors.split(",") if args.file and v):
        t0 = time.perf_counter()
        scene = load_scene_file(args.file)
        sol = solve(scene if f == 1.0 else scene.remeshed(f), "mortar")
        seconds = time.perf_counter() - t0
        label = f"{args.file} x {f:g}"
        rows.append(measure(sol, seconds, sol.dofs <= args.energy_max_dofs, label, reaches))
    if args.adapt_levels > 0:
        params = HertzParams(
            refine=args.adapt_from, h_far=args.adapt_h_far, refine_edge=0.0, slope=args.slope
        )
        # The residual goal's loop with the pressure sizing (its levels are the meshes).
        opts = AdaptOptions(
            Goal.RESIDUAL,
            tol=0.001,
            max_dofs=args.max_dofs,
            max_levels=args.adapt_levels,
            growth=1.5,
            contact_weight=1.0,
            pressure_tol=args.pressure_tol,
        )
        res = adapt(hertz(params), SolveRequest.parse("mortar"), opts, say=lambda line: None)
        for lv in res.levels:
            seconds = lv.time
            rows.append(
                measure(
                    lv.solution,
                    seconds,
                    lv.dofs <= args.energy_max_dofs,
                    f"adaptive level {lv.index}",
                    reaches,
                )
            )
    with open(args.json, "w") as f:
        json.dump({"settings": vars(args), "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
