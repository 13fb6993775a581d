# # Rigid obstacles: an indenter and a punch with no mesh of their own
#
# "Model no more than a scene needs." A steel indenter on rubber, a punch, a rigid floor:
# meshing such a body as a second elastic body costs DOFs and conditioning for nothing. An
# `[[obstacle]]` is an analytic rigid surface (a circle, a plane or a polyline) that one
# curve group of a body may touch, moved rigidly by a prescribed displacement. Every method
# works against it: `nts`, `sts`, `mortar` (standard or dual basis) and `penalty`.
#
# Two classic problems check it, each with only the elastic block meshed
# (`meshes/rigid_block.geo`: the block $[0, 20] \times [-20, 0]$, half model by
# symmetry at $x = 0$, $E = 7000$, $\nu = 0.3$, plane strain):
#
# 1. **A rigid cylinder** ($R = 20$) pushed $0.05$ into the block: plane-strain Hertz with
#    $E_2 \to \infty$, so $E^* = E / (1 - \nu^2)$ and, for the line load $P$ the contact
#    carries, $a = \sqrt{4 P R / (\pi E^*)}$ and $p_0 = 2P / (\pi a)$.
# 2. **A rigid flat punch** of half-width $b = 1$ pushed $0.01$ into the block: Sadowsky's
#    pressure $p(x) = P / (\pi \sqrt{b^2 - x^2})$ for $|x| < b$, singular at the edges.
#
# Both are displacement controlled: the load $P$ is a result (twice the half model's
# force), and the references are evaluated with it. The demo takes a few seconds (3.7k
# DOFs per solve), so it has no quick mode.

# +
import os
import time
from pathlib import Path

import dolfinx_solver  # noqa: F401
import matplotlib
import numpy as np
from mpi4py import MPI

from contactfx import (
    HertzReference,
    Obstacle,
    SolveRequest,
    load_scene_file,
    run_scene,
    scene_from_gmsh,
)
from contactfx.results.references import exact_pressure, hertz_summary
from contactfx.scenes import Dirichlet

matplotlib.use("Agg")
import matplotlib.pyplot as plt

comm = MPI.COMM_WORLD
OUT = Path(os.environ.get("CONTACTFX_RESULTS", "results")) / "obstacles"
SCENES = Path(__file__).resolve().parent / "scenes"
MESHES = Path(__file__).resolve().parents[1] / "meshes"  # the scenes' gmsh geometry
METHODS = [
    ("nts", {}),
    ("sts", {}),
    ("mortar", {}),
    ("mortar", {"basis": "dual"}),
    ("penalty", {}),
]


def say(*args: object) -> None:
    if comm.rank == 0:
        print(*args, flush=True)


def label(method: str, options: dict) -> str:
    return method + ("-dual" if options.get("basis") == "dual" else "")


# -

# ## The indenter: a scene file with an `[[obstacle]]`
#
# `demos/scenes/rigid_indenter.toml` is an ordinary scene file with one body and one
# obstacle table instead of a second body and a `[[contact]]` pair:
#
# ```toml
# [[obstacle]]
# name = "indenter"            # label in the JSON and the output files
# shape = "circle"             # "circle" | "plane" | "polyline"
# center = [0.0, 20.0]         # touches the block's top at the origin
# radius = 20.0
# displacement = [0.0, -0.05]  # prescribed rigid motion
# surface = "top"              # the body's curve group that may touch it
# ```
#
# The gap and the normal are the circle's exact ones at every quadrature point (or node,
# for NTS); the obstacle's motion enters the gap. The JSON has one `contacts` entry for the
# obstacle, `passive` being its name, `force` the force on the block and `force_passive`
# the force on the indenter.

# +
indenter = load_scene_file(SCENES / "rigid_indenter.toml", comm)
hertz = {}
for method, options in METHODS:
    t0 = time.perf_counter()
    sol, data = run_scene(indenter, SolveRequest.parse(method, **options))
    data = data.to_json()
    c = data["contacts"][0]
    P = 2.0 * abs(c["force"][1])
    h = hertz_summary(sol, HertzReference(0, 20.0, P, symmetric=True)).to_json()
    hertz[label(method, options)] = (h, c)
    say(
        f"{label(method, options):12s} P = {P:.4f}: a "
        f"{100 * (h['a'] / h['a_exact'] - 1):+.2f} %, "
        f"p0 {100 * (h['p0'] / h['p0_exact'] - 1):+.2f} %, L2 "
        f"{100 * h['l2_error']:.2f} %, "
        f"{c['active_nodes']} active nodes, balance {c['balance']:.1e}, "
        f"{time.perf_counter() - t0:.2f} s"
    )
h = hertz["mortar"][0]
say(f"exact (E* = {h['E_star']:.2f}): a = {h['a_exact']:.4f}, p0 = {h['p0_exact']:.3f}")
# -

# The same obstacle from Python, on the same `.geo`:

# +
same = scene_from_gmsh(
    MESHES / "rigid_block.geo",
    bodies={"block": {"E": 7000.0, "nu": 0.3}},
    dirichlet=[Dirichlet("symmetry", ux=0.0), Dirichlet("base", uy=0.0)],
    obstacles=[
        Obstacle(
            "indenter",
            "circle",
            "top",
            center=(0, 20),
            radius=20,
            displacement=(0, -0.05),
        )
    ],
    comm=comm,
)
_, again = run_scene(same, SolveRequest.parse("mortar"))
again = again.to_json()
say(f"Python API: force {again['contacts'][0]['force']}")
# -

