"""Pictures of exact solutions: round-off drawn flat, units as the scene names them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT
from matplotlib.figure import Figure

from contactfx import SolveRequest, load_scene_file, run_scene
from contactfx.results.figures import plot_pair, round_off_band, stick_spans
from contactfx.scenes import Units

SCENES = ROOT / "tests" / "scenes"


def test_round_off_band_flattens_noise_and_keeps_real_variation() -> None:
    rng = np.random.default_rng(0)
    noisy = 10.0 + 1e-9 * rng.standard_normal(50)
    lo, hi = round_off_band(noisy) or (0.0, 0.0)
    assert lo == pytest.approx(9.5, abs=1e-6) and hi == pytest.approx(10.5, abs=1e-6)
    # Noise of 1e-10 against a traction scale of 10 is flat around 0.
    assert round_off_band(1e-10 * rng.standard_normal(50), scale=10.0) == pytest.approx(
        (-0.5, 0.5), abs=1e-6
    )
    assert round_off_band(np.linspace(9.0, 10.0, 50)) is None
    assert round_off_band(np.array([np.nan])) is None


def chart_axes(run: object, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> list:
    figures: list[Figure] = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, *_, **__: figures.append(fig))
    plot_pair(run, 0, tmp_path / "pair.png")  # type: ignore[arg-type]
    figures[0].canvas.draw()
    return figures[0].axes


@pytest.mark.serial
def test_patch_test_chart_is_flat_and_in_the_scenes_units(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The inclined patch test (pressure 10 everywhere, to 1e-9): no '1e-8+1e1' offset axis,
    limits +-5 % of the traction, and the axes say length/stress (the scene names no units)."""
    _, run = run_scene(
        load_scene_file(SCENES / "inclined_patch.toml"), SolveRequest.parse("mortar")
    )
    assert run.units == Units()
    ax, bx = chart_axes(run, tmp_path, monkeypatch)
    for a in (ax, bx):
        assert a.yaxis.get_offset_text().get_text() == "", a.yaxis.get_offset_text().get_text()
    assert ax.get_ylim() == pytest.approx((9.5, 10.5), abs=1e-6)
    assert bx.get_ylim() == pytest.approx((-0.5, 0.5), abs=1e-6)
    assert "(stress" in ax.get_ylabel() and "(length)" in bx.get_xlabel()
    assert "cm" not in bx.get_xlabel() and "MPa" not in ax.get_ylabel()


@pytest.mark.serial
def test_units_named_by_the_scene_file_reach_the_charts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    toml = (SCENES / "inclined_patch.toml").read_text()
    (tmp_path / "inclined_patch.geo").write_text((SCENES / "inclined_patch.geo").read_text())
    scene_file = tmp_path / "s.toml"
    scene_file.write_text('units = { length = "mm", stress = "N/mm^2" }\n' + toml)
    _, run = run_scene(load_scene_file(scene_file), SolveRequest.parse("mortar"))
    assert run.units == Units("mm", "N/mm^2")
    ax, bx = chart_axes(run, tmp_path, monkeypatch)
    assert "N/mm^2" in ax.get_ylabel() and "(mm)" in bx.get_xlabel()


def test_stick_spans_are_the_runs_of_stick_nodes() -> None:
    s = np.arange(7.0)
    status = ["open", "stick", "stick", "slip", "stick", "slip", "stick"]
    assert stick_spans(s, status) == [(1.0, 2.0), (4.0, 4.0), (6.0, 6.0)]
    assert stick_spans(s[:2], ["open", "slip"]) == []


@pytest.mark.serial
def test_a_frictional_pairs_chart_draws_shear_mu_p_and_the_stick_zone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A block pressed and pushed (mortar, mu = 0.3): the chart's |shear| and mu p lines are
    the interface's columns, and the shaded stick spans cover exactly the stick nodes."""
    from contactfx import ContactPair, scene_from_gmsh
    from contactfx.scenes import Dirichlet, Material, Pressure

    mu = 0.3
    scene = scene_from_gmsh(
        SCENES / "friction_blocks.geo",
        bodies={"base": Material(1000.0, 0.3), "block": Material(1000.0, 0.3)},
        contacts=[ContactPair("block_bottom", "base_top", mu=mu)],
        dirichlet=[Dirichlet("base_bottom", ux=0.0, uy=0.0), Dirichlet("block_top", ux=0.002)],
        loads=[Pressure("block_top", 10.0)],
    )
    _, run = run_scene(scene, SolveRequest.parse("mortar"))
    itf = run.contacts[0].interface
    s, status = np.asarray(itf["s"]), np.asarray(itf["status"])
    assert "stick" in status and "slip" in status
    figures: list[Figure] = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, *_, **__: figures.append(fig))
    plot_pair(run, 0, tmp_path / "pair.png", mu)
    ax = figures[0].axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    np.testing.assert_array_equal(lines["|shear| (multipliers)"].get_ydata(), np.abs(itf["shear"]))
    mu_p = lines[f"mu p (mu = {mu:g})"].get_ydata()
    np.testing.assert_allclose(mu_p, mu * np.asarray(itf["pressure"]))
    assert "|shear|" in ax.get_ylabel()
    spans = [p for p in ax.patches if p.get_gid() == "stick"]
    assert spans  # the stick zones, beside the grey active set
    covered = np.zeros(len(s), dtype=bool)
    for p in spans:
        xs = p.get_patch_transform().transform(p.get_path().vertices)[:, 0]
        covered |= (s >= xs.min() - 1e-12) & (s <= xs.max() + 1e-12)
    np.testing.assert_array_equal(covered, status == "stick")
    # Frictionless (mu = 0), the same chart has no friction lines.
    figures.clear()
    plot_pair(run, 0, tmp_path / "pair.png")
    assert not [ln for ln in figures[0].axes[0].get_lines() if "shear" in str(ln.get_label())]
