"""Edge variants of the pressure goal's estimate, measured on one loop's levels (issue 30).

The pre-asymptotic out-of-band levels (r08 level 1, r12 level 2) are where the zone's edge
falls in the level's and the refined mesh's cells (docs/adapt.md). Candidates: keep the
two-level difference d / (1 - q) away from the edge, and in a window of W level cells at
the edge compare the level's pressure with a model of the exact one fitted to the refined
solution, p^2 a polynomial in x (the square-root edge: p^2 ~ alpha (a - x) + ...):
- `linear`: p^2 linear over the refined loaded nodes within 4 level cells of the refined
  zone's last loaded node (not counting it), W = 2 (the local asymptote);
- `quadratic`: p^2 quadratic over the refined loaded nodes in [0.3 L, L), L the last one,
  W = 2 (exact for Hertz's p0^2 (1 - x^2 / a^2): a model of the scenes' own answer).
estimate = sqrt((d_out / (1 - q))^2 + e_edge^2) / ||p_ref||. And one with a second
refined solve:
- `edge`: the refined mesh of the rule before it with the cells within EDGE_CELLS edge
  segment lengths of the zone's edge (the last loaded node and the next) refined twice
  more (x 2^-(k+2)), so that the refined edge cell is too small to be the unlucky one;
  the same d / (1 - q). Adopted (goal.py EDGE_CELLS, EDGE_HALVINGS); `linear` and
  `quadratic` rejected. With the adopted rule the `shipped` column is `edge` itself: the
  run in benchmarks/edge_model.json was made with the rule before it.
Each case of
benchmarks/adapt_goal.py runs as the loop runs it (the shipped estimate steers); per
level the level's and the refined pressure are kept and every candidate is evaluated on
them, against the overkill of benchmarks/hertz_overkill.npz (no second solve).

Run: python benchmarks/edge_model.py r12 r08 r1 h06 h15 --json benchmarks/edge_model.json
(serial, about 30 s per case). docs/adapt.md ("The pre-asymptotic scatter") has the numbers.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import adapt_goal as AG
from hertz_overkill import WINDOW, finest, l2_between

Curve = tuple[np.ndarray, np.ndarray]
# The `edge` variant refines the cells within this many level edge cells of the zone's edge.
EDGE_CELLS = 2.0


def _norm_between(
    x: np.ndarray, p: np.ndarray, xr: np.ndarray, pr: np.ndarray, lo: float, hi: float
) -> float:
    """||p - pr|| over [lo, hi] of two piecewise-linear curves, exactly (union of nodes)."""
    s = np.union1d(np.union1d(x, xr), [lo, hi])
    s = s[(s >= lo) & (s <= hi)]
    d = np.interp(s, x, p, left=0.0, right=0.0) - np.interp(s, xr, pr, left=0.0, right=0.0)
    h, v0, v1 = np.diff(s), d[:-1], d[1:]
    return float(np.sqrt(np.sum(h * (v0 * v0 + v0 * v1 + v1 * v1) / 3.0)))


def _norm_of(f: Callable[[np.ndarray], np.ndarray], lo: float, hi: float) -> float:
    """||f|| over [lo, hi] by the trapezoid rule on 20,001 points (f has a sqrt in it)."""
    s = np.linspace(lo, hi, 20001)
    v = f(s)
    return float(np.sqrt(np.trapezoid(v * v, s)))


def edge_estimate(level: Curve, ref: Curve, k: int, kind: str, upto: float) -> float | None:
    """The candidate's relative estimate of the level's pressure error, or None (no fit)."""
    (x, p), (xr, pr) = level, ref
    q = 2.0 ** (-1.5 * k)
    n = _norm_between(xr, pr, xr, 0.0 * pr, 0.0, upto)
    last = float(x[p > 0].max())
    j = int(np.searchsorted(x, last))
    if j + 1 >= len(x):
        return None
    he = float(x[j + 1] - x[j])  # the level's cell past its last loaded node: the edge cell
    lr = float(xr[pr > 0].max())
    if kind == "linear":
        sel = (xr > lr - 4 * he) & (xr < lr) & (pr > 0)
        deg = 1
    else:
        sel = (xr >= 0.3 * lr) & (xr < lr) & (pr > 0)
        deg = 2
    if sel.sum() < deg + 2:
        return None
    poly = np.poly1d(np.polyfit(xr[sel], pr[sel] ** 2, deg))
    roots = np.roots(poly.coeffs)
    roots = roots[np.isreal(roots)].real
    roots = roots[roots > 0.5 * lr]
    if not len(roots):
        return None
    a_fit = float(roots[np.argmin(np.abs(roots - lr))])
    lo = min(a_fit, last) - 2 * he
    d_out = _norm_between(x, p, xr, pr, 0.0, lo)

    def error(s: np.ndarray) -> np.ndarray:
        model = np.sqrt(np.clip(np.where(s < a_fit, poly(s), 0.0), 0.0, None))
        return np.interp(s, x, p, left=0.0, right=0.0) - model

    e_edge = _norm_of(error, lo, upto)
    return float(np.sqrt((d_out / (1.0 - q)) ** 2 + e_edge**2) / n)


def edge_refined(sol: Any, solver: Any) -> tuple[Any, int]:
    """The shipped refined solve with the level's edge cells x 1/4 more: (solution, k)."""
    from scipy.spatial import cKDTree

    from contactfx.adapt import goal as G
    from contactfx.adapt.sizing import cell_sizes, owned_cells, vertex_sizes

    k = G.zone_halvings(sol)
    quads, verts = owned_cells(sol)
    h = cell_sizes(quads)
    mid = quads.mean(axis=1)
    # The shipped per-cell factor, as goal.refined_field computes it (BAND, REACH).
    pts, size = G._surface_points(sol)
    dist, nearest = cKDTree(pts).query(mid)
    close = dist <= G.BAND * size[nearest]
    for zone, length in G._zones(sol):
        if len(zone):
            close |= cKDTree(zone).query(mid)[0] <= G.REACH * length
    factor = np.where(close, 0.5**k, 1.0)
    for pv in sol.pairs:
        x = pv.active.surface.x[:, :2]
        p = np.zeros(len(x))
        p[pv.nodes] = sol.pressure[pv.rows]
        seg = pv.active.surface.segments
        on = (p[seg[:, 0]] > 0) ^ (p[seg[:, 1]] > 0)  # the segments the zone ends in
        for a, b in seg[on]:
            he = float(np.linalg.norm(x[b] - x[a]))
            for node in (a, b):
                near = np.linalg.norm(mid - x[node], axis=1) <= EDGE_CELLS * he
                factor[near] = 0.5 ** (k + 2)
    field = vertex_sizes(sol.scene.comm, quads, verts, h * factor)
    return G._refined(sol, field, solver, {}), k


