"""The scaling table of the condensed path (issue 33, point 3): 1 and 2 ranks, per-rank work.

The accurate Hertz family, as a user runs it:

    contactfx solve hertz --mesh structured --refine R --h-far 10R --method mortar \
        --basis dual --solver condensed

(R = 0.0048: 10.46M DOFs). Each (size, ranks) is one fresh process (`mpirun -n P` from 2
ranks) running that solve through the CLI's own parser and `run_scene`, with a PETSc log stage
per phase (mesh, assemble, search, contact, predictor, solve) and PETSc's log written as
`-log_view` text, parsed by benchmarks/scaling_model.py. Per run: DOFs, ranks, the phases'
wall times, CG iterations per active-set step, peak memory per rank (VmHWM, summed), memory
per DOF, and for the solve stage (condensed matrix, GAMG setup, CG) flops, messages, message
bytes and allreduces per rank, GAMG's setup (PCSetUp) apart. The load average is recorded
before and after each run (the machine may be shared). Runs merge into the JSON by (solver,
target DOFs, ranks); `--replot` redraws the chart, `--model` prints the 8-256-rank model
fitted to the JSON's runs (docs/scale.md, "Scaling: measured and modelled").

    python benchmarks/scaling.py --sizes 100e3,400e3 --ranks 1,2
    python benchmarks/scaling.py --sizes 1e6,2e6,10.46e6 --ranks 2 --solver condensed
    python benchmarks/scaling.py --model

`--solver mumps` runs the direct default on the same meshes (its memory per DOF).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from scaling_model import (
    CG_REDUCTIONS,
    Measured,
    Network,
    Part,
    Phases,
    counted_reductions,
    parse_log_view,
    power_fit,
    predict,
    whole_run,
)

HERE = Path(__file__).resolve().parent
PY = sys.executable
MPIRUN = str(Path(PY).parent / "mpirun")
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
# The family's refine for 10.46M DOFs (docs/scale.md, "10M DOFs on an accurate mesh").
REFINE_10M = 0.0048
# A fresh condensed solve's CG iterations on this family: with the structured grid's
# geometric multigrid 7 at 100,224 DOFs and 6 at 2,004,136 (benchmarks/gamg_options.py, run
# gmg_sweep; docs/scale.md, "Geometric multigrid on the structured grid"): taken as flat.
# GAMG's were 21 and 29 (N^0.108, "GAMG on stretched cells").
ITS_GROWTH = 0.0
MODEL_SIZES = (10.46e6, 40e6, 100e6)
MODEL_RANKS = (2, 8, 16, 32, 64, 128, 256)


def cli_args(refine: float, solver: str) -> list[str]:
    """The user's command line (after `contactfx`) for one size of the family.

    `mumps` also prints MUMPS' statistics (ICNTL(4) = 2: INFOG(22), the factorization's
    memory, and INFOG(29), the factor's entries, parsed by `mumps_stats`).
    """
    extra = ["--petsc-option", "mat_mumps_icntl_4=2"] if solver == "mumps" else []
    return [
        "solve",
        "hertz",
        *extra,
        "--mesh",
        "structured",
        "--refine",
        f"{refine:g}",
        "--h-far",
        f"{10 * refine:g}",
        "--method",
        "mortar",
        "--basis",
        "dual",
        "--solver",
        solver,
    ]


def worker(refine: float, solver: str, log_path: Path, out: Path) -> None:
    """Under mpirun: the CLI's solve with one PETSc stage per phase; log and JSON to files."""
    import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)
    from mpi4py import MPI
    from petsc4py import PETSc

    from contactfx.api import run_scene
    from contactfx.cli.params import build_from_args, is_scene_file, request_from_args
    from contactfx.cli.parser import parser
    from contactfx.timers import Timers

    class StageTimers(Timers):
        """Timers whose every label is also a PETSc log stage (events go to their phase)."""

        def __init__(self) -> None:
            super().__init__()
            self.stages: dict[str, Any] = {}

        @contextmanager
        def __call__(self, label: str):  # type: ignore[override]
            stage = self.stages.setdefault(label, PETSc.Log.Stage(label))
            stage.push()
            try:
                with Timers.__call__(self, label):
                    yield
            finally:
                stage.pop()

    comm = MPI.COMM_WORLD
    PETSc.Log.begin()
    args = parser().parse_args(cli_args(refine, solver))
    request = request_from_args(args)
    t_start = time.perf_counter()
    timers = StageTimers()
    with timers("mesh"):
        scene = build_from_args(args)
    _sol, record = run_scene(
        scene, request, paper_interface=not is_scene_file(args.scene), t_start=t_start,
        timers=timers,
    )  # fmt: skip
    rec = record.to_json()
    rec["vmhwm_mb"] = comm.gather(vmhwm_mb(), root=0)
    viewer = PETSc.Viewer().createASCII(str(log_path), comm=comm)
    PETSc.Log.view(viewer)
    viewer.destroy()
    if comm.rank == 0:
        out.write_text(json.dumps(rec))


