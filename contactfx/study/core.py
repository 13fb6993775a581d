"""Run a study: every method on every level, errors against the reference, fitted rates.

Levels run coarsest first, all methods on each level's mesh (meshed once, its time counted
in every run's times.mesh), so an interrupted study has every method on the coarse levels.
A run that raises a ContactFxError (a bad level, a solver that gives up) is recorded as
failed and the study goes on; other exceptions are bugs and propagate.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from mpi4py import MPI

from ..api import as_request, run_scene
from ..errors import ContactFxError, InputError
from ..options import Method
from ..request import SolveRequest
from ..results.records import RunSummary
from ..scenes import CattaneoReference, HertzReference, Reference, Scene, UniformStress
from ..timers import Timers
from .levels import Level
from .measures import (
    ROUND_OFF,
    cattaneo_study_errors,
    contact_size,
    fit_rate,
    hertz_errors,
    patch_error,
    profiles,
)
from .measures import self_errors as compare_profiles
from .progress import Progress
from .runs import Run, Study

# Most accurate first: the self-convergence reference is the finest level of the first of
# these that the study ran (mortar passes the patch test on non-matching meshes).
ACCURACY_ORDER = ("mortar", "sts", "nts", "penalty", "schwarz")


def reference_kind(scene: Scene) -> str:
    """The kind of reference: cattaneo, hertz, patch (uniform stress) or self (the finest level).

    A frictional scene's Cattaneo reference comes first: its Hertz pressure is part of it.
    """
    if any(isinstance(r, CattaneoReference) for r in scene.references):
        return "cattaneo"
    if any(isinstance(r, HertzReference) for r in scene.references):
        return "hertz"
    if any(isinstance(r, UniformStress) for r in scene.references):
        return "patch"
    return "self"


def exact_errors(kind: str, summary: RunSummary) -> dict[str, float | None]:
    """Errors of one run against the scene's exact solution."""
    if kind == "cattaneo":
        return cattaneo_study_errors(summary)
    return hertz_errors(summary) if kind == "hertz" else patch_error(summary)


def solve_one(
    scene: Scene, request: SolveRequest, level: Level, mesh_time: float, kind: str
) -> Run:
    """Solve one level as `request` asks; a ContactFxError makes a failed Run."""
    run = Run(request.label, level.index, level.factor)
    t0 = time.perf_counter()
    try:
        sol, record = run_scene(
            scene,
            request,
            t_start=t0,
            timers=Timers(),
            paper_interface=level.paper_interface,
        )
    except ContactFxError as err:
        run.status, run.message = "failed", f"{type(err).__name__}: {err}"
        return run
    times = dict(record.times)
    times["mesh"] = mesh_time
    times["total"] += mesh_time
    run.dofs, run.elements, run.iterations = record.dofs, record.elements, record.iterations
    run.times, run.summary, run.h = times, record, contact_size(record)
    run.forces = [list(c.components) for c in record.contacts]
    if kind == "self":
        run.profiles = profiles(sol, record)
    else:
        run.errors = exact_errors(kind, record)
    return run


def failed_level(method: str, level: Level, err: ContactFxError) -> Run:
    """The run of a level whose mesh could not be built."""
    return Run(
        method,
        level.index,
        level.factor,
        status="failed",
        message=f"{type(err).__name__} (meshing): {err}",
    )


def self_reference(runs: list[Run], methods: list[str]) -> Run | None:
    """The finest finished run of the most accurate method (mortar first)."""
    order = [m for m in ACCURACY_ORDER if m in methods] + [
        m for m in methods if m not in ACCURACY_ORDER
    ]
    for method in order:
        done = [r for r in runs if r.method == method and r.ok]
        if done:
            return max(done, key=lambda r: r.level)
    return None


def hertz_window(references: tuple[Reference, ...]) -> str:
    """The interval the Hertz L2 error is taken over, as the scene's references say."""
    refs = [r for r in references if isinstance(r, HertzReference)]
    windows = sorted(
        {"[0, 1.5 a] (half model)" if r.symmetric else "[-1.5 a, 1.5 a] (full model)" for r in refs}
    )
    return " and ".join(windows) or "[0, 1.5 a]"


def hertz_reference_block(runs: list[Run], references: tuple[Reference, ...]) -> dict[str, Any]:
    """The study's `reference` block for Hertz, as the runs' records describe it.

    Hertz is the scene's analytic reference but not its exact solution (a half-space
    theory): `exact` is False, `validity` says how far the scene is from the theory (a / R_min
    of the finest run), and the errors and rates include that model error.
    """
    records = [r.summary.hertz[0] for r in runs if r.ok and r.summary and r.summary.hertz]
    what = records[-1].description if records else "Hertz contact"
    window = records[-1].window if records else hertz_window(references)
    return {
        "kind": "exact",
        "type": "hertz",
        "description": f"{what}: half-width a, peak pressure p0, relative L2 error of the "
        f"pressure over {window}",
        "exact": False,
        "validity": records[-1].validity if records else "approximate: half-space theory",
    }


