"""Bad thermal and interference-fit input: one line on stderr, exit 2, no traceback.

The scene files are tests/scenes/shrink_fit.toml (rings drawn overlapping, interference =
true), shrink_fit_touching.toml (drawn touching, interference = D) and heated_block.toml,
each edited by one key here.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import ROOT, cli

from contactfx import ContactPair, Material
from contactfx.errors import InputError
from contactfx.scenes import LameReference

SCENES = ROOT / "tests" / "scenes"
NO_REFERENCE = "\n# (the Lame reference dropped)"


def _edited(tmp_path: Path, name: str, old: str, new: str) -> Path:
    """A copy of scene file `name` (its mesh path made absolute) with `old` replaced.

    A `new` ending in NO_REFERENCE also drops the file's last table, its [[reference]].
    """
    text = (SCENES / name).read_text()
    assert old in text, old
    geo = text.split('mesh = "')[1].split('"')[0]
    text = text.replace(f'mesh = "{geo}"', f'mesh = "{SCENES / geo}"').replace(old, new)
    if new.endswith(NO_REFERENCE):
        text = text[: text.rindex("[[reference]]")]
    path = tmp_path / name
    path.write_text(text)
    return path


BLOCK = "heated_block.toml"
FIT = "shrink_fit.toml"
TOUCH = "shrink_fit_touching.toml"


@pytest.mark.parametrize(
    ("name", "old", "new", "needle"),
    [
        (BLOCK, "alpha = 1e-5\n", "", "dT needs alpha"),
        (BLOCK, "dT = 100.0\n", "", "alpha needs dT"),
        (BLOCK, "alpha = 1e-5", "alpha = 0.5", "|alpha| < 0.01"),
        (BLOCK, "dT = 100.0", "dT = 1e5", "is not small"),
        (BLOCK, "dT = 100.0", 'dT = "hot"', "expected a number"),
        (FIT, "interference = true", "interference = -0.001", "interference: must be"),
        (FIT, "interference = true", "interference = 0", "interference: must be"),
        (FIT, "interference = true", 'interference = "yes"', "expected a number"),
        # Drawn touching with interference = true: nothing to fit.
        (
            TOUCH,
            "interference = 0.002",
            "interference = true" + NO_REFERENCE,
            "do not overlap as drawn",
        ),
        # Drawn overlapping with interference = D (or without interference): an overlap.
        (FIT, "interference = true", "interference = 0.002", "overlap"),
        (FIT, "interference = true\n", "", "bodies 'shaft' and 'hub' overlap"),
        (FIT, "c = 3.0", "c = 1.5", "0 <= a < b < c"),
        (FIT, "delta = 0.002", "delta = -1.0", "delta must be > 0"),
        (FIT, "delta = 0.002\n", "", "give delta"),
        (FIT, 'type = "lame"', 'type = "lame"\nd = 1.0', "unknown key 'd'"),
    ],
)
def test_bad_thermal_and_fit_input_is_one_line(
    tmp_path: Path, name: str, old: str, new: str, needle: str
) -> None:
    """Each bad key exits 2 with one line naming it (no JSON written)."""
    path = _edited(tmp_path, name, old, new)
    out = tmp_path / "r.json"
    proc = cli("solve", str(path), "--json", str(out))
    assert proc.returncode == 2, proc.stdout[-2000:] + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    assert not out.exists()


def test_api_checks_thermal_and_interference() -> None:
    """The Python API checks the same: Material(alpha, dT), ContactPair(interference), Lame."""
    with pytest.raises(InputError, match="alpha needs dT"):
        Material(1.0, 0.3, alpha=1e-5).check("body 'b'")
    Material(1.0, 0.3, alpha=1e-5, dT=10.0).check("body 'b'")
    assert Material(1.0, 0.3, alpha=1e-5, dT=10.0).thermal_strain == pytest.approx(1e-4)
    assert Material(1.0, 0.3).thermal_strain == 0.0
    for bad in (-1.0, 0.0, float("nan")):
        with pytest.raises(InputError, match="interference must be"):
            ContactPair("a", "b", bad)
    assert ContactPair("a", "b", 2).interference == 2.0
    assert ContactPair("a", "b", 0.5).prescribed_overlap == 0.5
    assert ContactPair("a", "b", True).prescribed_overlap == 0.0
    with pytest.raises(InputError, match="a < b < c"):
        LameReference(2.0, 1.0, 3.0)
