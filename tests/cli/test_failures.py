"""Bad input and failure modes: a specific exception from the API, one stderr line from the CLI."""

from __future__ import annotations

import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import dolfinx_solver  # noqa: F401
import numpy as np
import pytest
from conftest import ENV, MPIRUN
from conftest import cli as run_in_process
from dolfinx import mesh as dmesh
from mpi4py import MPI

from contactfx.api import run_case
from contactfx.errors import (
    ActiveSetError,
    GeometryError,
    InputError,
    MeshError,
    SingularSystemError,
    SolverError,
)
from contactfx.methods.multipliers import solve_contact
from contactfx.methods.penalty import solve_penalty
from contactfx.options import SOLVERS, Method, SolverKind, SolverSpec
from contactfx.request import SolveRequest
from contactfx.scenes import BLOCK_SCENES, BlockParams, Groups, Scene, build_scene

COARSE = replace(BLOCK_SCENES["S4"], size1=0.5, size2=0.6)


def solvers():
    """Both solve entry points: the multiplier methods and the penalty baseline."""
    return [
        lambda s: solve_contact(s, SolveRequest.parse(Method.MORTAR)),
        lambda s: solve_penalty(s, SolveRequest.parse("penalty", penalty=1e7)),
    ]


def coarse_scene(params: BlockParams = COARSE) -> Scene:
    """A small S4-like scene on COMM_SELF (cheap to build, safe to modify)."""
    return build_scene("blocks", params, active=2, comm=MPI.COMM_SELF)


def with_groups(scene: Scene, **changes: tuple[int, int] | None) -> Scene:
    """The scene with physical groups replaced (a value) or removed (None)."""
    groups = {**scene.groups.by_name, **changes}
    return replace(scene, groups=Groups({k: v for k, v in groups.items() if v is not None}))


def shift_body(scene: Scene, body: int, dx: float, dy: float) -> None:
    """Move every geometry node of `body` rigidly (the bodies share no node)."""
    cells = scene.cell_tags.find(scene.groups.by_name[f"body{body}"][1])
    nodes = np.unique(scene.mesh.geometry.dofmaps[0][cells])
    scene.mesh.geometry.x[nodes, 0] += dx
    scene.mesh.geometry.x[nodes, 1] += dy


def cli(tmp_path: Path, *args: str, mpi: int = 0) -> tuple[int, list[str], Path]:
    """Run the CLI; return the exit code, the non-empty stderr lines and the JSON path.

    Serially in this process (main() is what turns an error into its line and exit code);
    with `mpi`, as docs/usage.md runs it, in fresh processes under mpirun.
    """
    out = tmp_path / "run.json"
    args = ("solve", *args, "--json", str(out), "-q")
    if mpi:
        # Every rank raises the same (collective) error and exits 2; under `-m mpi4py` a
        # non-zero exit would become an MPI_Abort with its own message.
        cmd = [MPIRUN, "-n", str(mpi), sys.executable, "-m", "contactfx", *args]
        res = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=300)
    else:
        res = run_in_process(*args)
    return res.returncode, [ln for ln in res.stderr.splitlines() if ln.strip()], out


def assert_clean_failure(tmp_path: Path, args: list[str], words: str, mpi: int = 0) -> str:
    """The CLI exits non-zero with exactly one 'contactfx: error:' line and writes no JSON."""
    rc, err, out = cli(tmp_path, *args, mpi=mpi)
    assert rc != 0
    assert len(err) == 1, err
    assert err[0].startswith("contactfx: error: "), err
    assert words in err[0], err
    assert not out.exists()
    assert not any(tmp_path.iterdir()), list(tmp_path.iterdir())  # no temp file either
    return err[0]


# ---------------------------------------------------------------- parameters (API)


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"nu1": 0.5}, "Poisson ratio"),
        ({"nu2": 0.7}, "Poisson ratio"),
        ({"nu1": -1.0}, "Poisson ratio"),
        ({"E1": 0.0}, "Young's modulus"),
        ({"E2": -7e4}, "Young's modulus"),
        ({"size1": 0.0}, "size1"),
        ({"size2": -0.1}, "size2"),
    ],
)
def test_bad_parameters_raise_input_error(change: dict, words: str) -> None:
    with pytest.raises(InputError, match=words):
        run_case(
            "blocks", replace(COARSE, **change), SolveRequest.parse("mortar"), comm=MPI.COMM_SELF
        )


