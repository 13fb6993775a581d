"""The command line as a user runs it: the JSON schema, outputs, and one-line errors."""

import json
import subprocess
from pathlib import Path

import pytest
from conftest import cli, run_cli

KEYS = {
    "scene",
    "method",
    "params",
    "ranks",
    "dofs",
    "multipliers",
    "elements",
    "iterations",
    "times",
    "contact_force",
    "interface",
}


def test_blocks_nts_writes_schema(tmp_path) -> None:
    """`solve blocks --method nts --json r.json` writes every documented key."""
    out = tmp_path / "r.json"
    proc = cli(
        "solve", "blocks", "--method", "nts", "--json", str(out), "--out", str(tmp_path / "fields")
    )
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert KEYS <= data.keys()
    assert {"mesh", "assemble", "contact", "solve", "total"} <= data["times"].keys()
    assert {"x", "pressure", "sigma_yy_1", "sigma_yy_2"} <= data["interface"].keys()
    params = data["params"]
    assert (params["l1"], params["l2"], params["E1"], params["p"], params["size1"]) == (
        10.0,
        6.0,
        70000.0,
        50.0,
        0.125,
    )
    n = data["multipliers"]
    assert all(len(data["interface"][k]) == n for k in ("x", "pressure", "sigma_yy_1"))
    assert data["contact_force"] == pytest.approx(150.0, rel=1e-10)
    assert (tmp_path / "fields" / "fields.pvtu").exists()
    assert (tmp_path / "fields" / "interface.png").stat().st_size > 10_000


def test_mortar_patch_test_from_the_issue(tmp_path) -> None:
    """The issue's acceptance command: mortar on S4 geometry gives sigma_yy = -p to 1e-8."""
    out = tmp_path / "r.json"
    proc = cli(
        "solve",
        "blocks",
        "--method",
        "mortar",
        "--l2",
        "10",
        "--E1",
        "700000",
        "--E2",
        "70000",
        "--size1",
        "0.12",
        "--size2",
        "0.15",
        "--json",
        str(out),
    )
    assert proc.returncode == 0, proc.stderr
    itf = json.loads(out.read_text())["interface"]
    for key in ("sigma_yy_1", "sigma_yy_2"):
        assert max(abs(v / 50.0 + 1) for v in itf[key]) < 1e-8


def assert_refused(proc: subprocess.CompletedProcess[str], needle: str, out: Path) -> None:
    """Exit 2, one stderr line holding `needle`, no traceback, no JSON."""
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    assert not out.exists()


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["blocks", "--nu1", "0.5"], "Poisson"),
        (["blocks", "--nu2", "-1"], "Poisson"),
        (["blocks", "--E2", "0"], "Young"),
        (["blocks", "--E1", "-7"], "Young"),
        (["blocks", "--size1", "0"], "size1"),
        (["blocks", "--size2", "-0.1"], "size2"),
        (["cylinder"], "unknown scene"),
        (["blocks", "--R", "3"], "does not apply"),
        (["blocks", "--solver", "cg"], "unknown solver"),
    ],
)
def test_bad_input_one_line_no_traceback(tmp_path, args: list[str], needle: str) -> None:
    """Bad input: exit 2, one line on stderr naming the problem, no JSON written (in this
    process: main() turns the error into its line; the fresh-process contract is below)."""
    out = tmp_path / "r.json"
    assert_refused(cli("solve", *args, "--json", str(out)), needle, out)


def test_hertz_structured_mesh_from_the_cli(tmp_path) -> None:
    """`--mesh structured` builds the Hertz scene in DOLFINx and lands near the exact a."""
    out = tmp_path / "h.json"
    proc = cli(
        "solve",
        "hertz",
        "--mesh",
        "structured",
        "--refine",
        "0.04",
        "--method",
        "mortar",
        "--json",
        str(out),
    )
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert data["params"]["mesh"] == "structured"
    hz = data["hertz"]
    assert abs(hz["a"] / hz["a_exact"] - 1) < 0.03
    assert data["contact_force"] == pytest.approx(50.0, rel=1e-9)


def test_mesh_option_is_hertz_only(tmp_path) -> None:
    """--mesh on the blocks scene is refused with one line."""
    proc = cli("solve", "blocks", "--mesh", "structured", "--json", str(tmp_path / "r.json"))
    assert proc.returncode == 2 and "hertz scene only" in proc.stderr


@pytest.mark.parametrize(
    ("args", "needle"),
    [(["blocks", "--E2", "0"], "Young"), (["blocks", "--solver", "cg"], "unknown solver")],
    ids=["model-error", "usage-error"],
)
def test_bad_input_in_a_fresh_process_exits_2(tmp_path, args: list[str], needle: str) -> None:
    """`python -m contactfx` itself: exit status 2, one stderr line, no traceback, no JSON."""
    out = tmp_path / "r.json"
    assert_refused(run_cli("solve", *args, "--json", str(out)), needle, out)
