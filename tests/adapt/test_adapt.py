"""contactfx adapt: the loop, adapt.json, the final mesh, refusals, two ranks."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import pytest
from conftest import COARSE_HERTZ, ROOT, cli, run_cli


def _adapt(tmp: Path, *args: str, ranks: int = 1) -> dict:
    cmd = ("adapt", *args, "--out", str(tmp))
    proc = cli(*cmd) if ranks == 1 else run_cli(*cmd, ranks=ranks)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert "level 0:" in proc.stdout and "stopped:" in proc.stdout
    return json.loads((tmp / "adapt.json").read_text())


@pytest.fixture(scope="module")
def hertz_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, Path]:
    out = tmp_path_factory.mktemp("adapt_hertz")
    # The residual estimate's loop (the default before the goal loop; tests/adapt/
    # test_goal_loop.py has the goal loop's).
    args = (*COARSE_HERTZ, "--goal", "residual", "--max-dofs", "12000", "--compare-uniform")
    return _adapt(out, *args), out


def test_hertz_levels(hertz_run: tuple[dict, Path]) -> None:
    data, out = hertz_run
    levels = data["levels"]
    assert len(levels) >= 2
    for lv in levels:
        assert isinstance(lv["estimate"], float) and lv["time"] > 0
        assert {"hertz", "contacts", "dofs", "estimate_parts"} <= set(lv)
    est = [lv["estimate"] for lv in levels]
    assert all(b < a for a, b in itertools.pairwise(est)), est
    # The adapted mesh is better than the uniform one of about the same size.
    assert levels[-1]["hertz"]["l2_error"] < levels[0]["hertz"]["l2_error"]
    assert levels[-1]["dofs"] <= 12000 and "max-dofs" in data["stop"]
    uni = data["uniform"]
    assert len(uni) >= 2 and uni[0]["dofs"] == levels[0]["dofs"]
    for name in ("fields.pvtu", "mesh.msh", "adapt_dofs.png", "adapt_time.png"):
        assert (out / name).is_file(), name


def test_final_mesh_loads_back(hertz_run: tuple[dict, Path], tmp_path: Path) -> None:
    """mesh.msh as a scene file's mesh: the same DOFs and the same contact force."""
    data, out = hertz_run
    scene = tmp_path / "final.toml"
    scene.write_text(
        f'mesh = "{out / "mesh.msh"}"\n'
        "[bodies.body1]\nE = 7000.0\nnu = 0.23\n[bodies.body2]\nE = 7000.0\nnu = 0.23\n"
        '[[contact]]\nactive = "contact2"\npassive = "contact1"\n'
        '[[dirichlet]]\ngroup = "symmetry"\nux = 0.0\n'
        '[[dirichlet]]\ngroup = "support"\nuy = 0.0\n'
        f'[[pressure]]\ngroup = "load"\np = {100.0 / 120.0!r}\n'
    )
    proc = cli("solve", str(scene), "--json", str(tmp_path / "r.json"))
    assert proc.returncode == 0, proc.stderr
    r = json.loads((tmp_path / "r.json").read_text())
    last = data["levels"][-1]
    assert r["dofs"] == last["dofs"] and r["elements"] == last["elements"]
    assert abs(r["contact_force"] - last["contact_force"]) < 1e-8 * last["contact_force"]


def test_blocks(tmp_path: Path) -> None:
    # --goal residual: the patch-test pressure is exact, so the goal loop stops at level 0.
    args = ("blocks", "--size1", "0.5", "--size2", "0.5", "--max-levels", "2")
    data = _adapt(tmp_path, *args, "--goal", "residual")
    levels = data["levels"]
    assert len(levels) == 2 and levels[1]["estimate"] < levels[0]["estimate"]
    assert all(abs(lv["contact_force"] - 150.0) < 1e-8 for lv in levels)


def test_geo_scene(tmp_path: Path) -> None:
    scene = ROOT / "tests" / "scenes" / "two_cylinders.toml"
    args = ("--max-levels", "2", "--max-dofs", "60000", "--goal", "residual")
    data = _adapt(tmp_path, str(scene), *args)
    assert len(data["levels"]) == 2
    assert data["levels"][1]["estimate"] < data["levels"][0]["estimate"]
    assert "hertz" in data["levels"][0]


