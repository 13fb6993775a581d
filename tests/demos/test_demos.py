"""Run every demo (quick mode) serially, and under mpirun -n 2 those on distinct parallel paths.

Each demo asserts its own result. On 2 ranks: the blocks (several pairs, every method) and the
user scene (gmsh .geo, a TOML scene); the other demos' parallel paths (Hertz, Schwarz, penalty,
obstacles) are compared with serial runs case by case in tests/ranks/test_ranks.py.
"""

import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ENV, MPIRUN, ROOT

DEMOS = sorted((ROOT / "demos").glob("demo_*.py"))


PARALLEL_DEMOS = ("demo_blocks", "demo_own_scene")
CASES = [pytest.param(d, 1, id=f"{d.stem}-1") for d in DEMOS] + [
    pytest.param(d, 2, id=f"{d.stem}-2", marks=pytest.mark.mpi)
    for d in DEMOS
    if d.stem in PARALLEL_DEMOS
]


@pytest.mark.parametrize(("demo", "ranks"), CASES)
def test_demo(demo: Path, ranks: int, tmp_path: Path) -> None:
    """The demo runs to its final assertions."""
    env = {**ENV, "CONTACTFX_QUICK": "1", "CONTACTFX_RESULTS": str(tmp_path), "MPLBACKEND": "Agg"}
    cmd = [sys.executable, str(demo)]
    if ranks > 1:
        cmd = [MPIRUN, "-n", str(ranks), sys.executable, "-m", "mpi4py", str(demo)]
    proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=180)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]


def test_there_are_demos() -> None:
    """The demo folder is not empty (a glob that finds nothing would test nothing)."""
    assert len(DEMOS) >= 1
    assert {d.stem for d in DEMOS} >= set(PARALLEL_DEMOS)
