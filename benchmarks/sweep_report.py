"""The size sweep's summaries: medians per case, the README tables and the ratio charts.

Ratios, all within one process: contact solve / a fresh solve of the final system by the
same solver (`ratio`), / a fresh LU of it (`ratio_lu`) and / a fresh LDL^T of it
(`ratio_ldlt`); the fresh factorizations come after the contact solve, so they are warm.
"""

from __future__ import annotations

import statistics
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
# Targets of the direct floor (issue 18): contact solve <= 1.15 x a warm LDL^T from 20k DOFs,
# <= 0.85 x a warm LU from 100k DOFs.
LDLT_TARGET = 1.15
LU_TARGET = 0.85
LU_FROM = 100e3
START, END = "<!-- bench:start -->", "<!-- bench:end -->"


def t(record: dict[str, Any], key: str) -> float:
    """A timer of a run record (0 if absent)."""
    return float(record["times"].get(key, 0.0))


def contact_solve(record: dict[str, Any]) -> float:
    """Search + B assembly + the coarse predictor's whole solve (if any) + active-set solves."""
    return sum(t(record, k) for k in ("search", "contact", "predictor", "solve"))


def family(record: dict[str, Any]) -> str:
    """The mesh family: `10H` (h_far = 10 h) or `default` (h_far = R/6, the default grading)."""
    return record.get("family") or ("default" if record.get("h_far") == 0.0 else "10H")


def group_key(r: dict[str, Any]) -> tuple[Any, ...]:
    """What makes two run records repeats of one case."""
    return (
        r.get("mesh", "structured"),
        family(r),
        r["method"],
        r["solver"],
        r.get("fixed_set", False),
        r["ranks"],
        r["refine"],
    )


def _ratio(rs: list[dict[str, Any]], key: str) -> tuple[float, list[float]] | None:
    vals = [contact_solve(r) / t(r, key) for r in rs if t(r, key) > 0]
    return (float(statistics.median(vals)), [min(vals), max(vals)]) if vals else None


