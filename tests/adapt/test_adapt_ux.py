"""contactfx adapt as a new user meets it: every Hertz pair, refusals, units, charts."""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from conftest import COARSE_HERTZ, ROOT, cli

from contactfx.adapt import charts
from contactfx.adapt.goal import Goal
from contactfx.adapt.records import AdaptOptions

CYLINDER = ROOT / "demos" / "scenes" / "cylinder_between_blocks.toml"


def _level(index: int, dofs: int, time: float, l2: list[float], est: float = 0.1) -> Any:
    """A stand-in AdaptLevel: what the charts read of one."""
    hertz = [SimpleNamespace(pair=k, l2_error=e) for k, e in enumerate(l2)]
    summary = SimpleNamespace(hertz=hertz, patch=None)
    return SimpleNamespace(
        index=index,
        dofs=dofs,
        time=time,
        summary=summary,
        est=SimpleNamespace(relative=est),
        goal=None,
    )


def test_every_hertz_pair_is_shown(tmp_path: Path) -> None:
    """Two Hertz pairs: the log prints both, the charts plot the worst."""
    proc = cli("adapt", str(CYLINDER), "--max-levels", "1", "--out", str(tmp_path))
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    pairs = json.loads((tmp_path / "adapt.json").read_text())["levels"][0]["hertz_pairs"]
    line = next(ln for ln in proc.stdout.splitlines() if ln.startswith("level 0:"))
    shown = dict(re.findall(r"pair (\d+) ([0-9.]+) %", line))
    assert sorted(shown) == ["0", "1"], line
    for k, value in shown.items():
        assert float(value) == pytest.approx(100 * pairs[int(k)]["l2_error"], abs=1e-3)
    # Charts: the worst pair, whichever it is, and the label says so.
    label, value = charts.reference_error(_level(0, 100, 1.0, [0.0133, 0.1385]))
    assert value == 0.1385 and "worst of 2 pairs" in label


@pytest.mark.parametrize("growth", ["0.5", "1"])
def test_growth_at_most_one_refused(tmp_path: Path, growth: str) -> None:
    out = tmp_path / "o"
    proc = cli("adapt", *COARSE_HERTZ, "--growth", growth, "--out", str(out))
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert "--growth must be > 1" in proc.stderr and "Traceback" not in proc.stderr
    assert "level 0" not in proc.stdout and not out.exists()


def test_start_over_the_budget_refused(tmp_path: Path) -> None:
    """--max-dofs below the starting mesh: one line naming both numbers, nothing solved."""
    out = tmp_path / "o"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy's overflow warning fails the run
        proc = cli("adapt", *COARSE_HERTZ, "--max-dofs", "100", "--out", str(out))
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert re.search(r"starting mesh already has \d+ DOFs > --max-dofs 100", proc.stderr)
    assert "level 0" not in proc.stdout and not out.exists()


def test_stop_line_in_percent() -> None:
    """The levels print percent; the stop reason does too, tol included."""
    est = SimpleNamespace(relative=2.42e-9, pressure=SimpleNamespace(relative=0.004))
    residual = AdaptOptions(Goal.RESIDUAL, tol=0.05)
    assert residual.met(est) == "estimate 2.4e-07 % <= tol 5 %"  # type: ignore[arg-type]
    both = AdaptOptions(Goal.RESIDUAL, tol=0.05, pressure_tol=0.01).met(est)  # type: ignore[arg-type]
    assert both == "estimate 2.4e-07 % <= tol 5 %, pressure estimate 0.4 % <= 1 %"


def test_time_chart_is_cumulative_and_titled_by_its_data() -> None:
    levels = [_level(k, 1000 * 4**k, t, [0.1 / 2**k]) for k, t in enumerate([1.0, 2.0, 4.0])]
    pts = charts.chart_points(levels, "estimate", "time", cumulative=True)
    assert [p[0] for p in pts] == [1.0, 3.0, 7.0]
    assert "uniform" not in charts.chart_title("hertz", "mortar", uniform=False)
    assert "against uniform" in charts.chart_title("hertz", "mortar", uniform=True)


def test_ticks_are_plain_numbers(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Less than a decade of DOFs: labels like 3000, not overlapping 3x10^3 minor labels."""
    kept = []
    monkeypatch.setattr(charts.plt, "close", kept.append)
    levels = [_level(k, n, 1.0 + k, [0.02 - 0.002 * k]) for k, n in enumerate([2800, 3500, 4600])]
    charts.plot_adapt(levels, [], tmp_path / "c.png", "dofs", "t")
    fig = kept[0]
    fig.canvas.draw()
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            major = [t.get_text() for t in axis.get_majorticklabels() if t.get_text()]
            minor = [t.get_text() for t in axis.get_minorticklabels() if t.get_text()]
            assert len(major) >= 2 and not minor, (major, minor)
            assert all(re.fullmatch(r"[0-9.e+-]+", t) for t in major), major
    # Ticks near both ends of a short axis (9000 and 10000) must not run into each other.
    ticks = charts.tick_values(8900.0, 45000.0)
    steps = np.diff(np.log10(ticks))
    assert len(ticks) >= 3 and steps.min() >= np.log10(45000 / 8900) / 12, ticks
