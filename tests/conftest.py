"""Shared helpers: run the CLI or a script under mpirun -n 2 as a user would, the one
mpirun -n 2 launch of the rank-comparison cases (tests/ranks/rank_cases.py,
tests/ranks/test_ranks.py), and a solver on a contact setup (solver_for).

The tests are laid out like the package: tests/<stage>/ holds the tests of contactfx/<stage>/
(contact, scenes, meshes, linalg, methods, results, adapt, study, cli), tests/ranks/ the
1-rank vs 2-rank comparisons and tests/demos/ the demos and the examples of the README and
docs/. Every test file has a unique basename (no __init__.py: pytest puts each file's folder
on sys.path, and this folder, so `from conftest import ...` works from any of them).
Constants shared by several test files live here, never in a test module another one
imports.

The rule for expected values: a deterministic number (same mesh, same solver) is pinned as a
golden value at rel 1e-3 with its provenance (analytic, an independent computation, or a
labelled regression lock saying how to refresh it); bands only where the number is not
deterministic (timings, iteration counts across platforms, a bound that holds for every mesh
of a family). A regression lock is refreshed by printing the value in the test after an
intended change to the mesh or the method, and the commit says why it moved.
"""

from __future__ import annotations

import contextlib
import io
import logging
import os
import subprocess
import sys
from collections.abc import Callable
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from contactfx.contact import Surface
from contactfx.discretize.setup import ContactSetup
from contactfx.linalg.protocol import LinearSolver
from contactfx.methods.solvers import setup_solver
from contactfx.options import SOLVERS, Method, SolverSpec
from contactfx.scenes import Scene

ROOT = Path(__file__).resolve().parents[1]
MPIRUN = str(Path(sys.executable).parent / "mpirun")
ENV = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Every test that launches no mpirun runs in this process on one rank: mark it serial."""
    for item in items:
        if item.get_closest_marker("mpi") is None and item.get_closest_marker("serial") is None:
            item.add_marker(pytest.mark.serial)


def run_cli(
    *args: str, cwd: Path | None = None, ranks: int = 1, timeout: float = 300
) -> subprocess.CompletedProcess[str]:
    """Run `python -m contactfx ...` (optionally under mpirun) and capture its output."""
    cmd = [sys.executable, "-m", "contactfx", *args]
    if ranks > 1:
        cmd = [MPIRUN, "-n", str(ranks), *cmd]
    return subprocess.run(
        cmd, cwd=cwd or ROOT, env=ENV, capture_output=True, text=True, timeout=timeout
    )


def cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """Run `contactfx ...` in this process: its exit code, stdout (the log) and stderr.

    For checks of what the CLI computes and writes. The exit-code and one-line-error contract
    of a fresh process is tested with run_cli.
    """
    from contactfx.cli import main

    out, err = io.StringIO(), io.StringIO()
    root = logging.getLogger()
    saved = root.handlers[:]
    root.handlers.clear()  # main() configures logging onto the captured stdout
    try:
        with contextlib.chdir(cwd or ROOT), redirect_stdout(out), redirect_stderr(err):
            try:
                code = main(list(args))
            except SystemExit as exc:  # argparse's usage errors
                code = int(exc.code or 0)
    finally:
        for handler in root.handlers:
            handler.flush()
        root.handlers[:] = saved
    return subprocess.CompletedProcess(["contactfx", *args], code, out.getvalue(), err.getvalue())


def run_mpi_script(
    script: Path, *args: str, ranks: int = 2, timeout: float = 300
) -> subprocess.CompletedProcess[str]:
    """Run a python script under mpirun with mpi4py's abort-on-exception wrapper."""
    cmd = [MPIRUN, "-n", str(ranks), sys.executable, "-m", "mpi4py", str(script), *args]
    proc = subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=timeout)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return proc


RANK_CASES = ROOT / "tests" / "ranks" / "rank_cases.py"


class _NoMpirun(subprocess.Popen):
    """Popen that refuses mpirun: for tests without the mpi marker."""

    def __init__(self, args, *rest, **kwargs) -> None:
        first = args[0] if isinstance(args, list | tuple) else str(args).split()[0]
        if Path(str(first)).name in ("mpirun", "mpiexec"):
            raise AssertionError("this test launches mpirun: mark it @pytest.mark.mpi")
        super().__init__(args, *rest, **kwargs)


