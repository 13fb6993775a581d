# # A shaft-hub shrink fit against Lame
#
# A steel hollow shaft (bore $a = 0.5$, outer radius $b$) is pressed into an aluminium hub
# (bore $b = 2$, outer radius $c = 4$, lengths in cm, stresses in MPa) with the radial
# interference $\delta = 0.002$ cm. The scene file draws the shaft with radius $b + \delta$,
# overlapping the hub, and says so on the pair:
#
# ```toml
# [[contact]]
# active = "shaft_contact"
# passive = "hub_contact"
# interference = true   # the drawn overlap is the fit; or interference = D for bodies
#                       # drawn touching (the gap g becomes g - D along the normal)
# ```
#
# The pre-solve overlap check skips that pair only, and the JSON reports each pair's
# `initial_overlap` (the largest negative gap before the solve). The reference is Lame's
# contact pressure of two thick rings (plane stress; plane strain by
# $E \to E/(1-\nu^2)$, $\nu \to \nu/(1-\nu)$, see `docs/models.md`):
#
# $$p = \frac{\delta}{b\left[\frac{1}{E_o}\left(\frac{c^2+b^2}{c^2-b^2}+\nu_o\right)
#       + \frac{1}{E_i}\left(\frac{b^2+a^2}{b^2-a^2}-\nu_i\right)\right]}$$
#
# given by `[[reference]] type = "lame"`. A quarter model with symmetry supports, plane
# strain (a long hub); 2.7k DOFs, a second per method.

# +
import os
from pathlib import Path

import dolfinx_solver  # noqa: F401
import matplotlib
import numpy as np
from mpi4py import MPI

from contactfx import SolveRequest, load_scene_file, run_scene

matplotlib.use("Agg")
import matplotlib.pyplot as plt

comm = MPI.COMM_WORLD
OUT = Path(os.environ.get("CONTACTFX_RESULTS", "results")) / "shrink_fit"
SCENE = Path(__file__).resolve().parent / "scenes" / "shaft_hub.toml"
METHODS = ["mortar", "sts", "nts", "penalty"]


def say(*args: object) -> None:
    if comm.rank == 0:
        print(*args, flush=True)


# -

# ## Every method on the fit
#
# The mean contact pressure is $\sum_j p_j w_j / \sum_j w_j$ over the pair's multipliers
# ($w_j = \int N_j$, the nodal weights): the force per unit length of the interface.

# +
scene = load_scene_file(SCENE, comm)
rows, curves = [], {}
for method in METHODS:
    sol, run = run_scene(scene, SolveRequest.parse(method))
    data = run.to_json()
    (lame,) = data["lame"]
    c = data["contacts"][0]
    pv = sol.pairs[0]
    theta = np.degrees(np.arctan2(pv.x[:, 1], pv.x[:, 0]))
    order = np.argsort(theta)
    curves[method] = (theta[order], sol.pressure[pv.rows][order])
    rows.append(
        {
            "method": method,
            "p_mean": lame["p_mean"],
            "p_exact": lame["p_exact"],
            "error": lame["error"],
            "active": f"{c['active_nodes']}/{c['multipliers']}",
            "initial_overlap": c["initial_overlap"],
        }
    )
say("| method | mean pressure | Lame | error | active | initial overlap |")
say("|---|---|---|---|---|---|")
for r in rows:
    say(
        f"| {r['method']} | {r['p_mean']:.5g} | {r['p_exact']:.5g} | "
        f"{100 * r['error']:.3f} % "
        f"| {r['active']} | {r['initial_overlap']:.3e} |"
    )
# -

# ## The pressure along the interface
#
# Lame's pressure is uniform. Mortar and STS integrate the gap over the segments and are
# uniform to about 0.2 %; NTS collocates the gap at the nodes: the two end nodes on the
# symmetry lines get no row (47 multipliers instead of 49), their neighbours carry their
# share (up to 45 MPa) and its mean is about 2 % off. Penalty leaves the penetration
# $p/\varepsilon$, negligible at its default stiffness here.

# +
if comm.rank == 0:
    OUT.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(7, 4))
    for method, (theta, p) in curves.items():
        ax.plot(theta, p, marker=".", label=method)
    ax.axhline(rows[0]["p_exact"], color="k", ls="--", label="Lame")
    ax.set_xlabel("angle (degrees)")
    ax.set_ylabel("contact pressure (MPa)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(OUT / "pressure.png", dpi=120)
    plt.close(fig)
# -

# ## Checks
#
# Mortar (the method of choice on non-matching curved interfaces) is within 1 % of Lame with
# every node of the pair active; the initial overlap is the drawn interference.

# +
mortar = rows[0]
assert mortar["error"] < 0.01, mortar
assert mortar["active"] == "49/49", mortar
assert abs(mortar["initial_overlap"] / 0.002 - 1) < 1e-3, mortar
assert rows[1]["error"] < 0.01, rows[1]
say("all checks passed")
# -
