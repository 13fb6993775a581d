# # Two elastic blocks in frictionless contact: the paper's scenes S1-S4
#
# A block B2 (width $l_2$) is pressed onto a wider block B1 (width $l_1$) by a uniform
# pressure $p$ on its top; by symmetry we model the right half. B2 is held vertically *only*
# by the contact, so the elastic stiffness matrix alone is singular and the Lagrange
# multipliers carry the whole load. We solve the four scenes of the paper (see `SPEC.md`):
#
# | scene | what it tests |
# |---|---|
# | S1 | same material, matching meshes: all methods agree |
# | S2 | same material, non-matching meshes (0.08 / 0.1 cm) |
# | S3 | base 10x stiffer, non-matching meshes |
# | S4 | equal widths, non-matching and graded meshes: the **contact patch test** |
#
# with every contact discretization (node-to-surface `nts`, surface-to-surface with Gauss
# points `sts`, segment-based mortar `mortar`) and, on S2-S4, both choices of the active
# (slave) body. For each scene it writes $\sigma_{yy}$ of both bodies along the contact line
# (the paper's Figs. 4-8), the deformed fields scaled x100 (Fig. 3) and a table of the
# interface mismatch. Units: cm and MPa.

# +
import json
import os
import time
from pathlib import Path

import dolfinx_solver  # noqa: F401
import matplotlib
import numpy as np
from mpi4py import MPI

from contactfx import SolveRequest
from contactfx.api import run_case
from contactfx.options import Method
from contactfx.results.figures import deformed_fields
from contactfx.results.paper import mismatch, patch_errors
from contactfx.results.stress import body_stress_deviation
from contactfx.scenes import BLOCK_SCENES

matplotlib.use("Agg")
import matplotlib.pyplot as plt

comm = MPI.COMM_WORLD
OUT = Path(os.environ.get("CONTACTFX_RESULTS", "results")) / "blocks"
METHODS = [Method.NTS, Method.STS, Method.MORTAR, Method.SCHWARZ]
# CONTACTFX_QUICK=1 (the test suite): the same solves and checks, one field picture (S4).
QUICK = os.environ.get("CONTACTFX_QUICK") == "1"


def say(*args: object) -> None:
    if comm.rank == 0:
        print(*args, flush=True)


# -

# ## Solve every scene with every method
#
# `run_case` meshes the scene with gmsh, assembles the elasticity forms with DOLFINx, builds
# the contact operator $B$ and the weighted gap, and solves the saddle-point system
# $[[K, B^T], [B, 0]]$ (MUMPS on the PETSc MatNest) inside the active-set loop, which here
# stops after one solve because the whole contact line stays in contact.

# +
rows = []
t0 = time.perf_counter()
for name, params in BLOCK_SCENES.items():
    for active in (2,) if name == "S1" else (2, 1):
        for method in METHODS:
            sol, data = run_case(
                "blocks", params, SolveRequest.parse(method), active=active, comm=comm
            )
            data = data.to_json()
            corner = params.l2 / 2
            row = {
                "scene": name,
                "method": method.value,
                "active": active,
                "multipliers": data["multipliers"],
                "dofs": data["dofs"],
                "contact_force": data["contact_force"],
                "force_error": abs(
                    data["contact_force"] / (params.p * params.l2 / 2) - 1
                ),
                "time": data["times"]["total"],
                **{
                    f"mismatch_{k}": v
                    for k, v in mismatch(data["interface"], corner).items()
                },
            }
            if name == "S4":
                dev = body_stress_deviation(sol, -params.p)
                row.update(
                    {
                        f"patch_{k}": v
                        for k, v in patch_errors(data["interface"], params.p).items()
                    }
                )
                row.update({f"patch_field_{k}": v for k, v in dev.items()})
            row["interface"] = data["interface"]
            rows.append(row)
            say(
                f"{name} {method.value:7s} active={active}: force error "
                f"{row['force_error']:.1e}, mismatch centre "
                f"{row['mismatch_center']:.3g} MPa, "
                f"corner {row['mismatch_corner']:.3g} MPa ({row['time']:.2f} s)"
            )
            if method == Method.MORTAR and active == 2 and (name == "S4" or not QUICK):
                pic = deformed_fields(sol, OUT / f"{name}_fields.png")
                if pic:
                    say(f"   wrote {pic}")
say(f"{len(rows)} solves in {time.perf_counter() - t0:.1f} s")
# -

