"""Hertz benchmarks: the contact solve against its floor (fresh factorizations of the final system).

`make bench` runs this; `--quick` is a few-minute smoke version. The sweep: two mesh
families, `10H` (8 sizes from 20k to 2M dofs, h_far = 10 h) and `default` (the default
grading, h_far = R/6: many contact candidates per DOF; a list of refine values), on the
structured and the gmsh Hertz meshes (gmsh also refine_edge = h / 4), nts, sts and mortar,
for each solver of `--solvers` (default `mumps,mumps-lu`: the symmetric default and the old
LU side by side), with the default options, as `python -m contactfx solve hertz --refine H
[--refine-edge H/4 | --mesh structured] [--h-far 10H] --method M --solver S
--reference-timing` would run them. Every case runs in a fresh process (benchmarks/case.py,
serial or `mpirun -n 2`) that meshes once and solves the three methods in turn, so peak
memory belongs to that case. Writes benchmarks/results.json, the tables in
benchmarks/README.md and the chart (benchmarks/sweep_report.py). The machine may be shared:
the load average is recorded with every run, and the ratios are taken within one process.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

from sweep_report import charts as sweep_charts
from sweep_report import contact_solve, group_key, summarize, t, table, write_readme

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
FAMILIES = ("10H", "default")
# The default family by its refine values (its DOFs grow like 1/h: the far field is fixed):
# gmsh 14.5k, 24k, 45k, 86k; structured 69k, 137k, 280k, 584k, 1.2M DOFs.
DEFAULT_REFINE = {
    "gmsh": (0.01, 0.005, 0.0025, 0.00125),
    "structured": (0.01, 0.005, 0.0025, 0.00125, 0.000625),
}
QUICK_DEFAULT_REFINE = {"gmsh": (0.005,), "structured": (0.01,)}
METHODS = ("nts", "sts", "mortar")
MESHERS = ("structured", "gmsh")
# Repeats (medians): 5 up to SMALL_DOFS (0.1-1 s solves, the noisiest), 3 up to CHEAP_DOFS,
# one run above (the large cases dominate the time).
SMALL_DOFS = 100e3
CHEAP_DOFS = 700e3


def refine_for(dofs: float, mesh: str = "structured", ratio: float = H_RATIO) -> float:
    """Contact element size h0 (cm) whose Hertz mesh (h_far = ratio * h0) has about `dofs` dofs.

    Structured: the grid itself is counted. gmsh: a fit of its dof counts on these meshes
    (edge refinement h0 / 4), dofs ~ 125.6 / h0^2 + 324 / h0 (within ~5% from 14k to 500k).
    """

    def count(h: float) -> float:
        if mesh == "gmsh":
            return 125.6 / h**2 + 324.0 / h
        return 2 * len(hertz_grid(60.0, 60.0, 60.0, h, 2.0, ratio * h, 0.1)[0])

    # A bracket from the 2D count ~ 1 / h^2 (bisecting from 1e-3 built grids of 10^8 nodes
    # on the way to 10M DOFs with h_far = h, and ran out of memory).
    guess = 0.2 * (count(0.2) / dofs) ** 0.5
    lo, hi = guess / 1.5, guess * 1.5
    while count(lo) < dofs:
        lo /= 1.5
    while count(hi) > dofs:
        hi *= 1.5
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
    fam = "10H" if h_far is None else "default" if h_far == 0.0 else f"{h_far:g}"
    base = {
        "mesh": mesh,
        "family": fam,
        "solver": solver,
        "ranks": ranks,
        "refine": h0,
        "fixed_set": fixed,
    }
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
                {
                    **records[m],
                    "family": fam,
                    "fixed_set": fixed,
                    "load": load,
                    "wall": time.perf_counter() - t0,
                }
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


def plan(
    quick: bool,
    solvers: list[str],
    ranks: list[int],
    sizes: tuple[float, ...],
    families: tuple[str, ...] = FAMILIES,
) -> list[tuple[str, str, float, str, int, int]]:
    """(mesh, family, h0, solver, ranks, repeats) of every case, small meshes first."""
    cases = []

    def repeats(dofs: float) -> int:
        return 1 if quick else 5 if dofs <= SMALL_DOFS else 3 if dofs <= CHEAP_DOFS else 1

    sized = []
    for mesh in MESHERS:
        if "10H" in families:
            for n in QUICK_SIZES if quick and sizes == SIZES else sizes:
                sized.append((n, mesh, "10H", refine_for(n, mesh)))
        if "default" in families:
            for h0 in (QUICK_DEFAULT_REFINE if quick else DEFAULT_REFINE)[mesh]:
                sized.append((default_dofs(h0, mesh), mesh, "default", h0))
    for n, mesh, fam, h0 in sorted(sized):
        cases += [(mesh, fam, h0, s, r, repeats(n)) for s in solvers for r in ranks]
    return cases


def default_dofs(h0: float, mesh: str) -> float:
    """About the DOFs of the default-graded Hertz mesh with contact size h0 (for the order)."""
    if mesh == "gmsh":
        return 240.0 / h0**0.8  # 14.5k at 0.01 ... 86k at 0.00125 (measured)
    return 2 * len(hertz_grid(60.0, 60.0, 60.0, h0, 2.0, 10.0, 0.1)[0])


def save(meta: dict[str, Any], runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Summarize `runs`, write results.json, the charts and the README tables."""
    rows = summarize(runs)
    (HERE / "results.json").write_text(
        json.dumps({"meta": meta, "summary": rows, "runs": runs}, indent=1) + "\n"
    )
    write_readme(rows, meta, sweep_charts(rows))
    return rows


