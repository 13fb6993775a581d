# # Your own scene: a cylinder squeezed between two blocks
#
# The paper has two scenes; this demo builds a third one from scratch, the way a user brings
# their own geometry: a **gmsh `.geo` file** (the geometry, named physical groups, an
# all-quadrilateral mesh) and a **scene file** (`.toml`: materials, contact pairs, supports,
# loads, and an optional analytic reference). Nothing in contactfx knows this scene.
#
# A steel-like cylinder ($R = 20$, $E = 70000$, $\nu = 0.3$) sits between two softer blocks
# ($E = 7000$, $\nu = 0.3$); the top block carries a pressure whose resultant is the line load
# $P = 100$ per unit thickness. Half model by symmetry at $x = 0$: three bodies and **two
# contact pairs** (cylinder bottom on the lower block, cylinder top on the upper block). The
# cylinder and the top block are held vertically only by contact.
#
# Each pair is a plane-strain Hertz line contact with $1/R^* = 1/R$ (the block is flat) and
# $1/E^* = (1-\nu_c^2)/E_c + (1-\nu_b^2)/E_b$:
# $$a = \sqrt{4 P R^* / (\pi E^*)},\qquad p_0 = 2P/(\pi a).$$
# We solve with every method and check $a$ and $p_0$ of both pairs against these numbers.
# The whole demo takes a few seconds (9k DOFs), so it has no quick mode.

# +
import os
import time
from pathlib import Path

import dolfinx_solver  # noqa: F401
import matplotlib
import numpy as np
from mpi4py import MPI

from contactfx import SolveRequest, load_scene_file, run_scene

matplotlib.use("Agg")
import matplotlib.pyplot as plt

comm = MPI.COMM_WORLD
OUT = Path(os.environ.get("CONTACTFX_RESULTS", "results")) / "own_scene"
TEMPLATE = (
    Path(__file__).resolve().parents[1] / "meshes" / "cylinder_between_blocks.geo"
)
METHODS = ["nts", "sts", "mortar", "penalty"]


def say(*args: object) -> None:
    if comm.rank == 0:
        print(*args, flush=True)


# -

# ## The geometry: a `.geo` file
#
# The shipped `meshes/cylinder_between_blocks.geo` is parametric (`DefineConstant`):
# radius, block size, mesh size at the contacts. We write our own copy with the contact
# sizes we want. What contactfx needs from a `.geo`: one physical surface per body, one
# physical curve per contact surface, named groups for supports and loads, bodies built from
# their own points and curves (so the interface nodes are duplicated) and quadrilaterals only
# (`Mesh.RecombineAll = 1` with `Mesh.Algorithm = 8` and `Mesh.RecombinationAlgorithm = 3`).

# +
OUT.mkdir(parents=True, exist_ok=True)
geo = TEMPLATE.read_text()
# Our contact sizes: 25 cylinder segments and 21 block segments across Hertz's a.
for name, default, value in (("hc_cyl", 0.025, 0.024), ("hc_blk", 0.03, 0.029)):
    geo = geo.replace(f"  {name} = {{{default}", f"  {name} = {{{value}")
geo_path = OUT / "squeezed_cylinder.geo"
if comm.rank == 0:
    geo_path.write_text(geo)
# -

# ## The scene: a `.toml` file
#
# Materials by body (the physical surface names), contact pairs by curve group (active
# first: the cylinder carries the multipliers), rollers on the symmetry line and the base,
# the pressure on the top block, and the Hertz reference of each pair.

# +
P, R, W = 100.0, 20.0, 30.0
scene_toml = f'''
mesh = "{geo_path.name}"

[bodies.lower_block]
E = 7000.0
nu = 0.3
[bodies.cylinder]
E = 70000.0
nu = 0.3
[bodies.upper_block]
E = 7000.0
nu = 0.3

[[contact]]
active = "cyl_bottom_contact"
passive = "lower_block_contact"
[[contact]]
active = "cyl_top_contact"
passive = "upper_block_contact"

[[dirichlet]]
group = "symmetry"
ux = 0.0
[[dirichlet]]
group = "base"
uy = 0.0

[[pressure]]
group = "load"
p = {P / (2 * W)}

[[reference]]
type = "hertz"
pair = 0
R = {R}
P = {P}
symmetric = true
[[reference]]
type = "hertz"
pair = 1
R = {R}
P = {P}
symmetric = true
'''
toml_path = OUT / "squeezed_cylinder.toml"
if comm.rank == 0:
    toml_path.write_text(scene_toml)
comm.Barrier()
scene = load_scene_file(toml_path, comm)
# -

# The same from the command line: `python -m contactfx solve squeezed_cylinder.toml
# --method mortar --json r.json --out out/` (add `mpirun -n 2` in front for two ranks).
#
# ## Every method on both pairs

# +
results = {}
for method in METHODS:
    t0 = time.perf_counter()
    _, data = run_scene(scene, SolveRequest.parse(method))
    data = data.to_json()
    results[method] = data
    for h, c in zip(data["hertz_pairs"], data["contacts"], strict=True):
        say(
            f"{method:8s} pair {h['pair']}: a "
            f"{100 * (h['a'] / h['a_exact'] - 1):+6.2f} %, "
            f"p0 {100 * (h['p0'] / h['p0_exact'] - 1):+6.2f} %, L2 "
            f"{100 * h['l2_error']:5.2f} %, "
            f"force {c['force'][1]:+.8g}, balance {c['balance']:.1e}"
        )
    say(
        f"{method:8s} {data['dofs']} dofs, {data['iterations']} active-set iterations, "
        f"{time.perf_counter() - t0:.2f} s"
    )
# -

# ## The pressure of both pairs against Hertz

# +
if comm.rank == 0:
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True, layout="constrained")
    for k, ax in enumerate(axes):
        h = results["mortar"]["hertz_pairs"][k]
        a, p0 = h["a_exact"], h["p0_exact"]
        r = np.linspace(0.0, 1.6 * a, 300)
        ax.plot(
            r,
            p0 * np.sqrt(np.clip(1 - (r / a) ** 2, 0, None)),
            "k-",
            lw=2,
            alpha=0.4,
            label="exact plane-strain Hertz",
        )
        for method, style in zip(METHODS, ("o", "s", ".-", "x"), strict=True):
            itf = results[method]["contacts"][k]["interface"]
            x = np.asarray(itf["x"])
            ax.plot(np.abs(x), itf["pressure"], style, ms=4, label=method)
        ax.set_xlim(0, 1.6 * a)
        ax.set_xlabel("distance from the contact point along the block (x)")
        ax.set_title(scene.contacts[k].active + " on " + scene.contacts[k].passive)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("contact pressure")
    axes[0].legend()
    fig.savefig(OUT / "squeezed_cylinder_pressure.png", dpi=120)
    say(f"wrote {OUT / 'squeezed_cylinder_pressure.png'}")
# -

# ## What the demo asserts
#
# Mortar matches Hertz on both pairs (half-width and peak within 1 %), every method carries
# the load $P/2$ of the half model through each pair, and each pair's forces on its two
# bodies balance to round-off.

# +
for h in results["mortar"]["hertz_pairs"]:
    assert abs(h["a"] / h["a_exact"] - 1) < 0.01, h
    assert abs(h["p0"] / h["p0_exact"] - 1) < 0.01, h
for method, data in results.items():
    for c in data["contacts"]:
        assert abs(abs(c["force"][1]) - P / 2) < 1e-6 * P, (method, c["force"])
        assert c["balance"] < 1e-8, (method, c["balance"])
say("own scene: all checks passed")
# -
