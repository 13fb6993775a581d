"""The docs site as a user meets it: math rendered without the network, every page in a
section (so the section navigation is never empty), user pages and not lab notebooks."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
SECTIONS = ["user_guide.md", "demos.md", "benchmarks.md", "reference/index.md"]


def _toctree_entries(page: Path) -> list[str]:
    """The entries of a page's toctree blocks (globs included), relative to the page."""
    text = page.read_text()
    entries = []
    for block in re.findall(r"```\{toctree\}\n(.*?)```", text, re.S):
        entries += [
            ln.strip() for ln in block.splitlines() if ln.strip() and not ln.startswith(":")
        ]
    return entries


@pytest.mark.serial
def test_math_is_rendered_from_the_site_itself() -> None:
    """sphinx.ext.mathjax alone loads MathJax from a CDN: offline the pages showed raw LaTeX.
    The offline extension copies MathJax into the site; no remote MathJax path is set."""
    conf = (DOCS / "conf.py").read_text()
    assert '"sphinx-mathjax-offline"' in conf
    assert not re.search(r"mathjax_path\s*=\s*['\"]https?:", conf)


@pytest.mark.serial
def test_every_page_sits_in_a_section() -> None:
    """A page outside the four sections' toctrees has an empty section navigation."""
    listed = {"index"}
    for section in SECTIONS:
        base = (DOCS / section).parent.relative_to(DOCS)
        for entry in _toctree_entries(DOCS / section):
            if "*" in entry:
                listed |= {
                    str(p.relative_to(DOCS).with_suffix(""))
                    for p in (DOCS / base).glob(entry + ".md")
                }
            else:
                listed.add(str(base / entry).removeprefix("./"))
    pages = {str(p.relative_to(DOCS).with_suffix("")) for p in DOCS.glob("*.md")}
    pages -= {s.removesuffix(".md") for s in SECTIONS}
    assert pages <= listed, sorted(pages - listed)


@pytest.mark.serial
def test_pages_are_for_users() -> None:
    """No page is a measurement notebook (the notebooks live under benchmarks/log/): none
    over 600 lines, none speaks of issue numbers or of who measured what."""
    for page in sorted(DOCS.rglob("*.md")):
        if "_build" in page.parts or page.parent.name == "demos":
            continue
        text = page.read_text()
        assert len(text.splitlines()) <= 600, page
        assert not re.search(r"\bissues? \d|\bthe lead\b", text, re.I), page
