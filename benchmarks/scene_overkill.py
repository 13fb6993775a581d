"""The pressure goal's effectivity on a scene file against overkills of the same scene (issue 30).

For scenes whose analytic reference is not the scene's own solution (a finite body, a
rotated model, three bodies): `levels` runs `contactfx adapt SCENE ARGS...` in this process
and keeps, per level and per pair, the active surface's nodes and multipliers and the goal
estimate (per pair and the loop's max); `solve` solves the same scene file with every gmsh
size times F (Mesh.MeshSizeFactor: a uniform refinement of its recipe), the adapt command's
method, direct MUMPS, and keeps the same curves; `compare` measures each level's pair
pressure against the finest overkill in the loop's norm (goal.pressure_difference: the
relative L2 norm along the active surface, exact on the union of the nodes) and prints
estimate / error. The abscissa is the exact arc length on the active surface's circle
(ARCS), not the polyline's: the polyline's length differs between meshes by O(h^2) per
segment, which would shift a coarse level's curve against the overkill's.

Run (serial, one solve per process, CONTACTFX_MESH_CACHE=0; docs/adapt.md "Two scenes
against overkills of their own"; likewise demos/scenes/cylinder_between_blocks.toml with
--edge 0.6034):
python benchmarks/scene_overkill.py levels tests/scenes/rotated_hertz.toml /tmp/rh.npz
    -- --tol 0.002 --max-dofs 60000
python benchmarks/scene_overkill.py solve tests/scenes/rotated_hertz.toml 0.2 /tmp/rh_e02.npz
    --edge 0.782   (and 0.1 -> /tmp/rh_e01.npz; without --edge: the uniform ones)
python benchmarks/scene_overkill.py compare /tmp/rh.npz /tmp/rh_e02.npz /tmp/rh_e01.npz
    --json benchmarks/scene_overkill.json --key rotated_hertz
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

# Per scene (file stem): per pair, the active surface's circle (centre, radius) and the
# first touching point, from the scene's .geo (rotated_hertz.geo: the disc centred at (0, R)
# rotated by phi = 30 degrees about the origin; cylinder_between_blocks.geo: centre (0, 0),
# R = 20, touching at (0, -R) and (0, R)).
_PHI = np.radians(30.0)
# The edge-graded overkill's sizes at the zone's ends, before the size factor: a tenth of
# the scenes' contact sizes (0.04, 0.025), growing 0.1 per unit distance.
EDGE_H = 0.003
EDGE_SLOPE = 0.1
ARCS: dict[str, list[tuple[tuple[float, float], float, tuple[float, float]]]] = {
    "rotated_hertz": [((-10.0 * np.sin(_PHI), 10.0 * np.cos(_PHI)), 10.0, (0.0, 0.0))],
    "cylinder_between_blocks": [((0.0, 0.0), 20.0, (0.0, -20.0)), ((0.0, 0.0), 20.0, (0.0, 20.0))],
    # two_cylinders.geo: the active (upper) disc centred at (0, 60), R = 60, touching at the
    # origin; a half model (x >= 0).
    "two_cylinders": [((0.0, 60.0), 60.0, (0.0, 0.0))],
}
# Each scene's .geo background field, which the edge grading joins by a Min.
BACKGROUND = {"rotated_hertz": 1, "cylinder_between_blocks": 7, "two_cylinders": 5}


def edge_points(scene: str, a: float) -> list[tuple[float, float]]:
    """The zone's ends (half-width a) of every pair, on both surfaces (flat and circle)."""
    if scene == "rotated_hertz":
        c, sn, dy = np.cos(_PHI), np.sin(_PHI), 10.0 - np.sqrt(100.0 - a * a)
        pts = [(x, y) for x in (a, -a) for y in (0.0, dy)]
        return [(x * c - y * sn, x * sn + y * c) for x, y in pts]
    if scene == "two_cylinders":
        # The zone's one end (x = a) on the lower (R 40) and the upper (R 60) disc, twice.
        lower, upper = (a, -40.0 + np.sqrt(1600.0 - a * a)), (a, 60.0 - np.sqrt(3600.0 - a * a))
        return [lower, upper, lower, upper]
    y = np.sqrt(400.0 - a * a)
    return [(a, -20.0), (a, -y), (a, 20.0), (a, y)]