def vmhwm_mb() -> float:
    """This process's peak resident memory (MB, /proc/self/status VmHWM)."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def mumps_stats(stdout: str) -> dict[str, float]:
    """MUMPS' printed statistics (ICNTL(4) = 2) of the largest factorization, if any.

    infog22_mb: memory effectively used by the factorization (MB, summed over the ranks);
    infog29_entries: entries in the factors; elimination_flops: RINFOG(3);
    factorization_s: MUMPS' own elapsed time of that factorization.
    """
    keys = {
        "infog22_mb": r"INFOG\(22\)\):\s+(\S+)",
        "infog29_entries": r"INFOG \(29\)[^=]*=\s+(\S+)",
        "elimination_flops": r"\(3\) Operations in node elimination\s*=\s+(\S+)",
        "factorization_s": r"Elapsed time for factorization\s*=\s+(\S+)",
    }
    out = {}
    for key, pattern in keys.items():
        values = [float(x.replace("D", "e")) for x in re.findall(pattern, stdout)]
        if values:
            out[key] = max(values)
    return out


def refine_for_dofs(dofs: float) -> float:
    """The family's refine R for about `dofs` DOFs (benchmarks/run.py's grid count)."""
    from run import refine_for  # the mesh generator's count (imports contactfx)

    return refine_for(dofs, "structured", 10.0)


def run_case(
    target: float, ranks: int, solver: str, timeout: float, logs: Path | None = None
) -> dict[str, Any]:
    """One fresh process; the merged record of its JSON and its parsed -log_view.

    `logs`: a folder to keep the -log_view text in (SOLVER-DOFS-RANKS.txt).
    """
    refine = REFINE_10M if abs(target - 10.46e6) < 1e5 else refine_for_dofs(target)
    with tempfile.TemporaryDirectory() as tmp:
        log_path, out = Path(tmp) / "log_view.txt", Path(tmp) / "run.json"
        cmd = [PY, str(Path(__file__).resolve()), "--worker", "--refine", str(refine)]
        cmd += ["--solver", solver, "--log", str(log_path), "--out", str(out)]
        if ranks > 1:
            cmd = [MPIRUN, "-n", str(ranks), *cmd]
        load_before = os.getloadavg()
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=timeout)
        wall = time.perf_counter() - t0
        if proc.returncode != 0 or not out.exists():
            tail = (proc.stdout + proc.stderr)[-2000:]
            raise RuntimeError(f"{target:g} DOFs on {ranks} rank(s) failed:\n{tail}")
        rec = json.loads(out.read_text())
        rec["mumps"] = mumps_stats(proc.stdout)
        text = log_path.read_text()
        log = parse_log_view(text)
        if logs is not None:
            logs.mkdir(parents=True, exist_ok=True)
            (logs / f"{solver}-{rec['dofs']}-{ranks}.txt").write_text(text)
    user = "contactfx " + shlex.join(cli_args(refine, solver))
    user = (f"mpirun -n {ranks} " if ranks > 1 else "") + user
    return summarize(rec, log, target, ranks, solver, refine, wall, load_before, user)


def summarize(
    rec: dict[str, Any],
    log: dict[str, Any],
    target: float,
    ranks: int,
    solver: str,
    refine: float,
    wall: float,
    load_before: tuple[float, float, float],
    user: str,
) -> dict[str, Any]:
    """The table row of one run: phases, iterations, memory, per-rank work of the solve stage."""
    its = [int(h["linear_iterations"]) for h in rec["active_set"]]
    dofs = int(rec["dofs"])
    peak = [float(x) for x in rec["vmhwm_mb"]]
    stage = log["stages"].get("solve", {})
    ev = log["events"].get("solve", {})
    setup = ev.get("PCSetUp", {})
    per_rank = {
        "flops": stage.get("flops", 0.0) / ranks,
        "messages": stage.get("messages", 0.0) / ranks,
        "message_bytes": stage.get("message_bytes", 0.0) / ranks,
        "reductions_logged": stage.get("reductions", 0.0),
        "reductions_counted": counted_reductions(ev) if ranks > 1 else 0.0,
        "setup_flops": setup.get("flops", 0.0),
        "setup_time": setup.get("time", 0.0),
        "setup_messages": setup.get("messages", 0.0) / ranks,
        "setup_bytes": setup.get("message_bytes", 0.0) / ranks,
        "setup_reductions_logged": setup.get("reductions", 0.0),
    }
    hz = rec.get("hertz") or {}
    hz = hz[0] if isinstance(hz, list) else hz
    return {
        "target": target,
        "solver": solver,
        "ranks": ranks,
        "refine": refine,
        "dofs": dofs,
        "command": user,
        "when": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "load_before": list(load_before),
        "load_after": list(os.getloadavg()),
        "wall": wall,
        "times": rec["times"],
        "solve_stage_time": stage.get("time"),
        "steps": len(its),
        "cg_iterations": its,
        "cg_total": sum(its),
        "peak_mb_ranks": peak,
        "peak_mb": sum(peak),
        "kb_per_dof": sum(peak) * 1024.0 / dofs,
        "l2_error": hz.get("l2_error"),
        "a_error": hz["a"] / hz["a_exact"] - 1 if hz.get("a") else None,
        "per_rank": per_rank,
        "mumps": rec.get("mumps", {}),
        "log": {"global": log["global"], "stages": log["stages"], "solve_events": ev},
    }


def merge(path: Path, new: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The JSON's runs with `new` replacing those of the same (solver, target, ranks)."""
    old = json.loads(path.read_text())["runs"] if path.exists() else []
    keys = {(r["solver"], r["target"], r["ranks"]) for r in new}
    runs = [r for r in old if (r["solver"], r["target"], r["ranks"]) not in keys] + new
    runs.sort(key=lambda r: (r["solver"], r["target"], r["ranks"]))
    path.write_text(json.dumps({"runs": runs}, indent=1) + "\n")
    return runs


