"""The condensed solver against MUMPS, 100k to 10M dofs (issue 12, item 3): `make bench-scale`.

Mesh: the structured Hertz mesh with cells of aspect ratio 1, `python -m contactfx solve hertz
--mesh structured --refine H --h-far H` (the graded `--h-far 10H` family of `run.py` leaves
cells of aspect up to 10 along the contact surfaces, which GAMG's point smoothers do not
handle: its iterations are recorded here as well). Cases, each in a fresh process
(benchmarks/case.py), nts and mortar with the dual basis solved in turn on one mesh:
- serial sweep, condensed and mumps (contact solve only; condensed also its reference solve,
  one fresh CG + GAMG solve from zero to the final tolerance: the iterations per solve);
- 2M dofs on 1 and 2 ranks, both solvers;
- 10M dofs on 2 ranks, condensed: the whole run (process wall time) and peak memory, once
  as a user runs it and once with the reference solve (its iterations);
- the graded family (h_far = 10 H), condensed, nts: iterations per solve.
Writes benchmarks/scale.json, the table between the scale markers of benchmarks/README.md and
benchmarks/bench_scale.png. About 25 minutes on this 2-core machine.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path
from typing import Any

# The sweep's helpers (benchmarks/run.py, next to this script: on sys.path as its folder).
from run import contact_solve, refine_for, run_process

HERE = Path(__file__).resolve().parent

SERIAL = (100e3, 250e3, 500e3, 1e6, 2e6, 4e6)
GRADED = (100e3, 500e3, 2e6)
PARALLEL = 2e6
LARGEST = 10e6
METHODS = ("nts", "mortar")
START, END = "<!-- scale:start -->", "<!-- scale:end -->"
# The floor the chart draws: one assembled multigrid solve of 2D elasticity, setup and
# solve each at about 1M DOFs per second and core (deal.II step-37/50 and AMGCL's published
# timings; benchmarks/README.md, "The floor").
FLOOR_DOF_PER_S_PER_CORE = 1.0e6


def case(
    dofs: float,
    solver: str,
    ranks: int = 1,
    ratio: float = 1.0,
    reference: bool = False,
    methods: tuple[str, ...] = METHODS,
) -> list[dict[str, Any]]:
    """One process: the Hertz mesh of about `dofs` (h_far = ratio * h), each method in turn."""
    h = refine_for(dofs, ratio=ratio)
    out = run_process(
        "structured",
        methods,
        solver,
        h,
        ranks,
        timeout=1800,
        basis="dual",
        h_far=ratio * h,
        reference=reference,
    )
    for r in out:
        r.update(target=dofs, ratio_far=ratio, with_reference=reference)
        label = f"{r['method']:6s} {solver:9s} {ranks} rank(s) h_far/h {ratio:g}"
        if "error" in r:
            print(f"{label}: {r['error']}", flush=True)
        else:
            print(
                f"{label}: {r['dofs']:>10,} dofs, contact solve {contact_solve(r):7.2f} s, "
                f"CG its {linear_its(r)}, ref its {r.get('reference_linear_iterations')}, "
                f"wall {r['wall']:.1f} s, {r['peak_rss_mb']:.0f} MB",
                flush=True,
            )
    return out


def linear_its(r: dict[str, Any]) -> list[int]:
    """The linear iterations of each active-set step (the last one solves to the end)."""
    return [int(h["linear_iterations"]) for h in r.get("history", [])]


def plan(quick: bool) -> list[tuple[float, str, int, float, bool, tuple[str, ...]]]:
    """(dofs, solver, ranks, h_far ratio, reference, methods) of every case, in run order."""
    if quick:
        return [
            (60e3, "condensed", 1, 1.0, True, METHODS),
            (60e3, "mumps", 1, 1.0, False, METHODS),
            (60e3, "condensed", 2, 1.0, False, METHODS),
        ]
    cases: list[tuple[float, str, int, float, bool, tuple[str, ...]]] = []
    for dofs in SERIAL:
        cases.append((dofs, "condensed", 1, 1.0, True, METHODS))
        cases.append((dofs, "mumps", 1, 1.0, False, METHODS))
    cases.append((PARALLEL, "condensed", 2, 1.0, False, METHODS))
    cases.append((PARALLEL, "mumps", 2, 1.0, False, METHODS))
    cases.append((LARGEST, "condensed", 2, 1.0, False, ("nts",)))
    cases.append((LARGEST, "condensed", 2, 1.0, True, ("nts",)))
    for dofs in GRADED:
        cases.append((dofs, "condensed", 1, 10.0, True, ("nts",)))
    return cases


def rows(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One table row per run (no repeats: the large cases are single runs)."""
    out = []
    for r in runs:
        if "error" in r:
            continue
        hz = r.get("hertz", {})
        out.append(
            {
                "h_far/h": r["ratio_far"],
                "method": r["method"] + ("-dual" if r["method"] == "mortar" else ""),
                "solver": r["solver"],
                "ranks": r["ranks"],
                "dofs": r["dofs"],
                "steps": r["iterations"],
                "cg_its": linear_its(r) if r["solver"] == "condensed" else [],
                "ref_its": r.get("reference_linear_iterations"),
                "contact_solve": contact_solve(r),
                "wall": r["wall"],
                "peak_mb": r["peak_rss_mb"],
                "mb_per_100k": r["peak_rss_mb"] / r["dofs"] * 1e5,
                "a_err": (hz["a"] / hz["a_exact"] - 1) if hz.get("a") else None,
                "l2": hz.get("l2_error"),
                "with_reference": r["with_reference"],
            }
        )
    return out