def apply_reference(
    kind: str, runs: list[Run], methods: list[str], references: tuple[Reference, ...] = ()
) -> dict[str, Any]:
    """Fill in the self-convergence errors; return the report's `reference` block.

    `references`: the scene's, for what the description says (the Hertz window) where no
    run finished. `kind` "exact" means the errors are against an analytic solution; the
    block's `exact` says whether that solution is the scene's own (False: Hertz).
    """
    if kind == "hertz":
        return hertz_reference_block(runs, references)
    if kind == "cattaneo":
        return {
            "kind": "exact",
            "type": "cattaneo",
            "description": "Cattaneo-Mindlin line contact (similar materials) under each "
            "run's own forces P and Q, the last load step: relative L2 error of the shear "
            "(shear) and relative error of the stick half-width read from the statuses (stick)",
            "exact": False,
            "validity": "approximate: half-space theory, and a slip-free approach "
            "(the runs' `cattaneo` warnings say where it slipped)",
        }
    if kind == "patch":
        return {
            "kind": "exact",
            "type": "uniform_stress",
            "description": "uniform stress of the patch test: max error of the stresses "
            "and pressures relative to the largest exact stress component",
            "exact": True,
            "validity": "exact: the patch test's uniform stress is the scene's solution",
        }
    ref = self_reference(runs, methods)
    if ref is not None:
        for r in runs:
            if r.ok and r is not ref and r.profiles is not None:
                r.errors = compare_profiles(r.profiles, ref.profiles)  # type: ignore[arg-type]
    for m in methods:
        done = {r.level: r for r in runs if r.method == m and r.ok and r.profiles is not None}
        for k, r in done.items():
            if k + 1 in done:
                r.successive = compare_profiles(r.profiles, done[k + 1].profiles)  # type: ignore[arg-type]
    return {
        "kind": "self",
        "type": "finest level",
        "method": ref.method if ref else None,
        "level": ref.level if ref else None,
        "h": ref.h if ref else None,
        "rates": "log-log slope of the differences between successive levels of each "
        "method (|u_k - u_k+1| ~ C h_k^r), against h_k",
        "description": "no exact solution: the finest level of the most accurate method; "
        "relative L2 differences in arc length along every contact surface of the "
        "pressure and of the displacement (both sides)",
    }


def series(
    runs: list[Run], method: str, name: str, against: str, kind: str
) -> tuple[np.ndarray, np.ndarray]:
    """The (x, value) points a rate is fitted to and a chart draws, coarse to fine.

    x is h ("h") or the run's whole wall time, meshing included ("time": a fine level's
    meshing is most of its cost). The value is the error against the
    exact solution, or (self-convergence, `kind` "self") the difference from the same
    method's next finer level: the finest level is the reference and has none, and the
    differences of successive levels fall like h^r for any r, with no model of the
    reference's own error.
    """
    pts = []
    for r in runs:
        if r.method != method or not r.ok:
            continue
        x = r.h if against == "h" else r.times.get("total")
        e = (r.successive if kind == "self" else r.errors).get(name)
        if x and e is not None and e > 0:
            pts.append((r.level, x, e))
    pts.sort()
    return np.array([p[1] for p in pts]), np.array([p[2] for p in pts])


def monotone(errors: np.ndarray) -> bool:
    """Whether errors (coarse to fine) above round-off fall at every level."""
    e = errors[errors > ROUND_OFF]
    return bool(np.all(np.diff(e) < 0.0))


def fit_rates(
    runs: list[Run], methods: list[str], names: list[str], against: str, reference: dict[str, Any]
) -> tuple[dict[str, dict[str, float | None]], dict[str, dict[str, str]]]:
    """Fitted rates of each error against h ("h") or the wall time with meshing ("time").

    The log-log slope of `series`; returns (rates, flags), flags naming the non-monotone
    series (the slope is reported but is not a convergence rate).
    """
    kind = "self" if reference["kind"] == "self" else "exact"
    rates: dict[str, dict[str, float | None]] = {}
    flags: dict[str, dict[str, str]] = {}
    for m in methods:
        rates[m], flags[m] = {}, {}
        for n in names:
            xs, errs = series(runs, m, n, against, kind)
            rates[m][n] = fit_rate(xs, errs)
            if rates[m][n] is not None and not monotone(errs):
                flags[m][n] = "non-monotone"
    return rates, flags


def run_study(
    levels: list[Level],
    requests: Sequence[SolveRequest | Method | str],
    *,
    ratio: float = 2.0,
    comm: MPI.Comm = MPI.COMM_WORLD,
    say: Callable[[str], None] | None = None,
    settings: dict[str, Any] | None = None,
) -> Study:
    """Run every request on every level (coarsest first) and measure them against the reference.

    A method's name stands for its request with the defaults; each run is labelled by its
    request's `label` (the method's name). `say` prints progress (rank 0).
    """
    asked = [as_request(r) for r in requests]
    methods = [r.label for r in asked]
    if len(set(methods)) != len(methods):
        raise InputError(f"the study lists a method twice: {', '.join(methods)}")
    say = say or (lambda line: print(line, flush=True) if comm.rank == 0 else None)
    progress = Progress(methods, len(levels), ratio, say)
    runs: list[Run] = []
    kind, name = None, "scene"
    references: tuple[Reference, ...] = ()  # the scene's (the same on every level)
    for level in levels:
        progress.meshing(level)
        t0 = time.perf_counter()
        try:
            scene = level.build()
        except ContactFxError as err:
            for m in methods:
                runs.append(failed_level(m, level, err))
                progress.finished(runs[-1], None)
            continue
        mesh_time = time.perf_counter() - t0
        kind, name = kind or reference_kind(scene), scene.name
        references = references or scene.references
        for k, request in enumerate(asked):
            runs.append(solve_one(scene, request, level, mesh_time, kind))
            progress.finished(runs[-1], mesh_time if k == 0 else None)
        del scene
    reference = apply_reference(kind or "self", runs, methods, references)
    names = list(dict.fromkeys(n for r in runs for n in r.errors))
    rates, flags = fit_rates(runs, methods, names, "h", reference)
    time_rates, _ = fit_rates(runs, methods, names, "time", reference)
    return Study(
        name,
        methods,
        levels,
        runs,
        reference,
        names,
        rates,
        time_rates,
        time.perf_counter() - progress.t0,
        comm.size,
        dict(settings or {}),
        flags,
    )
