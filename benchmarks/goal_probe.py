"""Probe of the pressure goal's refined mesh: one adapt_goal.py case, variants per level.

Runs the case's `contactfx adapt` in this process with `goal_estimate` replaced by a copy
whose refined mesh is --path (the loop's estimate) and also solves the --extras on every
level's mesh: `reach4` (the shipped rule: the zone's cells within BAND and REACH halved k
times, zone_halvings), `all` (every cell halved, the zone's cells 2^-k), a `+1` suffix (one
more halving of the zone, levels up to --plus-max DOFs), `seg32` (k such that 32 loaded
segments cross the refined zone). Per level: effectivity against Hertz and the refined
solution's Hertz error / the level's. --overkills HC:SLOPE,... (the cyl case): the level
and refined pressures against solves of tests/scenes/two_cylinders.toml with those contact
sizes and slope. docs/adapt.md ("Halving every cell, quartering the zone") has the runs:

python benchmarks/goal_probe.py fine --path all --extras reach4,all+1 --out all_fine.json
python benchmarks/goal_probe.py cyl --path all --extras reach4
    --overkills 0.002:0.04,0.001:0.05,0.0015:0.03 --out all_cyl.json
python benchmarks/goal_probe.py r1 --args "hertz --refine 0.6 --h-far 6 --refine-edge 0"
    --path all --extras reach4,all+1 --out all_h06.json
"""

import argparse
import gc
import json
import re
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import adapt_goal as AG

import contactfx.adapt.planned as P
from contactfx.adapt import goal as G
from contactfx.results.references import hertz_summary
from contactfx.scenes.model import HertzReference, Model

ap = argparse.ArgumentParser()
ap.add_argument("case")
ap.add_argument("--path", default="reach4")
ap.add_argument("--extras", default="")
ap.add_argument("--out", required=True)
ap.add_argument("--plus-max", type=int, default=12000)
ap.add_argument("--overkills", default="", help="cyl: HC:SLOPE,... overkill meshes")
ap.add_argument("--args", default="", help="replace the case's start args (space separated)")
ap.add_argument("--more", default="", help="extra CLI args appended")
a = ap.parse_args()
original = P.goal_estimate
state = {"last": None, "request": None, "curves": [], "ref_curves": []}


def cylinders(hc: str, slope: str) -> Path:
    """A copy of tests/scenes/two_cylinders.toml with contact size hc and slope (an overkill)."""
    src = AG.ROOT / "tests" / "scenes"
    folder = Path(tempfile.mkdtemp())
    geo = (src / "two_cylinders.geo").read_text()
    for name, value in {"hc1": hc, "hc2": hc, "slope": slope}.items():
        geo = re.sub(rf"{name} = {{[^,]*,", f"{name} = {{{value},", geo, count=1)
    (folder / "two_cylinders.geo").write_text(geo)
    (folder / "two_cylinders.toml").write_text((src / "two_cylinders.toml").read_text())
    return folder / "two_cylinders.toml"


def exact(sol):
    refs = [r for r in sol.scene.references if isinstance(r, HertzReference)]
    if not refs:
        return None
    return max(hertz_summary(sol, r).l2_error for r in refs)


def curves(sol):
    return [G.pressure_curve(pv, sol.pressure) for pv in sol.pairs]


def segs(sol):
    return [len(z) for z, _ in G._zones(sol)]


def variant(sol, mode, solver):
    k = G.zone_halvings(sol) + (1 if mode.endswith("+1") else 0)
    if mode == "seg32":
        counts = [len(z) for z, _ in G._zones(sol) if len(z)]
        k = 1
        while counts and min(counts) * 2**k < 32 and k < 3:
            k += 1
    far = 0.5 if mode.startswith("all") else 1.0
    near = 0.5**k
    t0 = time.perf_counter()
    field = G.refined_field(sol, far=far, near=near, reach=G.REACH)
    ref = G._refined(sol, field, solver, {})
    q = 2.0 ** (-1.5 * k)
    G._check_bounded(sol, ref, solver, {})
    parts = {}
    for pv, pr in zip(sol.pairs, ref.pairs, strict=True):
        d, n = G.pressure_difference(
            G.pressure_curve(pv, sol.pressure),
            G.pressure_curve(pr, ref.pressure),
            radial=sol.scene.model is Model.AXISYMMETRIC,
        )
        parts[pv.label] = d / n / (1.0 - q) if n > 0 else 0.0
    rel = max(parts.values(), default=0.0)
    sec = time.perf_counter() - t0
    ge = G.GoalEstimate(G.Goal.PRESSURE, float(rel), parts, 1.5, ref.dofs, sec, ref, k)
    return ge


