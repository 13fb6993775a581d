"""Convergence studies (`contactfx study`, contactfx.study): rates, references, files, failures.

The Hertz band, from theory: the exact pressure p0 sqrt(1 - x^2/a^2) has a square-root edge
at x = a. On the element of size h_e containing the edge, even the best continuous piecewise
linear function misses it by ~ p0 sqrt(h_e/a) over a length h_e, so the relative L2 error is
~ h_e / a: the rate in h is limited to about 1 for every method (the smooth interior alone
would give 2). The mesh is not aligned with a (the free boundary moves), so where the nodes
fall relative to a scatters the error from level to level by ~ +-0.3 in a 3-level slope.
Measured: 1.03 (mortar, sts) and 0.78 (nts) in the measured contact element size h on
h_e = 0.04 -> 0.01 (the test below; 0.93, 0.93 and 0.71 fitted in h_e);
0.78, 0.79 and 0.69 on h_e = 0.005 -> 0.0003 (`study hertz --levels 5`; mortar's pressure
against its own finest level converges at the same 0.79 there, so that is the
discretization, not a floor of the half-space reference); earlier 0.96 and 0.85 on
0.04 -> 0.0025. Each method's rate on these fixed meshes is deterministic, so each has its
own expected value within +-0.1 (as scikit-fem's convergence tests do): a mortar regression
to NTS-like convergence (0.7-0.8) fails. Refining only the contact sizes (Scene.resize)
plateaus near 0.3 % L2 with a rate of 0.14 (test below): the band can fail.
"""

from __future__ import annotations

import csv
import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, cli, run_cli

from contactfx.scenes import HertzParams, hertz
from contactfx.study import Level, run_study
from contactfx.study.measures import fit_rate

SCENES = ROOT / "tests" / "scenes"
# Fitted L2 rates on the cheap levels, in the measured contact element size (see above).
EXPECTED_RATE = {"nts": 0.78, "sts": 1.03, "mortar": 1.03}
RATE_EPS = 0.1
# Cheap Hertz levels: h_e = 0.04, 0.02, 0.01 cm (393 to 1933 elements).
HERTZ = ("study", "hertz", "--levels", "3", "--size-factor", "8")
# The user scene: two_cylinders.geo at 4x, 2x and 1x its sizes (324 to 3778 elements).
GEO = ("--levels", "3", "--size-factor", "4")


def scene_without_reference(tmp: Path) -> Path:
    """two_cylinders.toml and its .geo in `tmp`, without the [[reference]] entry."""
    text = (SCENES / "two_cylinders.toml").read_text()
    (tmp / "two_cylinders.geo").write_text((SCENES / "two_cylinders.geo").read_text())
    toml = tmp / "two_cylinders.toml"
    toml.write_text(text[: text.index("[[reference]]")])
    return toml