def edge_graded(scene: Path, a: float, folder: Path) -> Path:
    """A copy of the scene file whose .geo sizes are also at most EDGE_H + EDGE_SLOPE * rho,
    rho the distance from the nearest zone end (half-width a): the same geometry, groups,
    materials and loads, the square-root edge resolved as the adaptive levels resolve it.
    """
    geo = (scene.parent / f"{scene.stem}.geo").read_text()
    d = [f"Sqrt((x - ({x:.17g}))^2 + (y - ({y:.17g}))^2)" for x, y in edge_points(scene.stem, a)]
    field = f"{EDGE_H} + {EDGE_SLOPE} * Min(Min({d[0]}, {d[1]}), Min({d[2]}, {d[3]}))"
    old = BACKGROUND[scene.stem]
    top = f"Background Field = {old};"
    extra = (
        f'Field[20] = MathEval;\nField[20].F = "{field}";\n'
        f"Field[21] = Min;\nField[21].FieldsList = {{{old}, 20}};\nBackground Field = 21;"
    )
    assert top in geo
    (folder / f"{scene.stem}.geo").write_text(geo.replace(top, extra))
    (folder / scene.name).write_text(scene.read_text())
    return folder / scene.name


def arc_coordinate(scene: str, pair: int, xy: np.ndarray) -> np.ndarray:
    """Signed arc length on the pair's circle from its touching point."""
    (cx, cy), radius, (tx, ty) = ARCS[scene][pair]
    t = np.array([tx - cx, ty - cy])
    n = xy - np.array([cx, cy])
    cross = t[0] * n[:, 1] - t[1] * n[:, 0]
    return radius * np.arctan2(cross, n @ t)


def pair_curves(sol: Any) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per pair: the active surface's nodes (x, y) and multipliers (0 where no row)."""
    out = []
    for pv in sol.pairs:
        xy = pv.active.surface.x[:, :2].copy()
        p = np.zeros(len(xy))
        p[pv.nodes] = sol.pressure[pv.rows]
        out.append((xy, p))
    return out


def request_of(scene: Path, extra: list[str]) -> Any:
    """The SolveRequest `contactfx adapt SCENE EXTRA` would use."""
    from contactfx.cli.params import request_from_args
    from contactfx.cli.parser import parser

    return request_from_args(parser().parse_args(["adapt", str(scene), "--out", "x", *extra]))


def run_levels(scene: Path, out: Path, extra: list[str]) -> None:
    """The adapt loop in this process, each level's pair curves and goal estimate kept."""
    import contactfx.adapt.planned as planned
    from contactfx.adapt import goal as G
    from contactfx.cli import main as cli_main

    original = planned.goal_estimate
    kept: list[dict[str, Any]] = []

    def wrapper(sol: Any, goal: Any, **kw: Any) -> Any:
        ge = original(sol, goal, **kw)
        if G.Goal(goal) is G.Goal.PRESSURE:
            kept.append(
                {"dofs": sol.dofs, "curves": pair_curves(sol), "parts": dict(ge.parts)}
                | {"estimate": ge.relative, "refined_dofs": ge.dofs, "k": ge.halvings}
            )
        return ge

    planned.goal_estimate = wrapper  # type: ignore[assignment]
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        rc = cli_main(["adapt", str(scene), *extra, "--out", tmp])
        data = json.loads((Path(tmp) / "adapt.json").read_text())
    wall = time.perf_counter() - t0
    arrays: dict[str, Any] = {}
    for i, rec in enumerate(kept):
        for j, (xy, p) in enumerate(rec["curves"]):
            arrays[f"L{i}_P{j}_xy"], arrays[f"L{i}_P{j}_p"] = xy, p
    meta = {
        "scene": str(scene),
        "args": extra,
        "rc": rc,
        "wall": wall,
        "stop": data["stop"],
        "levels": [
            {k: v for k, v in rec.items() if k != "curves"}
            | {
                "time": lv["time"],
                "loop_estimate": lv["estimate"],
                "hertz_error": lv.get("exact_error"),
            }
            for rec, lv in zip(kept, data["levels"], strict=False)
        ],
    }
    np.savez(out, meta=np.array(json.dumps(meta, default=float)), **arrays)
    for lv in meta["levels"]:
        print(lv, flush=True)
    print("stop:", data["stop"], "wall", round(wall, 1), "levels", len(kept))


def run_solve(scene: Path, factor: float, out: Path, extra: list[str], edge: float) -> None:
    """One overkill: the scene file with sizes x factor, the adapt command's method, MUMPS.

    edge > 0: the edge-graded copy of the scene (`edge_graded`, zone half-width `edge`).
    """
    from mpi4py import MPI

    from contactfx.api import solve_request
    from contactfx.results.references import hertz_summary
    from contactfx.scenes.model import HertzReference
    from contactfx.scenes.scene_file import load_scene_file

    t0 = time.perf_counter()
    tmp = tempfile.TemporaryDirectory()
    if edge > 0:
        scene = edge_graded(scene, edge, Path(tmp.name))
    sc = load_scene_file(scene, MPI.COMM_WORLD, size_factor=factor)
    sol = solve_request(sc, request_of(scene, [*extra, "--solver", "mumps"]))
    seconds = time.perf_counter() - t0
    refs = [r for r in sc.references if isinstance(r, HertzReference)]
    hertz = [hertz_summary(sol, r).l2_error for r in refs]
    arrays: dict[str, Any] = {}
    for j, (xy, p) in enumerate(pair_curves(sol)):
        arrays[f"P{j}_xy"], arrays[f"P{j}_p"] = xy, p
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    meta = {"factor": factor, "edge": edge, "dofs": sol.dofs, "seconds": seconds}
    meta["peak_mb"] = peak_mb
    meta["hertz_error"] = hertz
    np.savez(out, meta=np.array(json.dumps(meta)), **arrays)
    print(meta, flush=True)