@pytest.fixture(autouse=True)
def _mpirun_only_under_the_mpi_marker(
    request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch
) -> None:
    """`pytest -m "not mpi"` launches no mpirun: an unmarked test that tries fails."""
    if request.node.get_closest_marker("mpi") is None:
        monkeypatch.setattr(subprocess, "Popen", _NoMpirun)


@pytest.fixture(scope="session")
def two_rank_results(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Callable[[str], dict[str, np.ndarray]]:
    """One mpirun -n 2 of tests/ranks/rank_cases.py for every case the selected tests compare.

    Returns case -> its 2-rank arrays; a case the run did not write fails with the run's
    output (the run aborts at the first failing case: mpi4py -m).
    """
    names = sorted(
        {
            str(item.callspec.params["case"])
            for item in request.session.items
            if "two_rank_results" in getattr(item, "fixturenames", ())
            and hasattr(item, "callspec")
            and "case" in item.callspec.params
        }
    )
    outdir = tmp_path_factory.mktemp("two_ranks")
    cmd = [MPIRUN, "-n", "2", sys.executable, "-m", "mpi4py", str(RANK_CASES), str(outdir)]
    proc = subprocess.run(
        [*cmd, *names], cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=1800
    )
    log = f"exit {proc.returncode}\n{proc.stdout[-3000:]}{proc.stderr[-3000:]}"

    def load(name: str) -> dict[str, np.ndarray]:
        path = outdir / f"{name}.npz"
        assert path.exists(), f"mpirun -n 2 rank_cases.py wrote no {name}: {log}"
        with np.load(path) as data:
            return {k: data[k] for k in data.files}

    return load


# The coarse graded Hertz scene the adaptive-loop tests start from (tests/adapt/).
COARSE_HERTZ = ("hertz", "--refine", "2", "--h-far", "2", "--refine-edge", "0", "--slope", "0.3")

# The multiplier methods (one saddle-point discretization each): most tests run all three.
MULTIPLIER_METHODS = (Method.NTS, Method.STS, Method.MORTAR)


@pytest.fixture(params=MULTIPLIER_METHODS, ids=[m.value for m in MULTIPLIER_METHODS])
def multiplier_method(request: pytest.FixtureRequest) -> str:
    """Each multiplier method in turn (its name, as the API and the CLI take it)."""
    return str(request.param.value)


@pytest.fixture
def mpi_script():
    """The run_mpi_script helper as a fixture."""
    return run_mpi_script


def make_surface(pts: np.ndarray, ref: np.ndarray, dof0: int) -> Surface:
    """Polyline through pts; each segment normal is the perpendicular with n . ref > 0."""
    pts = np.asarray(pts, dtype=float)
    n = len(pts)
    seg = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    t = pts[seg[:, 1]] - pts[seg[:, 0]]
    nrm = np.column_stack([-t[:, 1], t[:, 0]]) / np.linalg.norm(t, axis=1)[:, None]
    nrm *= np.sign(np.einsum("md,md->m", nrm, np.broadcast_to(ref, nrm.shape)))[:, None]
    return Surface(pts, seg, nrm, dof0 + 2 * np.arange(n)[:, None] + np.arange(2))


def polyline(x: np.ndarray, y: np.ndarray, normal_up: bool, dof0: int) -> Surface:
    """Surface through (x, y) in order; normals point to +y (lower body) or -y (upper body)."""
    up = np.array([0.0, 1.0 if normal_up else -1.0])
    return make_surface(np.column_stack([x, y]), up, dof0)


def reshuffled(s: Surface, seed: int) -> Surface:
    """The same surface with every segment reversed and the segment order permuted."""
    perm = np.random.default_rng(seed).permutation(s.n_segments)
    return Surface(s.x, s.segments[perm, ::-1], s.normals[perm], s.dofs)


def renumbered(s: Surface, order: np.ndarray) -> Surface:
    """The same surface with its nodes renumbered: new node i is old node order[i]."""
    new = np.empty_like(order)
    new[order] = np.arange(len(order))
    return Surface(s.x[order], new[s.segments], s.normals, s.dofs[order])


def solver_for(
    setup: ContactSetup, spec: SolverSpec | str, scene: Scene, *, reuse: bool = True
) -> LinearSolver:
    """The solver the active-set loop builds on `setup` (methods/multipliers.py): `spec` is a
    SolverSpec or a name of SOLVERS; the rigid-body modes of `scene` for GAMG."""
    return setup_solver(setup, SOLVERS[spec] if isinstance(spec, str) else spec, scene, reuse=reuse)
