"""Hertz benchmarks: contact solve against its floor (one fresh solve of the final system).

`make bench` runs this (about 30 min on 2 cores); `--quick` is a two-minute smoke version.
The sweep: 8 sizes from 20k to 2M dofs, the structured and the gmsh Hertz meshes (h_far =
10 h, gmsh also refine_edge = h / 4), nts, sts and mortar, for each solver of `--solvers`
(default mumps; a new solver is one more name there), with the default options, as
`python -m contactfx solve hertz --refine H [--refine-edge H/4 | --mesh structured]
--h-far 10H --method M --solver S --reference-timing` would run them. Every (mesh, size,
solver, ranks) case runs in a fresh process (benchmarks/case.py, serial or `mpirun -n 2`)
that meshes once and solves the three methods in turn, so peak memory belongs to that case.
Writes benchmarks/results.json, the tables in benchmarks/README.md and the charts
benchmarks/*.png. The machine may be shared: the load average is recorded with every run, and
the ratios are taken within one run (contact solve and reference solve in the same process).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from contactfx.meshes.hertz_structured import hertz_grid

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

PY = sys.executable
MPIRUN = str(Path(PY).parent / "mpirun")
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
# Largest element size as a multiple of the contact element size: keeps cells at most 10:1.
H_RATIO = 10.0
# gmsh refines x = a to h / EDGE_RATIO (the pressure's square-root edge).
EDGE_RATIO = 4.0
SIZES = (20e3, 40e3, 80e3, 150e3, 300e3, 600e3, 1.2e6, 2e6)
QUICK_SIZES = (20e3, 60e3)
METHODS = ("nts", "sts", "mortar")
MESHERS = ("structured", "gmsh")
# Repeats (medians): 5 up to SMALL_DOFS (0.1-1 s solves, the noisiest), 3 up to CHEAP_DOFS,
# one run above (the large cases dominate the time).
SMALL_DOFS = 100e3
CHEAP_DOFS = 700e3
TARGET = 1.5
START, END = "<!-- bench:start -->", "<!-- bench:end -->"


def refine_for(dofs: float, mesh: str = "structured", ratio: float = H_RATIO) -> float:
    """Contact element size h0 (cm) whose Hertz mesh (h_far = ratio * h0) has about `dofs` dofs.

    Structured: the grid itself is counted. gmsh: a fit of its dof counts on these meshes
    (edge refinement h0 / 4), dofs ~ 125.6 / h0^2 + 324 / h0 (within ~5% from 14k to 500k).
    """

    def count(h: float) -> float:
        if mesh == "gmsh":
            return 125.6 / h**2 + 324.0 / h
        return 2 * len(hertz_grid(60.0, 60.0, 60.0, h, 2.0, ratio * h, 0.1)[0])

    lo, hi = 1e-3, 2.0
    for _ in range(30):
        mid = (lo * hi) ** 0.5
        lo, hi = (mid, hi) if count(mid) > dofs else (lo, mid)
    return round((lo * hi) ** 0.5, 6)


def run_process(
    mesh: str,
    methods: tuple[str, ...],
    solver: str,
    h0: float,
    ranks: int,
    fixed: bool = False,
    timeout: float = 1800,
    basis: str = "standard",
    h_far: float | None = None,
    reference: bool = True,
) -> list[dict[str, Any]]:
    """Run benchmarks/case.py once (all `methods` on one mesh); return one record per method.

    `h_far` defaults to H_RATIO * h0 (the sweep's meshes); `reference=False` skips the
    reference solve.
    """
    cmd = [
        PY,
        str(HERE / "case.py"),
        "--mesh",
        mesh,
        "--method",
        ",".join(methods),
        "--solver",
        solver,
        "--refine",
        str(h0),
        "--h-far",
        str(H_RATIO * h0 if h_far is None else h_far),
        "--basis",
        basis,
    ]
    if not reference:
        cmd.append("--no-reference")
    if mesh == "gmsh":
        cmd += ["--refine-edge", str(round(h0 / EDGE_RATIO, 8))]
    if fixed:
        cmd.append("--fixed-set")
    if ranks > 1:
        cmd = [MPIRUN, "-n", str(ranks), *cmd]
    base = {"mesh": mesh, "solver": solver, "ranks": ranks, "refine": h0, "fixed_set": fixed}
    t0 = time.perf_counter()
    load = os.getloadavg()[0]
    try:
        proc = subprocess.run(
            cmd, cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=timeout
        )
    except subprocess.TimeoutExpired:
        return [{**base, "method": m, "error": f"timeout after {timeout:.0f} s"} for m in methods]
    records = {}
    for line in proc.stdout.splitlines():
        if line.startswith("RESULT "):
            rec = json.loads(line[7:])
            records[rec["method"]] = rec
    out = []
    for m in methods:
        if m in records:
            out.append(
                {**records[m], "fixed_set": fixed, "load": load, "wall": time.perf_counter() - t0}
            )
        else:
            out.append(
                {
                    **base,
                    "method": m,
                    "error": f"exit {proc.returncode}: {(proc.stderr or proc.stdout)[-400:]}",
                }
            )
    return out


def t(record: dict[str, Any], key: str) -> float:
    """A timer of a run record (0 if absent)."""
    return float(record["times"].get(key, 0.0))


def contact_solve(record: dict[str, Any]) -> float:
    """Search + B assembly + the coarse predictor's whole solve (if any) + active-set solves."""
    return sum(t(record, k) for k in ("search", "contact", "predictor", "solve"))


def group_key(r: dict[str, Any]) -> tuple[Any, ...]:
    """What makes two run records repeats of one case."""
    return (
        r.get("mesh", "structured"),
        r["method"],
        r["solver"],
        r.get("fixed_set", False),
        r["ranks"],
        r["refine"],
    )


def summarize(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Medians over repeats per (mesh, method, solver, fixed, ranks, size)."""
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for r in runs:
        if "error" not in r:
            groups.setdefault(group_key(r), []).append(r)
    rows = []
    for (mesh, method, solver, fixed, ranks, h0), rs in sorted(
        groups.items(), key=lambda kv: (*kv[0][:5], -kv[0][5])
    ):

        def med(f: Any, rs: list[dict[str, Any]] = rs) -> float:
            return float(statistics.median(f(r) for r in rs))

        row: dict[str, Any] = {
            "mesh": mesh,
            "method": method,
            "solver": solver,
            "fixed_set": fixed,
            "ranks": ranks,
            "refine": h0,
            "dofs": rs[0]["dofs"],
            "runs": len(rs),
            "multipliers": rs[0]["multipliers"],
            "active_nodes": rs[0]["active_nodes"],
            "iterations": rs[0]["iterations"],
            "mesh_time": med(lambda r: t(r, "mesh")),
            "contact_solve": med(contact_solve),
            "reference": med(lambda r: t(r, "reference_solve")),
            "search_assembly": med(lambda r: t(r, "search") + t(r, "contact")),
            "mb_per_100k": med(lambda r: r["peak_rss_mb"] / (r["dofs"] / 1e5)),
            "load": med(lambda r: r["load"]),
        }
        if not fixed:
            ratios = [contact_solve(r) / t(r, "reference_solve") for r in rs]
            row["ratio"] = float(statistics.median(ratios))
            row["ratio_range"] = [min(ratios), max(ratios)]
            row["predictor"] = med(lambda r: t(r, "predictor"))
            row["linear_iterations"] = [h["linear_iterations"] for h in rs[0]["history"]]
            row["factorizations"] = sum(h.get("factorized", 1) for h in rs[0]["history"])
            row["probes"] = sum(h.get("probes", 0) for h in rs[0]["history"])
            row["step_times"] = [round(h["solve_time"], 3) for h in rs[0]["history"]]
        else:
            row["linear_iterations"] = [rs[0]["linear_iterations"]]
        rows.append(row)
    return rows


def plan(
    quick: bool, solvers: list[str], ranks: list[int], sizes: tuple[float, ...]
) -> list[tuple[str, str, float, int, int]]:
    """(mesh, solver, target dofs, ranks, repeats) of every case, small sizes first."""
    cases = []
    for n in QUICK_SIZES if quick and sizes == SIZES else sizes:
        for mesh in MESHERS:
            for solver in solvers:
                for r in ranks:
                    repeats = 5 if n <= SMALL_DOFS else 3 if n <= CHEAP_DOFS else 1
                    cases.append((mesh, solver, n, r, 1 if quick else repeats))
    return cases


def table(rows: list[dict[str, Any]]) -> str:
    """Markdown table of the summary rows of the active-set sweep."""
    head = (
        "| mesh | method | solver | ranks | dofs | multipliers | AS its | factorizations | "
        "probes | step times (s) | contact solve (s) | reference (s) | ratio (range) | "
        "MB/100k dofs | load |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n"
    )
    lines = []
    for r in rows:
        if r["fixed_set"]:
            continue
        lo, hi = r["ratio_range"]
        rng = f" ({lo:.2f}-{hi:.2f})" if r["runs"] > 1 else ""
        mark = "" if r["ratio"] <= TARGET else " **>1.5**"
        cells = [
            r["mesh"],
            r["method"],
            r["solver"],
            str(r["ranks"]),
            f"{r['dofs']:,}",
            str(r["multipliers"]),
            str(r["iterations"]),
            str(r["factorizations"]),
            str(r["probes"]),
            "/".join(f"{x:.2f}" for x in r["step_times"]),
            f"{r['contact_solve']:.2f}",
            f"{r['reference']:.2f}",
            f"{r['ratio']:.2f}{rng}{mark}",
            f"{r['mb_per_100k']:.0f}",
            f"{r['load']:.1f}",
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return head + "\n".join(lines) + "\n"


def extremes(rows: list[dict[str, Any]]) -> str:
    """Markdown table: min and max ratio (with their sizes) per mesh, method and solver."""
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for r in rows:
        if not r["fixed_set"]:
            groups.setdefault((r["mesh"], r["method"], r["solver"], r["ranks"]), []).append(r)
    out = (
        "| mesh | method | solver | ranks | sizes | dofs | min ratio | max ratio | "
        "sizes above 1.5 |\n|---|---|---|---|---|---|---|---|---|\n"
    )
    for (mesh, method, solver, ranks), rs in sorted(groups.items()):
        lo = min(rs, key=lambda r: r["ratio"])
        hi = max(rs, key=lambda r: r["ratio"])
        over = [f"{r['dofs']:,}" for r in rs if r["ratio"] > TARGET]
        dofs = f"{min(r['dofs'] for r in rs):,} - {max(r['dofs'] for r in rs):,}"
        out += (
            f"| {mesh} | {method} | {solver} | {ranks} | {len(rs)} | {dofs} | "
            f"{lo['ratio']:.2f} ({lo['dofs']:,}) | {hi['ratio']:.2f} ({hi['dofs']:,}) | "
            f"{', '.join(over) or 'none'} |\n"
        )
    return out


def charts(rows: list[dict[str, Any]]) -> list[str]:
    """Ratio against dofs (one panel per mesh) and time against dofs; returns the file names."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    loop = [r for r in rows if not r["fixed_set"]]
    meshes = [m for m in MESHERS if any(r["mesh"] == m for r in loop)]
    if not meshes:
        return []
    series = sorted({(r["method"], r["solver"], r["ranks"]) for r in loop})
    fig, axes = plt.subplots(2, len(meshes), figsize=(5.5 * len(meshes), 8), squeeze=False)
    markers = {"nts": "o", "sts": "s", "mortar": "^"}
    for col, mesh in enumerate(meshes):
        ax, axt = axes[0][col], axes[1][col]
        for i, (method, solver, ranks) in enumerate(series):
            sel = sorted(
                (
                    r
                    for r in loop
                    if r["mesh"] == mesh
                    and r["method"] == method
                    and r["solver"] == solver
                    and r["ranks"] == ranks
                ),
                key=lambda r: r["dofs"],
            )
            if not sel:
                continue
            label = f"{method}, {solver}" + (f", {ranks} ranks" if ranks > 1 else "")
            d = [r["dofs"] for r in sel]
            err = [
                [r["ratio"] - r["ratio_range"][0] for r in sel],
                [r["ratio_range"][1] - r["ratio"] for r in sel],
            ]
            ax.errorbar(
                d,
                [r["ratio"] for r in sel],
                yerr=err,
                marker=markers.get(method, "x"),
                color=f"C{i}",
                capsize=2,
                label=label,
            )
            axt.loglog(
                d,
                [r["contact_solve"] for r in sel],
                marker=markers.get(method, "x"),
                color=f"C{i}",
                label=f"contact solve, {label}",
            )
            if i == 0:
                axt.loglog(d, [r["reference"] for r in sel], "k--", label="reference solve")
        ax.set_xscale("log")
        ax.axhline(TARGET, color="k", lw=0.8, ls=":", label=f"target {TARGET}")
        ax.axhline(1.0, color="0.6", lw=0.6)
        ax.set_ylim(0.0, max(2.0, 1.1 * max(r["ratio"] for r in loop)))
        ax.set_xlabel("dofs")
        ax.set_ylabel("contact solve / reference solve")
        ax.set_title(f"Hertz, {mesh} mesh: cost over the one-solve floor")
        ax.legend(fontsize=7)
        axt.set_xlabel("dofs")
        axt.set_ylabel("wall time (s)")
        axt.set_title(f"Hertz, {mesh} mesh: times")
        axt.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(HERE / "bench_ratio.png", dpi=90)
    plt.close(fig)
    return ["bench_ratio.png"]


def write_readme(rows: list[dict[str, Any]], meta: dict[str, Any], figures: list[str]) -> None:
    """Regenerate the table section of benchmarks/README.md."""
    path = HERE / "README.md"
    text = (
        path.read_text()
        if path.exists()
        else (
            "# Benchmarks\n\nRegenerated by `make bench` "
            "(`python benchmarks/run.py [--quick]`).\n\n"
            f"{START}\n{END}\n"
        )
    )
    body = (
        f"Run {meta['date']} on {meta['machine']} ({meta['cpus']} cores), "
        f"{'quick' if meta['quick'] else 'full'} mode, {meta.get('minutes', 0):.0f} min, "
        f"load average {meta['load_before']:.1f} before / {meta['load_after']:.1f} after "
        f"(the machine is shared: compare ratios within a row, not times across runs).\n\n"
        + (f"Rows rerun later with `--case`: {meta['updated']}.\n\n" if meta.get("updated") else "")
        + "contact solve = search + B assembly + the coarse predictor (if the defaults use "
        "one) + all active-set solves; reference = one fresh solve (setup, analysis, "
        "factorization, solve) of the final system by the same solver, in the same "
        "process; ratio = contact solve / reference, median of the repeats (range in "
        "brackets: 5 runs up to 100k dofs, 3 up to 700k, 1 above; the methods take turns "
        "at being the first solve of the process, which pays its warm-up); step times = the "
        "active-set steps' solve times; MB/100k dofs = the process's peak RSS (three "
        "methods solved in turn on one mesh). Meshes: `--refine H --h-far 10H` and "
        "`--refine-edge H/4` (gmsh) or `--mesh structured`.\n\n"
        "Ratio extremes:\n\n"
        + extremes(rows)
        + "\nAll rows:\n\n"
        + table(rows)
        + "\n"
        + "".join(f"![{f}]({f})\n" for f in figures)
    )
    if START not in text:
        text += f"\n{START}\n{END}\n"
    pre, rest = text.split(START, 1)
    post = rest.split(END, 1)[1]
    path.write_text(f"{pre}{START}\n{body}{END}{post}")


def save(meta: dict[str, Any], runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Summarize `runs`, write results.json, the charts and the README tables."""
    rows = summarize(runs)
    (HERE / "results.json").write_text(
        json.dumps({"meta": meta, "summary": rows, "runs": runs}, indent=1) + "\n"
    )
    write_readme(rows, meta, charts(rows))
    return rows


def update(cases: list[str]) -> None:
    """Run `cases` and merge them into results.json (the README notes when rows changed)."""
    data = json.loads((HERE / "results.json").read_text())
    new = []
    for case in cases:
        mesh, methods, solver, dofs, ranks, repeats = case.split(":")
        h0 = refine_for(float(dofs), mesh)
        for _ in range(int(repeats)):
            recs = run_process(mesh, tuple(methods.split(",")), solver, h0, int(ranks))
            new += recs
            for rec in recs:
                print(
                    f"{mesh} {rec['method']} {solver} {ranks}r h0={h0}: "
                    f"{rec.get('error') or rec['times']}",
                    flush=True,
                )
    keys = {group_key(r) for r in new if "error" not in r}
    runs = [r for r in data["runs"] if "error" in r or group_key(r) not in keys] + new
    meta = data["meta"]
    stamp = f"{time.strftime('%Y-%m-%d %H:%M')} (load {os.getloadavg()[0]:.1f}): " + "; ".join(
        cases
    )
    meta["updated"] = f"{meta['updated']}; {stamp}" if meta.get("updated") else stamp
    print(table(save(meta, runs)))


def main() -> None:
    """Run the plan, write results.json, README tables and charts."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two small sizes, one repeat")
    ap.add_argument(
        "--solvers",
        default="mumps",
        help="comma-separated solvers, each run over the whole sweep (default "
        "mumps; e.g. mumps,condensed)",
    )
    ap.add_argument("--ranks", default="1", help="comma-separated rank counts (default 1)")
    ap.add_argument(
        "--methods",
        default=",".join(METHODS),
        help="comma-separated methods (default nts,sts,mortar)",
    )
    ap.add_argument(
        "--basis",
        default="standard",
        help="mortar's multiplier basis "
        "(standard or dual; e.g. with --solvers condensed --methods nts,mortar)",
    )
    ap.add_argument(
        "--sizes", default=None, help="comma-separated target dofs (default the 8 sizes 20k ... 2M)"
    )
    ap.add_argument(
        "--replot",
        action="store_true",
        help="only redo the charts and README tables from results.json",
    )
    ap.add_argument(
        "--case",
        action="append",
        default=[],
        metavar="MESH:METHODS:SOLVER:DOFS:RANKS:REPEATS",
        help="run only these cases (e.g. gmsh:nts,sts,mortar:mumps:1e6:1:3) and "
        "merge them into results.json, replacing earlier runs of the same case",
    )
    args = ap.parse_args()
    if args.case:
        return update(args.case)
    if args.replot:
        data = json.loads((HERE / "results.json").read_text())
        write_readme(data["summary"], data["meta"], charts(data["summary"]))
        return
    solvers = args.solvers.split(",")
    methods = tuple(args.methods.split(","))
    ranks = [int(r) for r in args.ranks.split(",")]
    sizes = tuple(float(s) for s in args.sizes.split(",")) if args.sizes else SIZES
    meta: dict[str, Any] = {
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "machine": platform.processor() or platform.machine(),
        "cpus": os.cpu_count(),
        "quick": args.quick,
        "load_before": os.getloadavg()[0],
        "h_ratio": H_RATIO,
        "edge_ratio": EDGE_RATIO,
        "solvers": solvers,
        "ranks": ranks,
        "methods": methods,
        "basis": args.basis,
    }
    t_start = time.perf_counter()
    refine: dict[tuple[float, str], float] = {}
    runs: list[dict[str, Any]] = []
    for mesh, solver, dofs, nranks, repeats in plan(args.quick, solvers, ranks, sizes):
        h0 = refine.setdefault((dofs, mesh), refine_for(dofs, mesh))
        for i in range(repeats):
            # The first solve of a process pays its warm-up (first-touch memory, MUMPS set-up:
            # 20k dofs, sts three times in one process: ratio 1.58, 1.19, 1.14): the methods
            # take turns at being first, over the repeats and over the sizes.
            k = (i + sizes.index(dofs) if dofs in sizes else i) % len(methods)
            order = methods[k:] + methods[:k]
            recs = run_process(mesh, order, solver, h0, nranks, basis=args.basis)
            runs += recs
            for rec in recs:
                status = rec.get("error") or (
                    f"{rec['dofs']:,} dofs, contact solve {contact_solve(rec):.2f} s, "
                    f"ref {t(rec, 'reference_solve'):.2f} s, "
                    f"ratio {contact_solve(rec) / t(rec, 'reference_solve'):.2f}"
                )
                print(
                    f"{mesh:10s} {rec['method']:6s} {solver:10s} {nranks}r h0={h0}: {status}",
                    flush=True,
                )
        meta["load_after"] = os.getloadavg()[0]
        meta["minutes"] = (time.perf_counter() - t_start) / 60
        save(meta, runs)  # after every case: a long run leaves its results so far
    print(table(summarize(runs)))


if __name__ == "__main__":
    main()
