"""An overkill pressure of the built-in Hertz scene: the reference floor of issue 30.

The adapt loop measures a level's pressure against analytic Hertz (a half-space), but the
built-in scene is a finite body (R 60 on a 60 x 60 block): Hertz has a model error of its
own. This solves the *same* scene (geometry, materials, load, supports, mortar with the
standard basis, MUMPS) on the structured mesher at sizes (h_contact, slope, h_far) scaled
together, and stores each solve's pressure along the active surface (x, p: x is Hertz's r,
the distance from the symmetry axis) in one small .npz. `compare` prints analytic Hertz
against each overkill (as the loop measures a level's error: the relative L2 over
[0, 1.5 a]) and the overkills against each other (their convergence).

Run (serial, one solve per process: each frees its factorization):
python benchmarks/hertz_overkill.py solve 0.002:0.1:2 /tmp/ok1.npz
python benchmarks/hertz_overkill.py solve 0.0014142:0.070711:1.41421 /tmp/ok2.npz
python benchmarks/hertz_overkill.py solve 0.001:0.05:1 /tmp/ok3.npz
python benchmarks/hertz_overkill.py compare /tmp/ok1.npz /tmp/ok2.npz /tmp/ok3.npz
    --npz benchmarks/hertz_overkill.npz --json benchmarks/hertz_overkill.json
docs/adapt.md ("The reference floor") has the numbers.
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import time
from pathlib import Path

import numpy as np

# Hertz's a and p0 of the default scene (scenes/builtin.hertz_exact), for the window [0, 1.5 a].
WINDOW = 1.5


def l2_between(
    x: np.ndarray, p: np.ndarray, xr: np.ndarray, pr: np.ndarray, upto: float
) -> tuple[float, float]:
    """(||p - pr||, ||pr||) over [0, upto] of two piecewise-linear pressures, exactly.

    Both are interpolated on the union of their nodes and the window's ends (zero outside
    their nodes, as the loop's l2_error does), where the difference is piecewise linear.
    """
    s = np.union1d(np.union1d(x, xr), [0.0, upto])
    s = s[(s >= 0.0) & (s <= upto)]
    a = np.interp(s, x, p, left=0.0, right=0.0)
    b = np.interp(s, xr, pr, left=0.0, right=0.0)

    def norm(v: np.ndarray) -> float:
        h, v0, v1 = np.diff(s), v[:-1], v[1:]
        return float(np.sqrt(np.sum(h * (v0 * v0 + v0 * v1 + v1 * v1) / 3.0)))

    return norm(a - b), norm(b)


def solve_one(spec: str, out: Path) -> None:
    """One overkill solve (structured mesh, mortar, MUMPS); its pressure curve to `out`."""
    import dolfinx_solver  # noqa: F401  (the PETSc of the wheel)

    from contactfx.api import solve
    from contactfx.results.references import centre_distance, hertz_summary
    from contactfx.scenes.builtin import HertzParams, hertz

    mesher, *sizes = spec.split(":")
    h0, h_edge, slope, h_far = (float(v) for v in sizes)
    t0 = time.perf_counter()
    params = HertzParams(mesh=mesher, refine=h0, refine_edge=h_edge, slope=slope, h_far=h_far)
    scene = hertz(params)
    sol = solve(scene, "mortar", solver="mumps", basis="standard")
    seconds = time.perf_counter() - t0
    ref = scene.references[0]
    r, p, _, _, _ = centre_distance(sol, ref)  # type: ignore[arg-type]
    order = np.argsort(r, kind="stable")
    hs = hertz_summary(sol)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    np.savez(
        out,
        x=r[order],
        p=p[order],
        spec=np.array([h0, h_edge, slope, h_far]),
        mesher=np.array(mesher),
        dofs=np.array(sol.dofs),
        a_exact=np.array(hs.a_exact),
        p0_exact=np.array(hs.p0_exact),
        hertz_l2=np.array(hs.l2_error),
        a_fit=np.array(hs.a if hs.a is not None else np.nan),
        seconds=np.array(seconds),
        peak_mb=np.array(peak_mb),
    )
    print(
        f"{spec}: {sol.dofs:,} DOFs, Hertz L2 {100 * hs.l2_error:.4f} %, a {hs.a} "
        f"(exact {hs.a_exact:.6f}), {seconds:.1f} s, peak {peak_mb:.0f} MB",
        flush=True,
    )


def load(path: Path) -> dict[str, np.ndarray]:
    """One solve's arrays."""
    with np.load(path) as f:
        return {k: f[k] for k in f.files}