def table(data: list[dict[str, Any]]) -> str:
    """The markdown table of every run."""
    head = (
        "| h_far/h | method | solver | ranks | dofs | AS steps | CG its per step | "
        "CG its, fresh solve | contact solve (s) | whole run (s) | peak MB | MB/100k | "
        "Hertz a err | L2 err |\n|" + "---|" * 14
    )
    lines = [head]
    for d in sorted(data, key=lambda d: (d["h_far/h"], d["method"], d["dofs"], d["solver"])):
        lines.append(
            f"| {d['h_far/h']:g} | {d['method']} | {d['solver']} | {d['ranks']} | "
            f"{d['dofs']:,} | {d['steps']} | {', '.join(map(str, d['cg_its'])) or '(direct)'} | "
            f"{d['ref_its'] if d['ref_its'] is not None else '-'} | {d['contact_solve']:.2f} | "
            f"{d['wall']:.1f}{' (with ref.)' if d['with_reference'] else ''} | "
            f"{d['peak_mb']:.0f} | {d['mb_per_100k']:.0f} | "
            + (f"{100 * d['a_err']:+.2f} % | " if d["a_err"] is not None else "- | ")
            + (f"{100 * d['l2']:.2f} % |" if d["l2"] is not None else "- |")
        )
    return "\n".join(lines)


