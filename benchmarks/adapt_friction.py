"""adapt on a frictional scene: the pressure goal's and the shear's estimates against the truth.

tests/scenes/cattaneo_mirrored.toml (two mirrored half-cylinders pressed, then pushed to
Q / mu P = 0.62; mortar) at size factor F (every element size of the .geo times F), adapted
on the pressure goal for up to L levels with no tolerance (the budget and the levels decide).
Per level: DOFs, the pressure goal's estimate and the pressure's true relative L2 error
(against Hertz's pressure under the pair's force: Cattaneo-Mindlin's), the shear's two-level
estimate (reported by adapt, not bounded) and its true error (Cattaneo-Mindlin's closed
form), their effectivities, and the residual estimate. docs/adapt.md, "With friction"
(the machine was shared; about 1.5 min at factor 4 and 8 min at factor 1 on one core):

    OPENBLAS_NUM_THREADS=1 python benchmarks/adapt_friction.py --factors 4 --levels 3 \
        --json benchmarks/adapt_friction_f4.json
    OPENBLAS_NUM_THREADS=1 python benchmarks/adapt_friction.py --factors 1 --levels 3 \
        --json benchmarks/adapt_friction_f1.json
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import dolfinx_solver  # noqa: F401  (before dolfinx)

from contactfx.adapt.loop import adapt
from contactfx.adapt.records import AdaptOptions
from contactfx.request import SolveRequest
from contactfx.scenes.scene_file import load_scene_file

SCENE = Path(__file__).resolve().parents[1] / "tests" / "scenes" / "cattaneo_mirrored.toml"


def run(factor: float, levels: int, max_dofs: int) -> list[dict[str, Any]]:
    """The adaptive levels from the scene at `factor`: estimates, true errors, ratios."""
    scene = load_scene_file(SCENE, size_factor=factor)
    opts = AdaptOptions(tol=None, max_levels=levels, max_dofs=max_dofs)
    result = adapt(scene, SolveRequest.parse("mortar"), opts)
    rows = []
    for lv in result.levels:
        g = lv.goal
        assert g is not None
        p_true, s_true = lv.exact_error, lv.exact_shear_error
        rows.append(
            {
                "factor": factor,
                "level": lv.index,
                "dofs": lv.dofs,
                "pressure_estimate": g.relative,
                "pressure_error": p_true,
                "pressure_effectivity": g.relative / p_true if p_true else None,
                "shear_estimate": g.shear_estimate,
                "shear_error": s_true,
                "shear_effectivity": (g.shear_estimate or 0.0) / s_true if s_true else None,
                "residual": lv.est.relative,
                "tangential_term": lv.est.summary().terms["tangential"],
                "refined_dofs": g.dofs,
            }
        )
    return rows


def main() -> None:
    """Run the factors and write the JSON."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--factors", type=float, nargs="+", default=[4.0])
    ap.add_argument("--levels", type=int, default=3)
    ap.add_argument("--max-dofs", type=int, default=200_000)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    rows = [r for f in args.factors for r in run(f, args.levels, args.max_dofs)]
    for r in rows:
        print(
            f"F {r['factor']:g} level {r['level']}: {r['dofs']} DOFs, pressure est "
            f"{100 * r['pressure_estimate']:.3g} % true {100 * r['pressure_error']:.3g} % "
            f"(eff {r['pressure_effectivity']:.2f}), shear est {100 * r['shear_estimate']:.3g} % "
            f"true {100 * r['shear_error']:.3g} % (eff {r['shear_effectivity']:.2f}), "
            f"residual {100 * r['residual']:.3g} %"
        )
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
