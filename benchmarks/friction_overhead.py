"""What a frictional solve costs: against GetFEM on the same mesh, and against mu = 0.

Two measurements, each the wall time of `contactfx.solve` in this process (assembly, search,
predictor and every load step; the mesh, built by `load_scene_file`, apart), the median of
`--repeat` runs after one warm-up run (form compilation), with the active-set (semismooth
Newton) iterations per load step:

- `getfem`: tests/scenes/cylinder_block.toml (a half-cylinder pressed on a block with friction,
  then pushed; 9,988 DOFs) with mortar, dual mortar and nts, against GetFEM's Alart-Curnier
  Coulomb law on the same mesh: the median wall time of its Newton solves of both steps and its
  iterations, as recorded in benchmarks/getfem_cylinder_block.json and
  getfem_cylinder_block_bisector.json (one core, this machine, an earlier session; made by
  benchmarks/getfem_cylinder_block.py, see benchmarks/cylinder_block_compare.py).
- `getfem_live` (with `--getfem-msh MSH`, the scene's mesh written by
  `cylinder_block_compare.py --write-mesh MSH`): GetFEM run here, now, one process per run
  (its Newton solves' wall time), alternated with contactfx's three methods, `--repeat` times.
- `mu0`: tests/scenes/cattaneo_mirrored.toml at `--size-factor` (pressed, then pushed: two
  load steps) frictional (mu = 0.3) against the same scene, steps and method with mu = 0,
  the two solves alternated so both see the same load on a shared machine.

    OPENBLAS_NUM_THREADS=1 python benchmarks/cylinder_block_compare.py --write-mesh /tmp/cb1.msh
    OPENBLAS_NUM_THREADS=1 python benchmarks/friction_overhead.py --repeat 5 \
        --size-factor 2 --getfem-msh /tmp/cb1.msh --json benchmarks/friction_overhead.json

(about five minutes on one core; without `--getfem-msh`, three.)
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from contactfx import solve
from contactfx.scenes import Scene
from contactfx.scenes.scene_file import load_scene_file

ROOT = Path(__file__).resolve().parents[1]
BLOCK = ROOT / "tests" / "scenes" / "cylinder_block.toml"
MIRRORED = ROOT / "tests" / "scenes" / "cattaneo_mirrored.toml"
GETFEM = [ROOT / "benchmarks" / f for f in ("getfem_cylinder_block.json",)]
GETFEM += [ROOT / "benchmarks" / "getfem_cylinder_block_bisector.json"]
GETFEM_PYTHON = "/usr/bin/python3"  # Debian's python3-getfem
METHODS = {"mortar": {}, "dual": {"basis": "dual"}, "nts": {}}


def timed(scene: Scene, method: str) -> dict[str, Any]:
    """One solve of `scene` by `method` (dual: mortar with the dual basis): time, iterations."""
    name = "mortar" if method == "dual" else method
    t0 = time.perf_counter()
    sol = solve(scene, name, **METHODS[method])  # type: ignore[arg-type]
    wall = time.perf_counter() - t0
    steps = sol.steps or [sol]
    return {"wall_s": wall, "iterations": [s.iterations for s in steps], "dofs": sol.dofs}


def series(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """The median wall time of `runs` (their iterations are the same run to run)."""
    return {
        "wall_s": float(np.median([r["wall_s"] for r in runs])),
        "wall_s_runs": [r["wall_s"] for r in runs],
        "iterations": runs[0]["iterations"],
        "dofs": runs[0]["dofs"],
    }


def against_getfem(repeat: int) -> list[dict[str, Any]]:
    """The cylinder on the block, each method, against GetFEM's recorded runs."""
    scene = load_scene_file(BLOCK)
    getfem = [json.loads(p.read_text()) for p in GETFEM]
    rows = []
    for method in METHODS:
        timed(scene, method)  # warm-up
        ours = series([timed(scene, method) for _ in range(repeat)])
        for gf in getfem:
            rows.append(
                {
                    "method": method,
                    "getfem_frame": gf["frame"],
                    **ours,
                    "getfem_wall_s": gf["wall_s_median"],
                    "getfem_iterations": [s["iterations"] for s in gf["steps"]],
                    "ratio": ours["wall_s"] / gf["wall_s_median"],
                }
            )
    return rows


