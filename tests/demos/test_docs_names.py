"""The code names docs/failures.md cites (where each failure is raised) exist in the code."""

from __future__ import annotations

import importlib
import re

import pytest
from conftest import ROOT

STAGES = ("", "cli.", "adapt.", "study.", "results.", "methods.", "discretize.", "scenes.",
          "linalg.", "contact.")  # fmt: skip


def resolves(dotted: str) -> bool:
    """Whether contactfx.<stage><dotted> names a module or an attribute chain in one."""
    for stage in STAGES:
        parts = f"contactfx.{stage}{dotted}".removeprefix("contactfx.contactfx.").split(".")
        if parts[0] != "contactfx":
            parts = ["contactfx", *parts]
        for cut in range(len(parts), 1, -1):
            try:
                obj = importlib.import_module(".".join(parts[:cut]))
            except ImportError:
                continue
            try:
                for attr in parts[cut:]:
                    obj = getattr(obj, attr)
            except AttributeError:
                break
            return True
    return False


NAMES = sorted(
    set(re.findall(r"`((?:[a-z_]+\.)+[A-Za-z_]+)`", (ROOT / "docs" / "failures.md").read_text()))
    - {"contact.rigid"}
    | {"contact.rigid"}
)


@pytest.mark.parametrize("dotted", NAMES)
def test_failures_page_names_code_that_exists(dotted: str) -> None:
    assert resolves(dotted), f"docs/failures.md cites `{dotted}`, which the code does not have"
