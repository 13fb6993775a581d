"""The generated reference pages cover every CLI option and every scene-file key.

`make docs` generates both pages (docs/conf.py, docs/reference/cli.md); these checks need no
Sphinx: the CLI page renders the very parser `contactfx` runs, with nothing hidden, and the
scene-file page is reference_markdown() over the table the parser checks files against.
"""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path
from typing import Any

import pytest
from conftest import ROOT

import contactfx.cli
from contactfx.cli.parser import parser
from contactfx.errors import InputError
from contactfx.scenes.obstacle import OBSTACLE_SHAPES
from contactfx.scenes.scene_file import SECTION_KEYS, TOP_KEYS, parse_scene_file
from contactfx.scenes.schema import SECTIONS, SHAPE_KEYS, TYPE_ERRORS, reference_markdown

pytestmark = pytest.mark.serial

DOCS = ROOT / "docs"


def subcommands() -> dict[str, argparse.ArgumentParser]:
    (sub,) = [a for a in parser()._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(sub.choices)


def test_cli_page_renders_the_parser_contactfx_runs() -> None:
    """reference/cli.md is sphinx-argparse over contactfx.cli.parser.parser, main()'s parser."""
    page = (DOCS / "reference" / "cli.md").read_text()
    assert ".. argparse::" in page
    assert ":module: contactfx.cli.parser" in page and ":func: parser" in page
    # Options such as :path: or :nosubcommands: would leave subcommands out.
    assert ":path:" not in page and ":nosubcommands:" not in page
    assert contactfx.cli.main.__globals__["parser"] is parser


def test_every_cli_option_is_documented() -> None:
    """Every option of every subcommand has a help text and none is hidden from the page."""
    subs = subcommands()
    assert {"solve", "study", "adapt"} <= set(subs)
    for name, sub in subs.items():
        options = [a for a in sub._actions if a.option_strings]
        assert len(options) > 5, name
        for action in options:
            assert action.help, f"{name} {action.option_strings}: no help text"
            assert action.help != argparse.SUPPRESS, f"{name} {action.option_strings} hidden"


def test_every_scene_key_is_on_the_generated_page() -> None:
    """Every key the parser accepts, every shape and every type's error are on the page."""
    page = reference_markdown()
    accepted = set(TOP_KEYS) | {k for keys in SECTION_KEYS.values() for k in keys}
    accepted |= {k for keys in OBSTACLE_SHAPES.values() for k in keys}
    for key in accepted:
        assert f"| `{key}` |" in page, key
    for shape in OBSTACLE_SHAPES:
        assert f'`shape = "{shape}"`' in page, shape
    for section, keys in SECTIONS.items():
        for k in keys:
            default = "required" if k.default is None else f"`{k.default}`"
            row = f"| `{k.name}` | {k.type} | {default} | {k.meaning} |"
            assert row in page, (section, k.name)
            assert TYPE_ERRORS[k.type] in page
    assert set(SHAPE_KEYS) == {k for keys in OBSTACLE_SHAPES.values() for k in keys}
    assert "reference_markdown()" in (DOCS / "conf.py").read_text()


# A minimal valid scene file (the parser does not open the mesh).
BASE = """
mesh = "m.geo"
[bodies.a]
E = 1.0
nu = 0.3
[bodies.b]
E = 1.0
nu = 0.3
[[contact]]
active = "x"
passive = "y"
[[dirichlet]]
group = "g"
uy = 0.0
[[pressure]]
group = "g"
p = 1.0
[[traction]]
group = "g"
t = [0.0, 1.0]
"""


def parse(tmp_path: Path, doc: dict[str, Any]) -> None:
    def value(v: Any) -> str:
        if isinstance(v, str):
            return f'"{v}"'
        if isinstance(v, bool):
            return str(v).lower()
        return repr(v)

    lines = [f"{k} = {value(v)}" for k, v in doc.items() if not isinstance(v, dict | list)]
    for body, table in doc.get("bodies", {}).items():
        lines += [f"[bodies.{body}]", *(f"{k} = {value(v)}" for k, v in table.items())]
    for key in ("contact", "dirichlet", "pressure", "traction"):
        for entry in doc.get(key, []):
            lines += [f"[[{key}]]", *(f"{k} = {value(v)}" for k, v in entry.items())]
    path = tmp_path / "s.toml"
    path.write_text("\n".join(lines) + "\n")
    parse_scene_file(path)


SECTION_OF = {"bodies": ("bodies", "a"), "contact": ("contact", 0), "pressure": ("pressure", 0)}


@pytest.mark.parametrize("section", sorted(SECTION_OF))
def test_required_keys_and_types_are_the_tables(tmp_path: Path, section: str) -> None:
    """A required key of the table is refused when missing; a number given as text, by type."""
    parse(tmp_path, tomllib.loads(BASE))  # the base is valid
    for key in SECTIONS[section]:
        doc = tomllib.loads(BASE)
        where, index = SECTION_OF[section]
        entry = doc[where][index]
        if key.default is None:
            del entry[key.name]
            with pytest.raises(InputError, match=f"missing key '{key.name}'"):
                parse(tmp_path, doc)
        if key.type == "number":
            doc = tomllib.loads(BASE)
            doc[where][index][key.name] = "text"
            with pytest.raises(InputError, match=TYPE_ERRORS["number"]):
                parse(tmp_path, doc)