def test_msh_refused(tmp_path: Path) -> None:
    (tmp_path / "m.msh").write_text("")
    scene = tmp_path / "s.toml"
    scene.write_text(
        'mesh = "m.msh"\n[bodies.a]\nE = 1.0\nnu = 0.3\n[bodies.b]\nE = 1.0\nnu = 0.3\n'
        '[[contact]]\nactive = "x"\npassive = "y"\n'
    )
    proc = cli("adapt", str(scene), "--out", str(tmp_path / "o"))
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1
    assert "no geometry to remesh" in proc.stderr
    assert not (tmp_path / "o").exists()


@pytest.mark.mpi
def test_two_ranks_print_once_and_match_serial(tmp_path: Path) -> None:
    """mpirun -n 2: each progress line once (rank 0), one set of files, serial's levels.

    tests/ranks/rank_cases.py (cli-adapt-hertz) compares a Hertz run number by number.
    """
    args = ("blocks", "--size1", "0.5", "--size2", "0.5", "--max-levels", "2", "--goal")
    args += ("residual",)
    serial = _adapt(tmp_path / "one", *args)
    cmd = ("adapt", *args, "--out", str(tmp_path / "two"))
    proc = run_cli(*cmd, ranks=2)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    for line in ("level 0:", "level 1:", "remeshed:", "stopped:", "wrote ", "2 ranks"):
        assert proc.stdout.count(line) == 1, (line, proc.stdout)
    two = json.loads((tmp_path / "two" / "adapt.json").read_text())
    assert [lv["dofs"] for lv in two["levels"]] == [lv["dofs"] for lv in serial["levels"]]
    for a, b in zip(serial["levels"], two["levels"], strict=True):
        assert b["estimate"] == pytest.approx(a["estimate"], rel=1e-9)
    assert sorted(p.name for p in (tmp_path / "two").glob("fields_p*.vtu")) == [
        "fields_p0.vtu",
        "fields_p1.vtu",
    ]


def test_weight_below_one_refused(tmp_path: Path) -> None:
    proc = cli("adapt", *COARSE_HERTZ, "--weight-contact", "0.5", "--out", str(tmp_path / "o"))
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert "--weight-contact" in proc.stderr and not (tmp_path / "o").exists()


def test_overshooting_mesh_is_replanned_not_dropped() -> None:
    """A remeshed level above --max-dofs is planned again with a smaller budget and kept."""
    from contactfx.adapt.goal import Goal
    from contactfx.adapt.loop import ResidualPlan, adapt
    from contactfx.adapt.records import AdaptOptions
    from contactfx.adapt.sizing import plan_mesh
    from contactfx.methods.predictor import scene_dofs
    from contactfx.request import SolveRequest
    from contactfx.scenes import HertzParams
    from contactfx.scenes.builtin import hertz

    budgets: list[float] = []

    def recording(sol, est, tol, cells, rule, pressure_tol):
        budgets.append(strategy.budget)
        return plan_mesh(sol, est, tol, cells, rule, pressure_tol)

    def overshoot_once(scene):
        # gmsh's first mesh of level 1 counted as twice --max-dofs, as if it overshot.
        return scene_dofs(scene) if len(budgets) > 1 else 2 * opts.max_dofs

    opts = AdaptOptions(Goal.RESIDUAL, 0.05, max_levels=2, max_dofs=20_000)
    strategy = ResidualPlan(opts, size=recording)
    scene = hertz(HertzParams(refine=2, h_far=2, refine_edge=0, slope=0.3))
    result = adapt(
        scene,
        SolveRequest.parse("mortar"),
        opts,
        say=lambda _: None,
        count_dofs=overshoot_once,
        strategy=strategy,
    )
    assert len(budgets) == 2 and budgets[1] == pytest.approx(budgets[0] * 0.95 / 2)
    assert len(result.levels) == 2 and result.levels[1].dofs <= opts.max_dofs