def targets(data: list[dict[str, Any]]) -> str:
    """The four targets of the issue, each with the numbers that decide it."""

    def pick(**kw: Any) -> list[dict[str, Any]]:
        return [d for d in data if all(d[k] == v for k, v in kw.items())]

    out = ["| target | measured | met |", "|---|---|---|"]
    for method in ("nts", "mortar-dual"):
        ref = sorted(
            (
                d
                for d in pick(method=method, solver="condensed", **{"h_far/h": 1.0})
                if d["ref_its"]
            ),
            key=lambda d: d["dofs"],
        )
        if len(ref) >= 2:
            lo, hi = ref[0], ref[-1]
            growth = hi["ref_its"] / lo["ref_its"] - 1
            out.append(
                f"| CG its per solve grow <= 20 % from 100k to 10M ({method}) | "
                f"{lo['ref_its']} at {lo['dofs']:,}, "
                + ", ".join(f"{d['ref_its']} at {d['dofs']:,}" for d in ref[1:])
                + f" (+{100 * growth:.0f} %) | {'yes' if growth <= 0.2 else 'no'} |"
            )
        c = pick(method=method, solver="condensed", ranks=1, **{"h_far/h": 1.0})
        m = pick(method=method, solver="mumps", ranks=1, **{"h_far/h": 1.0})
        both = [
            (a, b)
            for a in c
            for b in m
            if abs(a["dofs"] - b["dofs"]) < 1 and abs(a["dofs"] - 2e6) < 0.3e6
        ]
        for a, b in both:
            out.append(
                f"| faster than MUMPS at 2M serial ({method}) | {a['contact_solve']:.1f} s "
                f"vs {b['contact_solve']:.1f} s at {a['dofs']:,} | "
                f"{'yes' if a['contact_solve'] < b['contact_solve'] else 'no'} |"
            )
        one = [d for d in c if abs(d["dofs"] - PARALLEL) < 0.3e6]
        two = [
            d
            for d in pick(method=method, solver="condensed", ranks=2, **{"h_far/h": 1.0})
            if abs(d["dofs"] - PARALLEL) < 0.3e6
        ]
        for a in one:
            for b in two:
                s = a["contact_solve"] / b["contact_solve"]
                out.append(
                    f"| 1 -> 2 ranks >= 1.7x at 2M ({method}) | {a['contact_solve']:.1f} s -> "
                    f"{b['contact_solve']:.1f} s ({s:.2f}x) | {'yes' if s >= 1.7 else 'no'} |"
                )
    for d in pick(solver="condensed", ranks=2, with_reference=False, **{"h_far/h": 1.0}):
        if d["dofs"] > 5e6:
            ok = d["wall"] < 180 and d["peak_mb"] < 20000
            out.append(
                f"| 10M dofs on 2 ranks: whole run < 180 s, peak < 20,000 MB ({d['method']}) | "
                f"{d['dofs']:,} dofs: {d['wall']:.1f} s, {d['peak_mb']:,.0f} MB | "
                f"{'yes' if ok else 'no'} |"
            )
    return "\n".join(out)


