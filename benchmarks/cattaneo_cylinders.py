"""Cattaneo-Mindlin against a frictional solve: two identical half-cylinders, pressed, pushed.

tests/scenes/cattaneo_cylinders.geo (R = 1; element size h at the contact), E = 1000,
nu = 0.3, mu = 0.3: the lower flat face held, the upper one moved down by `press` (a rigid
flat face, no tilt) and then sideways by `push`, mortar on the direct path. The computed P and
Q give Cattaneo-Mindlin's line contact (R_eff = R / 2, the pair's E*); the stick half-width
read from the statuses and the shear's relative L2 error come from
contactfx.results.friction_references.cattaneo_errors. The table of docs/friction_verification.md:

    OPENBLAS_NUM_THREADS=1 python benchmarks/cattaneo_cylinders.py 0.004 0.03 0.01
    OPENBLAS_NUM_THREADS=1 python benchmarks/cattaneo_cylinders.py 0.0012 0.0037 0.0008
    OPENBLAS_NUM_THREADS=1 python benchmarks/cattaneo_cylinders.py 0.002 0.03 0.01

(arguments: h, press, push; the second about a minute on one loaded core). Rows in the
bisector frame (docs/friction_verification.md).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from contactfx import ContactPair, scene_from_gmsh, solve
from contactfx.results.friction_references import cattaneo_errors, cattaneo_mindlin
from contactfx.scenes import Dirichlet, Material

GEO = Path(__file__).resolve().parents[1] / "tests" / "scenes" / "cattaneo_cylinders.geo"
E, NU, MU, R = 1000.0, 0.3, 0.3, 1.0


def main(h: float, press: float, push: float) -> None:
    """Solve and print P, Q / mu P, a, the stick half-width against c (in cells), the L2 error."""
    text = GEO.read_text().replace("h = {0.004,", f"h = {{{h!r},")
    with tempfile.TemporaryDirectory() as tmp:
        geo = Path(tmp) / "cattaneo_cylinders.geo"
        geo.write_text(text)
        scene = scene_from_gmsh(
            geo,
            bodies={"upper": Material(E, NU), "lower": Material(E, NU)},
            contacts=[ContactPair("upper_arc", "lower_arc", mu=MU)],
            dirichlet=[
                Dirichlet("lower_flat", ux=0.0, uy=0.0),
                Dirichlet("upper_flat", uy=-press, name="press"),
                Dirichlet("upper_flat", ux=push, name="push"),
            ],
            steps=[{"press": 1.0}, {"push": 1.0}],
        )
        sol = solve(scene, "mortar")
    assert sol.friction is not None
    w, x = sol.layout.weights, sol.layout.x[:, 0]
    p_total, q_total = float(w @ sol.pressure), float(w @ sol.friction.shear)
    ref = cattaneo_mindlin(p_total, q_total, MU, R / 2, E / (2 * (1 - NU**2)))
    err = cattaneo_errors(ref, x, sol.friction.shear, sol.pressure, sol.friction.status == 1)
    cell = float(np.median(np.diff(np.sort(x[sol.active]))))
    print(
        f"h {h}: P {p_total:.4f}, Q/muP {q_total / (MU * p_total):.3f}, a {ref.a:.4f}, "
        f"stick half-width - c {(err.c - ref.c) / cell:+.2f} cells (cell {cell:.4f}), "
        f"shear L2 {100 * err.shear_l2:.1f} %, slip law {err.slip_law:.1e}"
    )


if __name__ == "__main__":
    main(*(float(v) for v in sys.argv[1:4]))
