"""The solve request: one validated record, two axes (discretization x enforcement).

Penalty on every discretization (its patch test and its O(1/eps) distance to the multiplier
solution), the impossible combinations refused when the request is made, the CLI's alias
table and --enforcement, and the Schur preconditioner as a typed field of the solver spec.
"""

from __future__ import annotations

import itertools
import json
import subprocess
from dataclasses import replace
from pathlib import Path

import dolfinx_solver  # noqa: F401
import numpy as np
import pytest
from conftest import cli
from mpi4py import MPI

from contactfx import solve
from contactfx.api import run_case, run_scene
from contactfx.contact import Kernel
from contactfx.errors import InputError
from contactfx.options import (
    SCHUR_KEY,
    SOLVERS,
    Basis,
    Discretization,
    Enforcement,
    Method,
    SchurPre,
    SolverKind,
    SolverSpec,
)
from contactfx.request import SchwarzOptions, SolveRequest
from contactfx.results.paper import patch_errors
from contactfx.scenes import BLOCK_SCENES, HertzParams, build_scene

# The patch test of S4 on matching meshes: NTS and STS pass it only there.
MATCHING = replace(BLOCK_SCENES["S4"], size1=0.4, size2=0.4, grading1=1.0, grading2=1.0)
HERTZ = HertzParams(refine=0.1)


@pytest.mark.parametrize("discretization", ["nts", "sts"])
def test_penalty_on_nts_and_sts_passes_the_patch_test(discretization: str) -> None:
    """Uniform pressure p carried with the uniform penetration p / eps, as on mortar."""
    eps, p = 1e7, MATCHING.p
    sol, run = run_case(
        "blocks",
        MATCHING,
        SolveRequest.parse(discretization, enforcement="penalty", penalty=eps),
        comm=MPI.COMM_SELF,
    )
    data = run.to_json()
    assert (data["method"], data["discretization"], data["enforcement"]) == (
        "penalty",
        discretization,
        "penalty",
    )
    assert patch_errors(data["interface"], p)["pressure"] < 1e-9
    assert np.allclose(sol.gap, -p / eps, rtol=1e-8, atol=0)
    assert data["penetration"] == pytest.approx(p / eps, rel=1e-8)


@pytest.mark.parametrize("discretization", ["nts", "sts"])
def test_penalty_on_nts_and_sts_converges_to_the_multipliers_like_one_over_eps(
    discretization: str,
) -> None:
    """Ten times eps, a tenth of the distance to the same discretization's multipliers."""
    ref, _ = run_case("hertz", HERTZ, SolveRequest.parse(discretization), comm=MPI.COMM_SELF)
    diffs = []
    for eps in (1e7, 1e8, 1e9):
        sol, _ = run_case(
            "hertz",
            HERTZ,
            SolveRequest.parse(discretization, enforcement="penalty", penalty=eps),
            comm=MPI.COMM_SELF,
        )
        assert np.array_equal(sol.active, ref.active)
        diffs.append(np.max(np.abs(sol.pressure - ref.pressure)) / np.max(ref.pressure))
    for coarse, fine in itertools.pairwise(diffs):
        assert 8.0 < coarse / fine < 12.0, diffs


CONDENSED = SOLVERS["condensed"]
IMPOSSIBLE = [
    ({"enforcement": Enforcement.PENALTY, "solver": CONDENSED}, "no multiplier block"),
    ({"enforcement": Enforcement.PENALTY, "solver": SOLVERS["fieldsplit"]}, "no multiplier block"),
    ({"enforcement": Enforcement.SCHWARZ, "solver": CONDENSED}, "schwarz factorizes"),
    ({"enforcement": Enforcement.SCHWARZ, "solver": SOLVERS["fieldsplit"]}, "schwarz factorizes"),
    (
        {"discretization": Discretization.NTS, "enforcement": Enforcement.SCHWARZ},
        "mortar matrices",
    ),
    ({"discretization": Discretization.NTS, "basis": Basis.DUAL}, "mortar method only"),
    ({"discretization": Discretization.STS, "basis": Basis.DUAL}, "mortar method only"),
    ({"enforcement": Enforcement.PENALTY, "basis": Basis.DUAL}, "mortar method only"),
    ({"penalty": 1e6}, "--penalty applies"),
    ({"enforcement": Enforcement.PENALTY, "penalty": -1.0}, "positive number"),
    ({"schwarz": SchwarzOptions()}, "schwarz enforcement only"),
    ({"solver": CONDENSED}, "needs a diagonal D"),
    ({"discretization": Discretization.STS, "solver": CONDENSED}, "needs a diagonal D"),
    ({"max_iterations": 0}, "max_iterations"),
]


@pytest.mark.parametrize(("fields", "needle"), IMPOSSIBLE)
def test_the_request_refuses_an_impossible_combination(fields: dict, needle: str) -> None:
    with pytest.raises(InputError, match=needle) as err:
        SolveRequest(**fields)
    assert "\n" not in str(err.value)


