"""Pictures of exact solutions: round-off drawn flat, units as the scene names them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT
from matplotlib.figure import Figure

from contactfx import SolveRequest, load_scene_file, run_scene
from contactfx.results.figures import plot_pair, round_off_band
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