def run(case: str) -> list[dict[str, Any]]:
    """One adapt_goal.py case as the loop runs it; per level the curves and the candidates."""
    import contactfx.adapt.planned as planned
    from contactfx.cli import main as cli_main
    from contactfx.results.references import centre_distance

    def curve(sol: Any) -> Curve:
        r, p, _, _, _ = centre_distance(sol, sol.scene.references[0])
        order = np.argsort(r, kind="stable")
        return r[order], p[order]

    original = planned.goal_estimate
    kept: list[dict[str, Any]] = []

    def keep(sol: Any, goal: Any, **kw: Any) -> Any:
        est = original(sol, goal, **kw)
        edge, _ = edge_refined(sol, kw.get("solver", "mumps"))
        kept.append(
            {"dofs": sol.dofs, "estimate": est.relative, "k": est.halvings, "level": curve(sol)}
            | {"ref": curve(est.reference), "edge": curve(edge), "edge_dofs": edge.dofs}
            | {"ref_dofs": est.dofs}
        )
        return est

    planned.goal_estimate = keep  # type: ignore[assignment]
    try:
        with tempfile.TemporaryDirectory() as tmp:
            cli_main(["adapt", *AG.CASES[case], "--out", str(Path(tmp) / "out")])
    finally:
        planned.goal_estimate = original
    xo, po, a = finest(AG.OVERKILL)
    upto = WINDOW * a
    rows = []
    for lv in kept:
        d, n = l2_between(*lv["level"], xo, po, upto)
        exact = d / n
        row = {"dofs": lv["dofs"], "k": lv["k"], "exact_ok": exact}
        row["shipped"] = lv["estimate"] / exact
        for kind in ("linear", "quadratic"):
            est = edge_estimate(lv["level"], lv["ref"], lv["k"], kind, upto)
            row[kind] = None if est is None else est / exact
        d, n = l2_between(*lv["level"], *lv["edge"], upto)
        row["edge"] = d / n / (1.0 - 2.0 ** (-1.5 * lv["k"])) / exact
        row["edge_dofs"], row["ref_dofs"] = lv["edge_dofs"], lv["ref_dofs"]
        d, n = l2_between(*lv["edge"], xo, po, upto)
        row["edge_ratio"] = d / n / exact  # the edge-refined solution's error / the level's
        rows.append(row)
    return rows


def main() -> None:
    """Run the cases, print the effectivities, store them."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cases", nargs="+")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    out = {}
    for case in args.cases:
        out[case] = run(case)
        for i, r in enumerate(out[case]):
            cells = " ".join(
                f"{k} {'-' if r[k] is None else format(r[k], '.2f')}"
                for k in ("shipped", "linear", "quadratic", "edge", "edge_ratio")
            )
            cells += f" dofs ref {r['ref_dofs']} edge {r['edge_dofs']}"
            print(
                f"{case} L{i} {r['dofs']:>7} k {r['k']} error {100 * r['exact_ok']:.3g} % {cells}"
            )
    if args.json is not None:
        args.json.write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