def hertz_against(ok: dict[str, np.ndarray]) -> float:
    """Analytic Hertz's relative L2 distance from an overkill, over [0, 1.5 a]."""
    from contactfx.results.references import l2_error

    a, p0 = float(ok["a_exact"]), float(ok["p0_exact"])
    # l2_error(x, p, a, p0) is the loop's measure of a level: here the overkill is the level.
    return l2_error(ok["x"], ok["p"], a, p0, samples=400001)


def compare(
    paths: list[Path],
    npz: Path | None,
    out: Path | None,
    key: str = "overkills",
    reference: Path | None = None,
) -> None:
    """Hertz against each overkill, each overkill against the next; optionally stored.

    `reference` (a compare --npz file): each solve's distance from its finest curve too.
    `out` gains (or replaces) the list `key`; `npz` holds the curves near the zone.
    """
    oks = [load(p) for p in paths]
    ref = finest(reference) if reference is not None else None
    rows = []
    for k, ok in enumerate(oks):
        upto = WINDOW * float(ok["a_exact"])
        row = {
            "mesher": str(ok.get("mesher", "structured")),
            "spec": ok["spec"].tolist(),
            "dofs": int(ok["dofs"]),
            "seconds": float(ok["seconds"]),
            "peak_mb": float(ok["peak_mb"]),
            "a_fit": float(ok["a_fit"]),
            "a_exact": float(ok["a_exact"]),
            "hertz_l2": float(ok["hertz_l2"]),
            "hertz_l2_fine": hertz_against(ok),
        }
        if k + 1 < len(oks):
            d, n = l2_between(ok["x"], ok["p"], oks[-1]["x"], oks[-1]["p"], upto)
            row["to_finest"] = d / n
            d, n = l2_between(ok["x"], ok["p"], oks[k + 1]["x"], oks[k + 1]["p"], upto)
            row["to_next"] = d / n
        if ref is not None:
            d, n = l2_between(ok["x"], ok["p"], ref[0], ref[1], upto)
            row["to_reference"] = d / n
        rows.append(row)
        print(json.dumps(row), flush=True)
    if npz is not None:
        arrays = {}
        for k, ok in enumerate(oks):
            # The window and a margin only: what the comparisons read (keeps the file small).
            keep = ok["x"] <= 2.0 * float(ok["a_exact"])
            for name in ("x", "p"):
                arrays[f"{name}{k}"] = ok[name][keep]
            arrays[f"spec{k}"] = ok["spec"]
            arrays[f"mesher{k}"] = ok.get("mesher", np.array("structured"))
            arrays[f"dofs{k}"] = ok["dofs"]
        arrays["a_exact"] = oks[-1]["a_exact"]
        arrays["p0_exact"] = oks[-1]["p0_exact"]
        np.savez_compressed(npz, **arrays)
    if out is not None:
        data = json.loads(out.read_text()) if out.exists() else {}
        data[key] = rows
        out.write_text(json.dumps(data, indent=1) + "\n")


def finest(npz: Path) -> tuple[np.ndarray, np.ndarray, float]:
    """(x, p, a_exact) of the finest overkill stored in `npz` (compare --npz)."""
    with np.load(npz) as f:
        k = max(int(name[4:]) for name in f.files if name.startswith("dofs"))
        return f[f"x{k}"], f[f"p{k}"], float(f["a_exact"])


def main() -> None:
    """solve SPEC OUT | compare NPZ... [--npz FILE] [--json FILE]."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("solve")
    s.add_argument("spec", help="MESHER:h_contact:h_edge:slope:h_far (MESHER gmsh, structured)")
    s.add_argument("out", type=Path)
    c = sub.add_parser("compare")
    c.add_argument("paths", type=Path, nargs="+")
    c.add_argument("--npz", type=Path)
    c.add_argument("--json", type=Path)
    c.add_argument("--key", default="overkills", help="the JSON list these rows go to")
    c.add_argument("--reference", type=Path, help="an npz of compare --npz: distances to it")
    args = ap.parse_args()
    if args.cmd == "solve":
        solve_one(args.spec, args.out)
    else:
        compare(args.paths, args.npz, args.json, args.key, args.reference)


if __name__ == "__main__":
    sys.exit(main())