def update(cases: list[str]) -> None:
    """Run `cases` and merge them into results.json (the README notes when rows changed).

    A case is MESH:FAMILY:METHODS:SOLVER:SIZE:RANKS:REPEATS[:BASIS], SIZE the target DOFs
    for the 10H family and the refine value for the default one, BASIS mortar's multiplier
    basis (standard; `condensed` needs dual).
    """
    data = json.loads((HERE / "results.json").read_text())
    new = []
    for case in cases:
        mesh, fam, methods, solver, size, ranks, repeats, *basis = case.split(":")
        h0 = refine_for(float(size), mesh) if fam == "10H" else float(size)
        h_far = None if fam == "10H" else 0.0
        for _ in range(int(repeats)):
            recs = run_process(
                mesh,
                tuple(methods.split(",")),
                solver,
                h0,
                int(ranks),
                h_far=h_far,
                basis=basis[0] if basis else "standard",
            )
            new += recs
            for rec in recs:
                print(
                    f"{mesh} {fam} {rec['method']} {solver} {ranks}r h0={h0}: "
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
    ap.add_argument("--quick", action="store_true", help="the smallest sizes, one repeat")
    ap.add_argument(
        "--solvers",
        default="mumps,mumps-lu",
        help="comma-separated solvers, each run over the whole sweep (default mumps,mumps-lu)",
    )
    ap.add_argument("--ranks", default="1", help="comma-separated rank counts (default 1)")
    ap.add_argument("--families", default=",".join(FAMILIES), help="10H, default or both")
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
        "--sizes", default=None, help="comma-separated target dofs of the 10H family (20k ... 2M)"
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
        metavar="MESH:FAMILY:METHODS:SOLVER:SIZE:RANKS:REPEATS[:BASIS]",
        help="run only these cases (e.g. gmsh:10H:nts,sts,mortar:mumps:1e6:1:3) and merge "
        "them into results.json, replacing earlier runs of the same case",
    )
    args = ap.parse_args()
    if args.case:
        return update(args.case)
    if args.replot:
        data = json.loads((HERE / "results.json").read_text())
        write_readme(data["summary"], data["meta"], sweep_charts(data["summary"]))
        return
    solvers = args.solvers.split(",")
    methods = tuple(args.methods.split(","))
    ranks = [int(r) for r in args.ranks.split(",")]
    families = FAMILIES if args.families == "both" else tuple(args.families.split(","))
    if unknown := set(families) - set(FAMILIES):
        ap.error(f"--families: unknown {', '.join(sorted(unknown))} (10H, default or both)")
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
        "families": families,
        "methods": methods,
        "basis": args.basis,
    }
    t_start = time.perf_counter()
    runs: list[dict[str, Any]] = []
    for i, (mesh, fam, h0, solver, nranks, repeats) in enumerate(
        plan(args.quick, solvers, ranks, sizes, families)
    ):
        for k in range(repeats):
            # The first solve of a process pays its warm-up: the methods take turns at being
            # first, over the repeats and over the cases.
            j = (k + i) % len(methods)
            order = methods[j:] + methods[:j]
            h_far = None if fam == "10H" else 0.0
            recs = run_process(mesh, order, solver, h0, nranks, basis=args.basis, h_far=h_far)
            runs += recs
            for rec in recs:
                status = rec.get("error") or (
                    f"{rec['dofs']:,} dofs, contact solve {contact_solve(rec):.2f} s, "
                    f"LDL^T {t(rec, 'reference_ldlt'):.2f} s, LU {t(rec, 'reference_lu'):.2f} s"
                )
                print(
                    f"{mesh:10s} {fam:7s} {rec['method']:6s} {solver:9s} {nranks}r h0={h0}: "
                    f"{status}",
                    flush=True,
                )
        meta["load_after"] = os.getloadavg()[0]
        meta["minutes"] = (time.perf_counter() - t_start) / 60
        save(meta, runs)  # after every case: a long run leaves its results so far
    print(table(summarize(runs)))


if __name__ == "__main__":
    main()
