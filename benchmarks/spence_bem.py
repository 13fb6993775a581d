"""Spence's stick ratio c/a by a half-plane boundary-element computation of the loading history.

A rigid cylinder (radius R) is pressed into an elastic half-plane with Coulomb friction mu, in
small steps of the approach. The surface is cut into n equal cells carrying uniform pressure p
and shear q; the half-plane's coupled influence functions (contactfx.results.friction_references
.half_plane_influence: u_z = G p + H q, u_x = G q - H p) give the surface displacements. Each
step is solved for its three sets by an active-set iteration of its own (not the library's
friction kernel): a contact cell has u_z = delta - x^2 / 2R; a stick cell keeps the u_x it had at
the end of the step before (the indenter does not move sideways); a slip cell has q = mu p times
the sign opposite to its slip increment. Nothing imposes a stick width: c/a is read off the
history, as the slope of the stick cell count over the contact cell count in the second half of
the loading (the problem is self-similar, so the slope is c/a). Goodman's approximation drops H
from u_z (the shear no longer moves the surface normally).

This is route (b) of docs/friction_verification.md; route (a) is
friction_references.spence_stick_ratio (the self-similar reduction to a flat-punch increment). Run:

    OPENBLAS_NUM_THREADS=1 python benchmarks/spence_bem.py --json benchmarks/spence_bem.json

(about ten minutes on one loaded core) prints, per (mu, nu), both routes and Goodman's, and
writes them; `--table benchmarks/spence_bem.json` prints docs/friction_verification.md's
table from them.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from contactfx.results.friction_references import (
    coupling_beta,
    half_plane_influence,
    spence_stick_ratio,
)

CASES = [(0.1, 0.3), (0.2, 0.3), (0.3, 0.3), (0.2, 0.0), (0.3, 0.2), (0.4, 0.0), (0.5, 0.3)]


def loading_history(
    mu: float, nu: float, cells: int = 400, steps: int = 160, coupled: bool = True
) -> dict[str, np.ndarray]:
    """Press a rigid cylinder (R = 1, E* = 1) into the half-plane over cells on [-1, 1].

    Returns per step the contact and stick cell counts and the final p, q and cell midpoints.
    """
    beta = coupling_beta(nu)
    edges = np.linspace(-1.0, 1.0, cells + 1)
    x = 0.5 * (edges[:-1] + edges[1:])
    h = edges[1] - edges[0]
    G, H, _ = half_plane_influence(edges, x, beta)
    Hz = H if coupled else np.zeros_like(H)
    # Load control (a 2D half-plane fixes the approach only up to a constant): the frictionless
    # Hertz half-width a = sqrt(4 P / pi) (R = E* = 1) grows evenly to 0.7.
    loads = 0.25 * np.pi * np.linspace(0.0, 0.7, steps + 1)[1:] ** 2
    n = cells
    p, q = np.zeros(n), np.zeros(n)
    ux_prev = np.zeros(n)
    contact = np.abs(x) < h
    stick = contact.copy()
    sign = np.sign(x)
    n_contact, n_stick = [], []
    for load in loads:
        for _ in range(200):
            p, q, delta = _solve_sets(G, H, Hz, x, load, ux_prev, contact, stick, sign, mu)
            uz = G @ p + Hz @ q
            target = delta - 0.5 * x**2
            ux = G @ q - H @ p
            slip_inc = ux - ux_prev
            new_contact = np.where(contact, p > 0, target - uz > 0)
            # Stick holds while |q| <= mu p; a slipping cell sticks again when its increment
            # turns against the shear it carries (the shear on the half-plane opposes its slip).
            new_stick = np.where(stick, np.abs(q) <= mu * p, sign * slip_inc > 0)
            new_sign = np.where(stick & ~new_stick, np.sign(q), sign)
            new_stick &= new_contact
            if (
                np.array_equal(new_contact, contact)
                and np.array_equal(new_stick, stick)
                and np.array_equal(new_sign, sign)
            ):
                break
            contact, stick, sign = new_contact, new_stick, new_sign
        else:
            raise RuntimeError(f"no converged sets at load={load}")
        ux_prev = G @ q - H @ p
        n_contact.append(int(contact.sum()))
        n_stick.append(int(stick.sum()))
    return {
        "n_contact": np.array(n_contact),
        "n_stick": np.array(n_stick),
        "x": x,
        "p": p,
        "q": q,
        "h": np.array(h),
    }


def _solve_sets(
    G: np.ndarray,
    H: np.ndarray,
    Hz: np.ndarray,
    x: np.ndarray,
    load: float,
    ux_prev: np.ndarray,
    contact: np.ndarray,
    stick: np.ndarray,
    sign: np.ndarray,
    mu: float,
) -> tuple[np.ndarray, np.ndarray, float]:
    """p, q and the approach delta for a total load, given contact, stick sets and slip signs."""
    n = len(x)
    h = 2.0 / n
    A = np.zeros((2 * n + 1, 2 * n + 1))
    b = np.zeros(2 * n + 1)
    ci = np.flatnonzero(contact)
    oi = np.flatnonzero(~contact)
    # Contact: u_z = delta - x^2 / 2 (R = 1), delta unknown.
    A[ci, :n], A[ci, n : 2 * n], A[ci, 2 * n] = G[ci], Hz[ci], -1.0
    b[ci] = -0.5 * x[ci] ** 2
    A[oi, oi] = 1.0
    si = np.flatnonzero(contact & stick)
    A[n + si, :n], A[n + si, n : 2 * n] = -H[si], G[si]
    b[n + si] = ux_prev[si]
    li = np.flatnonzero(contact & ~stick)
    A[n + li, n + li] = 1.0
    A[n + li, li] = -mu * sign[li]
    fi = np.flatnonzero(~contact)
    A[n + fi, n + fi] = 1.0
    # The total load: h sum p = load.
    A[2 * n, :n] = h
    b[2 * n] = load
    sol = np.linalg.solve(A, b)
    return sol[:n], sol[n : 2 * n], float(sol[2 * n])


def stick_ratio(history: dict[str, np.ndarray]) -> float:
    """Slope of the stick cell count over the contact cell count, second half of the loading."""
    nc, ns = history["n_contact"], history["n_stick"]
    half = len(nc) // 2
    slope = np.polyfit(nc[half:], ns[half:], 1)[0]
    return float(slope)


def table(rows: list[dict[str, float]]) -> str:
    """The docs' markdown table (docs/friction_verification.md) of the recorded rows."""
    out = [
        "| mu | nu | beta | mu / beta | c/a (a) self-similar | c/a (b) BEM | (a) - (b) "
        "| Goodman (a) | Goodman (b) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        out.append(
            f"| {r['mu']:.2f} | {r['nu']:.2f} | {r['beta']:.4f} | {r['mu'] / r['beta']:.3f} "
            f"| {r['self_similar']:.4f} | {r['bem']:.4f} | {r['self_similar'] - r['bem']:+.4f} "
            f"| {r['goodman_self_similar']:.4f} | {r['goodman_bem']:.4f} |"
        )
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    """Both routes and Goodman's for each case; print a table and write the JSON."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cells", type=int, default=400)
    ap.add_argument("--steps", type=int, default=160)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--table", type=Path, help="print the markdown table of a recorded JSON")
    args = ap.parse_args(argv)
    if args.table:
        print(table(json.loads(args.table.read_text())["rows"]))
        return 0
    rows = []
    for mu, nu in CASES:
        bem = stick_ratio(loading_history(mu, nu, args.cells, args.steps))
        good_bem = stick_ratio(loading_history(mu, nu, args.cells, args.steps, coupled=False))
        ssr = spence_stick_ratio(mu, nu)
        good = spence_stick_ratio(mu, nu, coupled=False)
        row = {
            "mu": mu,
            "nu": nu,
            "beta": coupling_beta(nu),
            "self_similar": ssr,
            "bem": bem,
            "goodman_self_similar": good,
            "goodman_bem": good_bem,
        }
        rows.append(row)
        print(table([row]).splitlines()[-1], flush=True)
    print(table(rows))
    if args.json:
        meta = {"cells": args.cells, "steps": args.steps, "command": " ".join(sys.argv)}
        args.json.write_text(json.dumps({"meta": meta, "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
