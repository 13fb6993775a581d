"""The README's five-minute example runs as written; docs/python.md documents the API.

docs/python.md shows references= and says what a Solution and a RunSummary hold.
"""

from __future__ import annotations

import ast
import dataclasses
import re
import subprocess
import sys

import pytest
from conftest import ENV, ROOT

from contactfx import HertzReference, UniformStress
from contactfx.cli.parser import parser
from contactfx.methods.solution import PairView, Solution

README = (ROOT / "README.md").read_text()
PYTHON_PAGE = (ROOT / "docs" / "python.md").read_text()


def python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


@pytest.mark.serial
def test_readme_python_example_runs() -> None:
    """The README's Python block runs from the repository root and prints both Hertz pairs."""
    (block,) = python_blocks(README)
    proc = subprocess.run(
        [sys.executable, "-c", block],
        cwd=ROOT,
        env=ENV,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert "pair 0: a = 0.60" in proc.stdout and "pair 1: a = 0.60" in proc.stdout


@pytest.mark.serial
def test_readme_command_line_example_parses() -> None:
    """The README's command lines are valid `contactfx` calls on scenes that exist."""
    lines = [ln for ln in README.splitlines() if ln.startswith(".venv/bin/python -m contactfx")]
    assert lines, "no command line in the README"
    for line in lines:
        argv = line.split()[3:]
        args = parser().parse_args(argv)
        assert args.scene in ("blocks", "hertz") or (ROOT / args.scene).is_file(), args.scene


@pytest.mark.serial
def test_readme_shows_references_in_the_python_api() -> None:
    """A python block passes references= with both reference types, and it parses."""
    blocks = [b for b in python_blocks(PYTHON_PAGE) if "references=" in b]
    assert blocks, "no python example with references="
    for block in blocks:
        ast.parse(block)
        assert "HertzReference(" in block and "UniformStress(" in block
    # The example's calls are the real signatures: P may be omitted.
    assert HertzReference(pair=0, R=24.0).P is None
    assert UniformStress(sigma=((-10.0, 0.0), (0.0, -10.0))).sigma[0][0] == -10.0


@pytest.mark.serial
def test_readme_says_what_a_solution_holds() -> None:
    """Every field of Solution (but its private cache) and PairView's geometry are named."""
    start = PYTHON_PAGE.index("What a `Solution` holds")
    text = PYTHON_PAGE[start : PYTHON_PAGE.index("\n\n", start)]
    for f in dataclasses.fields(Solution):
        if f.name != "cache":
            assert f"`{f.name}`" in text, f.name
    pair_view = {f.name for f in dataclasses.fields(PairView)} | set(dir(PairView))
    for name in ("rows", "s", "n", "t", "frame"):
        assert f"`{name}`" in text and name in pair_view, name


def test_readme_says_what_a_run_summary_holds() -> None:
    """Every field of RunSummary is named, and the examples read real attributes."""
    from contactfx.results import RunSummary

    start = PYTHON_PAGE.index("What a `RunSummary` holds")
    text = PYTHON_PAGE[start : PYTHON_PAGE.index("\n\n", start)]
    for f in dataclasses.fields(RunSummary):
        assert f"`{f.name}`" in text, f.name
    names = {f.name for f in dataclasses.fields(RunSummary)} | set(dir(RunSummary))
    for name in ("hertz", "patch", "to_json", "with_estimate"):
        assert name in names, name


def test_testing_page_counts_the_rank_cases() -> None:
    """docs/testing.md gives the number of 2-rank cases: the registry's (it drifted once)."""
    sys.path.insert(0, str(ROOT / "tests" / "ranks"))
    try:
        from rank_cases import CASES
    finally:
        sys.path.pop(0)
    text = " ".join((ROOT / "docs" / "testing.md").read_text().split())
    assert f"compares {len(CASES)} cases" in text


@pytest.mark.serial
def test_readme_commands_write_under_an_ignored_folder() -> None:
    """The README's command left out/ and r.json untracked in the repository root: every
    --json and --out it gives lies under results/, which .gitignore ignores."""
    lines = [ln for ln in README.splitlines() if ln.startswith(".venv/bin/python -m contactfx")]
    ignored = (ROOT / ".gitignore").read_text().splitlines()
    assert "/results/" in ignored
    for line in lines:
        args = parser().parse_args(line.split()[3:])
        for path in (getattr(args, "json", None), getattr(args, "out", None)):
            assert path is None or path.parts[0] == "results", line


@pytest.mark.serial
def test_make_installs_the_package_without_the_editable_banner() -> None:
    """`make demo` printed setuptools' editable-install banner (a build-backend warning that
    pip's --quiet lets through): every editable install runs with warnings ignored."""
    import shutil
    import subprocess

    if shutil.which("make") is None:
        pytest.skip("no make")
    for target in ("venv", "docs"):
        dry = subprocess.run(
            ["make", "-n", "-B", target], cwd=ROOT, capture_output=True, text=True, check=True
        )
        installs = [ln for ln in dry.stdout.splitlines() if "pip install" in ln and " -e " in ln]
        assert installs, dry.stdout
        assert all("PYTHONWARNINGS=ignore" in ln for ln in installs), installs
