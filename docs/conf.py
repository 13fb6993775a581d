"""Sphinx configuration of the contactfx site (`make docs`).

The pages that must follow the code are generated here, on every build, so a merge that adds a
demo, a page, a CLI option, a scene-file key or a public name shows up without editing the site:

- demos/demo_*.py (jupytext light scripts) -> demos/<name>.ipynb, executed by myst-nb;
- the scene-file reference from contactfx.scenes.schema (the table the parser checks against);
- one API page per package that declares `__all__`.

The command-line reference is `.. argparse::` over contactfx.cli.parser.parser
(reference/cli.md); docs/*.md are the guides (index.md's glob).
"""

from __future__ import annotations

import importlib
import inspect
import os
import pkgutil
import shutil
import sys
from pathlib import Path

import jupytext
from sphinx.errors import PycodeError
from sphinx.pycode import ModuleAnalyzer

import contactfx
from contactfx.scenes.schema import reference_markdown

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
# The demos write their results here, never into the repository (each notebook its own folder).
DEMO_RESULTS = HERE / "_build" / "demo_results"
# The demos run at their own sizes (the figures are the demos' real results); CONTACTFX_QUICK=1
# in the environment runs them at the test suite's small sizes instead.
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

project = "contactfx"
author = "contactfx developers"
release = contactfx.__version__
version = release

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    # MathJax 3 from the installed package, copied into _static/mathjax: the site renders its
    # math with no network (sphinx.ext.mathjax alone loads MathJax from a CDN).
    "sphinx-mathjax-offline",
    "sphinxarg.ext",
]
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]
html_theme = "pydata_sphinx_theme"
html_title = f"contactfx {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    # The top bar holds the four sections of index.md's toctree (user guide, demos,
    # benchmarks, reference); each section's pages fill the left "Section Navigation".
    "header_links_before_dropdown": 4,
    "show_nav_level": 1,
    "navigation_depth": 2,
}
# The front page is a landing page: no section sidebar on it.
html_sidebars = {"index": []}
html_static_path = ["_static"]
html_css_files = ["contactfx.css"]

myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3
# The guides are Markdown written for GitHub too: links into the repository outside docs/
# (benchmarks/README.md, demos/scenes/...) are left as plain links by fix_repo_links below.

nb_execution_mode = "force"
nb_execution_timeout = 900
nb_execution_raise_on_error = True
nb_execution_show_tb = True
# Any file a demo writes outside CONTACTFX_RESULTS lands in a temporary folder, not in docs/.
nb_execution_in_temp = True
nb_merge_streams = True

autodoc_member_order = "bysource"
autodoc_default_options = {"show-inheritance": True}
napoleon_google_docstring = True
napoleon_numpy_docstring = False
# Attributes as fields of the class: autodoc documents dataclass fields too, and
# `.. attribute::` entries from both would be duplicate descriptions.
napoleon_use_ivar = True

# --- demos: jupytext step -----------------------------------------------------------------

# First cell of every demo notebook, hidden on the page: the demo's own path (the scripts find
# their scene files next to themselves), a results folder of its own, and every PNG the demo
# writes (matplotlib charts and pyvista pictures alike) shown under the cell that wrote it.
_SETUP = """\
import os
import pathlib
import shutil

from IPython import get_ipython
from IPython.display import Image, display

__file__ = {script!r}
_results = pathlib.Path({results!r})
shutil.rmtree(_results, ignore_errors=True)
_results.mkdir(parents=True)
os.environ["CONTACTFX_RESULTS"] = str(_results)
_shown: set[pathlib.Path] = set()


def _show_new_figures() -> None:
    new = [p for p in _results.rglob("*.png") if p not in _shown]
    for p in sorted(new, key=lambda p: p.stat().st_mtime):
        _shown.add(p)
        display(Image(filename=str(p)))


get_ipython().events.register("post_execute", _show_new_figures)
"""


def write_demo_notebooks() -> None:
    """demos/demo_*.py -> docs/demos/demo_*.ipynb (unexecuted; myst-nb runs them)."""
    out = HERE / "demos"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    for script in sorted((ROOT / "demos").glob("demo_*.py")):
        nb = jupytext.reads(script.read_text(), fmt="py:light")
        setup = _SETUP.format(script=str(script), results=str(DEMO_RESULTS / script.stem))
        cell = jupytext.reads(setup, fmt="py:percent").cells[0]
        cell.metadata["tags"] = ["remove-cell"]
        nb.cells.insert(0, cell)
        nb.metadata["kernelspec"] = {
            "name": "python3",
            "display_name": "Python 3",
            "language": "python",
        }
        (out / f"{script.stem}.ipynb").write_text(jupytext.writes(nb, fmt="ipynb"))


# --- references ---------------------------------------------------------------------------


def write_scene_reference() -> None:
    """reference/scene_file.md from the scene-file schema."""
    text = "# Scene-file reference\n\n" + reference_markdown() + "\n"
    (HERE / "reference" / "scene_file.md").write_text(text)


def public_packages() -> list[str]:
    """Contactfx and every subpackage of it that declares `__all__`."""
    names = ["contactfx"]
    for info in pkgutil.iter_modules(contactfx.__path__, "contactfx."):
        if info.ispkg and hasattr(importlib.import_module(info.name), "__all__"):
            names.append(info.name)
    return names


def _directive(path: str, obj: object) -> str:
    """The autodoc directive of one exported name."""
    if inspect.isclass(obj):
        return f".. autoclass:: {path}\n   :members:\n\n"
    if callable(obj):
        return f".. autofunction:: {path}\n\n"
    return f".. py:data:: {path}\n\n" + "".join(f"   {line}\n" for line in _doc_comment(path))


def _doc_comment(path: str) -> list[str]:
    """The `#:` comment of re-exported data, read in the module that defines it.

    (autodata would read the comment in the exporting __init__.py only, and fall back to the
    docstring of the value's type, dict's for a dict.)
    """
    package, name = path.rsplit(".", 1)
    for module in [m for m in list(sys.modules) if m == package or m.startswith(package + ".")]:
        try:
            docs = ModuleAnalyzer.for_module(module).find_attr_docs()
        except PycodeError:
            continue
        if ("", name) in docs:
            return [*docs[("", name)], ""]
    return []


def write_api_pages() -> None:
    """reference/api/<package>.md: autodoc of the names in each package's `__all__`.

    An object exported by several packages (contactfx.Scene is contactfx.scenes.Scene) is
    documented once, on the first page that exports it; the later pages link to it.
    """
    out = HERE / "reference" / "api"
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir()
    documented: dict[int, str] = {}
    for package in public_packages():
        module = importlib.import_module(package)
        new, again = [], []
        for name in module.__all__:
            obj = getattr(module, name)
            key = id(obj)
            if key in documented and not isinstance(obj, str | int | float):
                again.append(f"- `{name}`: {{py:obj}}`{documented[key]}`")
            else:
                documented[key] = f"{package}.{name}"
                new.append(name)
        rst = f".. automodule:: {package}\n   :no-members:\n\n"
        rst += "".join(_directive(f"{package}.{name}", getattr(module, name)) for name in new)
        body = f"# `{package}`\n\n```{{eval-rst}}\n{rst}```\n"
        if again:
            body += "\nAlso exported here, documented where first exported:\n\n"
            body += "\n".join(again) + "\n"
        (out / f"{package}.md").write_text(body)


write_demo_notebooks()
write_scene_reference()
write_api_pages()