def test_hertz_default_sizes_are_none_and_a_zero_asks_for_them_on_the_command_line() -> None:
    """r_refine and h_far default to None (1.4 a, R / 6); a 0 is refused from Python and, on
    the command line, still asks for the default."""
    from contactfx.cli.params import scene_params
    from contactfx.cli.parser import parser
    from contactfx.scenes import HertzParams
    from contactfx.scenes.builtin import validate

    assert (HertzParams().r_refine, HertzParams().h_far) == (None, None)
    for key in ("r_refine", "h_far"):
        with pytest.raises(InputError, match=f"{key} must be positive"):
            validate(replace(HertzParams(), **{key: 0.0}))
    zeros = parser().parse_args(["solve", "hertz", "--h-far", "0", "--r-refine", "0"])
    assert scene_params(zeros) == HertzParams()
    given = parser().parse_args(["solve", "hertz", "--h-far", "3", "--r-refine", "2"])
    assert scene_params(given) == HertzParams(h_far=3.0, r_refine=2.0)


def test_unknown_scene_raises_input_error() -> None:
    with pytest.raises(InputError, match="unknown scene 'cube'"):
        build_scene("cube", COARSE, comm=MPI.COMM_SELF)


# ---------------------------------------------------------------- meshes and tags (API)


@pytest.mark.parametrize("solve", solvers(), ids=["mortar", "penalty"])
def test_missing_contact_tag(solve) -> None:
    scene = coarse_scene()
    with pytest.raises(MeshError, match="no physical group 'contact2'"):
        solve(with_groups(scene, contact2=None))


@pytest.mark.parametrize("solve", solvers(), ids=["mortar", "penalty"])
def test_empty_contact_tag(solve) -> None:
    scene = coarse_scene()
    with pytest.raises(MeshError, match="'contact1' has no facet"):
        solve(with_groups(scene, contact1=(1, 9999)))


def test_triangle_mesh_is_refused() -> None:
    msh = dmesh.create_rectangle(
        MPI.COMM_SELF, [[0.0, 0.0], [1.0, 1.0]], [2, 2], dmesh.CellType.triangle
    )
    msh.topology.create_connectivity(1, 2)
    empty = np.zeros(0, dtype=np.int32)
    ct = dmesh.meshtags(msh, 2, empty, empty)
    ft = dmesh.meshtags(msh, 1, empty, empty)
    base = coarse_scene()
    scene = replace(base, mesh=msh, cell_tags=ct, facet_tags=ft)
    for solve in solvers():
        with pytest.raises(MeshError, match="all-quadrilateral mesh, got triangle cells"):
            solve(scene)


# ---------------------------------------------------------------- geometry (API)


@pytest.mark.parametrize("solve", solvers(), ids=["mortar", "penalty"])
def test_surfaces_not_facing(solve) -> None:
    # The top (load) face of B2 tagged as its contact face: its normal points away from B1.
    scene = coarse_scene()
    with pytest.raises(GeometryError, match=r"do not face each other.*angle of 0 degrees"):
        solve(with_groups(scene, contact2=scene.groups.by_name["load"]))


@pytest.mark.parametrize("solve", solvers(), ids=["mortar", "penalty"])
def test_surfaces_do_not_overlap(solve) -> None:
    scene = coarse_scene()
    shift_body(scene, 2, 20.0, 0.0)
    with pytest.raises(GeometryError, match="does not overlap"):
        solve(scene)


@pytest.mark.parametrize("solve", solvers(), ids=["mortar", "penalty"])
def test_initial_penetration(solve) -> None:
    scene = coarse_scene()
    shift_body(scene, 2, 0.0, -0.01)
    with pytest.raises(GeometryError, match=r"overlap: initial penetration 1\.000e-02 at"):
        solve(scene)


