"""mpirun -n 2 gives the serial answer: displacements and multipliers to 1e-8."""

import json
import textwrap

import numpy as np
import pytest
from conftest import run_cli

SCRIPT = textwrap.dedent("""
    import sys
    import numpy as np
    from mpi4py import MPI
    from contactfx.api import run_case
    from contactfx.results.interface import u_at_points
    from contactfx.scenes import BLOCK_SCENES

    scene, method, active, solver, out = sys.argv[1:6]
    sol, data = run_case("blocks", BLOCK_SCENES[scene], method, active=int(active),
                         solver=solver)
    u = u_at_points(sol)
    if MPI.COMM_WORLD.rank == 0:
        np.savez(out, u=u, x=np.asarray(data["interface"]["x"]),
                 p=np.asarray(data["interface"]["pressure"]), ranks=data["ranks"])
""")


@pytest.mark.parametrize(
    ("scene", "method", "active", "solver"),
    [
        ("S2", "nts", 2, "mumps"),
        ("S3", "sts", 1, "mumps"),
        ("S4", "mortar", 2, "mumps"),
        ("S2", "mortar", 1, "fieldsplit"),
    ],
)
def test_two_ranks_equal_serial(tmp_path, mpi_script, scene, method, active, solver) -> None:
    """Same mesh, same answer: the rank count changes only the round-off."""
    script = tmp_path / "run.py"
    script.write_text(SCRIPT)
    results = {}
    for ranks in (1, 2):
        out = tmp_path / f"r{ranks}.npz"
        mpi_script(script, scene, method, str(active), solver, str(out), ranks=ranks)
        results[ranks] = np.load(out)
    assert int(results[2]["ranks"]) == 2
    u1, u2 = results[1]["u"], results[2]["u"]
    assert u1.shape == u2.shape
    np.testing.assert_allclose(u2[:, :2], u1[:, :2], atol=1e-12)
    scale = np.abs(u1[:, 2:]).max()
    assert np.abs(u2[:, 2:] - u1[:, 2:]).max() < 1e-8 * scale
    np.testing.assert_allclose(results[2]["x"], results[1]["x"], atol=1e-12)
    p1, p2 = results[1]["p"], results[2]["p"]
    assert np.abs(p2 - p1).max() < 1e-8 * np.abs(p1).max()


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