def parts_of(run: dict[str, Any]) -> tuple[Part, ...]:
    """The solve stage of one run in three parts: GAMG setup, CG, the rest (per rank).

    setup = the PCSetUp event, cg = KSPSolve (per CG iteration), rest = the stage minus both
    (the condensed matrix, right-hand sides, the pivots: its flops are a few per cent, so its
    measured rank-seconds per DOF stand for flops per DOF, at rate 1). Allreduces: CG_REDUCTIONS per
    iteration; the stage's other dot products (GAMG's eigenvalue estimates) and PETSc's
    logged reductions of PCSetUp go to the setup, the stage's remaining logged ones to the rest.
    """
    n, p, its = run["dofs"], run["ranks"], run["cg_total"]
    stage, ev = run["log"]["stages"]["solve"], run["log"]["solve_events"]
    setup, ksp = ev.get("PCSetUp", {}), ev.get("KSPSolve", {})
    dots = counted_reductions(ev)

    def share(e: dict[str, float], key: str) -> float:
        return e.get(key, 0.0) / p  # summed over the ranks in the log

    rest_time = stage["time"] - setup.get("time", 0.0) - ksp.get("time", 0.0)
    return (
        Part("setup", p * setup["flops"] / n, setup["flops"] / setup["time"],
             share(setup, "messages"), share(setup, "message_bytes"),
             setup["reductions"] + dots - CG_REDUCTIONS * its, False),
        Part("cg", p * ksp["flops"] / (n * its), ksp["flops"] / ksp["time"],
             share(ksp, "messages") / its, share(ksp, "message_bytes") / its,
             CG_REDUCTIONS, True),
        # Mostly without flops (copies, sums, pivots): its time counts as "flops" at rate 1.
        Part("rest", rest_time * p / n, 1.0,
             (stage["messages"] - setup.get("messages", 0) - ksp.get("messages", 0)) / p,
             (stage["message_bytes"] - setup.get("message_bytes", 0)
              - ksp.get("message_bytes", 0)) / p,
             stage["reductions"] - setup["reductions"], False),
    )  # fmt: skip


def fit(runs: list[dict[str, Any]], growth: float = ITS_GROWTH) -> Measured:
    """The model's inputs: the largest 2-rank condensed run, its iterations grown by `growth`.

    The loop's total CG iterations depend on its number of active-set steps (2-3 here, set by
    the predictor's set), so the trend is a fresh solve's (ITS_GROWTH) and the total is the
    measured one at the reference size: its(N) = its_ref (N / N_ref)^growth.
    """
    cond = [r for r in runs if r["solver"] == "condensed"]
    two = max((r for r in cond if r["ranks"] == 2), key=lambda r: r["dofs"])
    its_c = two["cg_total"] / two["dofs"] ** growth
    return Measured(dofs=two["dofs"], parts=parts_of(two), its_c=its_c, its_g=growth)