def chart(data: list[dict[str, Any]]) -> str:
    """Contact solve time and CG iterations against dofs, both solvers."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2))
    styles = {"condensed": "o-", "mumps": "s--"}
    for solver in ("condensed", "mumps"):
        for method, color in (("nts", "C0"), ("mortar-dual", "C1")):
            for ranks in (1, 2):
                pts = sorted(
                    (d["dofs"], d["contact_solve"])
                    for d in data
                    if d["solver"] == solver
                    and d["method"] == method
                    and d["ranks"] == ranks
                    and d["h_far/h"] == 1.0
                    and not (d["with_reference"] and d["dofs"] > 5e6)
                )
                if pts:
                    x, y = zip(*pts, strict=True)
                    ax.plot(
                        x,
                        y,
                        styles[solver],
                        color=color,
                        alpha=1.0 if ranks == 1 else 0.5,
                        label=f"{method}, {solver}, {ranks} rank{'s' if ranks > 1 else ''}",
                    )
    x_floor = [min(d["dofs"] for d in data), max(d["dofs"] for d in data)]
    for ranks, alpha in ((1, 1.0), (2, 0.5)):
        ax.plot(
            x_floor,
            [2.0 * n / (FLOOR_DOF_PER_S_PER_CORE * ranks) for n in x_floor],
            "k:",
            alpha=alpha,
            label=f"floor: setup + solve at 1M DOF/s per core, {ranks} core{'s' * (ranks > 1)}",
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("dofs")
    ax.set_ylabel("contact solve (s)")
    ax.set_title("Hertz, structured mesh, h_far = h")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    for ratio, marker in ((1.0, "o-"), (10.0, "^:")):
        for method, color in (("nts", "C0"), ("mortar-dual", "C1")):
            pts = sorted(
                (d["dofs"], d["ref_its"])
                for d in data
                if d["solver"] == "condensed"
                and d["method"] == method
                and d["ref_its"]
                and d["h_far/h"] == ratio
            )
            if pts:
                x, y = zip(*pts, strict=True)
                bx.plot(x, y, marker, color=color, label=f"{method}, h_far = {ratio:g} h")
    bx.set_xscale("log")
    bx.set_ylim(bottom=0)
    bx.set_xlabel("dofs")
    bx.set_ylabel("CG iterations, one fresh solve to 1e-9")
    bx.set_title("condensed: CG iterations (geometric multigrid)")
    bx.grid(True, which="both", alpha=0.3)
    bx.legend(fontsize=7)
    fig.tight_layout()
    name = "bench_scale.png"
    fig.savefig(HERE / name, dpi=110)
    plt.close(fig)
    return name


def write_readme(data: list[dict[str, Any]], meta: dict[str, Any], figure: str) -> None:
    """Replace the scale section of benchmarks/README.md."""
    readme = HERE / "README.md"
    text = readme.read_text()
    body = (
        f"{START}\nRun {meta['date']} on {meta['machine']} ({meta['cores']} cores), "
        f"{meta['minutes']:.0f} min, load average {meta['load_before']:.1f} before / "
        f"{meta['load_after']:.1f} after.\n\nTargets:\n\n{targets(data)}\n\nAll runs:\n\n"
        f"{table(data)}\n\n![condensed vs mumps]({figure})\n{END}"
    )
    if START in text:
        text = text[: text.index(START)] + body + text[text.index(END) + len(END) :]
    else:
        text = text.rstrip() + "\n\n## The condensed solver at scale\n\n" + body + "\n"
    readme.write_text(text)


def main() -> None:
    """Run the plan (or `--replot`), write scale.json, the README section and the chart."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="three small cases")
    ap.add_argument("--replot", action="store_true", help="redo table and chart from scale.json")
    ap.add_argument(
        "--resume", action="store_true", help="keep scale.json's cases, run the plan's others"
    )
    args = ap.parse_args()
    path = HERE / ("scale_quick.json" if args.quick else "scale.json")
    if args.replot:
        saved = json.loads(path.read_text())
        data = rows(saved["runs"])
        write_readme(data, saved["meta"], chart(data))
        return
    t0 = time.perf_counter()
    meta: dict[str, Any] = {
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "machine": platform.processor() or platform.machine(),
        "cores": os.cpu_count(),
        "load_before": os.getloadavg()[0],
        "quick": args.quick,
    }
    runs: list[dict[str, Any]] = []
    if args.resume:
        saved = json.loads(path.read_text())
        meta, runs = saved["meta"], saved["runs"]
        meta["resumed"] = time.strftime("%Y-%m-%d %H:%M")
    done = {
        (r["target"], r["solver"], r["ranks"], r["ratio_far"], r["with_reference"]) for r in runs
    }
    for dofs, solver, ranks, ratio, reference, methods in plan(args.quick):
        if (dofs, solver, ranks, ratio, reference) in done:
            continue
        runs += case(dofs, solver, ranks, ratio, reference, methods)
        path.write_text(json.dumps({"meta": meta, "runs": runs}, indent=1))
    meta.update(minutes=(time.perf_counter() - t0) / 60, load_after=os.getloadavg()[0])
    path.write_text(json.dumps({"meta": meta, "runs": runs}, indent=1))
    data = rows(runs)
    print(targets(data))
    if not args.quick:
        write_readme(data, meta, chart(data))
    print(f"median wall {statistics.median(r.get('wall', 0.0) for r in runs):.1f} s")


if __name__ == "__main__":
    main()
