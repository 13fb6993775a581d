"""What a study fits and draws: self-convergence rates, non-monotone data, the charts' ticks,
the Hertz window, and each run's contact forces.

The rotated scene is tests/scenes/rotated_hertz.toml (a displacement-controlled Hertz contact
rotated by 30 degrees, full model) without its reference: a study of it measures
self-convergence. With 3 levels at --size-factor 2 (1106 to 15498 elements) the old fit
err ~ C (h^r - h_ref^r) printed pressure rates of 0.00 (nts), 0.11 (sts) and 0.10 (mortar)
beside errors falling from 3.3e-2 to 1.6e-2: differences from the finest level that fall by
less than 2 per halving have no such r > 0. Successive differences |u_k - u_k+1| ~ h_k^r need
no model of the reference's own error: measured 0.88 / 0.90 / 0.90 (pressure, the rate the
square-root edge allows, docs/study.md) and 2.00 (displacement).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from conftest import ROOT, cli

matplotlib.use("Agg")
from matplotlib.figure import Figure

from contactfx.study.charts import plot_convergence
from contactfx.study.core import Study, fit_rates
from contactfx.study.levels import Level
from contactfx.study.runs import Run

SCENES = ROOT / "tests" / "scenes"
ROTATED = ("--levels", "3", "--size-factor", "2")
PHI = 30.0  # the rotation of rotated_hertz.geo (degrees)


def rotated_scene(tmp: Path, reference: bool) -> Path:
    """rotated_hertz.toml and its .geo in `tmp`, with or without its Hertz reference."""
    text = (SCENES / "rotated_hertz.toml").read_text()
    (tmp / "rotated_hertz.geo").write_text((SCENES / "rotated_hertz.geo").read_text())
    toml = tmp / "rotated_hertz.toml"
    toml.write_text(text if reference else text[: text.index("[[reference]]")])
    return toml


def study(args: tuple[str, ...], out: Path) -> tuple[dict, str]:
    """Run `contactfx study ...`; its study.json and stdout."""
    proc = cli("study", *args, "--out", str(out))
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return json.loads((out / "study.json").read_text()), proc.stdout


@pytest.fixture(scope="module")
def rotated_self(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, str]:
    """The rotated scene's self-convergence study (3 levels)."""
    scene = rotated_scene(tmp_path_factory.mktemp("scene"), reference=False)
    return study((str(scene), *ROTATED), tmp_path_factory.mktemp("rotated"))


@pytest.mark.serial
def test_self_convergence_rate_of_a_falling_line_is_positive(rotated_self) -> None:
    """Pressure differences that clearly fall get a rate near 1, not 0.00 (measured 0.88 to
    0.90; the sqrt edge of the pressure caps it near 1); the displacement's near 2."""
    data, stdout = rotated_self
    assert data["reference"]["kind"] == "self"
    for method in ("nts", "sts", "mortar"):
        assert 0.6 < data["rates"][method]["pressure"] < 1.3, (method, data["rates"])
        assert 1.6 < data["rates"][method]["displacement"] < 2.4, (method, data["rates"])
        runs = [r for r in data["runs"] if r["method"] == method]
        falling = [r["successive"]["pressure"] for r in runs if r["successive"]]
        assert len(falling) == 2 and falling[0] > 1.5 * falling[1], (method, falling)
    assert "rates: log-log slope of the differences between successive levels" in stdout
    assert "pressure 0.00" not in stdout


@pytest.mark.serial
def test_study_records_each_runs_contact_force(rotated_self, tmp_path: Path) -> None:
    """Every run has its pair's force; frictionless on the 30-degree block, it lies along
    the rotated normal (0.1 degree), and it converges (1 % between the two finest levels)."""
    data, _ = rotated_self
    for r in data["runs"]:
        ((fx, fy),) = r["forces"]
        assert abs(math.degrees(math.atan2(-fx, fy)) - PHI) < 0.1, r["forces"]
    mortar = [np.linalg.norm(r["forces"][0]) for r in data["runs"] if r["method"] == "mortar"]
    assert abs(mortar[2] / mortar[1] - 1) < 0.01, mortar


def run(method: str, level: int, h: float, **errors: float) -> Run:
    """A finished run with given errors (against an exact solution)."""
    return Run(
        method,
        level,
        0.5**level,
        h=h,
        errors=dict(errors),
        times={"mesh": 0.0, "total": 1.0 + level},
    )


EXACT = {"kind": "exact", "type": "hertz"}


@pytest.mark.serial
def test_non_monotone_data_is_flagged_not_fitted_silently() -> None:
    """An error that rises on a finer level is flagged; a falling one is not."""
    runs = [
        run("mortar", 0, 0.04, l2=1e-2, a=2e-3),
        run("mortar", 1, 0.02, l2=5e-3, a=4e-3),
        run("mortar", 2, 0.01, l2=2.6e-3, a=1e-3),
    ]
    rates, flags = fit_rates(runs, ["mortar"], ["l2", "a"], "h", EXACT)
    assert rates["mortar"]["l2"] == pytest.approx(0.97, abs=0.02)
    assert "l2" not in flags["mortar"]
    assert flags["mortar"]["a"] == "non-monotone"


