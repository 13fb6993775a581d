# # A heated block between rigid walls: thermal strain
#
# A block $[0, L] \times [0, H]$ ($L = 2$, $H = 1$, $E = 1000$, $\nu = 0.3$) touches two
# rigid walls, the planes $x = 0$ and $x = L$ (two `[[obstacle]]` tables, no mesh for them),
# and is heated by $\Delta T$ with the expansion coefficient $\alpha = 10^{-5}$:
#
# ```toml
# [bodies.block]
# E = 1000.0
# nu = 0.3
# alpha = 1e-5   # the eigenstrain alpha dT I (both keys or neither)
# dT = 100.0
# ```
#
# The block is free in $y$ (one corner holds $u_y = 0$); the walls hold it in $x$. With
# $\varepsilon_{xx} = 0$ and $\sigma_{yy} = 0$, Hooke's law with the initial strain
# $\varepsilon_0 = \alpha\,\Delta T$ gives, in plane strain ($\varepsilon_{zz} = 0$:
# $\sigma_{zz} = \nu\sigma_{xx} - E\alpha\Delta T$), the wall pressure
# $E\alpha\Delta T/(1-\nu)$, and in plane stress $E\alpha\Delta T$. The displacement
# $u = (0, (1+\nu)\alpha\Delta T\,y)$ (plane strain) is bilinear, so every multiplier method
# reproduces it to round-off on the unstructured mesh: a thermal patch test. The load
# enters the right-hand side as $\int \sigma_0 : \varepsilon(v)$ with
# $\sigma_0 = C\varepsilon_0$ (`discretize/thermal.py`, `docs/models.md`).

# +
import os
from pathlib import Path

import dolfinx_solver  # noqa: F401
import matplotlib
import numpy as np
from mpi4py import MPI

from contactfx import SolveRequest, load_scene_file, run_scene
from contactfx.discretize import elasticity

matplotlib.use("Agg")
import matplotlib.pyplot as plt

comm = MPI.COMM_WORLD
OUT = Path(os.environ.get("CONTACTFX_RESULTS", "results")) / "heated_block"
MESHES = Path(__file__).resolve().parents[1] / "meshes"  # the scenes' gmsh geometry
E, NU, ALPHA = 1000.0, 0.3, 1e-5
METHODS = ["mortar", "sts", "nts", "penalty"]


def say(*args: object) -> None:
    if comm.rank == 0:
        print(*args, flush=True)


def scene_text(dT: float, model: str) -> str:
    """The scene file for a temperature change dT in `model`."""
    return f'''model = "{model}"
mesh = "{MESHES / "heated_block.geo"}"

[bodies.block]
E = {E}
nu = {NU}
alpha = {ALPHA}
dT = {dT}

[[obstacle]]
name = "wall_left"
shape = "plane"
point = [0.0, 0.0]
normal = [1.0, 0.0]
surface = "left"

[[obstacle]]
name = "wall_right"
shape = "plane"
point = [2.0, 0.0]
normal = [-1.0, 0.0]
surface = "right"

[[dirichlet]]
group = "pin"
uy = 0.0
'''


def walls(dT: float, method: str, model: str = "plane_strain") -> np.ndarray:
    """The contact pressure at every multiplier of both walls."""
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / f"heated_{model}_{comm.rank}.toml"
    path.write_text(scene_text(dT, model))
    sol, _ = run_scene(load_scene_file(path, comm), SolveRequest.parse(method))
    return np.concatenate([sol.pressure[pv.rows] for pv in sol.pairs])


# -

# ## The wall pressure, every method, plane strain
#
# Linear in $\Delta T$: two temperatures, the largest relative error over both walls' nodes.

# +
rows = []
for dT in (50.0, 100.0):
    exact = E * ALPHA * dT / (1 - NU)
    for method in METHODS:
        p = walls(dT, method)
        rows.append((dT, method, exact, float(np.max(np.abs(p / exact - 1.0)))))
say("| dT | method | E alpha dT / (1 - nu) | max error |")
say("|---|---|---|---|")
for dT, method, exact, err in rows:
    say(f"| {dT:g} | {method} | {exact:.6g} | {err:.1e} |")
if comm.rank == 0:
    fig, ax = plt.subplots(figsize=(6, 3.5))
    for method in METHODS:
        errs = [err for _, m, _, err in rows if m == method]
        ax.semilogy([50, 100], np.maximum(errs, 1e-17), marker="o", label=method)
    ax.set_xlabel("dT")
    ax.set_ylabel("max relative wall-pressure error")
    ax.legend()
    fig.tight_layout()
    fig.savefig(OUT / "wall_pressure_error.png", dpi=120)
    plt.close(fig)
# -

# ## Plane stress
#
# $\sigma_{zz} = 0$: the wall pressure is $E\alpha\Delta T$. It needs the plane-stress
# elastic law in `sigma` (the stress law made model-aware); run once that is there.

# +
plane_stress = hasattr(elasticity, "stress")
if plane_stress:
    p = walls(100.0, "mortar", "plane_stress")
    ps_error = float(np.max(np.abs(p / (E * ALPHA * 100.0) - 1.0)))
    say(f"plane stress, mortar: max wall-pressure error {ps_error:.1e}")
else:
    say("plane stress: skipped (the elastic law is plane strain only in this build)")
# -

# ## Checks
#
# Every multiplier method is exact to 1e-8 (round-off); penalty is off by its penetration.

# +
for dT, method, _, err in rows:
    assert err < (1e-3 if method == "penalty" else 1e-8), (dT, method, err)
if plane_stress:
    assert ps_error < 1e-8, ps_error
say("all checks passed")
# -
