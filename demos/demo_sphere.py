# # An elastic sphere on an elastic block: the axisymmetric model against 3D Hertz
#
# With `model = axisymmetric` the 2D section is a half plane $x = r \ge 0$ revolved about
# the axis $y$: the built-in Hertz scene (a quarter disc on a block) becomes a hemisphere of
# radius $R = 60$ cm on a cylindrical block, pressed by a uniform pressure on its equatorial
# disc with the **total** force $P = 100$ MPa cm$^2$ ($E = 7000$ MPa, $\nu = 0.23$ for both
# bodies). Every integral carries $2 \pi r$: the stiffness (with the hoop strain $u_r / r$),
# the load, and every contact integral (the mortar $D$ and $M$, the nodal weights), so the
# forces are totals over the turn. The reference is Hertz's point contact (Johnson sec. 3.4):
#
# $$a = \left(\frac{3 P R}{4 E^*}\right)^{1/3},\quad p_0 = \frac{3P}{2\pi a^2},\quad
#   p(r) = p_0 \sqrt{1 - r^2/a^2},$$
#
# with $1/E^* = (1-\nu_1^2)/E_1 + (1-\nu_2^2)/E_2$: $a = 1.068$ cm, $p_0 = 41.87$ MPa.
# The $L^2$ error of the pressure is weighted by $r$ (the integral over the contact disc).
# `CONTACTFX_QUICK=1` runs the two coarser meshes only.

# +
import os
from dataclasses import replace
from pathlib import Path

import dolfinx_solver  # noqa: F401
import matplotlib
import numpy as np
from mpi4py import MPI

from contactfx import SolveRequest
from contactfx.api import run_case
from contactfx.results.references import exact_pressure
from contactfx.scenes import HertzParams, Model, hertz_exact

matplotlib.use("Agg")
import matplotlib.pyplot as plt

comm = MPI.COMM_WORLD
QUICK = os.environ.get("CONTACTFX_QUICK", "0") == "1"
OUT = Path(os.environ.get("CONTACTFX_RESULTS", "results")) / "sphere"
METHODS = ["nts", "sts", "mortar"]


def say(*args: object) -> None:
    if comm.rank == 0:
        print(*args, flush=True)


# -

# ## The meshes
#
# The graded meshes of the Hertz demo: the size $h_e$ at the expected edge of contact, $4 h_e$
# on the rest of the zone ($r \le 1.4 a$) and a growth slope of $0.1 \sqrt{h_e / 0.005}$.


# +
def graded(h_edge: float) -> HertzParams:
    """The sphere on a block, graded with size h_edge at the edge of contact."""
    return HertzParams(
        refine=4 * h_edge,
        refine_edge=h_edge,
        slope=min(0.3, 0.1 * np.sqrt(h_edge / 0.005)),
        model=Model.AXISYMMETRIC,
    )


EDGES = [0.04, 0.02] if QUICK else [0.04, 0.02, 0.01]
exact = hertz_exact(replace(HertzParams(), model=Model.AXISYMMETRIC))
say(
    f"3D Hertz: a = {exact['a']:.4f} cm, p0 = {exact['p0']:.3f} MPa, E* = "
    f"{exact['E_star']:.1f}"
)
rows, profiles = [], {}
for h in EDGES:
    for method in METHODS:
        sol, record = run_case(
            "hertz", graded(h), SolveRequest.parse(method), comm=comm
        )
        data = record.to_json()
        hz = data["hertz"]
        rows.append(
            (
                h,
                method,
                data["elements"],
                data["contact_force"],
                hz["a"] / hz["a_exact"] - 1,
                hz["p0"] / hz["p0_exact"] - 1,
                hz["l2_error"],
            )
        )
        profiles[(h, method)] = (data["interface"]["x"], data["interface"]["pressure"])
# -

# ## Results
#
# The contact force equals the applied load (the total over the turn) to round-off, and the
# half-width and the peak pressure approach the 3D values.

# +
say(
    f"{'h_e':>6} {'method':>7} {'cells':>6} {'force':>12} {'a err':>8} {'p0 err':>8} "
    f"{'L2':>7}"
)
for h, method, cells, force, ea, ep, l2 in rows:
    say(
        f"{h:6.3f} {method:>7} {cells:6d} {force:12.8f} {ea:+8.2%} {ep:+8.2%} {l2:7.2%}"
    )

if comm.rank == 0:
    OUT.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 4))
    r = np.linspace(0, 1.5 * exact["a"], 400)
    ax.plot(r, exact_pressure(r, exact["a"], exact["p0"]), "k-", label="3D Hertz")
    for method in METHODS:
        x, p = profiles[(EDGES[-1], method)]
        ax.plot(x, p, ".", label=f"{method}, h_e = {EDGES[-1]}")
    ax.set_xlim(0, 1.5 * exact["a"])
    ax.set_xlabel("r (cm)")
    ax.set_ylabel("contact pressure (MPa)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(OUT / "sphere_pressure.png", dpi=120)
    say(f"wrote {OUT / 'sphere_pressure.png'}")
# -

# ## Checks
#
# Every run carries the whole load through the contact; on the finest mesh every method is
# within 2.5 % of 3D Hertz in $a$ and $p_0$.

# +
for h, method, _cells, force, ea, ep, l2 in rows:
    assert abs(force / 100.0 - 1) < 1e-6, (h, method, force)
    if h == EDGES[-1]:
        assert abs(ea) < 0.025 and abs(ep) < 0.025, (h, method, ea, ep)
        assert l2 < 0.05, (h, method, l2)
say("demo_sphere: all checks passed")
# -