def test_penetration_within_tolerance_is_accepted() -> None:
    # A round-off-sized overlap (1e-9 of the element size) is a touching contact, not an error.
    scene = coarse_scene()
    shift_body(scene, 2, 0.0, -1e-9 * 0.5)
    sol = solve_contact(scene, SolveRequest.parse(Method.MORTAR))
    assert np.all(sol.active)


# ---------------------------------------------------------------- singular systems (API)


@pytest.mark.parametrize("method", ["mortar", "nts", "penalty"])
def test_body_pulled_off_is_singular(method: str) -> None:
    with pytest.raises(SingularSystemError, match="body 'body2' is not held by its supports"):
        run_case("blocks", replace(COARSE, p=-50.0), SolveRequest.parse(method), comm=MPI.COMM_SELF)


@pytest.mark.parametrize("solve", solvers(), ids=["mortar", "penalty"])
def test_no_support_at_all(solve) -> None:
    scene = coarse_scene()
    with pytest.raises(
        SingularSystemError, match=r"body 'body1' can still move freely.*translation along y"
    ):
        solve(with_groups(scene, support=(1, 9999)))


# ---------------------------------------------------------------- solvers (API)


def test_linear_solve_not_converging_reports_reason() -> None:
    few = ["ksp_max_it=5", "fieldsplit_lambda_ksp_max_it=1"]
    with pytest.raises(SolverError, match=r"reason -3 \(DIVERGED_MAX_IT\) after 5 iterations"):
        spec = SOLVERS["fieldsplit"].with_petsc(few)
        run_case("blocks", COARSE, SolveRequest.parse("mortar", solver=spec), comm=MPI.COMM_SELF)
    # Penalty factorizes: an iterative spec is refused when the request is made.
    plain = SolverSpec(SolverKind.CONDENSED, {"ksp_type": "gmres", "pc_type": "none"})
    with pytest.raises(InputError, match="no multiplier block"):
        run_case(
            "blocks",
            COARSE,
            SolveRequest.parse("penalty", solver=plain.with_petsc(few[:1])),
            comm=MPI.COMM_SELF,
        )


@pytest.mark.parametrize(("method", "solver"), [("mortar", "fieldsplit"), ("penalty", "mumps")])
def test_petsc_error_becomes_solver_error(method: str, solver: str) -> None:
    bogus = SOLVERS[solver].with_petsc(["ksp_type=bogus"])
    with pytest.raises(SolverError, match=r"PETSc error 86 .*Unable to find requested KSP type"):
        run_case("blocks", COARSE, SolveRequest.parse(method, solver=bogus), comm=MPI.COMM_SELF)


def test_petsc_options_cannot_change_the_solver_kind() -> None:
    """The kind is a value of the spec: options that contradict it are refused, not obeyed."""
    for name, item in [("mumps", "pc_type=fieldsplit"), ("condensed", "pc_type=fieldsplit")]:
        with pytest.raises(InputError, match="contradicts it"):
            SOLVERS[name].with_petsc([item])
    with pytest.raises(InputError, match="contradicts it"):
        SolverSpec(SolverKind.FIELDSPLIT, {"pc_type": "lu"})


def test_penalty_refuses_fieldsplit() -> None:
    with pytest.raises(InputError, match="no multiplier block"):
        run_case(
            "blocks", COARSE, SolveRequest.parse("penalty", solver="fieldsplit"), comm=MPI.COMM_SELF
        )


# Serial mortar with MUMPS converges in two steps (every row probed first), penalty in more.
@pytest.mark.parametrize(("method", "limit"), [("mortar", 1), ("penalty", 2)])
def test_active_set_iteration_limit(method: str, limit: int) -> None:
    from contactfx.scenes import HertzParams

    with pytest.raises(ActiveSetError, match=f"did not converge in {limit} iterations"):
        run_case(
            "hertz",
            HertzParams(refine=0.1),
            SolveRequest.parse(method, max_iterations=limit),
            comm=MPI.COMM_SELF,
        )


