"""A study's outputs: study.json, study.csv (one row per run) and the terminal table."""

from __future__ import annotations

import csv
import json
from pathlib import Path

from .measures import ROUND_OFF
from .progress import error_heading, format_seconds
from .runs import Run, Study

TIME_KEYS = ("mesh", "assemble", "search", "contact", "solve", "predictor", "total")


def main_errors(study: Study) -> list[str]:
    """The error names the table and the charts show (per-pair details stay in the files)."""
    return [n for n in study.error_names if "_pair" not in n]


def write_study_json(study: Study, path: Path) -> Path:
    """Write study.json."""
    path.write_text(json.dumps(study.to_json(), indent=1) + "\n")
    return path


def write_study_csv(study: Study, path: Path) -> Path:
    """Write study.csv: one row per run, sizes, times and every error as columns."""
    size_keys = list(dict.fromkeys(k for lv in study.levels for k in lv.sizes))
    pairs = max((len(r.forces) for r in study.runs if r.forces), default=0)
    force_keys = [f"force{k}_{c}" for k in range(pairs) for c in force_names(study)]
    succ = study.reference["kind"] == "self"
    head = [
        "method",
        "level",
        "factor",
        *size_keys,
        "status",
        "h",
        "dofs",
        "elements",
        "iterations",
        *(f"time_{k}" for k in TIME_KEYS),
        "time_after_mesh",
        *study.error_names,
        *(f"successive_{n}" for n in study.error_names if succ),
        *force_keys,
        "message",
    ]
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(head)
        for r in study.runs:
            sizes = study.levels[r.level].sizes
            w.writerow(
                [
                    r.method,
                    r.level,
                    r.factor,
                    *(sizes.get(k, "") for k in size_keys),
                    r.status,
                    _cell(r.h),
                    _cell(r.dofs),
                    _cell(r.elements),
                    _cell(r.iterations),
                    *(_cell(r.times.get(k)) for k in TIME_KEYS),
                    _cell(r.after_mesh),
                    *(_cell(r.errors.get(n)) for n in study.error_names),
                    *(_cell(r.successive.get(n)) for n in study.error_names if succ),
                    *(_cell(f) for f in _forces(r, pairs)),
                    r.message or "",
                ]
            )
    return path


def force_names(study: Study) -> tuple[str, str]:
    """The names of the force columns: x, y; axisymmetric: radial_per_radian, axial."""
    for r in study.runs:
        if r.summary is not None and r.summary.contacts:
            return r.summary.contacts[0].component_names
    return ("x", "y")


def _forces(run: Run, pairs: int) -> list[float | None]:
    """fx, fy of every pair (None for a failed run)."""
    if not run.forces:
        return [None] * (2 * pairs)
    return [float(v) for f in run.forces for v in f]


def _cell(v: float | int | None) -> str:
    return "" if v is None else repr(v) if isinstance(v, float) else str(v)


def _num(v: float | None, fmt: str = ".3e") -> str:
    return "-" if v is None else format(v, fmt)


def is_reference(study: Study, run: Run) -> bool:
    """Whether `run` is the self-convergence reference (it has no error of its own)."""
    ref = study.reference
    return ref["kind"] == "self" and (ref.get("method"), ref.get("level")) == (
        run.method,
        run.level,
    )


def _error_cell(study: Study, run: Run, name: str) -> str:
    return "reference" if is_reference(study, run) else _num(run.errors.get(name))


def _rate_cell(study: Study, method: str, name: str, rate: float | None) -> str:
    """The rate (flagged if its data are not monotone), or why there is none."""
    if rate is not None:
        flag = study.flags.get(method, {}).get(name)
        return f"{rate:.2f}" + (f" ({flag}: not a convergence rate)" if flag else "")
    found = [r.errors.get(name) for r in study.runs if r.method == method and r.ok]
    errs = [e for e in found if e is not None]
    return "none (exact to round-off)" if errs and max(errs) <= ROUND_OFF else "n/a"


def level_lines(study: Study) -> list[str]:
    """Which sizes each level used."""
    lines = []
    for lv in study.levels:
        # A scene file's only size is the factor itself: say it once.
        sizes = {k: v for k, v in lv.sizes.items() if not (k == "size_factor" and v == lv.factor)}
        lines.append(
            f"level {lv.index}: factor {lv.factor:.4g}"
            + "".join(f", {k} {v:.4g}" for k, v in sizes.items())
        )
    return lines


def table_lines(study: Study) -> list[str]:
    """The final table: one row per run, then the fitted rates and the reference."""
    names = main_errors(study)
    head = [
        "method",
        "level",
        "h",
        "elements",
        "dofs",
        "its",
        "after mesh (s)",
        *(error_heading(n) for n in names),
    ]
    rows = []
    for r in study.runs:
        if r.ok:
            rows.append(
                [
                    r.method,
                    str(r.level),
                    _num(r.h, ".4g"),
                    str(r.elements),
                    str(r.dofs),
                    str(r.iterations),
                    f"{r.after_mesh:.3f}",
                    *(_error_cell(study, r, n) for n in names),
                ]
            )
        else:
            rows.append([r.method, str(r.level), "FAILED", *[""] * (len(head) - 3)])
    width = [max(len(head[i]), *(len(row[i]) for row in rows)) for i in range(len(head))]
    fmt = "  ".join(f"{{:>{w}}}" for w in width)
    lines = [fmt.format(*head), fmt.format(*("-" * w for w in width))]
    lines += [fmt.format(*row) for row in rows]
    lines += [f"failed: {r.method} level {r.level}: {r.message}" for r in study.runs if not r.ok]
    if study.reference["kind"] == "self" and len(study.methods) > 1:
        lines.append(
            "(on the reference's level the other methods' numbers are their differences "
            "from it on the same mesh: not in the fits or charts)"
        )
    lines.append(
        f"reference: {study.reference['description']}"
        + (
            f" ({study.reference['method']}, level {study.reference['level']})"
            if study.reference["kind"] == "self"
            else ""
        )
    )
    if study.reference.get("exact") is False:
        lines.append(
            f"the reference is {study.reference['validity']}: the errors and rates above "
            "include its model error (they level off at it on fine meshes)"
        )
    if study.reference["kind"] == "self":
        lines.append(f"rates: {study.reference['rates']} (study.json: runs[].successive)")
    for m, rates in study.rates.items():
        lines.append(
            f"fitted rates in h, {m}: "
            + ", ".join(f"{n} {_rate_cell(study, m, n, v)}" for n, v in rates.items() if n in names)
        )
    lines.append(
        f"study: {len(study.runs)} runs on {study.ranks} rank"
        f"{'s' * (study.ranks > 1)} in {format_seconds(study.wall)}"
    )
    return lines


def adaptive_lines(study: Study) -> list[str]:
    """The adaptive levels (study --adaptive): DOFs, estimate, errors, cumulative time."""
    if not study.adaptive:
        return []
    names = main_errors(study)
    lines = [
        "",
        "adaptive levels (time: cumulative level-0 meshing, solves, estimates and remeshing):",
    ]
    for r in study.adaptive:
        errs = ", ".join(f"{error_heading(n)} {_num(r.errors.get(n))}" for n in names)
        lines.append(
            f"  {r.method} level {r.level}: {r.dofs} dofs, estimate {r.estimate:.3g}, "
            f"{errs}, {r.cumulative:.2f} s"
        )
    stops = dict.fromkeys((r.method, r.stop) for r in study.adaptive)
    lines += [f"  {m} stopped: {stop}" for m, stop in stops]
    return lines
