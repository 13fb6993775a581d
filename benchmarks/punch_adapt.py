"""Adaptive against uniform meshes on the rigid flat punch (demos/scenes/rigid_punch.toml).

Both start from the same ungraded mesh of the block (every size `--h0`, 0.5 by default):
uniform levels halve every size, the adaptive loop (nts, contactfx adapt's sizing) remeshes
from the estimate. Per level:
- the energy-norm error, from the force alone: the constraints are nodal on a flat face
  with a node at the punch's edge, so the discrete set is inside the exact one and, with
  the whole face active (checked), a(u_h, u) = a(u, u) = F delta and
  ||u - u_h||_E^2 / ||u||_E^2 = (F_h - F) / F. F: Richardson from two meshes graded
  towards the edge (h = s r, r the distance to it), whose energy error falls like s;
- the pressure away from the edge (|x| <= b/2): max error relative to p(0) against
  Sadowsky's half-plane pressure (the block is finite: its own model error is measured on
  the reference), and against the reference mesh's pressure (the discretization alone).

Run: python benchmarks/punch_adapt.py [--max-dofs 60000] (serial, a few minutes).
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

import dolfinx_solver  # noqa: F401
import numpy as np

from contactfx import load_scene_file, run_scene
from contactfx.adapt.loop import AdaptOptions, adapt, uniform_levels
from contactfx.adapt.sizing import SizingRule
from contactfx.request import SolveRequest

ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "demos" / "scenes"
DELTA, B = 0.01, 1.0


def scene_with(tmp: Path, name: str, field: str) -> Path:
    """rigid_punch.toml on a copy of rigid_block.geo whose size field is `field` (MathEval)."""
    geo = (ROOT / "meshes" / "rigid_block.geo").read_text()
    start = geo.index("Field[1].F")
    end = geo.index("Background Field")
    geo = geo[:start] + f'Field[1].F = "{field}";\n' + geo[end:]
    (tmp / f"{name}.geo").write_text(geo)
    toml = (
        (SCENES / "rigid_punch.toml")
        .read_text()
        .replace("../../meshes/rigid_block.geo", f"{name}.geo")
    )
    (tmp / f"{name}.toml").write_text(toml)
    return tmp / f"{name}.toml"


def measures(data: dict, ref: dict | None) -> dict:
    """Force, whole face active, pressure errors at |x| <= b/2 (Sadowsky, reference)."""
    c = data["contacts"][0]
    itf = c["interface"]
    x, p = np.asarray(itf["x"]), np.asarray(itf["pressure"])
    act = np.asarray(itf["active"], dtype=bool)
    order = np.argsort(x)
    x, p, act = x[order], p[order], act[order]
    F = abs(c["force"][1])
    face = x <= B * (1 + 1e-9)
    inner = x <= 0.5 * B
    p_ref0 = 2.0 * F / (np.pi * B)  # Sadowsky's p(0), full load P = 2F
    sad = 2.0 * F / (np.pi * np.sqrt(B * B - x[inner] ** 2))
    out = {
        "dofs": data["dofs"],
        "force": F,
        "face_active": bool(np.all(act[face])) and not np.any(act[~face]),
        "p_sadowsky": float(np.max(np.abs(p[inner] - sad)) / p_ref0),
    }
    if ref is not None:
        pr = np.interp(x[inner], ref["x"], ref["p"])
        out["p_reference"] = float(np.max(np.abs(p[inner] - pr)) / p_ref0)
    out["x"], out["p"] = x, p
    return out


def reference(tmp: Path, slope: float, hmin: float) -> dict:
    """A mesh graded towards the punch edge: h = max(hmin, slope r), at most 2."""
    f = f"Min(2, Max({hmin}, {slope} * Sqrt((x - 1)^2 + y^2)))"
    _, data = run_scene(
        load_scene_file(scene_with(tmp, f"ref{slope}", f)), SolveRequest.parse("nts")
    )
    data = data.to_json()
    return measures(data, None)


def main() -> None:
    """Measure and print one line per level; write the numbers as JSON."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--h0", type=float, default=0.5)
    ap.add_argument("--max-dofs", type=int, default=60000)
    ap.add_argument("--uniform-dofs", type=int, default=None, help="default: --max-dofs")
    ap.add_argument("--growth", type=float, default=4.0, help="adapt's --growth")
    ap.add_argument("--weight-contact", type=float, default=10.0, help="adapt's --weight-contact")
    ap.add_argument("--slopes", default="0.08,0.04", help="the two reference gradings")
    ap.add_argument("--json", type=Path, default=Path("punch_adapt.json"))
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp())
    slopes = [float(v) for v in args.slopes.split(",")]
    refs = [reference(tmp, s, 1e-4) for s in slopes]
    for s, r in zip(slopes, refs, strict=True):
        print(f"reference s {s}: {r['dofs']} DOFs, F {r['force']:.8g}, face {r['face_active']}")
    if len(refs) > 2:  # the s^2 model: successive differences fall by (s_k / s_k+1)^2
        d = np.diff([r["force"] for r in refs])
        print(f"reference differences {d}, ratios {d[:-1] / d[1:]}")
    (s1, r1), (s2, r2) = list(zip(slopes, refs, strict=True))[-2:]
    # Energy error ~ s on the graded meshes: F_s - F ~ s^2.
    q = (s1 / s2) ** 2
    F = (q * r2["force"] - r1["force"]) / (q - 1)
    print(
        f"F = {F:.8g} (Richardson); Sadowsky error of the finest reference at "
        f"|x| <= b/2: {100 * r2['p_sadowsky']:.3f} %"
    )
    start = load_scene_file(scene_with(tmp, "uniform", f"{args.h0}"))
    quiet = lambda line: None  # noqa: E731
    nts = SolveRequest.parse("nts")
    result = adapt(
        start,
        nts,
        AdaptOptions(
            1e-9,
            args.max_dofs,
            12,
            SizingRule(growth=args.growth, contact_weight=args.weight_contact),
        ),
        say=print,
    )
    uni = uniform_levels(start, nts, args.uniform_dofs or args.max_dofs, say=quiet)
    rows = {}
    for name, levels in (("adaptive", result.levels), ("uniform", uni)):
        rows[name] = []
        for lv in levels:
            m = measures(lv.summary.to_json(), r2)
            m["energy"] = float(np.sqrt(max(m["force"] - F, 0.0) / F))
            m["estimate"] = float(lv.est.relative)
            del m["x"], m["p"]
            rows[name].append(m)
            print(
                f"{name:8s} {m['dofs']:7d} DOFs: energy {100 * m['energy']:.3f} %, estimate "
                f"{100 * m['estimate']:.2f} %, p(|x|<=b/2) vs Sadowsky "
                f"{100 * m['p_sadowsky']:.3f} %, vs reference {100 * m['p_reference']:.3f} %, "
                f"face active {m['face_active']}"
            )
        n = np.array([m["dofs"] for m in rows[name]], dtype=float)
        e = np.array([m["energy"] for m in rows[name]])
        ok = e > 0
        rate = float(np.polyfit(np.log(n[ok]), np.log(e[ok]), 1)[0]) if ok.sum() > 1 else None
        print(f"{name}: energy error ~ N^{rate:.3f}" if rate is not None else name)
        rows[name + "_rate"] = rate  # type: ignore[assignment]
        if ok.sum() > 2:
            tail = np.polyfit(np.log(n[ok][-3:]), np.log(e[ok][-3:]), 1)[0]
            print(f"{name}: over the last three levels ~ N^{tail:.3f}")
    args.json.write_text(json.dumps({"F": F, **rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