def curve(scene: str, pair: int, xy: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, ...]:
    """(s, p, x) sorted by the exact arc length, as goal.pressure_difference takes them."""
    s = arc_coordinate(scene, pair, xy)
    order = np.argsort(s, kind="stable")
    return s[order], p[order], xy[order, 0]


def run_compare(levels: Path, oks: list[Path], out: Path | None, key: str) -> None:
    """Each level's pair errors against the finest overkill; the overkills against it."""
    from contactfx.adapt.goal import pressure_difference

    lv = np.load(levels)
    meta = json.loads(str(lv["meta"]))
    scene = Path(meta["scene"]).stem
    ok = [np.load(p) for p in oks]
    okmeta = [json.loads(str(f["meta"])) for f in ok]
    npairs = len(ARCS[scene])
    fine = [curve(scene, j, ok[-1][f"P{j}_xy"], ok[-1][f"P{j}_p"]) for j in range(npairs)]
    for k, (f, m) in enumerate(zip(ok[:-1], okmeta[:-1], strict=True)):
        dist = []
        for j in range(npairs):
            d, n = pressure_difference(curve(scene, j, f[f"P{j}_xy"], f[f"P{j}_p"]), fine[j])
            dist.append(d / n)
        m["to_finest"] = dist
        if k + 1 < len(ok) - 1:
            nxt = ok[k + 1]
            steps = []
            for j in range(npairs):
                d, n = pressure_difference(
                    curve(scene, j, f[f"P{j}_xy"], f[f"P{j}_p"]),
                    curve(scene, j, nxt[f"P{j}_xy"], nxt[f"P{j}_p"]),
                )
                steps.append(d / n)
            m["to_next"] = steps
    rows = []
    for i, rec in enumerate(meta["levels"]):
        errors = []
        for j in range(npairs):
            c = curve(scene, j, lv[f"L{i}_P{j}_xy"], lv[f"L{i}_P{j}_p"])
            d, n = pressure_difference(c, fine[j])
            errors.append(d / n)
        worst = max(errors)
        row = {
            "dofs": rec["dofs"],
            "estimate": rec["estimate"],
            "parts": list(rec["parts"].values()),
            "error_ok": errors,
            "worst_error_ok": worst,
            "effectivity_ok": rec["estimate"] / worst,
            "pair_effectivity_ok": [
                e / x for e, x in zip(rec["parts"].values(), errors, strict=True)
            ],
            "hertz_error": rec["hertz_error"],
            "refined_dofs": rec["refined_dofs"],
            "k": rec["k"],
            "time": rec["time"],
        }
        rows.append(row)
        print(
            f"L{i} {rec['dofs']:>7} est {100 * rec['estimate']:.4g} % "
            f"err_ok {[round(100 * e, 4) for e in errors]} % eff {row['effectivity_ok']:.3f} "
            f"pair eff {[round(e, 3) for e in row['pair_effectivity_ok']]} "
            f"hertz {rec['hertz_error']}",
            flush=True,
        )
    for m in okmeta:
        print("overkill", m)
    if out is not None:
        data = json.loads(out.read_text()) if out.exists() else {}
        data[key] = {
            "scene": meta["scene"],
            "args": meta["args"],
            "stop": meta["stop"],
            "wall": meta["wall"],
            "overkills": okmeta,
            "levels": rows,
        }
        out.write_text(json.dumps(data, indent=1) + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    a = sub.add_parser("levels")
    a.add_argument("scene", type=Path)
    a.add_argument("out", type=Path)
    a.add_argument("extra", nargs="*")
    b = sub.add_parser("solve")
    b.add_argument("scene", type=Path)
    b.add_argument("factor", type=float)
    b.add_argument("out", type=Path)
    b.add_argument("extra", nargs="*")
    b.add_argument("--edge", type=float, default=0.0, help="edge-graded, zone half-width")
    c = sub.add_parser("compare")
    c.add_argument("levels", type=Path)
    c.add_argument("overkills", type=Path, nargs="+")
    c.add_argument("--json", type=Path)
    c.add_argument("--key", required=True)
    args = ap.parse_args()
    if args.cmd == "levels":
        run_levels(args.scene, args.out, args.extra)
    elif args.cmd == "solve":
        run_solve(args.scene, args.factor, args.out, args.extra, args.edge)
    else:
        run_compare(args.levels, args.overkills, args.json, args.key)
    sys.stdout.flush()


if __name__ == "__main__":
    main()
