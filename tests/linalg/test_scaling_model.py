"""benchmarks/scaling_model.py: the -log_view parser on captured PETSc output, and the model.

The fixture log_view_condensed_2ranks.txt is PETSc 3.25's -log_view of
`python benchmarks/scaling.py --sizes 100e3 --ranks 2` (100,224 DOFs, condensed, 2 ranks),
trimmed to its header, stage summary and a few events of the solve stage. Expected values are
read off that text by hand; the model's against arithmetic done by hand below.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "benchmarks"))

from scaling_model import (  # noqa: E402  (benchmarks/ is not a package)
    Measured,
    Network,
    Part,
    Phases,
    RankWork,
    counted_reductions,
    halo_factor,
    neighbours,
    parse_log_view,
    phase_time,
    predict,
    scale_work,
    whole_run,
)

pytestmark = pytest.mark.serial


@pytest.fixture(scope="module")
def log() -> dict:
    return parse_log_view((HERE / "log_view_condensed_2ranks.txt").read_text())


def test_header_and_stages(log: dict) -> None:
    assert log["ranks"] == 2
    g = log["global"]
    assert g["flops"] == {"max": 1.789e9, "ratio": 1.016, "avg": 1.775e9, "total": 3.550e9}
    assert g["messages"]["total"] == 4.309e3
    assert g["reductions"]["max"] == 277.0
    assert set(log["stages"]) == {
        "Main Stage", "mesh", "predictor", "assemble", "search", "contact", "solve"
    }  # fmt: skip
    solve = log["stages"]["solve"]
    assert solve["time"] == 2.7159
    assert solve["flops"] == 3.5404e9
    assert solve["messages"] == 4.194e3
    assert solve["message_bytes"] == pytest.approx(4.194e3 * 3.089e3, rel=1e-12)
    assert solve["reductions"] == 195.0
    # The stage's "Avg" flop column is the sum over the ranks: the stages add up to the total.
    total = sum(s["flops"] for s in log["stages"].values())
    assert total == pytest.approx(g["flops"]["total"], rel=1e-3)


def test_events(log: dict) -> None:
    ev = log["events"]["solve"]
    assert set(ev) == {
        "BuildTwoSided", "VecTDot", "VecNorm", "MatMult", "PCGAMG Gal l00", "PCSetUp",
        "PCApply", "KSPSolve",
    }  # fmt: skip
    assert ev["PCGAMG Gal l00"]["flops"] == 2.41e7
    ksp = ev["KSPSolve"]
    assert (ksp["count"], ksp["time"], ksp["flops"], ksp["messages"]) == (4, 1.7408, 1.6e9, 3.5e3)
    assert ev["PCSetUp"]["reductions"] == 160.0
    assert ev["PCApply"]["count"] == 44.0
    assert counted_reductions(ev) == 353 + 120
    # The object table repeats the stage headers: it must not reset the events.
    assert log["events"]["Main Stage"] == {}


def test_phase_time_by_hand() -> None:
    net = Network(latency=2e-6, bandwidth=5e9, allreduce_latency=2e-6)
    w = RankWork(flops=2e9, messages=1000, message_bytes=1e8, reductions=100)
    t = phase_time(w, rate=1e9, ranks=8, net=net)
    # 2 s compute, 1000 x 2 us, 1e8 B / 5e9 B/s, 100 x log2(8) x 2 us
    assert t["compute"] == pytest.approx(2.0)
    assert t["latency"] == pytest.approx(2e-3)
    assert t["bandwidth"] == pytest.approx(0.02)
    assert t["allreduce"] == pytest.approx(6e-4)
    assert t["total"] == pytest.approx(2.0226)
    assert phase_time(w, rate=1e9, ranks=1, net=net)["allreduce"] == 0.0


def test_scaled_work_by_hand() -> None:
    assert (neighbours(2), neighbours(4), neighbours(64)) == (1.0, 3.0, 6.0)
    assert (halo_factor(2), halo_factor(16), halo_factor(64)) == (1.0, 1.0, 0.5)
    cg = Part("cg", 100.0, 1e9, 10.0, 1000.0, 3.0, per_iteration=True)
    setup = Part("setup", 500.0, 2e8, 300.0, 1e6, 50.0, per_iteration=False)
    m = Measured(dofs=1e6, parts=(setup, cg), its_c=20.0, its_g=0.0)
    w = scale_work(cg, m, dofs=4e6, ranks=16)
    # 100 x 4e6 x 20 / 16; 10 x 6 neighbours x 20; 1000 x sqrt(4) x 4/sqrt(16) x 20; 3 x 20
    assert (w.flops, w.messages, w.message_bytes, w.reductions) == pytest.approx(
        (5e8, 1200.0, 40_000.0, 60.0)
    )
    s = scale_work(setup, m, dofs=4e6, ranks=16)
    assert (s.flops, s.messages, s.message_bytes, s.reductions) == pytest.approx(
        (1.25e8, 1800.0, 2e6, 50.0)
    )
    net = Network()
    t = predict(m, 4e6, 16, net)
    cg_t = 5e8 / 1e9 + 1200 * 2e-6 + 40_000 / 5e9 + 60 * 4 * 2e-6
    setup_t = 1.25e8 / 2e8 + 1800 * 2e-6 + 2e6 / 5e9 + 50 * 4 * 2e-6
    assert t["cg"] == pytest.approx(cg_t)
    assert t["setup"] == pytest.approx(setup_t)
    assert t["total"] == pytest.approx(cg_t + setup_t)
    assert t["communication"] == pytest.approx(cg_t + setup_t - 0.5 - 0.625)
    ph = Phases(mesh=1e-6, assemble_rank=2e-6, predictor=5e-7)
    # mesh 4 s and predictor 2 s on rank 0 whatever P; assembly 8 s / 16
    assert whole_run(m, ph, 4e6, 16, net) == pytest.approx(4 + 0.5 + 2 + cg_t + setup_t)
    # Serially: no messages and no allreduces, compute only.
    serial = predict(m, 1e6, 1, net)
    assert serial["communication"] == 0.0
    assert serial["total"] == pytest.approx(100 * 1e6 * 20 / 1e9 + 500 * 1e6 / 2e8)
    assert math.isclose(serial["iterations"], 20.0)
