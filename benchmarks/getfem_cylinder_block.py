"""GetFEM: a cylinder pressed on a block with friction during the approach, then pushed.

The independent computation for tests/scenes/cylinder_block.toml: the same mesh
(tests/scenes/cylinder_block.geo, meshed by the gmsh of contactfx's environment and written as
a .msh), the same materials (E = 1000, nu = 0.3, plane strain), mu = 0.3 from the first step,
the cylinder's flat face moved by (0, -0.03) in step 1 and by (0.01, -0.03) in step 2, the
block's bottom held. GetFEM 5.4, Coulomb's law in its weak-form language: a Q1 vector
multiplier lam (the contact stress on the cylinder) on the cylinder's arc, Q1 displacements,
each arc point facing the block's point below it (an interpolate transformation
`[X(1);0]`: small sliding on the flat block), the gap and the slip increment since the
previous step (the displacements wt1, wt2 of the step before) along a contact direction n,
and the non-symmetric Alart-Curnier law lam = Coulomb_friction_coupled_projection(lam, n,
slip, gap, mu, r) (GetFEM's operator, r = E / h) tested with the multiplier's test functions,
Newton on the whole system with MUMPS. `--frame flat`: n the block's normal, (0, -1);
`--frame bisector`: the bisector of the block's and the cylinder's normals, as contactfx's
rows (docs/friction_verification.md). GetFEM's packaged brick
(`add_integral_contact_between_nonmatching_meshes_brick`) is not usable here: it projects
only points closer to the master than 5 % of an element (getfem_projected_fem.cc), so the
cylinder's initial gap leaves all but a few points out of contact.
Run with Debian's python (`apt-get install python3-getfem`), not contactfx's environment:

    .venv/bin/python benchmarks/cylinder_block_compare.py --write-mesh /tmp/cylinder_block.msh
    /usr/bin/python3 benchmarks/getfem_cylinder_block.py /tmp/cylinder_block.msh \
        --frame bisector --json benchmarks/getfem_cylinder_block_bisector.json

(benchmarks/cylinder_block_compare.py lists every run committed.)

The JSON holds per step the arc nodes' x, y, the multiplier there (the contact stress on the
cylinder, x and y components, per unit length of the arc), the pressure and shear in the
bisector frame of the circle's normal and the block's, the slip increment (x, y), the force
on the cylinder, the Newton iterations and the solve's wall time;
benchmarks/cylinder_block_compare.py reads it beside a contactfx solve.
"""

from __future__ import annotations

import argparse
import json
import time

import getfem as gf
import numpy as np

gf.util("trace level", 0)

E, NU, MU = 1000.0, 0.3, 0.3
PRESS, PUSH = 0.03, 0.01
NOISY: list[str] = []
FRAMES = {
    "flat": "[0;-1]",
    "bisector": "Normalized([X(1);X(2)-1]+[0;-1])",  # R = 1, the centre at (0, 1)
}
R = 1.0  # the cylinder's radius (its centre at (0, R))


def read_msh22(path: str) -> tuple[np.ndarray, dict[str, list[np.ndarray]]]:
    """Nodes (n, 2) and, per physical name, the node ids (0-based) of its quads or lines."""
    lines = open(path).read().split("\n")
    i = lines.index("$PhysicalNames")
    names = {}
    for k in range(int(lines[i + 1])):
        dim, tag, name = lines[i + 2 + k].split(maxsplit=2)
        names[(int(dim), int(tag))] = name.strip('"')
    i = lines.index("$Nodes")
    n = int(lines[i + 1])
    raw = np.array([list(map(float, lines[i + 2 + k].split())) for k in range(n)])
    index = {int(t): k for k, t in enumerate(raw[:, 0])}
    nodes = raw[:, 1:3]
    i = lines.index("$Elements")
    groups: dict[str, list[np.ndarray]] = {}
    for k in range(int(lines[i + 1])):
        f = list(map(int, lines[i + 2 + k].split()))
        etype, ntags = f[1], f[2]
        dim = {1: 1, 3: 2}.get(etype)
        if dim is None:
            continue
        name = names[(dim, f[3])]
        groups.setdefault(name, []).append(np.array([index[t] for t in f[3 + ntags :]]))
    return nodes, groups


def body_mesh(nodes: np.ndarray, quads: list[np.ndarray]) -> gf.Mesh:
    """A GetFEM mesh of the quads (gmsh's counter-clockwise nodes to GetFEM's tensor order)."""
    m = gf.Mesh("empty", 2)
    gt = gf.GeoTrans("GT_QK(2,1)")
    q = np.array(quads)[:, [0, 1, 3, 2]]
    pts = np.transpose(nodes[q], (2, 1, 0))  # (dim, 4, cells)
    m.add_convex(gt, pts)
    return m


