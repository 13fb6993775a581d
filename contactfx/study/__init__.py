"""Convergence studies: every method on a sequence of refined meshes of one scene.

`python -m contactfx study SCENE ...` (contactfx/cli/study.py) and demos/demo_hertz.py are
thin layers over `run_study` and `write_outputs`; docs/study.md says what is measured.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from .core import Study, run_study
from .levels import Level, builtin_levels, hertz_at, scene_file_levels, size_factors
from .measures import fit_rate
from .report import level_lines, table_lines, write_study_csv, write_study_json
from .runs import Run

__all__ = [
    "Level",
    "Run",
    "Study",
    "builtin_levels",
    "fit_rate",
    "hertz_at",
    "level_lines",
    "run_study",
    "scene_file_levels",
    "size_factors",
    "table_lines",
    "write_outputs",
]


def write_outputs(study: Study, out: Path, extra: Sequence[tuple[str, Study]] = ()) -> list[Path]:
    """study.json, study.csv, convergence.png and accuracy_vs_time.png in `out` (rank 0 only).

    With adaptive levels (study --adaptive) also accuracy_vs_dofs.png.

    `extra`: (label, study) pairs the charts also draw, dashed (e.g. another mesh family).
    """
    from .charts import plot_convergence, plot_dofs, plot_time

    out.mkdir(parents=True, exist_ok=True)
    written = [
        write_study_json(study, out / "study.json"),
        write_study_csv(study, out / "study.csv"),
        plot_convergence(study, out / "convergence.png", extra),
        plot_time(study, out / "accuracy_vs_time.png", extra),
    ]
    if study.adaptive:
        written.append(plot_dofs(study, out / "accuracy_vs_dofs.png"))
    return written