def summarize(runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Medians over repeats per (mesh, family, method, solver, fixed, ranks, size)."""
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for r in runs:
        if "error" not in r:
            groups.setdefault(group_key(r), []).append(r)
    rows = []
    for key, rs in sorted(groups.items(), key=lambda kv: (*kv[0][:6], -kv[0][6])):
        mesh, fam, method, solver, fixed, ranks, h0 = key

        def med(f: Any, rs: list[dict[str, Any]] = rs) -> float:
            return float(statistics.median(f(r) for r in rs))

        row: dict[str, Any] = {
            "mesh": mesh,
            "family": fam,
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
            "reference_lu": med(lambda r: t(r, "reference_lu")),
            "reference_ldlt": med(lambda r: t(r, "reference_ldlt")),
            "search_assembly": med(lambda r: t(r, "search") + t(r, "contact")),
            "mb_per_100k": med(lambda r: r["peak_rss_mb"] / (r["dofs"] / 1e5)),
            "load": med(lambda r: r["load"]),
            "l2_error": rs[0].get("hertz", {}).get("l2_error"),
        }
        if not fixed:
            for name, ref in (
                ("ratio", "reference_solve"),
                ("ratio_lu", "reference_lu"),
                ("ratio_ldlt", "reference_ldlt"),
            ):
                got = _ratio(rs, ref)
                if got is not None:
                    row[name], row[f"{name}_range"] = got
            row["predictor"] = med(lambda r: t(r, "predictor"))
            row["linear_iterations"] = [h["linear_iterations"] for h in rs[0]["history"]]
            row["factorizations"] = sum(h.get("factorized", 1) for h in rs[0]["history"])
            row["probes"] = sum(h.get("probes", 0) for h in rs[0]["history"])
            row["step_times"] = [round(h["solve_time"], 3) for h in rs[0]["history"]]
        else:
            row["linear_iterations"] = [rs[0]["linear_iterations"]]
        rows.append(row)
    return rows


def _cell(r: dict[str, Any], name: str, target: float | None = None) -> str:
    if name not in r:
        return "-"
    lo, hi = r[f"{name}_range"]
    rng = f" ({lo:.2f}-{hi:.2f})" if r["runs"] > 1 else ""
    mark = f" **>{target}**" if target is not None and r[name] > target else ""
    return f"{r[name]:.2f}{rng}{mark}"


def table(rows: list[dict[str, Any]]) -> str:
    """Markdown table of the summary rows of the active-set sweep."""
    head = (
        "| mesh | family | method | solver | ranks | dofs | multipliers | AS its | "
        "factorizations | probes | step times (s) | contact solve (s) | fresh LDL^T (s) | "
        "fresh LU (s) | / LDL^T | / LU | / same solver | MB/100k | load |\n"
        "|" + "---|" * 19 + "\n"
    )
    lines = []
    for r in rows:
        if r["fixed_set"]:
            continue
        lu_target = LU_TARGET if r["dofs"] >= LU_FROM and r["solver"] == "mumps" else None
        ldlt_target = LDLT_TARGET if r["solver"] == "mumps" else None
        cells = [
            r["mesh"],
            r["family"],
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
            f"{r['reference_ldlt']:.2f}",
            f"{r['reference_lu']:.2f}",
            _cell(r, "ratio_ldlt", ldlt_target),
            _cell(r, "ratio_lu", lu_target),
            _cell(r, "ratio"),
            f"{r['mb_per_100k']:.0f}",
            f"{r['load']:.1f}",
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return head + "\n".join(lines) + "\n"


def extremes(rows: list[dict[str, Any]]) -> str:
    """Markdown table: min and max ratios (with their sizes) per case family."""
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for r in rows:
        if not r["fixed_set"] and "ratio_ldlt" in r:
            key = (r["mesh"], r["family"], r["method"], r["solver"], r["ranks"])
            groups.setdefault(key, []).append(r)
    out = (
        "| mesh | family | method | solver | ranks | dofs | / LDL^T min - max | "
        "/ LU min - max | / LU max from 100k |\n|---|---|---|---|---|---|---|---|---|\n"
    )
    for (mesh, fam, method, solver, ranks), rs in sorted(groups.items()):

        def span(name: str, rs: list[dict[str, Any]] = rs) -> str:
            vals = sorted(rs, key=lambda row: row[name])
            lo, hi = vals[0], vals[-1]
            return f"{lo[name]:.2f} ({lo['dofs']:,}) - {hi[name]:.2f} ({hi['dofs']:,})"

        big = [r for r in rs if r["dofs"] >= LU_FROM]
        lu_big = f"{max(r['ratio_lu'] for r in big):.2f}" if big else "-"
        dofs = f"{min(r['dofs'] for r in rs):,} - {max(r['dofs'] for r in rs):,}"
        out += (
            f"| {mesh} | {fam} | {method} | {solver} | {ranks} | {dofs} | "
            f"{span('ratio_ldlt')} | {span('ratio_lu')} | {lu_big} |\n"
        )
    return out


def charts(rows: list[dict[str, Any]]) -> list[str]:
    """Contact solve over a fresh solve by the same solver and over a warm LU, per family.

    The first row has every solver (MUMPS' fresh solve is its LDL^T); the second only the
    direct ones (an iterative run times no LU).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    loop = [r for r in rows if not r["fixed_set"] and "ratio" in r]
    panels = sorted({(r["mesh"], r["family"]) for r in loop})
    if not panels:
        return []
    series = sorted({(r["method"], r["solver"], r["ranks"]) for r in loop})
    fig, axes = plt.subplots(2, len(panels), figsize=(4.8 * len(panels), 8), squeeze=False)
    markers = {"nts": "o", "sts": "s", "mortar": "^"}
    for col, (mesh, fam) in enumerate(panels):
        for row, (name, target, what) in enumerate(
            (
                ("ratio", LDLT_TARGET, "a fresh solve, same solver"),
                ("ratio_lu", LU_TARGET, "a warm LU"),
            )
        ):
            ax = axes[row][col]
            for i, (method, solver, ranks) in enumerate(series):
                sel = sorted(
                    (
                        r
                        for r in loop
                        if (r["mesh"], r["family"], r["method"], r["solver"], r["ranks"])
                        == (mesh, fam, method, solver, ranks)
                        and name in r
                    ),
                    key=lambda r: r["dofs"],
                )
                if not sel:
                    continue
                label = f"{method}, {solver}" + (f", {ranks} ranks" if ranks > 1 else "")
                ax.plot(
                    [r["dofs"] for r in sel],
                    [r[name] for r in sel],
                    marker=markers.get(method, "x"),
                    ls="-" if solver == "mumps" else "--",
                    color=f"C{i}",
                    label=label,
                )
            ax.set_xscale("log")
            ax.axhline(target, color="k", lw=0.8, ls=":", label=f"target {target}")
            ax.axhline(1.0, color="0.6", lw=0.6)
            ax.set_ylim(0.0, max(2.0, 1.1 * max(r.get(name, 0.0) for r in loop)))
            ax.set_xlabel("dofs")
            ax.set_ylabel(f"contact solve / {what}")
            ax.set_title(f"Hertz, {mesh}, h_far {fam}", fontsize=10)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(HERE / "bench_ratio.png", dpi=90)
    plt.close(fig)
    return ["bench_ratio.png"]


def write_readme(rows: list[dict[str, Any]], meta: dict[str, Any], figures: list[str]) -> None:
    """Regenerate the table section of benchmarks/README.md."""
    path = HERE / "README.md"
    text = path.read_text() if path.exists() else f"# Benchmarks\n\n{START}\n{END}\n"
    body = (
        f"Run {meta['date']} on {meta['machine']} ({meta['cpus']} cores), "
        f"{'quick' if meta['quick'] else 'full'} mode, {meta.get('minutes', 0):.0f} min, "
        f"load average {meta['load_before']:.1f} before / {meta['load_after']:.1f} after "
        f"(the machine is shared: compare ratios within a row, not times across runs).\n\n"
        + (f"Rows rerun later with `--case`: {meta['updated']}.\n\n" if meta.get("updated") else "")
        + "contact solve = search + B assembly + the coarse predictor (if the defaults use "
        "one) + all active-set solves (probes included); fresh LDL^T / fresh LU = one fresh "
        "symmetric / LU factorization and solve of the final saddle point (same ordering), "
        "after the contact solve in the same process (so warm); / same solver = over a "
        "fresh solve by the case's own solver. Medians of the repeats (range in brackets: "
        "5 runs up to 100k dofs, 3 up to 700k, 1 above; the methods take turns at being the "
        "first solve of the process). Families: `10H` = `--refine H --h-far 10H` (cells "
        "at most 10:1), `default` = the default grading (`--h-far` R/6: many contact "
        "candidates per DOF); gmsh also `--refine-edge H/4`. Targets (bold when missed, "
        f"for the default solver): / LDL^T <= {LDLT_TARGET} from 20k DOFs, / LU <= "
        f"{LU_TARGET} from 100k DOFs.\n\n"
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
