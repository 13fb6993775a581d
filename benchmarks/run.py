"""Hertz benchmarks: contact solve against its floor (one fresh solve of the final system).

`make bench` runs this (20-30 min on 2 cores); `--quick` is a one-minute smoke version.
Every case runs in a fresh process (benchmarks/case.py, serial or `mpirun -n 2`), so peak
memory belongs to that case. Writes benchmarks/results.json, the table in
benchmarks/README.md and the charts benchmarks/*.png. The machine may be shared: the load
average is recorded before and after, and the ratios are taken within one run.
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

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

from meshes.hertz_structured import hertz_grid  # noqa: E402

PY = sys.executable
MPIRUN = str(Path(PY).parent / "mpirun")
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
# Largest element size as a multiple of the contact element size: keeps cells at most 10:1.
H_RATIO = 10.0
START, END = "<!-- bench:start -->", "<!-- bench:end -->"


def refine_for(dofs: float) -> float:
    """Contact element size h0 (cm) whose structured Hertz mesh has about `dofs` dofs."""
    lo, hi = 1e-3, 0.2
    for _ in range(30):
        mid = (lo * hi) ** 0.5
        n = 2 * len(hertz_grid(60.0, 60.0, 60.0, mid, 2.0, H_RATIO * mid, 0.1)[0])
        lo, hi = (mid, hi) if n > dofs else (lo, mid)
    return round((lo * hi) ** 0.5, 6)


def run_case(method: str, solver: str, h0: float, ranks: int, fixed: bool = False,
             timeout: float = 900) -> dict:
    """Run benchmarks/case.py once; return its record (or an error record)."""
    cmd = [PY, str(HERE / "case.py"), "--method", method, "--solver", solver,
           "--refine", str(h0), "--h-far", str(H_RATIO * h0)]
    if fixed:
        cmd.append("--fixed-set")
    if ranks > 1:
        cmd = [MPIRUN, "-n", str(ranks), *cmd]
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True,
                              timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"method": method, "solver": solver, "ranks": ranks, "refine": h0,
                "error": f"timeout after {timeout:.0f} s"}
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")]
    if proc.returncode != 0 or not lines:
        return {"method": method, "solver": solver, "ranks": ranks, "refine": h0,
                "error": f"exit {proc.returncode}: {(proc.stderr or proc.stdout)[-400:]}"}
    record = json.loads(lines[-1][7:])
    record["wall"] = time.perf_counter() - t0
    record["fixed_set"] = fixed
    record["load"] = os.getloadavg()[0]
    return record


def t(record: dict, key: str) -> float:
    """A timer of a run record (0 if absent)."""
    return record["times"].get(key, 0.0)


def contact_solve(record: dict) -> float:
    """Search + B assembly + the coarse predictor's whole solve (if any) + active-set solves."""
    return sum(t(record, k) for k in ("search", "contact", "predictor", "solve"))


def summarize(runs: list[dict]) -> list[dict]:
    """Medians over repeats per (method, solver, fixed, ranks, size)."""
    groups: dict[tuple, list[dict]] = {}
    for r in runs:
        if "error" not in r:
            key = (r["method"], r["solver"], r["fixed_set"], r["ranks"], r["refine"])
            groups.setdefault(key, []).append(r)
    rows = []
    for (method, solver, fixed, ranks, h0), rs in sorted(groups.items(),
                                                         key=lambda kv: (*kv[0][:4], -kv[0][4])):
        def med(f, rs=rs):
            return statistics.median(f(r) for r in rs)

        row = {"method": method, "solver": solver, "fixed_set": fixed, "ranks": ranks,
               "refine": h0, "dofs": rs[0]["dofs"], "runs": len(rs),
               "multipliers": rs[0]["multipliers"], "active_nodes": rs[0]["active_nodes"],
               "iterations": rs[0]["iterations"],
               "mesh": med(lambda r: t(r, "mesh")),
               "total": med(lambda r: r["times"].get("total", r.get("total", 0.0))),
               "contact_solve": med(contact_solve),
               "reference": med(lambda r: t(r, "reference_solve")),
               "search_assembly": med(lambda r: t(r, "search") + t(r, "contact")),
               "mb_per_100k": med(lambda r: r["peak_rss_mb"] / (r["dofs"] / 1e5)),
               "load": med(lambda r: r["load"])}
        if not fixed:
            row["ratio"] = med(lambda r: contact_solve(r) / t(r, "reference_solve"))
            row["predictor"] = med(lambda r: t(r, "predictor"))
            row["share"] = med(lambda r: (t(r, "search") + t(r, "contact")) / t(r, "total"))
            row["linear_iterations"] = [h["linear_iterations"] for h in rs[0]["history"]]
            row["factorizations"] = sum(h.get("factorized", 1) for h in rs[0]["history"])
            row["probes"] = sum(h.get("probes", 0) for h in rs[0]["history"])
        else:
            row["linear_iterations"] = [rs[0]["linear_iterations"]]
        rows.append(row)
    return rows


