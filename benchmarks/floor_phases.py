"""The large default command's phases, with and without the graph model of MUMPS' memory.

`python benchmarks/floor_phases.py [--ranks 2] [--repeats 1] [--out benchmarks/floor_phases.json]
[--variants before,after] H:AVAILABLE_MB [H:AVAILABLE_MB ...]` runs, per size, `mpirun -n R
python -m contactfx solve hertz --mesh structured --refine H --h-far 10H --method mortar
--basis dual --available-memory AVAILABLE_MB` (the default solver `auto`; AVAILABLE_MB 0
leaves the flag out, the command exactly as a user types it; else below MUMPS' need, so
that `auto` takes the condensed path as the 10.46M default command does on a 24 GB
machine) twice in fresh processes, alternating: `before` with the model switched off (the
environment variable CONTACTFX_NO_MUMPS_MODEL=1 read here, in `_child`: `auto` then runs the
analysis as it did: the fine one, or from 1.6M DOFs the coarse check) and `after` (the
model decides). It writes the phases (mesh, assembly, predictor, the solver decision =
the solve phase minus its active-set steps, the steps, CG iterations), the peak memory, the
Hertz L2 error, the active set and DOF/s per core end to end, and prints one JSON line per
run. `--table` prints the README's table from the JSON instead. docs/scale.md ("How `auto`
decides") and benchmarks/README.md cite it.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _child(argv: list[str]) -> int:
    """Run the CLI in this process, the model off where the environment says so."""
    if os.environ.get("CONTACTFX_NO_MUMPS_MODEL") == "1":
        import contactfx.methods.mumps_model as mm

        mm.MODEL_MIN_DOFS = 10**15
    from contactfx.cli import main

    return main(argv)


def run_one(h: float, available: float, variant: str, ranks: int) -> dict[str, object]:
    """One fresh run of the default command; its phases from the JSON summary."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run.json"
        cmd = [
            *([str(Path(sys.executable).parent / "mpirun"), "-n", str(ranks)] if ranks > 1 else []),
            sys.executable,
            __file__,
            "--child",
            "solve",
            "hertz",
            "--mesh",
            "structured",
            "--refine",
            str(h),
            "--h-far",
            str(round(10 * h, 8)),
            "--method",
            "mortar",
            "--basis",
            "dual",
            *(["--available-memory", str(available)] if available > 0 else []),
            "--json",
            str(out),
            "-q",
        ]
        env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
        env["CONTACTFX_NO_MUMPS_MODEL"] = "1" if variant == "before" else "0"
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            raise SystemExit(proc.stderr[-3000:])
        d = json.loads(out.read_text())
    times = d["times"]
    steps = [s["solve_time"] for s in d["active_set"]]
    total = times["total"]
    return {
        "variant": variant,
        "refine": h,
        "ranks": d["ranks"],
        "dofs": d["dofs"],
        "available_mb": available,
        "solver": d["solver"],
        "estimate_of": d["solver_choice"]["estimate_of"],
        "mesh_s": times["mesh"],
        "assembly_s": times["assemble"],
        "search_and_b_s": times["search"] + times["contact"],
        "predictor_s": times["predictor"],
        "decision_s": times["solve"] - sum(steps),
        "steps_s": steps,
        "solve_s": times["solve"],
        "total_s": total,
        "process_wall_s": wall,
        "cg_iterations": [s["linear_iterations"] for s in d["active_set"]],
        "active": d["active_set"][-1]["active"],
        "hertz_l2": d["hertz"]["l2_error"],
        "peak_mb": d["memory"]["peak_mb"],
        "dof_per_s_per_core": d["dofs"] / total / d["ranks"],
        "load": os.getloadavg()[0],
    }


def table(path: str) -> str:
    """The README's rows: one per run, in the order run."""
    data = json.loads(Path(path).read_text())
    head = "| DOFs | variant | decided from | mesh | assembly | predictor | decision | step(s) |"
    head += " total | DOF/s per core | CG its | active | Hertz L2 | peak MB | load |"
    lines = [head, "|" + "---|" * 15]
    for r in data["rows"]:
        steps = " + ".join(f"{s:.2f}" for s in r["steps_s"])
        its = ", ".join(str(i) for i in r["cg_iterations"])
        lines.append(
            f"| {r['dofs']:,} | {r['variant']} | {r['estimate_of']} | {r['mesh_s']:.2f} | "
            f"{r['assembly_s']:.2f} | {r['predictor_s']:.2f} | {max(r['decision_s'], 0):.2f} | "
            f"{steps} | {r['total_s']:.2f} | {r['dof_per_s_per_core']:,.0f} | {its} | "
            f"{r['active']} | {100 * r['hertz_l2']:.4f} % | {r['peak_mb']:,.0f} | {r['load']:.1f} |"
        )
    return "\n".join(lines)


def main() -> None:
    if sys.argv[1:2] == ["--table"]:
        print(table(sys.argv[2] if len(sys.argv) > 2 else str(HERE / "floor_phases.json")))
        return
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sizes", nargs="+", help="H:AVAILABLE_MB")
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--out", default=str(HERE / "floor_phases.json"))
    ap.add_argument(
        "--variants", default="before,after", help="comma list: before (model off), after"
    )
    args = ap.parse_args()
    rows = []
    for spec in args.sizes:
        h, _, avail = spec.partition(":")
        for k in range(args.repeats):
            order = ("before", "after") if k % 2 == 0 else ("after", "before")
            for variant in (v for v in order if v in args.variants.split(",")):
                row = run_one(float(h), float(avail), variant, args.ranks)
                print(json.dumps(row), flush=True)
                rows.append(row)
    stamp = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    Path(args.out).write_text(json.dumps({"run": stamp, "rows": rows}, indent=1) + "\n")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        sys.exit(_child(sys.argv[2:]))
    main()
