"""The structured grid's prolongations: each coarser node stays on its finer node's rank."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

SCRIPT = """
import dolfinx_solver  # noqa: F401
import numpy as np
from mpi4py import MPI
from contactfx.discretize.elasticity import assemble_elasticity
from contactfx.discretize.grid_mg import grid_interpolations
from contactfx.scenes import HertzParams, hertz

comm = MPI.COMM_WORLD
scene = hertz(HertzParams(refine=0.08, h_far=0.8, mesh="structured"), comm=comm)
el = assemble_elasticity(scene)
rows = []
for P in grid_interpolations(el.V, el.bcs, scene.grid):
    c0, c1 = P.getOwnershipRangeColumn()
    _, cols, _ = P.getValuesCSR()
    far = int(np.sum((cols < c0) | (cols >= c1)))
    rows.append(comm.allreduce(np.array([far, len(cols), c1 - c0]), op=MPI.SUM))
if comm.rank == 0:
    np.save({out!r}, np.array(rows))
"""


@pytest.mark.mpi
def test_coarser_nodes_stay_on_their_rank(tmp_path: Path, mpi_script) -> None:
    """On 2 ranks almost every entry of every prolongation has its column on its row's rank.

    Only rows next to the partition's cut reach across (a split of the grid's own numbering
    sent about half of them to the other rank), and every rank owns coarse nodes.
    """
    out = tmp_path / "levels.npy"
    script = tmp_path / "levels.py"
    script.write_text(textwrap.dedent(SCRIPT.format(out=str(out))))
    mpi_script(script, timeout=180)
    levels = np.load(out)
    assert len(levels) >= 3
    far, total = levels[:, 0], levels[:, 1]
    assert np.all(far <= 0.05 * total), far / total