def phases_of(run: dict[str, Any]) -> Phases:
    """Seconds per DOF of mesh, assembly (times ranks) and predictor of one run."""
    t, n = run["times"], run["dofs"]
    assemble = t["assemble"] + t.get("search", 0.0) + t.get("contact", 0.0)
    return Phases(t["mesh"] / n, assemble * run["ranks"] / n, t.get("predictor", 0.0) / n)


def model_table(runs: list[dict[str, Any]], m: Measured, net: Network) -> str:
    """Markdown: modelled seconds, solve stage / whole run (communication share), by ranks."""
    two = max((r for r in runs if r["solver"] == "condensed" and r["ranks"] == 2),
              key=lambda r: r["dofs"])  # fmt: skip
    ph = phases_of(two)
    head = "| DOFs | CG its | " + " | ".join(f"P = {p}" for p in MODEL_RANKS) + " |"
    lines = [head, "|" + "---|" * (len(MODEL_RANKS) + 2)]
    for n in MODEL_SIZES:
        cells = []
        for p in MODEL_RANKS:
            t = predict(m, n, p, net)
            whole = whole_run(m, ph, n, p, net)
            share = 100 * t["communication"] / t["total"]
            cells.append(f"{t['total']:.1f} / {whole:.1f} ({share:.0f} %)")
        its = predict(m, n, 1, net)["iterations"]
        lines.append(f"| {n / 1e6:g}M | {its:.0f} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def direct_table(runs: list[dict[str, Any]], m: Measured, net: Network) -> str:
    """Markdown: the direct path extrapolated from its serial runs, against the condensed model.

    MUMPS' factorization memory (INFOG(22)) and elimination flops (RINFOG(3)) as power laws
    of the DOFs through the serial `mumps` runs; its time on P ranks at the largest serial
    run's flop rate, divided by P (ideal: optimistic for MUMPS); the process around it as the
    largest serial run's peak minus its INFOG(22), per DOF.
    """
    serial = sorted((r for r in runs if r["solver"] == "mumps" and r["ranks"] == 1
                     and r["mumps"]), key=lambda r: r["dofs"])  # fmt: skip
    if len(serial) < 2:
        return "(the direct model needs two serial mumps runs)"
    n = [float(r["dofs"]) for r in serial]
    mem_c, mem_g = power_fit(n, [r["mumps"]["infog22_mb"] for r in serial])
    fl_c, fl_g = power_fit(n, [r["mumps"]["elimination_flops"] for r in serial])
    big = serial[-1]
    rate = big["mumps"]["elimination_flops"] / big["mumps"]["factorization_s"]
    rest_kb = (big["peak_mb"] - big["mumps"]["infog22_mb"]) * 1024 / big["dofs"]
    lines = [
        f"INFOG(22) = {mem_c:.3g} N^{mem_g:.3f} MB, elimination flops = {fl_c:.3g} N^{fl_g:.3f}, "
        f"factorization rate {rate / 1e9:.2f} Gflop/s (serial, {big['dofs']:,} DOFs), "
        f"rest of the process {rest_kb:.2f} KB/DOF",
        "",
        "| DOFs | factor GB | process GB | factorization s, P = 2 / 8 / 64 / 256 (ideal) | "
        "condensed solve stage s, P = 2 / 8 / 64 / 256 |",
        "|---|---|---|---|---|",
    ]
    for size in (400e3, 2e6, *MODEL_SIZES):
        factor = mem_c * size**mem_g / 1024
        proc = factor + rest_kb * size / 1024**2
        fact = " / ".join(f"{fl_c * size**fl_g / (p * rate):.1f}" for p in (2, 8, 64, 256))
        cond = " / ".join(f"{predict(m, size, p, net)['total']:.1f}" for p in (2, 8, 64, 256))
        lines.append(f"| {size / 1e6:g}M | {factor:.1f} | {proc:.1f} | {fact} | {cond} |")
    return "\n".join(lines)


def table(runs: list[dict[str, Any]]) -> str:
    """Markdown: one row per run."""
    head = (
        "| solver | ranks | DOFs | mesh | assemble | predictor | solve | total (s) | CG its | "
        "peak MB (ranks) | KB/DOF | solve Gflop/rank | msgs/rank | MB sent/rank | "
        "allreduces/rank | MUMPS factor MB | load |"
    )
    lines = [head, "|" + "---|" * 17]
    for r in runs:
        t, pr = r["times"], r["per_rank"]
        lines.append(
            f"| {r['solver']} | {r['ranks']} | {r['dofs']:,} | {t['mesh']:.1f} | "
            f"{t['assemble']:.1f} | {t.get('predictor', 0.0):.1f} | {t['solve']:.1f} | "
            f"{t['total']:.1f} | {'+'.join(map(str, r['cg_iterations']))} | "
            f"{r['peak_mb']:.0f} ({', '.join(f'{x:.0f}' for x in r['peak_mb_ranks'])}) | "
            f"{r['kb_per_dof']:.2f} | {pr['flops'] / 1e9:.1f} | {pr['messages']:.0f} | "
            f"{pr['message_bytes'] / 1e6:.1f} | {pr['reductions_counted']:.0f} | "
            f"{r.get('mumps', {}).get('infog22_mb', '-')} | "
            f"{r['load_before'][0]:.1f}-{r['load_after'][0]:.1f} |"
        )
    return "\n".join(lines)


def chart(runs: list[dict[str, Any]], path: Path) -> None:
    """Seconds per million DOFs (whole run, solve) and KB per DOF against DOFs, by ranks."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_t, ax_m) = plt.subplots(1, 2, figsize=(10, 4))
    colours = {"condensed": "tab:blue", "mumps": "tab:red"}
    for solver, ranks in (("condensed", 1), ("condensed", 2), ("mumps", 1), ("mumps", 2)):
        rs = sorted((r for r in runs if (r["solver"], r["ranks"]) == (solver, ranks)),
                    key=lambda r: r["dofs"])  # fmt: skip
        if not rs:
            continue
        n = [r["dofs"] for r in rs]
        label = f"{solver}, {ranks} rank{'s' * (ranks > 1)}"
        kw = {"color": colours[solver], "marker": "os"[ranks - 1], "ls": "-:"[ranks - 1]}
        ax_t.plot(n, [r["times"]["total"] / r["dofs"] * 1e6 for r in rs], label=label, **kw)
        if solver == "condensed":
            ax_t.plot(n, [r["times"]["solve"] / r["dofs"] * 1e6 for r in rs], alpha=0.4,
                      label=f"{label}: solve only", **kw)  # fmt: skip
        ax_m.plot(n, [r["kb_per_dof"] for r in rs], label=label, **kw)
    for ax, what in ((ax_t, "seconds per million DOFs"), (ax_m, "peak KB per DOF (summed)")):
        ax.set_xscale("log")
        ax.set_xlabel("DOFs")
        ax.set_ylabel(what)
        ax.grid(alpha=0.3)
    ax_t.legend(fontsize=7)
    fig.suptitle("Hertz, structured, h_far = 10 h, dual mortar (benchmarks/scaling.py)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> None:
    """Run the sizes x ranks asked (one process each), merge, print the table, chart, model."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--sizes", default="100e3,400e3", help="comma list of target DOFs")
    ap.add_argument("--ranks", default="1,2", help="comma list of rank counts")
    ap.add_argument("--solver", default="condensed", choices=("condensed", "mumps"))
    ap.add_argument("--json", type=Path, default=HERE / "scaling.json")
    ap.add_argument("--chart", type=Path, default=HERE / "bench_scaling.png")
    ap.add_argument("--timeout", type=float, default=3600.0)
    ap.add_argument("--logs", type=Path, help="keep each run's -log_view text in this folder")
    ap.add_argument("--replot", action="store_true", help="no runs: table and chart again")
    ap.add_argument("--model", action="store_true", help="no runs: the 8-256-rank model")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--refine", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--log", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker(args.refine, args.solver, args.log, args.out)
        return
    runs = json.loads(args.json.read_text())["runs"] if args.json.exists() else []
    if not (args.replot or args.model):
        for size in (float(s) for s in args.sizes.split(",")):
            for ranks in (int(p) for p in args.ranks.split(",")):
                r = run_case(size, ranks, args.solver, args.timeout, args.logs)
                print(
                    f"{r['command']}: {r['dofs']:,} DOFs, total {r['times']['total']:.1f} s, "
                    f"solve {r['times']['solve']:.1f} s, CG {r['cg_iterations']}, "
                    f"{r['peak_mb']:.0f} MB ({r['kb_per_dof']:.2f} KB/DOF), "
                    f"load {r['load_before'][0]:.1f}",
                    flush=True,
                )
                runs = merge(args.json, [r])
    print(table(runs))
    chart(runs, args.chart)
    if args.model or any(r["ranks"] == 2 and r["solver"] == "condensed" for r in runs):
        m = fit(runs)
        print(json.dumps(dataclasses.asdict(m), indent=1))
        print(model_table(runs, m, Network()))
        print(direct_table(runs, m, Network()))


if __name__ == "__main__":
    main()
