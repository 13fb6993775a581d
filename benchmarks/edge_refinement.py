"""Refinement study of a press fit's edge pressure: the peak grows at the corner's exponent.

tests/scenes/press_fit.toml (axisymmetric steel shaft longer than its steel hub, radial
interference 0.001, both hub edges sharp 90-degree corners) meshed with edge cells hc =
0.02, 0.01, 0.005, 0.0025 (the shaft's nodes at the top edge on the hub's end, f_top = 0,
at the bottom edge 0.72 cells beyond it, f_bot = 0.72: the placement of the issue's table).
For every method it reads, from the solve's JSON interface (what a user reads):

- the peak pressure at each edge, and its growth exponent between successive sizes,
  log(p(h/2) / p(h)) / log 2, and over all sizes (least squares of log p on log h), against
  the corner's s = 1 - lam of benchmarks/corner_exponent.py (0.22599);
- the mean pressure over the last `ell` of the hub at each edge (the edge load over a chosen
  length, divided by it): the pressure integrated over y in [H - ell, H] (piecewise linear
  between rows, the last row's value out to the end, where the end rows make it constant).
  It converges, the singularity being integrable.

Writes benchmarks/edge_refinement.json and docs/figures/edge_refinement.png; docs/edges.md
has the table. Exits 1 if a method's fitted exponent is off s by more than 0.05.

`--placements`: instead, at hc = 0.005, the top edge with a node on the hub's end and the
bottom edge with the nearest node f_bot = 0, 0.001, 0.25, 0.5, 0.72, 0.9, 0.999 cells beyond
it: each method's peaks and the largest ratio of the two edges' peaks
(benchmarks/edge_placements.json).

Run: python benchmarks/edge_refinement.py [--placements]   (serial, about a minute each)

benchmarks/edge_refinement_0.10.1.json is this study on 0.10.1's kernels (before the end
rows: `git archive 4ab0f58 contactfx | tar -x -C OLD`, then `PYTHONPATH=OLD python
benchmarks/edge_refinement.py --json benchmarks/edge_refinement_0.10.1.json --chart X.png`):
the top edge grew at 0.222 (mortar), the bottom one read 2,847-3,780 (mortar), 8,462-14,072
(sts), its node inside the hub released.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from corner_exponent import edge_exponent  # benchmarks/ is not a package: on sys.path above

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "tests" / "scenes" / "press_fit.toml"
H = 0.5  # the hub's half length (press_fit.geo)
METHODS = {
    "mortar": ("mortar", "standard"),
    "dual mortar": ("mortar", "dual"),
    "sts": ("sts", "standard"),
    "penalty": ("penalty", "standard"),
    "nts": ("nts", "standard"),
}


def press_fit(tmp: Path, **params: float) -> Any:
    """The press-fit scene with the .geo's constants overridden (DefineConstant keeps them)."""
    from mpi4py import MPI

    from contactfx.scenes.gmsh_io import scene_from_parts
    from contactfx.scenes.scene_file import parse_scene_file

    mesh, parts = parse_scene_file(SCENE)
    geo = tmp / "press_fit.geo"
    geo.write_text("".join(f"{k} = {v!r};\n" for k, v in params.items()) + mesh.read_text())
    return scene_from_parts(geo, parts, MPI.COMM_WORLD)


def edge_values(interface: dict[str, Any], ell: float) -> dict[str, float]:
    """Peak pressure and mean pressure over the last `ell` at the top and bottom edges."""
    y = np.array(interface["y"], dtype=float)
    p = np.array(interface["pressure"], dtype=float)
    out = {}
    for name, sign in (("top", 1.0), ("bottom", -1.0)):
        side = sign * y > 0
        d = H - sign * y[side]  # distance from the hub's end, inwards
        order = np.argsort(d)
        d, q = d[order], p[side][order]
        grid = np.linspace(0.0, ell, 4001)
        mean = float(np.mean(np.interp(grid, d, q)))  # np.interp holds the end value
        out[f"peak_{name}"] = float(q.max())
        out[f"mean_{name}"] = mean
    return out


def slopes(h: np.ndarray, v: np.ndarray) -> tuple[list[float], float]:
    """Growth exponents -dlog v / dlog h between successive sizes and over all of them."""
    local = [-float(np.log(v[k + 1] / v[k]) / np.log(h[k + 1] / h[k])) for k in range(len(h) - 1)]
    fit = -float(np.polyfit(np.log(h), np.log(v), 1)[0])
    return local, fit


