"""The README documents the Python API's references= and what a Solution holds."""

from __future__ import annotations

import ast
import dataclasses
import re

import pytest
from conftest import ROOT

from contactfx import HertzReference, UniformStress
from contactfx.methods.solution import PairView, Solution

README = (ROOT / "README.md").read_text()


def python_blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", README, flags=re.S)


@pytest.mark.serial
def test_readme_shows_references_in_the_python_api() -> None:
    """A python block passes references= with both reference types, and it parses."""
    blocks = [b for b in python_blocks() if "references=" in b]
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
    start = README.index("What a `Solution` holds")
    text = README[start : README.index("\n\n", start)]
    for f in dataclasses.fields(Solution):
        if f.name != "cache":
            assert f"`{f.name}`" in text, f.name
    pair_view = {f.name for f in dataclasses.fields(PairView)} | set(dir(PairView))
    for name in ("rows", "s", "n", "t", "frame"):
        assert f"`{name}`" in text and name in pair_view, name


def test_readme_says_what_a_run_summary_holds() -> None:
    """Every field of RunSummary is named, and the README's examples read real attributes."""
    from contactfx.results import RunSummary

    start = README.index("What a `RunSummary` holds")
    text = README[start : README.index("\n\n", start)]
    for f in dataclasses.fields(RunSummary):
        assert f"`{f.name}`" in text, f.name
    names = {f.name for f in dataclasses.fields(RunSummary)} | set(dir(RunSummary))
    for name in ("hertz", "patch", "to_json", "with_estimate"):
        assert name in names, name