@pytest.mark.parametrize(
    "err", [InputError, MeshError, GeometryError, SingularSystemError, SolverError, ActiveSetError]
)
def test_cli_turns_every_error_type_into_one_line(err: type, monkeypatch, capsys) -> None:
    """Whatever contactfx error a run raises, main() prints one line and returns 2."""
    from contactfx import cli
    from contactfx.cli import solve as cli_solve

    def fail(args: object) -> int:
        raise err(f"{err.__name__} raised on purpose")

    monkeypatch.setattr(cli_solve, "run", fail)
    assert cli.main(["solve", "blocks"]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines == [f"contactfx: error: {err.__name__} raised on purpose"]


# ---------------------------------------------------------------- the CLI

S4 = ["blocks", "--preset", "S4", "--size1", "0.5", "--size2", "0.6"]


@pytest.mark.parametrize(
    ("args", "words"),
    [
        ([*S4, "--nu1", "0.5"], "Poisson ratio must lie in (-1, 0.5) (got nu = 0.5)"),
        ([*S4, "--nu2", "-1"], "Poisson ratio"),
        ([*S4, "--E2", "0"], "Young's modulus must be > 0"),
        ([*S4, "--size1", "0"], "size1 must be a positive number"),
        (["cube"], "unknown scene 'cube'"),
        ([*S4, "--p", "-50"], "body 'body2' is not held"),
        ([*S4, "--method", "penalty", "--p", "-50"], "body 'body2' is not held"),
        (
            [
                *S4,
                *("--method", "penalty", "--solver", "condensed"),
                *("--petsc-option", "pc_type=none", "--petsc-option", "ksp_max_it=5"),
            ],
            # Penalty factorizes: an iterative (condensed) solver is refused up front.
            "penalty method has no multiplier block",
        ),
        # A PETSc option cannot switch the solver's kind (it used to, silently).
        ([*S4, "--petsc-option", "pc_type=fieldsplit"], "pc_type=fieldsplit contradicts it"),
        (
            [
                *S4,
                "--solver",
                "fieldsplit",
                "--petsc-option",
                "ksp_max_it=1",
                "--petsc-option",
                "fieldsplit_lambda_ksp_max_it=1",
            ],
            "did not converge: PETSc reason",
        ),
        ([*S4, "--solver", "fieldsplit", "--petsc-option", "ksp_type=bogus"], "PETSc error 86"),
        ([*S4, "--method", "penalty", "--penalty", "-1"], "penalty parameter must be a positive"),
        ([*S4, "--penalty", "1e6"], "--penalty applies to --method penalty only"),
        (["hertz", "--refine", "0.1", "--max-iterations", "1"], "did not converge in 1 iterations"),
    ],
)
def test_cli_one_line_no_json(tmp_path: Path, args: list[str], words: str) -> None:
    assert_clean_failure(tmp_path, args, words)


@pytest.mark.mpi
def test_cli_failure_under_mpi(tmp_path: Path) -> None:
    line = assert_clean_failure(tmp_path, [*S4, "--p", "-50"], "body 'body2' is not held", mpi=2)
    assert "SingularSystemError" not in line


@pytest.mark.mpi
def test_cli_failure_inside_the_solve_under_mpi(tmp_path: Path) -> None:
    """Raised on every rank inside the active-set loop, where the solver's PETSc objects are
    left to the traceback under mpirun (methods/cleanup.py): freed alike on every rank."""
    args = ["hertz", "--refine", "0.1", "--max-iterations", "1"]
    assert_clean_failure(tmp_path, args, "did not converge in 1 iterations", mpi=2)


def test_cli_success_writes_json(tmp_path: Path) -> None:
    # The counterpart: the same command line with a valid pressure writes its JSON.
    rc, err, out = cli(tmp_path, *S4, "--method", "penalty")
    assert rc == 0, err
    assert out.exists()


# ---------------------------------------------------------------- an error on one rank only

FAIL_ON_RANK = Path(__file__).with_name("fail_on_rank.py")


@pytest.mark.mpi
@pytest.mark.parametrize(
    ("stage", "rank", "kind"),
    [
        ("parsing", 1, "input"),
        ("meshing", 1, "internal"),
        ("assembly", 1, "input"),
        ("solve", 1, "input"),
        ("writing", 1, "internal"),
    ],
)
def test_an_error_on_one_rank_ends_every_rank(
    tmp_path: Path, stage: str, rank: int, kind: str
) -> None:
    """An exception on rank 1 only, while rank 0 goes on into a collective: every rank ends
    within seconds of the raise, exit 2, one message (with the failing rank), no JSON. It
    hung until killed: the other rank waited in its collective, the failing one in MPI's
    finalize or in the collective destroy of the solver."""
    import time

    raised, out = tmp_path / "raised", tmp_path / "run.json"
    cmd = [MPIRUN, "-n", "2", sys.executable, str(FAIL_ON_RANK), stage, str(rank), kind]
    args = ["solve", *S4, "--json", str(out), "--out", str(tmp_path / "out"), "-q"]
    res = subprocess.run(
        [*cmd, str(raised), "--", *args], capture_output=True, text=True, env=ENV, timeout=120
    )
    ended = time.time()
    assert res.returncode == 2, res.stdout[-2000:] + res.stderr[-2000:]
    assert ended - float(raised.read_text()) < 15.0
    lines = [ln for ln in res.stderr.splitlines() if ln.startswith("contactfx: ")]
    assert len(lines) == 1, res.stderr
    assert f"raised on purpose at {stage}" in lines[0] and f"on rank {rank} of 2" in lines[0]
    assert "MPI_Abort" not in res.stderr + res.stdout
    if kind == "input":
        assert lines[0].startswith("contactfx: error: ") and "Traceback" not in res.stderr
    else:  # a bug: the traceback once, then the line
        assert res.stderr.count("Traceback") == 1 and "internal error: RuntimeError" in lines[0]
    assert not out.exists()


@pytest.mark.parametrize(("option", "inside"), [("--out", ""), ("--json", ""), ("--json", "x")])
def test_an_output_path_of_the_wrong_kind_is_refused_before_the_solve(
    tmp_path: Path, option: str, inside: str
) -> None:
    """--out naming an existing file (a FileExistsError traceback after the whole solve),
    --json naming a directory or a path under a file: one line, exit 2, before anything
    runs, the path untouched."""
    target = tmp_path / "taken"
    if option == "--out" or inside:
        target.write_text("keep me")
    else:
        target.mkdir()
    res = run_in_process("solve", *S4, option, str(target / inside if inside else target))
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert res.returncode == 2 and len(lines) == 1, res.stderr
    assert lines[0].startswith(f"contactfx: error: {option} {target}"), lines
    assert res.stdout == ""  # nothing meshed nor solved
    assert target.read_text() == "keep me" if option == "--out" or inside else target.is_dir()


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["solve", *S4, "--goal", "energy"], "--goal energy applies with --estimate only"),
        (["study", *S4, "--goal", "force", "--out", "s"], "--goal applies to study --adaptive"),
    ],
)
def test_a_goal_without_its_estimate_is_refused(
    tmp_path: Path, args: list[str], words: str
) -> None:
    """`solve --goal energy` without --estimate was silently ignored (a run that seemed to
    estimate the energy error and did not): refused, one line, before anything runs."""
    res = run_in_process(*args, cwd=tmp_path)
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert res.returncode == 2 and len(lines) == 1 and words in lines[0], res.stderr
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize(
    ("err", "last"),
    [
        (PermissionError(13, "Permission denied", "/x/r.json"), "/x/r.json: Permission denied"),
        (RuntimeError("a bug"), "internal error: RuntimeError: a bug (a bug in contactfx"),
    ],
)
def test_cli_ends_any_exception_with_exit_2(err: Exception, last: str, monkeypatch, capsys) -> None:
    """A file the system refuses is one line; a bug keeps its traceback, then one line; both
    exit 2 (a bug's traceback ended the process with exit 1, and under mpirun hung it)."""
    from contactfx import cli
    from contactfx.cli import solve as cli_solve

    def fail(args: object) -> int:
        raise err

    monkeypatch.setattr(cli_solve, "run", fail)
    assert cli.main(["solve", "blocks"]) == 2
    text = capsys.readouterr().err
    lines = text.strip().splitlines()
    assert lines[-1].startswith("contactfx: ") and last in lines[-1], text
    assert ("Traceback" in text) == isinstance(err, RuntimeError)
    assert len(lines) == 1 or isinstance(err, RuntimeError)
