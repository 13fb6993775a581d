"""Run every demo (quick mode) serially and under mpirun -n 2; each asserts its own result."""

import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ENV, MPIRUN, ROOT

DEMOS = sorted((ROOT / "demos").glob("demo_*.py"))


@pytest.mark.parametrize("ranks", [1, pytest.param(2, marks=pytest.mark.mpi)])
@pytest.mark.parametrize("demo", DEMOS, ids=[d.stem for d in DEMOS])
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
    assert len(DEMOS) >= 1 and os.path.isdir(ROOT / "demos")