def plan(quick: bool) -> list[tuple]:
    """(method, solver, target dofs, ranks, repeats, fixed_set) of every case."""
    if quick:
        sizes = [30e3, 60e3]
        cases = [("mortar", "mumps", n, r, 1, False) for n in sizes for r in (1, 2)]
        cases += [(m, "mumps", sizes[0], 1, 1, False) for m in ("nts", "sts")]
        cases += [("mortar", "fieldsplit-gamg", n, 1, 1, True) for n in sizes]
        return cases
    sizes = [100e3, 250e3, 500e3, 1e6, 2e6]
    cases = [("mortar", "mumps", n, r, 3 if n <= 1e6 else 1, False)
             for n in sizes for r in (1, 2)]
    cases += [(m, "mumps", n, 1, 1, False) for m in ("nts", "sts") for n in sizes[:3]]
    cases += [("mortar", "fieldsplit-gamg", n, 1, 1, True) for n in sizes]
    cases += [("mortar", "fieldsplit-gamg", n, 2, 1, True) for n in sizes[3:]]
    cases += [("mortar", "fieldsplit-gamg", sizes[0], 1, 1, False)]
    return cases


def table(rows: list[dict]) -> str:
    """Markdown table of the summary rows."""
    head = ("| method | solver | ranks | dofs | AS its | linear its | contact solve (s) | "
            "reference (s) | ratio | search+B share | MB/100k dofs | load |\n"
            "|---|---|---|---|---|---|---|---|---|---|---|---|\n")
    lines = []
    for r in rows:
        its = "/".join(map(str, r["linear_iterations"]))
        loop = not r["fixed_set"]
        cells = [r["method"], r["solver"] + ("" if loop else " (fixed set)"), str(r["ranks"]),
                 f"{r['dofs']:,}", str(r["iterations"]), its,
                 f"{r['contact_solve']:.2f}" if loop else "-", f"{r['reference']:.2f}",
                 f"{r['ratio']:.2f}" if loop and r.get("ratio") else "-",
                 f"{100 * r['share']:.1f}%" if loop else "-", f"{r['mb_per_100k']:.0f}",
                 f"{r['load']:.1f}"]
        lines.append("| " + " | ".join(cells) + " |")
    return head + "\n".join(lines) + "\n"


