"""contactfx study as a new user meets it: the ETA, the headings, the help, the time axis."""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from conftest import cli

from contactfx.study.core import series
from contactfx.study.progress import Progress
from contactfx.study.report import level_lines
from contactfx.study.runs import Run


def test_time_left_follows_the_cost_per_dof() -> None:
    """Each method's first run pays a fixed overhead (form compilation): the estimate of the
    time left must not collapse once that overhead makes the next level look free."""
    methods, levels = ["nts", "mortar"], 4
    dofs = [1000 * 4**k for k in range(levels)]
    order = [(m, k) for k in range(levels) for m in methods]
    costs = [1e-3 * dofs[k] + (3.0 if k == 0 else 0.0) for _, k in order]
    progress = Progress(methods, levels, 2.0, lambda _: None)
    for i, ((m, k), t) in enumerate(zip(order, costs, strict=True)):
        run = Run(m, k, 1.0, dofs=dofs[k], times={"total": t, "mesh": 0.0})
        progress.finished(run, None)
        pending = order[i + 1 :]
        if i >= 3 and pending:  # both methods past their first level
            true = sum(costs[i + 1 :])
            assert progress.left(pending) == pytest.approx(true, rel=0.3), (i, true)


def test_headings_say_errors_and_a_level_line_says_its_factor_once(tmp_path: Path) -> None:
    proc = cli(
        "study", "hertz", "--levels", "2", "--size-factor", "8", "--methods", "mortar",
        "--out", str(tmp_path),
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    head = next(ln for ln in proc.stdout.splitlines() if ln.lstrip().startswith("method"))
    assert re.search(r"\ba err\b", head) and re.search(r"\bp0 err\b", head), head
    study: Any = SimpleNamespace(
        levels=[SimpleNamespace(index=0, factor=2.0, sizes={"size_factor": 2.0})]
    )
    assert level_lines(study) == ["level 0: factor 2"]


def test_help_groups_pressure_tol_with_the_study_options() -> None:
    proc = cli("study", "--help")
    text = proc.stdout
    group = text[text.index("\nstudy:") : text.index("\nlinear solver:")]
    assert "--pressure-tol" in group and "--adaptive" in group
    assert "one rank" not in text


def test_time_axis_includes_meshing() -> None:
    run = Run("mortar", 0, 1.0, dofs=10, times={"total": 5.0, "mesh": 4.0}, errors={"l2": 0.1})
    xs, _ = series([run], "mortar", "l2", "time", "hertz")
    assert list(xs) == [5.0]


def test_missing_half_width_says_why() -> None:
    from contactfx.cli.solve import terminal_summary
    from contactfx.results.records import ContactSummary, HertzErrors

    h = SimpleNamespace(
        pair=0, a=None, a_exact=0.7585, p0=10.0, p0_exact=10.5, l2_error=0.1, a_bracket=(0.5, 1),
        description=HertzErrors.description, validity="approximate",
    )  # fmt: skip
    contact = ContactSummary(
        active="a", passive="b", active_body="A", passive_body="B", force=(0.0, 1.0),
        force_passive=(0.0, -1.0), balance=0.0, multipliers=3, active_nodes=3, interface={},
    )  # fmt: skip
    run: Any = SimpleNamespace(
        scene="hertz", method=SimpleNamespace(value="mortar"), dofs=10, multipliers=3,
        iterations=2, times={"total": 1.0}, contacts=[contact], patch=None, hertz=[h],
        estimate=None, lame=(), cattaneo=(), pushout=(), spence=(), probes=(), steps=(),
    )  # fmt: skip
    line = next(ln for ln in terminal_summary(run) if ln.startswith("Hertz"))
    assert "nan" not in line and "a: n/a (3 active nodes" in line, line


def _study_lines(dofs: list[int], mesh: list[float], costs: list[float]) -> list[str]:
    """The progress lines of a one-method study with these DOFs, meshing and run costs."""
    lines: list[str] = []
    progress = Progress(["mortar"], len(dofs), 2.0, lines.append)
    for k, (n, m, c) in enumerate(zip(dofs, mesh, costs, strict=True)):
        run = Run("mortar", k, 1.0, dofs=n, times={"total": m + c, "mesh": m})
        progress.finished(run, m)
    return lines


def test_no_time_left_is_guessed_from_the_first_level_alone() -> None:
    """A study hertz said ~88 s left after its first run (29 s real): the DOFs of the graded
    Hertz meshes grow about 2.35x a level, not ratio^2 = 4, and level 0 is mostly overhead.
    Until two levels are measured the line says when the estimate comes."""
    # study hertz --levels 4 --size-factor 2 (one method): DOFs, meshing, solve times.
    lines = _study_lines([4180, 9610, 22614, 56922], [0.1, 0.25, 1.64, 6.3], [0.2, 0.26, 0.7, 3.0])
    assert lines[0].endswith("time left estimated after level 1"), lines[0]
    assert re.search(r"~\d+\.\d s left$", lines[1]) and lines[-1].endswith("done"), lines


def test_levels_not_meshed_yet_are_meshed_at_the_fresh_rate_seen() -> None:
    """Level 1 came from the mesh cache (6x faster than gmsh per DOF), level 0 from gmsh:
    the meshing of level 2 is estimated at gmsh's rate, not the cache's."""
    progress = Progress(["mortar"], 3, 2.0, lambda _: None)
    for k, (n, m) in enumerate([(10_000, 0.8), (40_000, 0.4)]):
        progress.finished(Run("mortar", k, 1.0, dofs=n, times={"total": m, "mesh": m}), m)
    solve = 0.0  # the runs cost nothing here: what is left is level 2's meshing
    assert progress.left([("mortar", 2)]) == pytest.approx(solve + 8e-5 * 160_000)


def test_the_time_chart_plots_each_runs_time_after_meshing(tmp_path: Path) -> None:
    """accuracy_vs_time.png put cached meshing (0.2 s) and gmsh's (6 s) on one axis with the
    solves: it plots the time after meshing, with the rate of the points drawn, and says so."""
    import matplotlib.pyplot as plt

    from contactfx.study import charts

    runs = [
        Run("mortar", k, 1.0, dofs=n, times={"total": m + t, "mesh": m}, errors={"l2": e})
        for k, (n, m, t, e) in enumerate([(1e4, 0.2, 1.0, 4e-3), (4e4, 6.0, 4.0, 2e-3)])
    ]
    study: Any = SimpleNamespace(
        runs=runs, methods=["mortar"], error_names=["l2"], rates={"mortar": {"l2": 1.0}},
        reference={"kind": "exact", "type": "hertz"}, flags={}, adaptive=[], scene="hertz",
        ranks=1,
    )  # fmt: skip
    xs, errors = charts._series(study, "mortar", "l2", "solve")
    assert list(xs) == [1.0, 4.0] and list(errors) == [4e-3, 2e-3]
    captured: dict[str, Any] = {}
    finish = charts._finish

    def keep(fig: Any, path: Path, title: str) -> Path:
        ax = fig.axes[0]
        captured["x"] = list(ax.lines[0].get_xdata())
        captured["label"], captured["legend"] = ax.get_xlabel(), ax.get_legend_handles_labels()[1]
        return finish(fig, path, title)

    charts._finish = keep
    try:
        charts.plot_time(study, tmp_path / "t.png")
    finally:
        charts._finish = finish
        plt.close("all")
    assert captured["x"] == [1.0, 4.0], captured
    assert "after meshing" in captured["label"] and "left out" in captured["label"]
    assert captured["legend"] == ["mortar: error ~ t^-0.50"], captured["legend"]