# ## The flat punch: a polyline
#
# `demos/scenes/rigid_punch.toml` gives the punch by its face alone, an open polyline from
# $(-1, 0)$ to $(1, 0)$ with the punch on the left of the points in order (above) and the
# block on the right (below). Beyond the polyline's ends the obstacle says nothing, so the
# block's top is free there. (With the punch's sides in the polyline as well, its corners
# would push the edge node along their bisector: give a flat punch as its face.)
#
# Sadowsky's pressure is singular at $x = \pm b$: we compare at the nodes with
# $|x| \le b/2$, and over the whole face in the $L^1$ norm (finite, the singularity is
# integrable; with $x = b \sin\theta$ the exact integrand is the constant $P / \pi$).


# +
def sadowsky(c: dict, b: float = 1.0) -> tuple[float, float, float]:
    """P, the max error at |x| <= b/2 (relative to p(0)), the L1 error over the face."""
    P = 2.0 * abs(c["force"][1])
    x, p = np.asarray(c["interface"]["x"]), np.asarray(c["interface"]["pressure"])
    order = np.argsort(x)
    x, p = x[order], p[order]
    inner = x <= 0.5 * b
    exact = P / (np.pi * np.sqrt(b * b - x[inner] ** 2))
    interior = float(np.max(np.abs(p[inner] - exact)) / (P / (np.pi * b)))
    theta = np.linspace(0.0, 0.5 * np.pi, 200001)
    ph = np.interp(b * np.sin(theta), x, p)
    l1 = float(
        np.trapezoid(np.abs(ph * b * np.cos(theta) - P / np.pi), theta) / (0.5 * P)
    )
    return P, interior, l1


punch = load_scene_file(SCENES / "rigid_punch.toml", comm)
flat = {}
for method, options in METHODS:
    _, data = run_scene(punch, SolveRequest.parse(method, **options))
    data = data.to_json()
    c = data["contacts"][0]
    P, interior, l1 = sadowsky(c)
    flat[label(method, options)] = (P, interior, l1, c)
    say(
        f"{label(method, options):12s} P = {P:.4f}: max error |x| <= b/2 "
        f"{100 * interior:.2f} %, "
        f"L1 over the face {100 * l1:.2f} %, {c['active_nodes']} active nodes"
    )
# -

# ## Both pressures against their references

# +
if comm.rank == 0:
    OUT.mkdir(parents=True, exist_ok=True)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4), layout="constrained")
    h = hertz["mortar"][0]
    r = np.linspace(0.0, 1.5 * h["a_exact"], 300)
    ax.plot(
        r,
        exact_pressure(r, h["a_exact"], h["p0_exact"]),
        "k-",
        lw=2,
        alpha=0.4,
        label="Hertz, E2 -> infinity",
    )
    for name, style in zip(hertz, ("o", "s", ".-", "x", "+"), strict=True):
        itf = hertz[name][1]["interface"]
        ax.plot(itf["x"], itf["pressure"], style, ms=4, label=name)
    ax.set_xlim(0, 1.5 * h["a_exact"])
    ax.set_title("rigid cylinder R = 20 on the block")
    P = flat["mortar"][0]
    x = np.linspace(0.0, 0.995, 300)
    bx.plot(x, P / (np.pi * np.sqrt(1 - x**2)), "k-", lw=2, alpha=0.4, label="Sadowsky")
    for name, style in zip(flat, ("o", "s", ".-", "x", "+"), strict=True):
        itf = flat[name][3]["interface"]
        bx.plot(itf["x"], itf["pressure"], style, ms=3, label=name)
    bx.set_xlim(0, 1.2)
    bx.set_ylim(0, 5 * P / np.pi)
    bx.set_title("rigid flat punch b = 1 on the block")
    for a_ in (ax, bx):
        a_.set_xlabel("x")
        a_.grid(alpha=0.3)
        a_.legend(fontsize=8)
    ax.set_ylabel("contact pressure")
    fig.savefig(OUT / "obstacles_pressure.png", dpi=120)
    say(f"wrote {OUT / 'obstacles_pressure.png'}")
# -

# ## What the demo asserts
#
# Every method: Hertz's half-width and peak within 1 %, the L2 error under 1 %, the
# indenter's force on the block and the block's on the indenter balancing to round-off;
# Sadowsky's pressure within 1.5 % at $|x| \le b/2$, the $L^1$ error under 15 %, and no
# horizontal force from the flat punch. The Python API gives the scene file's answer.

# +
for name, (h, c) in hertz.items():
    assert abs(h["a"] / h["a_exact"] - 1) < 0.01, (name, h)
    assert abs(h["p0"] / h["p0_exact"] - 1) < 0.01, (name, h)
    assert h["l2_error"] < 0.01, (name, h)
    assert c["balance"] < 1e-10, (name, c["balance"])
for name, (_, interior, l1, c) in flat.items():
    assert interior < 0.015 and l1 < 0.15, (name, interior, l1)
    assert abs(c["force"][0]) < 1e-10 * abs(c["force"][1]), (name, c["force"])
f_api, f_file = again["contacts"][0]["force"], hertz["mortar"][1]["force"]
assert np.allclose(f_api, f_file, rtol=1e-12, atol=0.0), (f_api, f_file)
say("obstacles: all checks passed")
# -
