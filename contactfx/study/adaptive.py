"""`study --adaptive`: the adaptive loop beside the uniform levels, on the same charts.

After the uniform study, each method (but schwarz, which has no estimate) runs the adaptive
loop (adapt/loop.py, no tolerance) from level 0's mesh, up to the DOFs of that method's
finest uniform level. Each adaptive level is measured like a uniform run: against the exact solution
(Hertz, patch test) or, without one, against the study's self-convergence reference (the
finest uniform level of the most accurate method). Its time on the charts is cumulative:
the meshing of level 0, then the solves, estimates and remeshings of all the levels up to it
(as the uniform runs' time includes their meshing), since a level cannot be had without the
ones before it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ..adapt.goal import Goal
from ..adapt.loop import adapt
from ..adapt.records import AdaptLevel, AdaptOptions
from ..options import Enforcement
from ..request import SolveRequest
from ..scenes import Scene
from .core import Study, exact_errors, self_reference
from .measures import contact_size, profiles
from .measures import self_errors as compare_profiles
from .runs import AdaptiveRun, Run

# The residual goal's cells per level at most x 2 (adapt's default is x 4): gmsh makes
# meshes finer than planned on coarse levels (vertex sizes are the smallest of the cells
# around), and a study's DOF range is one or two decades, which x 4 steps would cross in one
# or two levels.
GROWTH = 2.0


def adaptive_requests(requests: Sequence[SolveRequest]) -> list[SolveRequest]:
    """The requests whose solutions have an error estimate (all but schwarz's)."""
    return [r for r in requests if r.enforcement is not Enforcement.SCHWARZ]


def budget(study: Study, method: str) -> int | None:
    """DOFs of the method's finest finished uniform level (None if none finished)."""
    dofs = [r.dofs for r in study.runs if r.method == method and r.ok and r.dofs]
    return max(dofs) if dofs else None


def _errors(study: Study, level: AdaptLevel, ref: Run | None) -> dict[str, float | None]:
    """The level's errors, measured as the study measures its uniform runs."""
    if study.reference["kind"] == "exact":
        kind = {"hertz": "hertz", "cattaneo": "cattaneo"}.get(study.reference["type"], "patch")
        return exact_errors(kind, level.summary)
    if ref is None or ref.profiles is None:
        return {}
    return compare_profiles(profiles(level.solution, level.summary), ref.profiles)


def _prefixed(say: Callable[[str], None] | None, prefix: str) -> Callable[[str], None] | None:
    """`say` with every line prefixed (None stays None: the loop's own rank-0 print)."""
    if say is None:
        return None
    speak = say
    return lambda line: speak(prefix + line)


def level0_mesh(study: Study) -> float:
    """The meshing time of the study's level 0 (the adaptive loop's first mesh)."""
    return next((r.times["mesh"] for r in study.runs if r.level == 0 and "mesh" in r.times), 0.0)


def adaptive_runs(
    study: Study,
    scene: Scene,
    requests: Sequence[SolveRequest],
    *,
    paper_interface: bool = False,
    max_levels: int = 12,
    growth: float = GROWTH,
    pressure_tol: float | None = None,
    goal: Goal = Goal.PRESSURE,
    say: Callable[[str], None] | None = None,
) -> list[AdaptiveRun]:
    """Run the adaptive loop of every request from `scene` (level 0) and measure its levels.

    `requests` are the study's (those it ran, by label; schwarz's are skipped). The loop has
    no tolerance: each method's budget is its finest uniform level's DOFs.

    `goal`: a goal estimate's (adapt/planned.py: its estimate per level, its planned growth
    up to the budget), or Goal.RESIDUAL (growth `growth`; with `pressure_tol` the contact
    cells are sized for the pressure too, as adapt's).
    """
    residual = goal is Goal.RESIDUAL
    ref = self_reference(study.runs, study.methods) if study.reference["kind"] == "self" else None
    out: list[AdaptiveRun] = []
    for request in adaptive_requests(requests):
        m = request.label
        cap = budget(study, m) if m in study.methods else None
        if cap is None:
            continue
        opts = AdaptOptions(
            goal, None, cap, max_levels, growth if residual else None, None, pressure_tol, None
        )
        result = adapt(
            scene,
            request,
            opts,
            paper_interface=paper_interface,
            say=_prefixed(say, f"adaptive {m}: "),
            mesh_time=level0_mesh(study),
        )
        cumulative = 0.0
        for lv in result.levels:
            cumulative += lv.time
            run = lv.summary
            out.append(
                AdaptiveRun(
                    m,
                    lv.index,
                    lv.dofs,
                    run.elements,
                    contact_size(run),
                    run.iterations,
                    float(run.times["total"]),
                    lv.time,
                    cumulative,
                    float(lv.relative),
                    _errors(study, lv, ref),
                    result.stop,
                )
            )
        del result
    return out