def getfem_now(msh: Path) -> dict[str, Any]:
    """One GetFEM run of both steps on `msh` now (Debian's python3-getfem, flat frame)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "gf.json"
        script = ROOT / "benchmarks" / "getfem_cylinder_block.py"
        env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
        cmd = [GETFEM_PYTHON, str(script), str(msh), "--json", str(out)]
        subprocess.run(cmd, check=True, env=env, capture_output=True)
        gf = json.loads(out.read_text())
    return {"wall_s": gf["wall_s_median"], "iterations": [s["iterations"] for s in gf["steps"]]}


def against_getfem_live(msh: Path, repeat: int) -> list[dict[str, Any]]:
    """The cylinder on the block, GetFEM run here and now, alternated with each method."""
    scene = load_scene_file(BLOCK)
    for method in METHODS:
        timed(scene, method)  # warm-up
    gf: list[dict[str, Any]] = []
    ours: dict[str, list[dict[str, Any]]] = {m: [] for m in METHODS}
    for _ in range(repeat):
        gf.append(getfem_now(msh))
        for method in METHODS:
            ours[method].append(timed(scene, method))
    theirs = float(np.median([g["wall_s"] for g in gf]))
    return [
        {
            "method": method,
            "getfem_frame": "flat",
            **series(runs),
            "getfem_wall_s": theirs,
            "getfem_wall_s_runs": [g["wall_s"] for g in gf],
            "getfem_iterations": gf[0]["iterations"],
            "ratio": series(runs)["wall_s"] / theirs,
        }
        for method, runs in ours.items()
    ]


def against_mu0(size_factor: float, repeat: int) -> list[dict[str, Any]]:
    """The mirrored cylinders, frictional against mu = 0, runs alternated."""
    rough = load_scene_file(MIRRORED, size_factor=size_factor)
    smooth = dataclasses.replace(
        rough, contacts=tuple(dataclasses.replace(c, mu=0.0) for c in rough.contacts)
    )
    rows = []
    for method in METHODS:
        timed(rough, method)  # warm-up
        timed(smooth, method)
        fr, fl = [], []
        for _ in range(repeat):
            fr.append(timed(rough, method))
            fl.append(timed(smooth, method))
        a, b = series(fr), series(fl)
        rows.append(
            {
                "method": method,
                "size_factor": size_factor,
                "friction": a,
                "frictionless": b,
                "ratio": a["wall_s"] / b["wall_s"],
            }
        )
    return rows


def main() -> None:
    """Run both measurements, print them and write the JSON."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--size-factor", type=float, default=2.0)
    ap.add_argument("--json", type=Path)
    ap.add_argument(
        "--getfem-msh",
        type=Path,
        help="run GetFEM on this mesh of the scene now, alternated with contactfx",
    )
    args = ap.parse_args()
    out: dict[str, Any] = {"machine": platform.node()}
    if args.getfem_msh:
        out["getfem_live"] = against_getfem_live(args.getfem_msh, args.repeat)
    out["getfem"] = against_getfem(args.repeat)
    out["mu0"] = against_mu0(args.size_factor, args.repeat)
    for r in out.get("getfem_live", []):
        print(
            f"cylinder_block {r['method']:6s} {r['dofs']} DOFs: {r['wall_s']:.2f} s "
            f"{r['iterations']} it, GetFEM now {r['getfem_wall_s']:.2f} s "
            f"{r['getfem_iterations']} it: {r['ratio']:.2f}x"
        )
    for r in out["getfem"]:
        print(
            f"cylinder_block {r['method']:6s} {r['dofs']} DOFs: {r['wall_s']:.2f} s "
            f"{r['iterations']} it, GetFEM ({r['getfem_frame']}) {r['getfem_wall_s']:.2f} s "
            f"{r['getfem_iterations']} it: {r['ratio']:.2f}x"
        )
    for r in out["mu0"]:
        a, b = r["friction"], r["frictionless"]
        print(
            f"cattaneo_mirrored x{r['size_factor']} {r['method']:6s} {a['dofs']} DOFs: "
            f"mu 0.3 {a['wall_s']:.2f} s {a['iterations']} it, mu 0 {b['wall_s']:.2f} s "
            f"{b['iterations']} it: {r['ratio']:.2f}x"
        )
    if args.json:
        args.json.write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