def study(args: tuple[str, ...], out: Path, ranks: int = 1) -> tuple[dict, str]:
    """Run `contactfx study ...` (in this process when serial); its study.json and stdout."""
    proc = (
        cli(*args, "--out", str(out))
        if ranks == 1
        else run_cli(*args, "--out", str(out), ranks=ranks)
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return json.loads((out / "study.json").read_text()), proc.stdout


@pytest.fixture(scope="module")
def hertz_serial(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, str, Path]:
    """The cheap Hertz study, serial."""
    out = tmp_path_factory.mktemp("hertz")
    return (*study(HERTZ, out), out)


@pytest.fixture(scope="module")
def geo_scene(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A .geo user scene without a reference."""
    return scene_without_reference(tmp_path_factory.mktemp("scene"))


@pytest.fixture(scope="module")
def geo_serial(geo_scene: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, str, Path]:
    """The user-scene study, serial."""
    out = tmp_path_factory.mktemp("geo")
    return (*study(("study", str(geo_scene), *GEO), out), out)


def test_fit_rate_recovers_a_noisy_power_law() -> None:
    """err = C h^r with 5 % noise over 6 levels: the slope within 0.05 of r."""
    rng = np.random.default_rng(7)
    h = 0.1 / 2.0 ** np.arange(6)
    for rate in (0.5, 1.0, 2.0):
        err = 3.0 * h**rate * np.exp(rng.normal(0.0, 0.05, h.size))
        assert abs(fit_rate(h, err) - rate) < 0.05
    # Round-off (mortar on a patch test) and missing errors are no data points.
    assert fit_rate(h[:3], [4e-2, 2e-2, 1e-12]) == pytest.approx(1.0)
    assert fit_rate(h[:2], [4e-2, None]) is None


@pytest.mark.parametrize("method", sorted(EXPECTED_RATE))
def test_hertz_study_rates_per_method(hertz_serial: tuple[dict, str, Path], method: str) -> None:
    """Each method's fitted L2 rate within 0.1 of its own expected value; errors fall."""
    data, _, _ = hertz_serial
    assert data["reference"]["kind"] == "exact" and data["reference"]["type"] == "hertz"
    rate = data["rates"][method]["l2"]
    assert abs(rate - EXPECTED_RATE[method]) < RATE_EPS, (method, data["rates"])
    assert {"l2", "a", "p0"} <= set(data["rates"][method])
    errs = [r["errors"]["l2"] for r in data["runs"] if r["method"] == method]
    assert len(errs) == 3 and errs[0] > errs[1] > errs[2], errs


def test_axisymmetric_sphere_converges_as_the_plane_models_do(tmp_path: Path) -> None:
    """The sphere on a block (axisymmetric, 3D Hertz) on the same three levels: mortar's L2
    rate within 0.1 of its plane-strain expected rate, the errors fall, the finest < 1 %."""
    data, _ = study((*HERTZ, "--model", "axisymmetric", "--methods", "mortar"), tmp_path)
    assert data["levels"] and all(r["status"] == "ok" for r in data["runs"])
    rate = data["rates"]["mortar"]["l2"]
    assert abs(rate - EXPECTED_RATE["mortar"]) < RATE_EPS, data["rates"]
    errs = [r["errors"]["l2"] for r in data["runs"]]
    assert errs[0] > errs[1] > errs[2] and errs[2] < 0.01, errs


def test_mortar_converges_faster_than_nts(hertz_serial: tuple[dict, str, Path]) -> None:
    """NTS's collocated pressure oscillates on non-matching meshes: a slower rate."""
    rates = hertz_serial[0]["rates"]
    assert rates["mortar"]["l2"] > rates["nts"]["l2"] + 0.15, rates


def test_refining_only_the_contact_plateaus() -> None:
    """The band can fail: the contact sizes alone (slope kept) give a rate far below it."""
    base = HertzParams()
    levels = []
    for k, f in enumerate((1.0, 0.5, 0.25)):
        p = replace(base, refine=base.refine * f, refine_edge=base.refine_edge * f)
        levels.append(Level(k, f, {"refine_edge": p.refine_edge}, lambda p=p: hertz(p)))
    rate = run_study(levels, ["mortar"], say=lambda line: None).rates["mortar"]["l2"]
    assert rate < min(EXPECTED_RATE.values()) - RATE_EPS - 0.4, rate


def test_hertz_study_refines_the_whole_mesh(hertz_serial: tuple[dict, str, Path]) -> None:
    """Each level halves the edge and zone sizes and divides the slope by sqrt 2; the
    measured contact element size halves; the report shows the sizes, progress and table."""
    data, stdout, out = hertz_serial
    sizes = [lv["sizes"] for lv in data["levels"]]
    assert [s["refine_edge"] for s in sizes] == pytest.approx([0.04, 0.02, 0.01])
    assert [s["refine"] for s in sizes] == pytest.approx([0.16, 0.08, 0.04])
    assert [s["slope"] for s in sizes] == pytest.approx([0.1 * 8**0.5, 0.2, 0.1 * 2**0.5])
    mortar = [r for r in data["runs"] if r["method"] == "mortar"]
    assert all(r["status"] == "ok" for r in data["runs"]) and len(data["runs"]) == 9
    assert [r["h"] / mortar[0]["h"] for r in mortar] == pytest.approx([1, 0.5, 0.25], rel=0.1)
    assert mortar[0]["elements"] < mortar[1]["elements"] < mortar[2]["elements"]
    assert all(set(r["times"]) >= {"mesh", "total"} and r["iterations"] for r in mortar)
    assert "[run 9/9]" in stdout and "left" in stdout and "elapsed" in stdout
    assert "refine_edge 0.01" in stdout and "fitted rates in h, mortar: l2" in stdout
    rows = list(csv.DictReader((out / "study.csv").open()))
    assert len(rows) == 9 and float(rows[-1]["l2"]) == pytest.approx(mortar[-1]["errors"]["l2"])


def test_geo_user_scene_study_end_to_end(geo_serial: tuple[dict, str, Path]) -> None:
    """A .geo scene without reference: self-convergence against mortar's finest level,
    with study.json, study.csv and both charts written."""
    data, stdout, out = geo_serial
    ref = data["reference"]
    assert (ref["kind"], ref["method"], ref["level"]) == ("self", "mortar", 2)
    assert [lv["sizes"]["size_factor"] for lv in data["levels"]] == [4.0, 2.0, 1.0]
    mortar = {r["level"]: r for r in data["runs"] if r["method"] == "mortar"}
    assert mortar[2]["errors"] == {}
    for name in ("pressure", "displacement"):
        # Measured 6.5e-2 -> 1.9e-2 (pressure) and 1.6e-2 -> 4.4e-3 (displacement).
        assert mortar[0]["errors"][name] > 2 * mortar[1]["errors"][name] > 0
        assert data["rates"]["mortar"][name] > 0.5
    assert len(list(csv.DictReader((out / "study.csv").open()))) == 9
    for png in ("convergence.png", "accuracy_vs_time.png"):
        assert (out / png).stat().st_size > 20_000
    assert "reference" in stdout and "displacement" in stdout


def test_msh_scene_cannot_be_refined(tmp_path: Path) -> None:
    """A scene whose mesh is a .msh: one line on stderr, exit 2, nothing run."""
    import gmsh

    fresh = not gmsh.isInitialized()
    if fresh:
        gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.open(str(SCENES / "two_cylinders.geo"))
        gmsh.model.mesh.generate(2)
        gmsh.write(str(tmp_path / "two_cylinders.msh"))
    finally:
        gmsh.model.remove()
        if fresh:
            gmsh.finalize()
    toml = tmp_path / "scene.toml"
    toml.write_text(
        (SCENES / "two_cylinders.toml")
        .read_text()
        .replace('mesh = "two_cylinders.geo"', 'mesh = "two_cylinders.msh"')
    )
    proc = cli("study", str(toml), "--out", str(tmp_path / "out"))
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "cannot be refined" in lines[0] and ".geo" in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_failing_level_is_reported_and_the_study_goes_on(tmp_path: Path) -> None:
    """An iterative solver with a tight active-set limit fails mortar's finer levels.

    Probe steps need a direct solver (docs/hertz.md), so with fieldsplit-gamg the plain
    active-set iteration drops one or two edge nodes per solve and needs more solves as the
    zone gets more nodes: mortar 12, 19 on the first two levels, nts 9, 9 (measured). A limit
    of 15 passes level 0 and stops mortar at level 1; nts runs after the failure.
    """
    data, stdout = study(
        (
            "study",
            "hertz",
            "--levels",
            "2",
            "--size-factor",
            "8",
            "--methods",
            "mortar,nts",
            "--solver",
            "fieldsplit-gamg",
            "--max-iterations",
            "15",
        ),
        tmp_path,
    )
    runs = {(r["method"], r["level"]): r for r in data["runs"]}
    assert runs["mortar", 0]["status"] == "ok" and runs["mortar", 0]["errors"]["l2"] > 0
    assert runs["mortar", 1]["status"] == "failed"
    assert "ActiveSetError" in runs["mortar", 1]["message"]
    assert runs["mortar", 1]["errors"] == {}
    assert all(runs["nts", k]["status"] == "ok" for k in range(2))
    assert data["rates"]["mortar"]["l2"] is None and data["rates"]["nts"]["l2"] > 0
    assert stdout.count("FAILED") >= 2  # a progress line and a table row
    assert "failed: mortar level 1: ActiveSetError" in stdout
    status = [row["status"] for row in csv.DictReader((tmp_path / "study.csv").open())]
    assert status.count("failed") == 1 and len(status) == 4


def _same(a: float | None, b: float | None) -> bool:
    return (a is None and b is None) or abs(a - b) <= 1e-6 * max(abs(a), abs(b))


# The .geo user scene only: the Hertz levels' errors on 2 ranks are compared with serial to
# 1e-8 case by case in tests/ranks/test_ranks.py (hertz-graded-mortar).
@pytest.mark.mpi
@pytest.mark.parametrize("which", ["geo"])
def test_two_ranks_give_the_serial_errors(
    which: str,
    geo_serial: tuple[dict, str, Path],
    geo_scene: Path,
    tmp_path: Path,
) -> None:
    """mpirun -n 2: the same sizes, errors and rates as serial, to 1e-6 relative."""
    serial = geo_serial[0]
    args = ("study", str(geo_scene), *GEO)
    data, _ = study(args, tmp_path, ranks=2)
    assert data["ranks"] == 2 and len(data["runs"]) == len(serial["runs"])
    for r1, r2 in zip(serial["runs"], data["runs"], strict=True):
        assert (r1["method"], r1["level"], r1["dofs"], r1["elements"]) == (
            r2["method"],
            r2["level"],
            r2["dofs"],
            r2["elements"],
        )
        assert set(r1["errors"]) == set(r2["errors"])
        for name, value in r1["errors"].items():
            assert _same(value, r2["errors"][name]), (r1["method"], r1["level"], name)
        assert _same(r1["h"], r2["h"])
    for method, rates in serial["rates"].items():
        for name, value in rates.items():
            assert _same(value, data["rates"][method][name]), (method, name)