def chart(data: dict[str, Any], path: Path) -> None:
    """Peak and mean edge pressure against the edge cell size, log-log, with the slope -s."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    h = np.array(data["hc"])
    s = data["exponent"]
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.4))
    for k, (name, rows) in enumerate(data["methods"].items()):
        colour = f"C{k}"
        a.loglog(h, rows["peak_top"], "o-", color=colour, label=f"{name}, top edge")
        a.loglog(h, rows["peak_bottom"], "s--", color=colour, mfc="none", label="bottom edge")
        b.semilogx(h, rows["mean_top"], "o-", color=colour, label=name)
        b.semilogx(h, rows["mean_bottom"], "s--", color=colour, mfc="none")
    ref = np.array(data["methods"]["nts"]["peak_top"])[0] * 1.15 * (h / h[0]) ** (-s)
    a.loglog(h, ref, "k:", label=f"slope -{s:.3f} (corner eigenvalue)")
    a.set_xlabel("edge cell size hc")
    a.set_ylabel("peak edge pressure")
    a.set_title("Peak pressure: grows as hc^-s")
    a.legend(fontsize=7, ncol=2, loc="lower left")
    b.set_xlabel("edge cell size hc")
    b.set_ylabel(f"mean pressure over the last {data['ell']} of the hub")
    b.set_title("Edge load over a chosen length: converges")
    b.legend(fontsize=7)
    for ax in (a, b):
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


PLACEMENTS = [0.0, 0.001, 0.25, 0.5, 0.72, 0.9, 0.999]


def placements(path: Path) -> int:
    """Both edges' peaks as the shaft's nodes move across the bottom end (hc = 0.005)."""
    from contactfx import SolveRequest, run_scene

    out: dict[str, Any] = {"hc": 0.005, "f_top": 0.0, "f_bot": PLACEMENTS, "methods": {}}
    with tempfile.TemporaryDirectory() as tmp:
        scenes = [press_fit(Path(tmp), hc=0.005, f_top=0.0, f_bot=f) for f in PLACEMENTS]
        for name, (method, basis) in METHODS.items():
            top, bottom = [], []
            for scene in scenes:
                _, summary = run_scene(scene, SolveRequest.parse(method, basis=basis))
                vals = edge_values(summary.to_json()["contacts"][0]["interface"], 0.05)
                top.append(vals["peak_top"])
                bottom.append(vals["peak_bottom"])
            peaks = np.array(top + bottom)
            ratio = float(peaks.max() / peaks.min())
            out["methods"][name] = {"peak_top": top, "peak_bottom": bottom, "max_ratio": ratio}
            row = " ".join(f"{v:6.1f}" for v in bottom)
            span = f"{min(top):6.1f}-{max(top):6.1f}"
            print(f"{name:12s} top {span} bottom {row}  max/min {ratio:.3f}")
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {path}")
    return 0


def main() -> int:
    """Run the study, write the JSON and the chart, check the exponents."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hc", type=float, nargs="+", default=[0.02, 0.01, 0.005, 0.0025])
    ap.add_argument("--ell", type=float, default=0.05, help="length of the edge load")
    ap.add_argument("--json", type=Path, default=ROOT / "benchmarks" / "edge_refinement.json")
    ap.add_argument("--chart", type=Path, default=ROOT / "docs" / "figures" / "edge_refinement.png")
    ap.add_argument("--placements", action="store_true", help="the placement sweep instead")
    args = ap.parse_args()
    if args.placements:
        return placements(ROOT / "benchmarks" / "edge_placements.json")
    from contactfx import SolveRequest, run_scene

    s = edge_exponent()
    rows: dict[str, dict[str, list[float]]] = {m: {} for m in METHODS}
    dofs = []
    with tempfile.TemporaryDirectory() as tmp:
        for hc in args.hc:
            scene = press_fit(Path(tmp), hc=hc, f_top=0.0, f_bot=0.72)
            for name, (method, basis) in METHODS.items():
                _, summary = run_scene(scene, SolveRequest.parse(method, basis=basis))
                data = summary.to_json()
                vals = edge_values(data["contacts"][0]["interface"], args.ell)
                for key, v in vals.items():
                    rows[name].setdefault(key, []).append(v)
            dofs.append(int(data["dofs"]))
            print(f"hc {hc}: {dofs[-1]} dofs", flush=True)
    h = np.array(args.hc)
    ok = True
    out: dict[str, Any] = {"hc": args.hc, "dofs": dofs, "ell": args.ell, "exponent": s}
    out["methods"] = rows
    print(f"corner exponent s = {s:.5f}")
    print(f"{'method':12s} {'edge':6s} {'peaks':>34s} {'local exponents':>24s} {'fit':>6s}")
    for name, r in rows.items():
        for edge in ("top", "bottom"):
            local, fit = slopes(h, np.array(r[f"peak_{edge}"]))
            r[f"local_{edge}"], r[f"fit_{edge}"] = local, fit  # type: ignore[assignment]
            ok &= abs(fit - s) <= 0.05
            peaks = " ".join(f"{v:7.1f}" for v in r[f"peak_{edge}"])
            loc = " ".join(f"{v:.3f}" for v in local)
            print(f"{name:12s} {edge:6s} {peaks:>34s} {loc:>24s} {fit:6.3f}")
    args.json.write_text(json.dumps(out, indent=1) + "\n")
    chart(out, args.chart)
    print(f"wrote {args.json} and {args.chart}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