def chart_axes(study_: Study, tmp: Path, monkeypatch: pytest.MonkeyPatch) -> list:
    """The axes of the convergence chart, as saved."""
    saved: list = []
    original = Figure.savefig

    def keep(fig: Figure, *args, **kwargs):  # type: ignore[no-untyped-def]
        fig.canvas.draw()
        saved.extend(fig.axes)
        return original(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", keep)
    plot_convergence(study_, tmp / "convergence.png")
    return saved


def labelled(axis) -> list[str]:  # type: ignore[no-untyped-def]
    """The tick labels of `axis` inside its view."""
    lo, hi = sorted(axis.get_view_interval())
    return [
        t.get_text()
        for t, v in zip(axis.get_ticklabels(), axis.get_ticklocs(), strict=True)
        if t.get_text() and lo <= v <= hi
    ]


@pytest.mark.serial
@pytest.mark.parametrize("h", [(0.078, 0.039), (0.0205, 0.0195 * 1.02, 0.0195)])
def test_convergence_chart_has_readable_ticks_over_a_short_range(
    h: tuple[float, ...], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """h over one refinement (and over 5 %): three to seven distinct plain labels on x."""
    runs = [run("mortar", k, hk, l2=0.02 * (hk / h[0])) for k, hk in enumerate(h)]
    rates, flags = fit_rates(runs, ["mortar"], ["l2"], "h", EXACT)
    levels = [Level(k, 0.5**k, {}, build=lambda: None) for k in range(len(h))]  # type: ignore[arg-type,return-value]
    s = Study("synthetic", ["mortar"], levels, runs, EXACT, ["l2"], rates, rates, 1.0, 1, {}, flags)
    (ax,) = chart_axes(s, tmp_path, monkeypatch)
    labels = labelled(ax.xaxis)
    assert 3 <= len(labels) <= 7 and len(set(labels)) == len(labels), labels
    assert all(float(t) > 0 for t in labels), labels


@pytest.mark.serial
def test_tick_values_stay_readable() -> None:
    """Decades, a few decades, one decade, less: 3 to 9 round values inside the range."""
    from contactfx.study.charts import tick_values

    for lo, hi in ((1e-5, 1e-1), (3e-4, 2e-2), (0.037, 0.082), (0.0195, 0.0205), (0.9, 1.3)):
        ticks = tick_values(lo, hi)
        assert 3 <= len(ticks) <= 9 and all(lo <= t <= hi for t in ticks), (lo, hi, ticks)
        assert all(len(f"{t:g}") <= 7 for t in ticks), ticks


@pytest.mark.serial
def test_full_model_hertz_window_is_described_as_used(tmp_path: Path) -> None:
    """A full-model Hertz reference (the rotated scene, P computed): the study says the L2
    error is over [-1.5 a, 1.5 a], the window hertz.l2_error uses there."""
    scene = rotated_scene(tmp_path, reference=True)
    data, stdout = study(
        (str(scene), "--levels", "2", "--size-factor", "4", "--methods", "mortar"), tmp_path / "out"
    )
    ref = data["reference"]
    assert ref["type"] == "hertz" and "[-1.5 a, 1.5 a] (full model)" in ref["description"]
    assert "[0, 1.5 a]" not in ref["description"]
    assert "[-1.5 a, 1.5 a]" in stdout


def profile_run(level: int, h: float, p: np.ndarray, s: np.ndarray) -> Run:
    """A finished run whose pressure and displacement profiles along s are p."""
    from contactfx.study.measures import Profiles

    r = run("mortar", level, h)
    r.profiles = Profiles([(s, p)], [(s, np.column_stack([p, p]))])
    return r


@pytest.mark.serial
@pytest.mark.parametrize("shapes", ["one", "alternating"])
def test_successive_differences_recover_the_rate(shapes: str) -> None:
    """u_k = u + h_k phi_k on 3 levels: the rate is 1 whether the error keeps one shape or
    changes it every level. Against the finest level instead, the alternating case falls
    by 1.34 per halving (0.03 -> 0.022), which no C (h^r - h_ref^r) with r > 0 gives (it
    needs > 2 here): the old fit's 0.00."""
    from contactfx.study.core import apply_reference

    s = np.linspace(0.0, 3.0, 301)
    h = np.array([0.04, 0.02, 0.01])
    r = 1.0
    phis = [np.cos(3 * s), np.sin(5 * s)] if shapes == "alternating" else [np.cos(3 * s)] * 2
    runs = [profile_run(k, hk, 1.0 + np.sin(s) + hk**r * phis[k % 2], s) for k, hk in enumerate(h)]
    ref = apply_reference("self", runs, ["mortar"])
    rates, flags = fit_rates(runs, ["mortar"], ["pressure", "displacement"], "h", ref)
    # Successive differences of the alternating family: sqrt(h_k^2 |phi_k|^2 + h_k+1^2
    # |phi_k+1|^2), a power of h_k up to the two shapes' norms (0.97 measured).
    assert rates["mortar"]["pressure"] == pytest.approx(r, abs=0.05), rates
    assert flags["mortar"] == {}
    to_ref = [runs[k].errors["pressure"] for k in range(2)]
    if shapes == "alternating":
        assert 1.2 < to_ref[0] / to_ref[1] < 1.5, to_ref
