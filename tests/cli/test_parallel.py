"""The CLI under mpirun -n 2 (the 2-rank vs serial comparisons: tests/ranks/test_ranks.py)."""

import json

import pytest
from conftest import run_cli


@pytest.mark.mpi
def test_cli_under_mpirun(tmp_path) -> None:
    """The CLI under mpirun writes one JSON, from rank 0, saying 2 ranks."""
    out = tmp_path / "r.json"
    proc = run_cli(
        "solve", "blocks", "--method", "mortar", "--preset", "S2", "--json", str(out), ranks=2
    )
    assert proc.returncode == 0, proc.stderr
    data = json.loads(out.read_text())
    assert data["ranks"] == 2
    assert data["contact_force"] == pytest.approx(150.0, rel=1e-10)