def test_possible_combinations_are_accepted() -> None:
    """The rules refuse exactly the impossible: each of these is a request."""
    SolveRequest(basis=Basis.DUAL, solver=CONDENSED)
    SolveRequest(discretization=Discretization.NTS, solver=CONDENSED)
    SolveRequest(discretization=Discretization.STS, enforcement=Enforcement.PENALTY, penalty=1e6)
    # Schwarz with any direct MUMPS spec: compared by kind, never by value.
    SolveRequest(enforcement=Enforcement.SCHWARZ, solver=SOLVERS["mumps-lu"])
    SolveRequest(enforcement=Enforcement.SCHWARZ, solver=SOLVERS["mumps"].with_petsc(["a=1"]))


def test_the_alias_table() -> None:
    """--method penalty and schwarz are mortar with that enforcement; every method has a kernel."""
    assert (
        SolveRequest.parse("penalty")
        == SolveRequest.parse("mortar", enforcement="penalty")
        == SolveRequest(enforcement=Enforcement.PENALTY)
    )
    nts_penalty = SolveRequest.parse("nts", enforcement="penalty")
    assert (nts_penalty.method, nts_penalty.label, nts_penalty.kernel) == (
        Method.PENALTY,
        "penalty-nts",
        Kernel.NTS,
    )
    assert SolveRequest.parse("schwarz").discretization is Discretization.MORTAR
    assert {d.kernel for d in Discretization} == set(Kernel)
    with pytest.raises(InputError, match="drop --enforcement"):
        SolveRequest.parse("penalty", enforcement="multipliers")


def test_a_request_travels_alone() -> None:
    """solve takes a ready request but no option beside it; run_scene, run_case a request only."""
    scene = build_scene("blocks", MATCHING, comm=MPI.COMM_SELF)
    request = SolveRequest.parse("nts", enforcement="penalty", penalty=1e7)
    sol = solve(scene, request)
    assert sol.method is Method.PENALTY and sol.penalty is not None
    assert sol.penalty.eps == 1e7
    with pytest.raises(InputError, match="beside a SolveRequest"):
        solve(scene, request, max_iterations=3)
    # run_scene and run_case take the request only: a method's name is refused at once.
    with pytest.raises(InputError, match="expected a SolveRequest, not 'nts'"):
        run_case("blocks", MATCHING, "nts", comm=MPI.COMM_SELF)  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"SolveRequest\.parse"):
        run_scene(scene, "nts")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="unknown solve option tolerance"):
        solve(scene, "nts", tolerance=1e-3)  # type: ignore[call-arg]


def assert_refused(proc: subprocess.CompletedProcess[str], needle: str, out: Path) -> None:
    """Exit 2, one stderr line holding `needle`, no traceback, no JSON."""
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    assert not out.exists()


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--method", "penalty", "--solver", "condensed"], "no multiplier block"),
        (["--method", "schwarz", "--solver", "fieldsplit"], "schwarz factorizes"),
        (["--method", "sts", "--enforcement", "schwarz"], "mortar matrices"),
        (["--method", "penalty", "--enforcement", "multipliers"], "drop --enforcement"),
        (["--method", "nts", "--basis", "dual"], "mortar method only"),
    ],
)
def test_cli_refuses_an_impossible_request_in_one_line(tmp_path, args: list[str], needle) -> None:
    out = tmp_path / "r.json"
    assert_refused(cli("solve", "blocks", *args, "--json", str(out)), needle, out)