def faces_on(m: gf.Mesh, segments: list[np.ndarray], nodes: np.ndarray) -> np.ndarray:
    """The (convex, face) pairs of m's outer faces whose midpoints are those of `segments`."""
    faces = m.outer_faces()
    mids = []
    for cv, f in faces.T:
        pid = m.pid_in_faces(np.array([[cv], [f]]))
        mids.append(m.pts(pid).mean(axis=1))
    mids = np.array(mids)
    want = np.array([nodes[s].mean(axis=0) for s in segments])
    d = np.linalg.norm(mids[:, None, :] - want[None, :, :], axis=2)
    hit = d.min(axis=1) < 1e-10
    if hit.sum() != len(segments):
        raise SystemExit(f"found {hit.sum()} of {len(segments)} faces")
    return faces[:, hit]


def frame(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bisector normal (towards the cylinder) and tangent at arc points: of the block's (0, 1)
    and the cylinder's outward normal (the circle's; contactfx averages its segments')."""
    n_cyl = np.stack([x, y - R], axis=1) / R
    n = np.array([0.0, 1.0]) - n_cyl
    n /= np.linalg.norm(n, axis=1)[:, None]
    return n, np.stack([n[:, 1], -n[:, 0]], axis=1)


def main() -> None:
    """Solve both steps (--repeat times, for the timings) and write the JSON."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("msh", help="tests/scenes/cylinder_block.geo meshed, gmsh format 2.2")
    ap.add_argument("--json", help="write the results here")
    ap.add_argument("--r", type=float, default=None, help="augmentation (default E / h)")
    ap.add_argument("--frame", choices=sorted(FRAMES), default="flat")
    ap.add_argument("--repeat", type=int, default=1, help="solves (the wall time's median)")
    args = ap.parse_args()
    runs = [solve_once(args) for _ in range(args.repeat)]
    out = runs[-1]
    walls = [sum(s["wall_s"] for s in r["steps"]) for r in runs]
    out["wall_s_runs"] = walls
    out["wall_s_median"] = float(np.median(walls))
    print(f"both steps: {out['wall_s_median']:.2f} s (median of {len(walls)})")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1)
            fh.write("\n")


def solve_once(args: argparse.Namespace) -> dict:
    """Build the model and solve both steps: the JSON's content."""
    t_setup = time.perf_counter()
    nodes, groups = read_msh22(args.msh)
    m1, m2 = body_mesh(nodes, groups["cylinder"]), body_mesh(nodes, groups["block"])
    ARC, FLAT, TOP, BOTTOM = 1, 2, 3, 4
    m1.set_region(ARC, faces_on(m1, groups["cylinder_arc"], nodes))
    m1.set_region(FLAT, faces_on(m1, groups["cylinder_flat"], nodes))
    m2.set_region(TOP, faces_on(m2, groups["block_top"], nodes))
    m2.set_region(BOTTOM, faces_on(m2, groups["block_bottom"], nodes))
    seg = np.array([np.linalg.norm(np.diff(nodes[s], axis=0)) for s in groups["cylinder_arc"]])
    h = float(seg.min())

    mfu1, mfu2 = gf.MeshFem(m1, 2), gf.MeshFem(m2, 2)
    mfu1.set_classical_fem(1)
    mfu2.set_classical_fem(1)
    mfl = gf.MeshFem(m1, 2)
    mfl.set_classical_fem(1)
    mim1 = gf.MeshIm(m1, gf.Integ("IM_GAUSS_PARALLELEPIPED(2,6)"))
    mim2 = gf.MeshIm(m2, gf.Integ("IM_GAUSS_PARALLELEPIPED(2,6)"))

    md = gf.Model("real")
    md.add_fem_variable("u1", mfu1)
    md.add_fem_variable("u2", mfu2)
    lam = E * NU / ((1 + NU) * (1 - 2 * NU))  # plane strain
    mu_lame = E / (2 * (1 + NU))
    md.add_initialized_data("lambda", [lam])
    md.add_initialized_data("mu", [mu_lame])
    md.add_isotropic_linearized_elasticity_brick(mim1, "u1", "lambda", "mu")
    md.add_isotropic_linearized_elasticity_brick(mim2, "u2", "lambda", "mu")
    md.add_initialized_data("D1", [0.0, -PRESS])
    md.add_Dirichlet_condition_with_simplification("u1", FLAT, "D1")
    md.add_Dirichlet_condition_with_simplification("u2", BOTTOM)

    md.add_filtered_fem_variable("lam", mfl, ARC)
    r = args.r if args.r is not None else E / h
    md.add_initialized_data("r", [r])
    md.add_initialized_data("f", [MU])
    md.add_initialized_fem_data("wt1", mfu1, np.zeros(mfu1.nbdof()))
    md.add_initialized_fem_data("wt2", mfu2, np.zeros(mfu2.nbdof()))
    # Small sliding on the flat block: each arc point faces the block's point below it.
    md.add_interpolate_transformation_from_expression("proj", m1, m2, "[X(1);0]")
    # The contact direction (the cylinder's outward one): the block's (flat, the half-plane
    # theory's) or the bisector of the block's and the cylinder's (contactfx's rows).
    normal = FRAMES[args.frame]
    gap = f"((Interpolate(X,proj)+Interpolate(u2,proj)-X-u1).{normal})"
    slip = "(u1-wt1-Interpolate(u2,proj)+Interpolate(wt2,proj))"
    # lam is the contact stress on the cylinder; Alart-Curnier: lam = P(lam, n, slip, gap),
    # P = -(lam.n + r gap)_- n + P_B(n, f (lam.n + r gap)_-)(lam - r slip) (GetFEM's operator).
    md.add_nonlinear_term(mim1, "-lam.Test_u1 + lam.Interpolate(Test_u2,proj)", ARC)
    md.add_nonlinear_term(
        mim1,
        f"(1/r)*(Coulomb_friction_coupled_projection(lam,{normal},{slip},{gap},f,r)-lam).Test_lam",
        ARC,
    )
    t_setup = time.perf_counter() - t_setup

    # The multiplier's dofs on the arc, in the filtered variable's order (pairs of x, y).
    dofs = mfl.basic_dof_on_region(ARC)
    xy = mfl.basic_dof_nodes(dofs)[:, ::2].T
    steps = []
    for k, d1 in enumerate(([0.0, -PRESS], [PUSH, -PRESS])):
        md.set_variable("D1", d1)
        t0 = time.perf_counter()
        nbit, converged = md.solve("max_res", 1e-10, "max_iter", 100, "lsolver", "mumps", *NOISY)
        wall = time.perf_counter() - t0
        lam_v = md.variable("lam").reshape(-1, 2)
        # The step's slip increment at the arc nodes (cylinder relative to block).
        vs = np.asarray(md.interpolation(slip, mfl, ARC))
        vs = (vs[dofs] if vs.size == mfl.nbdof() else vs).reshape(-1, 2)
        force = gf.asm("generic", mim1, 0, "lam", ARC, md)
        # Contact stress on the cylinder: its normal part along the bisector is the pressure.
        n, t = frame(xy[:, 0], xy[:, 1])
        sign = 1.0 if force[1] > 0 else -1.0  # oriented so that the cylinder is pushed up
        trac = sign * lam_v
        steps.append(
            {
                "step": k + 1,
                "iterations": int(nbit),
                "converged": bool(converged),
                "wall_s": wall,
                "force": (sign * np.asarray(force)).tolist(),
                "x": xy[:, 0].tolist(),
                "y": xy[:, 1].tolist(),
                "traction": trac.tolist(),
                "pressure": np.einsum("ij,ij->i", trac, n).tolist(),
                "shear": (-np.einsum("ij,ij->i", trac, t)).tolist(),
                "slip_increment": vs.tolist(),
            }
        )
        print(
            f"step {k + 1}: {nbit} iterations, converged {bool(converged)}, "
            f"{wall:.2f} s, force on the cylinder {sign * np.asarray(force)}"
        )
        md.set_variable("wt1", md.variable("u1"))
        md.set_variable("wt2", md.variable("u2"))
    out = {
        "code": "GetFEM " + gf.getfem_env("version") if hasattr(gf, "getfem_env") else "GetFEM",
        "method": "Alart-Curnier Coulomb law in the weak-form language "
        "(Coulomb_friction_coupled_projection), small sliding on the block, Q1 displacements, "
        "Q1 vector multiplier on the cylinder's arc, Newton with MUMPS",
        "dofs": int(mfu1.nbdof() + mfu2.nbdof()),
        "multiplier_dofs": len(dofs),
        "h": h,
        "frame": args.frame,
        "normal": FRAMES[args.frame],
        "r": r,
        "setup_s": t_setup,
        "steps": steps,
    }
    return out


if __name__ == "__main__":
    main()