def charts(rows: list[dict]) -> list[str]:
    """Time, ratio and iteration charts; returns the file names."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = []
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ranks, color in ((1, "C0"), (2, "C3")):
        sel = [r for r in rows if r["method"] == "mortar" and r["solver"] == "mumps"
               and r["ranks"] == ranks and not r["fixed_set"]]
        if not sel:
            continue
        d = [r["dofs"] for r in sel]
        tag = f"{ranks} rank{'s' * (ranks > 1)}"
        axes[0].loglog(d, [r["contact_solve"] for r in sel], "o-", color=color,
                       label=f"contact solve, {tag}")
        axes[0].loglog(d, [r["reference"] for r in sel], "s--", color=color,
                       label=f"reference solve, {tag}")
        axes[1].semilogx(d, [r["ratio"] for r in sel], "o-", color=color, label=tag)
    axes[0].set_xlabel("dofs")
    axes[0].set_ylabel("wall time (s)")
    axes[0].set_title("Hertz, mortar, MUMPS: solve time")
    axes[0].legend(fontsize=8)
    axes[1].axhline(1.5, color="k", lw=0.8, ls=":", label="target 1.5")
    axes[1].set_xlabel("dofs")
    axes[1].set_ylabel("(search + B + active-set solves) / reference")
    axes[1].set_title("cost over the one-solve floor")
    axes[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(HERE / "bench_mumps.png", dpi=90)
    plt.close(fig)
    names.append("bench_mumps.png")

    sel = [r for r in rows if r["solver"] == "fieldsplit-gamg" and r["fixed_set"]]
    if sel:
        fig, ax = plt.subplots(figsize=(5.5, 4))
        for ranks in (1, 2):
            s = [r for r in sel if r["ranks"] == ranks]
            if s:
                ax.semilogx([r["dofs"] for r in s], [r["linear_iterations"][0] for r in s],
                            "o-", label=f"{ranks} rank{'s' * (ranks > 1)}")
        ax.set_xlabel("dofs")
        ax.set_ylabel("FGMRES iterations (rtol 1e-10)")
        ax.set_title("GAMG fieldsplit, AL Schur diagonal")
        ax.set_ylim(bottom=0)
        ax.legend()
        fig.tight_layout()
        fig.savefig(HERE / "bench_gamg.png", dpi=90)
        plt.close(fig)
        names.append("bench_gamg.png")
    return names


def write_readme(rows: list[dict], meta: dict, figures: list[str]) -> None:
    """Regenerate the table section of benchmarks/README.md."""
    path = HERE / "README.md"
    text = path.read_text() if path.exists() else (
        "# Benchmarks\n\nRegenerated by `make bench` (`python benchmarks/run.py [--quick]`). "
        "The Hertz scene on the structured graded mesh (`meshes/hertz_structured.py`).\n\n"
        f"{START}\n{END}\n")
    body = (f"Run {meta['date']} on {meta['machine']} ({meta['cpus']} cores), "
            f"{'quick' if meta['quick'] else 'full'} mode, load average "
            f"{meta['load_before']:.1f} before / {meta['load_after']:.1f} after "
            f"(the machine is shared: compare ratios within a row, not times across runs).\n\n"
            + (f"Rows rerun later with `--case`: {meta['updated']}.\n\n"
               if meta.get("updated") else "")
            + "contact solve = search + B assembly + the coarse predictor (meshing and solving "
            "the 8x coarser scene, above 200k dofs) + all active-set solves; reference = one "
            "fresh solve (setup, factorization, solve) of the final system by the same solver; "
            "ratio = contact solve / reference; share = (search + B) / total run time; "
            "linear its per active-set step; medians of the repeats.\n\n"
            + table(rows) + "\n" + "".join(f"![{f}]({f})\n" for f in figures))
    if START not in text:
        text += f"\n{START}\n{END}\n"
    pre, rest = text.split(START, 1)
    post = rest.split(END, 1)[1]
    path.write_text(f"{pre}{START}\n{body}{END}{post}")


def run_key(record: dict) -> tuple:
    """What makes two run records repeats of one case."""
    return (record["method"], record["solver"], record.get("fixed_set", False),
            record["ranks"], record["refine"])


def update(cases: list[str]) -> None:
    """Run `cases` and merge them into results.json (the README notes when rows changed)."""
    data = json.loads((HERE / "results.json").read_text())
    new = []
    for case in cases:
        method, solver, dofs, ranks, repeats = case.split(",")
        h0 = refine_for(float(dofs))
        for _ in range(int(repeats)):
            rec = run_case(method, solver, h0, int(ranks))
            new.append(rec)
            print(f"{method} {solver} {ranks}r h0={h0}: "
                  f"{rec.get('error') or rec['times']}", flush=True)
    keys = {run_key(r) for r in new if "error" not in r}
    runs = [r for r in data["runs"] if "error" in r or run_key(r) not in keys] + new
    meta = data["meta"]
    stamp = (f"{time.strftime('%Y-%m-%d %H:%M')} (load {os.getloadavg()[0]:.1f}): "
             + "; ".join(cases))
    meta["updated"] = f"{meta['updated']}; {stamp}" if meta.get("updated") else stamp
    rows = summarize(runs)
    (HERE / "results.json").write_text(json.dumps({"meta": meta, "summary": rows,
                                                   "runs": runs}, indent=1) + "\n")
    write_readme(rows, meta, charts(rows))
    print(table(rows))


def main() -> None:
    """Run the plan, write results.json, README table and charts."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="two small sizes, one repeat")
    ap.add_argument("--replot", action="store_true",
                    help="only redo the charts and README table from results.json")
    ap.add_argument("--case", action="append", default=[],
                    metavar="METHOD,SOLVER,DOFS,RANKS,REPEATS",
                    help="run only these cases (e.g. mortar,mumps,1e6,1,3) and merge them into "
                    "results.json, replacing earlier runs of the same case")
    args = ap.parse_args()
    if args.case:
        return update(args.case)
    if args.replot:
        data = json.loads((HERE / "results.json").read_text())
        write_readme(data["summary"], data["meta"], charts(data["summary"]))
        return
    meta = {"date": time.strftime("%Y-%m-%d %H:%M"), "machine": platform.processor() or
            platform.machine(), "cpus": os.cpu_count(), "quick": args.quick,
            "load_before": os.getloadavg()[0], "h_ratio": H_RATIO}
    refine = {}
    runs = []
    for method, solver, dofs, ranks, repeats, fixed in plan(args.quick):
        h0 = refine.setdefault(dofs, refine_for(dofs))
        for _ in range(repeats):
            rec = run_case(method, solver, h0, ranks, fixed)
            runs.append(rec)
            status = rec.get("error") or (f"{rec['dofs']:,} dofs, "
                                          f"solve {rec['times'].get('solve', 0):.2f} s, "
                                          f"ref {rec['times'].get('reference_solve', 0):.2f} s")
            print(f"{method:6s} {solver:16s} {ranks}r {'fixed ' if fixed else ''}h0={h0}: "
                  f"{status}", flush=True)
    meta["load_after"] = os.getloadavg()[0]
    rows = summarize(runs)
    (HERE / "results.json").write_text(json.dumps({"meta": meta, "summary": rows,
                                                   "runs": runs}, indent=1) + "\n")
    figures = charts(rows)
    write_readme(rows, meta, figures)
    print(table(rows))


if __name__ == "__main__":
    main()