# ## $\sigma_{yy}$ along the contact line
#
# One chart per scene: solid lines are the base B1, dashed lines the top block B2, one
# colour per method; left panel with B2 active, right panel with B1 active.

# +
if comm.rank == 0:
    OUT.mkdir(parents=True, exist_ok=True)
    for name, params in BLOCK_SCENES.items():
        actives = (2,) if name == "S1" else (2, 1)
        fig, axes = plt.subplots(
            1,
            len(actives),
            figsize=(6.5 * len(actives), 4.2),
            squeeze=False,
            layout="constrained",
        )
        for ax, active in zip(axes[0], actives, strict=True):
            for k, row in enumerate(
                r for r in rows if r["scene"] == name and r["active"] == active
            ):
                itf = row["interface"]
                x = np.asarray(itf["x"])
                for key, style in (("sigma_yy_1", "-"), ("sigma_yy_2", "--")):
                    y = np.array(
                        [np.nan if v is None else v for v in itf[key]], dtype=float
                    )
                    if name == "S4":
                        # The exact state is uniform: plot the relative error on a log axis.
                        y = np.maximum(np.abs(y / params.p + 1), 1e-16)
                    ax.plot(
                        x,
                        y,
                        style,
                        color=f"C{k}",
                        lw=1.2,
                        marker=".",
                        ms=3,
                        label=f"{row['method']} body {key[-1]}",
                    )
            ax.set_title(f"{name}: sigma_yy on the contact line, body {active} active")
            ax.set_xlabel("x (cm)")
            ax.set_ylabel("sigma_yy (MPa)")
            if name == "S4":
                ax.set_yscale("log")
                ax.set_ylim(1e-16, 10)
                ax.set_ylabel("|sigma_yy / p + 1|  (exact: 0)")
                ax.set_title(f"S4 patch test: error of sigma_yy, body {active} active")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8, ncol=2)
        fig.savefig(OUT / f"{name}_sigma_yy.png", dpi=110)
        plt.close(fig)
    say(f"wrote charts to {OUT}/")
# -

# ## The table
#
# Mismatch = max $|\sigma_{yy}^{(1)} - \sigma_{yy}^{(2)}|$ (MPa) along the contact line, away
# from the corner (first 90 % of the line) and next to it (last 10 %); for S4 the patch-test
# errors max $|\sigma_{yy}/p + 1|$ over all cells of each body and max $|\lambda/p - 1|$.

# +
if comm.rank == 0:
    header = (
        "| scene | method | active | mismatch centre (MPa) | mismatch corner (MPa) | "
        "S4: body 1 | S4: body 2 | S4: pressure | time (s) |"
    )
    lines = [header, "|" + "---|" * 9]
    for r in rows:
        patch = [
            f"{r[k]:.1e}" if k in r else ""
            for k in ("patch_field_body1", "patch_field_body2", "patch_pressure")
        ]
        lines.append(
            f"| {r['scene']} | {r['method']} | {r['active']} | "
            f"{r['mismatch_center']:.3g} | {r['mismatch_corner']:.3g} | "
            + " | ".join(patch)
            + f" | {r['time']:.2f} |"
        )
    table = "\n".join(lines)
    (OUT / "table.md").write_text(table + "\n")
    (OUT / "summary.json").write_text(
        json.dumps(
            [{k: v for k, v in r.items() if k != "interface"} for r in rows], indent=1
        )
    )
    print(table)
# -

# ## Checks
#
# Every block scene transmits exactly the applied load; the mortar variant passes the
# contact patch test S4 to round-off with either body active; on S1 (matching meshes) all
# methods agree to 0.1 % away from the corner.

# +
for r in rows:
    assert r["force_error"] < 1e-10, r
for r in rows:
    if r["scene"] == "S4" and r["method"] == "mortar":
        assert (
            max(r["patch_field_body1"], r["patch_field_body2"], r["patch_pressure"])
            < 1e-8
        ), r
s1 = [r for r in rows if r["scene"] == "S1"]
ref = np.array(s1[0]["interface"]["sigma_yy_2"], dtype=float)
xs = np.asarray(s1[0]["interface"]["x"])
far = xs < 0.9 * BLOCK_SCENES["S1"].l2 / 2
for r in s1[1:]:
    other = np.array(r["interface"]["sigma_yy_2"], dtype=float)
    assert np.max(np.abs(other[far] / ref[far] - 1)) < 1e-3, r["method"]
say("all checks passed")