def wrapper(sol, goal, *, solver="mumps", **kw):
    if G.Goal(goal) is not G.Goal.PRESSURE:
        return original(sol, goal, solver=solver, **kw)
    state["last"], state["request"] = sol, solver
    rec = {"dofs": sol.dofs, "exact": exact(sol), "segs": segs(sol), "variants": {}}
    main = None
    extras = [m for m in a.extras.split(",") if m and m != a.path]
    extras = [m for m in extras if not m.endswith("+1") or sol.dofs <= a.plus_max]
    for mode in [*extras, a.path]:
        ge = variant(sol, mode, solver)
        e_ref = exact(ge.reference)
        rec["variants"][mode] = {
            "estimate": ge.relative,
            "k": ge.halvings,
            "refined_dofs": ge.dofs,
            "seconds": ge.seconds,
            "refined_exact": e_ref,
            "ratio": (e_ref / rec["exact"]) if rec["exact"] and e_ref is not None else None,
            "effectivity": ge.relative / rec["exact"] if rec["exact"] else None,
            "refined_segs": segs(ge.reference),
        }
        if a.overkills:
            rec["variants"][mode]["_curves"] = curves(ge.reference)
        if mode == a.path:
            main = ge
        else:
            del ge
            gc.collect()
    if a.overkills:
        rec["_curves"] = curves(sol)
    state["curves"].append(rec)
    return main


P.goal_estimate = wrapper
from contactfx.cli import main as cli_main  # noqa: E402

args = list(AG.CASES[a.case])
if a.args:
    args = a.args.split() + args[len(AG.UNGRADED) :]
args += a.more.split()
t_start = time.perf_counter()
with tempfile.TemporaryDirectory() as tmp:
    if args[0] == "two_cylinders.toml":
        args = [str(AG.coarse_cylinders(Path(tmp))), *args[1:]]
    out = str(Path(tmp) / "out")
    rc = cli_main(["adapt", *args, "--out", out])
    data = json.loads((Path(out) / "adapt.json").read_text())
wall = time.perf_counter() - t_start
rows, cum = [], 0.0
for lv in data["levels"]:
    cum += lv["time"]
    rows.append(
        {
            "dofs": lv["dofs"],
            "time": cum,
            "estimate": lv["estimate"],
            "exact": lv.get("exact_error"),
            "effectivity": lv.get("effectivity"),
            "refined_dofs": lv.get("goal_refined_dofs"),
            "halvings": lv.get("goal_halvings"),
        }
    )

okinfo: list[dict] | None = None
if a.overkills:
    from mpi4py import MPI

    from contactfx.api import solve_request
    from contactfx.scenes.scene_file import load_scene_file

    okinfo = []
    radial = False
    prev = None
    for fac in a.overkills.split(","):
        t0 = time.perf_counter()
        hc, slope = fac.split(":")
        sc = load_scene_file(cylinders(hc, slope), MPI.COMM_WORLD)
        ok = solve_request(sc, state["request"])
        okc = curves(ok)
        info = {
            "factor": fac,
            "dofs": ok.dofs,
            "hertz": exact(ok),
            "seconds": time.perf_counter() - t0,
        }
        if prev is not None:
            d, n = G.pressure_difference(prev, okc[0])
            info["diff_from_previous"] = d / n
        prev = okc[0]
        okinfo.append(info)
        for rec in state["curves"]:
            d, n = G.pressure_difference(rec["_curves"][0], okc[0])
            rec[f"ok{fac}"] = d / n
            for v in rec["variants"].values():
                d2, n2 = G.pressure_difference(v["_curves"][0], okc[0])
                v[f"ok{fac}_refined"] = d2 / n2
                v[f"ok{fac}_eff"] = v["estimate"] / (d / n)
        del ok, sc
        gc.collect()
    for rec in state["curves"]:
        rec.pop("_curves", None)
        for v in rec["variants"].values():
            v.pop("_curves", None)
with open(a.out, "w") as f:
    json.dump(
        {
            "case": a.case,
            "args": args,
            "path": a.path,
            "rc": rc,
            "wall": wall,
            "stop": data["stop"],
            "overkill": okinfo,
            "levels": state["curves"],
            "level_times": [lv["time"] for lv in data["levels"]],
            "rows": rows,
        },
        f,
        indent=1,
        default=float,
    )
for i, rec in enumerate(state["curves"]):
    line = f"L{i} {rec['dofs']:>7} exact {rec['exact']} segs {rec['segs']}"
    line += "".join(f" {k} {rec[k]:.4g}" for k in rec if k.startswith("ok"))
    for m, v in rec["variants"].items():
        eff, ratio, n = v["effectivity"], v["ratio"], v["refined_dofs"]
        line += f" | {m} k{v['k']} eff {eff} ratio {ratio}"
        line += f" rdofs {n} ({n / rec['dofs']:.2f}x) {v['seconds']:.1f}s"
        line += f" rsegs {v['refined_segs']}"
        line += "".join(f" {k} {v[k]:.3f}" for k in v if k.startswith("ok") and k.endswith("_eff"))
    print(line)
print("stop:", data["stop"], "wall", round(wall, 1), "overkill", okinfo)
