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
        estimate=None, lame=(), probes=(), steps=(),
    )  # fmt: skip
    line = next(ln for ln in terminal_summary(run) if ln.startswith("Hertz"))
    assert "nan" not in line and "a: n/a (3 active nodes" in line, line