def test_cli_enforcement_runs_penalty_on_nts(tmp_path) -> None:
    out = tmp_path / "r.json"
    patch = ["--l2", "10", "--E1", "700000", "--size1", "0.4", "--size2", "0.4"]
    proc = cli(
        "solve", "blocks", *patch, "--method", "nts", "--enforcement", "penalty",
        "--penalty", "1e7", "--json", str(out),
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert (data["method"], data["discretization"], data["enforcement"]) == (
        "penalty",
        "nts",
        "penalty",
    )
    assert data["penalty"] == 1e7 and data["penetration"] == pytest.approx(50.0 / 1e7, rel=1e-8)


def test_the_schur_preconditioner_is_a_field() -> None:
    """The presets carry it, PETSc's option is derived from it, a contradiction is refused."""
    assert SOLVERS["fieldsplit-gamg"].schur is SchurPre.USER
    assert SOLVERS["fieldsplit-gamg"].petsc[SCHUR_KEY] == "user"
    assert SOLVERS["fieldsplit"].petsc[SCHUR_KEY] == "selfp"
    switched = SOLVERS["fieldsplit-gamg"].with_petsc([f"{SCHUR_KEY}=selfp"])
    assert switched.schur is SchurPre.SELFP and switched.petsc[SCHUR_KEY] == "selfp"
    with pytest.raises(InputError, match="contradicts"):
        SolverSpec(SolverKind.FIELDSPLIT, {"pc_type": "fieldsplit", SCHUR_KEY: "user"})
    with pytest.raises(InputError, match="contradicts"):
        SolverSpec(
            SolverKind.FIELDSPLIT,
            {"pc_type": "fieldsplit", SCHUR_KEY: "selfp"},
            schur=SchurPre.USER,
        )
    with pytest.raises(InputError, match="needs a fieldsplit"):
        SolverSpec(SolverKind.DIRECT, {"pc_type": "lu"}, schur=SchurPre.USER)


def test_freeing_the_products_is_a_field() -> None:
    """The condensed preset frees GAMG's product data, unless the options ask for the reuse
    of the interpolation that needs it."""
    from contactfx.methods.solvers import reuses_interpolation

    assert SOLVERS["condensed"].free_products
    assert not SOLVERS["mumps"].free_products and SOLVERS["condensed-gamg"].free_products
    assert not reuses_interpolation(SOLVERS["condensed"].petsc)
    for value, reuses in (("1", True), ("true", True), ("0", False), ("False", False)):
        spec = SOLVERS["condensed"].with_petsc([f"pc_gamg_reuse_interpolation={value}"])
        assert reuses_interpolation(spec.petsc) is reuses
    assert reuses_interpolation({"pc_gamg_reuse_interpolation": True})


# ------------------------------------------------------------- the solver table (TRAITS)


def test_every_kind_has_one_row_and_the_rules_read_it() -> None:
    """One typed row per kind; the request's rules ask the row, not the kind's name."""
    from contactfx.options import TRAITS, System

    assert set(TRAITS) == set(SolverKind)
    assert TRAITS[SolverKind.AUTO] == TRAITS[SolverKind.DIRECT]  # its direct path
    condensed, direct = TRAITS[SolverKind.CONDENSED], TRAITS[SolverKind.DIRECT]
    assert condensed.system is System.CONDENSED and condensed.needs_diagonal_d
    assert direct.system is System.SADDLE and direct.factorizes and not direct.needs_diagonal_d
    assert not TRAITS[SolverKind.FIELDSPLIT].factorizes and TRAITS[SolverKind.FIELDSPLIT].augmented
    # A condensed row without a diagonal D is refused by the row's trait.
    with pytest.raises(InputError, match="needs a diagonal D"):
        SolveRequest.parse("sts", solver="condensed-gamg")
    SolveRequest.parse("nts", solver="condensed-gamg")


def test_the_rejected_presets_are_not_offered() -> None:
    """mumps-schur, mumps-blr and condensed-direct left the package (benchmarks/README.md)."""
    assert set(SOLVERS) == {
        "auto", "mumps", "mumps-lu", "fieldsplit", "fieldsplit-gamg", "condensed", "condensed-gamg"
    }  # fmt: skip
    for name in ("mumps-schur", "mumps-blr", "condensed-direct"):
        with pytest.raises(InputError, match="unknown solver"):
            SolveRequest.parse("mortar", solver=name)


def test_the_linear_solver_is_a_choice_of_its_own() -> None:
    """LU, LDL^T, CG, GMRES: checked against the kind and a factorization's pc_type; which
    of them take an unsymmetric (frictional) system is the table's answer."""
    from contactfx.option_sets import GAMG, MUMPS_LU
    from contactfx.options import Linear

    assert SOLVERS["mumps"].linear is Linear.LDLT and SOLVERS["mumps-lu"].linear is Linear.LU
    assert SOLVERS["mumps"].with_petsc(["pc_type=lu"]).linear is Linear.LU
    assert SOLVERS["condensed"].linear is Linear.CG
    assert SOLVERS["condensed"].with_petsc(["ksp_type=gmres"]).linear is Linear.GMRES
    assert SOLVERS["fieldsplit"].linear is Linear.GMRES
    assert {m for m in Linear if m.unsymmetric} == {Linear.LU, Linear.GMRES}
    with pytest.raises(InputError, match="contradicts its linear solver"):
        SolverSpec(SolverKind.DIRECT, MUMPS_LU)  # LU options, the default LDL^T
    with pytest.raises(InputError, match="does not apply"):
        SolverSpec(SolverKind.CONDENSED, GAMG, linear=Linear.LU)


def test_the_multigrid_is_a_choice_not_a_second_option_set() -> None:
    """condensed: geometric, condensed-gamg: GAMG; the geometric options are GEOMETRIC_MG
    with the user's own changes (not GAMG's keys)."""
    from contactfx.methods.solvers import geometric_options
    from contactfx.option_sets import GEOMETRIC_MG
    from contactfx.options import Multigrid

    assert SOLVERS["condensed"].multigrid is Multigrid.GEOMETRIC
    assert SOLVERS["condensed-gamg"].multigrid is Multigrid.GAMG
    assert SOLVERS["mumps"].multigrid is None
    assert geometric_options(SOLVERS["condensed"].petsc) == GEOMETRIC_MG
    tuned = SOLVERS["condensed"].with_petsc(["mg_levels_ksp_max_it=2", "pc_gamg_threshold=0.1"])
    assert geometric_options(tuned.petsc) == {**GEOMETRIC_MG, "mg_levels_ksp_max_it": "2"}
    with pytest.raises(InputError, match="needs the condensed system"):
        replace(SOLVERS["mumps"], multigrid=Multigrid.GAMG)
