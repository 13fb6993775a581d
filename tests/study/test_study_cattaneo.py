"""A study of a frictional scene against its `cattaneo` reference: the shear's L2 error and the
stick half-width's error per run, with rates in h.

Measured on the mirrored cylinders (tests/scenes/cattaneo_cylinders.toml, mortar): size
factors 4, 2, 1 give shear 11.7, 5.4, 3.3 % and stick 12.9, 3.5, 1.5 % (rates 0.92 and 1.56;
`contactfx study tests/scenes/cattaneo_cylinders.toml --methods mortar --levels 3
--size-factor 4`). The two cheap levels here: 1.3 s of solves.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import ROOT, cli

SCENE = ROOT / "tests" / "scenes" / "cattaneo_cylinders.toml"


def test_cattaneo_study_reports_shear_and_stick_errors_with_rates(tmp_path: Path) -> None:
    """Both errors fall from the coarse level to the finer, their rates in h lie in a band
    about 1 (the shear's jump in slope at +-c limits it), and the finer level's shear error is
    the pinned value of the deterministic run."""
    out = tmp_path / "study"
    args = ("--methods", "mortar", "--levels", "2", "--size-factor", "4", "--out", str(out))
    proc = cli("study", str(SCENE), *args)
    assert proc.returncode == 0, proc.stderr
    data = json.loads((out / "study.json").read_text())
    assert data["reference"]["type"] == "cattaneo" and data["reference"]["exact"] is False
    runs = sorted(data["runs"], key=lambda r: r["level"])
    assert [r["status"] for r in runs] == ["ok", "ok"]
    shear = [r["errors"]["shear"] for r in runs]
    stick = [r["errors"]["stick"] for r in runs]
    assert shear[1] < shear[0] and stick[1] < stick[0]
    assert shear[1] == pytest.approx(0.05425, rel=1e-3)
    rates = data["rates"]["mortar"]
    assert 0.7 < rates["shear"] < 1.6 and 0.7 < rates["stick"] < 2.5
    assert "shear L2" in proc.stdout and "c err" in proc.stdout
