"""Dual (biorthogonal) mortar multipliers: diagonal D, partition of unity, patch test, ends."""

from fractions import Fraction

import numpy as np
import pytest
from conftest import make_surface, renumbered, reshuffled
from hypothesis import given, settings
from hypothesis import strategies as st

from contactfx.contact import Surface
from contactfx.contact.mortar import (
    DUAL_MAX_DIPOLE,
    contact_operator,
    dual_coefficients,
    mortar_matrices,
    subsegments,
)

FAST = settings(max_examples=30, deadline=None)
KINDS = ["flat", "tilted", "wavy", "arc"]


# ---------------------------------------------------------------- surfaces


def steps(rng: np.random.Generator, n: int, x0: float) -> np.ndarray:
    """n increasing abscissae from x0 with steps in [0.2, 1]."""
    return x0 + np.r_[0.0, np.cumsum(rng.uniform(0.2, 1.0, n - 1))]


def line_pair(rng: np.random.Generator, kind: str) -> tuple[Surface, Surface, int]:
    """Passive lower line, active upper line (non-matching, ends straddling), rotated by tilt."""
    xp, xa = steps(rng, rng.integers(3, 12), 0.0), steps(rng, rng.integers(3, 12), -0.6)
    xa += rng.uniform(0.0, 0.9)
    wiggle = 0.03 if kind == "wavy" else 0.0
    yp = wiggle * rng.uniform(-1, 1, len(xp))
    ya = 0.01 + wiggle * rng.uniform(-1, 1, len(xa)) + (0.02 * xa if kind == "tilted" else 0)
    tilt = rng.uniform(-np.pi, np.pi) if kind != "flat" else 0.0
    rot = np.array([[np.cos(tilt), -np.sin(tilt)], [np.sin(tilt), np.cos(tilt)]])
    up = rot @ [0.0, 1.0]
    passive = make_surface(np.column_stack([xp, yp]) @ rot.T, up, 0)
    active = make_surface(np.column_stack([xa, ya]) @ rot.T, -up, 2 * len(xp))
    return active, passive, 2 * (len(xp) + len(xa))


def arc_pair(rng: np.random.Generator) -> tuple[Surface, Surface, int]:
    """Passive disk arc (radius 1), active seat arc just outside it, non-matching nodes."""
    tp = np.sort(rng.uniform(0.4, 2.7, rng.integers(4, 14)))
    ta = np.sort(rng.uniform(tp[0] - 0.3, tp[-1] + 0.3, rng.integers(4, 14)))
    ra = 1.01 + 0.003 * rng.uniform(-1, 1, len(ta))
    pts_p = np.column_stack([np.cos(tp), np.sin(tp)])
    pts_a = ra[:, None] * np.column_stack([np.cos(ta), np.sin(ta)])
    mid_p = 0.5 * (pts_p[1:] + pts_p[:-1])
    mid_a = 0.5 * (pts_a[1:] + pts_a[:-1])
    passive = make_surface(pts_p, mid_p, 0)  # outward normals of the disk
    active = make_surface(pts_a, -mid_a, 2 * len(tp))  # towards the centre
    return active, passive, 2 * (len(tp) + len(ta))


def build_pair(seed: int, kind: str) -> tuple[Surface, Surface, int]:
    """A random surface pair of the given kind."""
    rng = np.random.default_rng(seed)
    return arc_pair(rng) if kind == "arc" else line_pair(rng, kind)


pairs = st.builds(build_pair, st.integers(0, 2**32 - 1), st.sampled_from(KINDS))


def flat_pair(xp, xa, ya) -> tuple[Surface, Surface, int]:
    """Passive line y = 0 (normal +y) and active polyline (xa, ya) above it (normal -y)."""
    xp, xa, ya = (np.asarray(v, dtype=float) for v in (xp, xa, ya))
    passive = make_surface(np.column_stack([xp, 0 * xp]), [0.0, 1.0], 0)
    active = make_surface(np.column_stack([xa, ya]), [0.0, -1.0], 2 * len(xp))
    return active, passive, 2 * (len(xp) + len(xa))


# ---------------------------------------------------------------- references


def gauss(lo: float, hi: float, n: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss rule on [lo, hi] (a different rule from the kernel's 2 points)."""
    x, w = np.polynomial.legendre.leggauss(n)
    return lo + 0.5 * (hi - lo) * (x + 1), 0.5 * (hi - lo) * w


def hats(xi: np.ndarray) -> np.ndarray:
    """(N_0, N_1) on a segment at local coordinates xi, shape (p, 2)."""
    return np.column_stack([1 - xi, xi])


def reference_dual(intervals: list[tuple[float, float]]) -> np.ndarray:
    """A = D_e M_e^-1 (psi_j = sum_k A_jk N_k) from the overlap intervals, in exact rationals."""
    # Antiderivatives of N_0^2, N_0 N_1, N_1^2 with N_0 = 1 - x, N_1 = x.
    prims = [
        lambda x: -((1 - x) ** 3) / 3,
        lambda x: x**2 / 2 - x**3 / 3,
        lambda x: x**3 / 3,
    ]
    m00, m01, m11 = (sum(f(Fraction(hi)) - f(Fraction(lo)) for lo, hi in intervals) for f in prims)
    d0, d1, det = m00 + m01, m01 + m11, m00 * m11 - m01 * m01
    A = [[d0 * m11 / det, -d0 * m01 / det], [-d1 * m01 / det, d1 * m00 / det]]
    return np.array([[float(v) for v in row] for row in A])


def assert_same_psi(A: np.ndarray, ref: np.ndarray, intervals: list, rtol: float) -> None:
    """psi_j (linear) agree at both ends of the overlap, relative to their size there."""
    ends = np.array([min(lo for lo, _ in intervals), max(hi for _, hi in intervals)])
    got, want = hats(ends) @ A.T, hats(ends) @ ref.T
    np.testing.assert_allclose(got, want, rtol=0, atol=rtol * np.abs(want).max())


def flat_overlap(xa: np.ndarray, xp: np.ndarray) -> list[tuple[float, float]]:
    """xi interval of each active segment over the passive x-range (empty: lo >= hi)."""
    x0, x1 = xa[:-1], xa[1:]
    lo = np.clip((xp.min() - x0) / (x1 - x0), 0, 1)
    hi = np.clip((xp.max() - x0) / (x1 - x0), 0, 1)
    return list(zip(lo, hi, strict=True))


def clipped_hat_integrals(x: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """int_lo^hi N_k dx for the hat functions N_k of the 1D mesh x (closed form)."""
    out = np.zeros(len(x))
    for k in range(len(x) - 1):
        a, b = max(x[k], lo), min(x[k + 1], hi)
        if b > a:
            h, m = x[k + 1] - x[k], 0.5 * (a + b)
            out[k] += (b - a) * (x[k + 1] - m) / h
            out[k + 1] += (b - a) * (m - x[k]) / h
    return out


def sub_intervals(active: Surface, passive: Surface) -> dict[int, list[tuple[float, float]]]:
    """Sub-segment xi intervals of each active segment, from the kernel's clipping."""
    ea, _, xi = subsegments(active, passive)
    out: dict[int, list[tuple[float, float]]] = {}
    for e, (lo, hi) in zip(ea, xi, strict=True):
        out.setdefault(int(e), []).append((lo, hi))
    return out


def offdiag_ratio(D) -> float:
    """max |D_jk| / sqrt(D_jj D_kk) over j != k (0 if D is exactly diagonal)."""
    D = D.tocoo()
    dg = D.diagonal()
    off = (D.row != D.col) & (D.data != 0)
    if not off.any():
        return 0.0
    return float(np.max(np.abs(D.data[off]) / np.sqrt(dg[D.row[off]] * dg[D.col[off]])))


def dof_vector(nd: int, u, *surfaces: Surface) -> np.ndarray:
    """Global vector holding the field u(x) (x (n, 2) -> (n, 2)) at the surface nodes."""
    U = np.zeros(nd)
    for s in surfaces:
        U[s.dofs] = u(s.x)
    return U


# ---------------------------------------------------------------- tests


@FAST
@given(pairs)
def test_dual_D_is_diagonal_and_M_is_psi_times_passive_shapes(pair):
    # The consistent dual basis itself (ends=False: no end modification); with the end rows
    # (test_merged_dual_D_is_diagonal_on_the_rows_nodes) the merged nodes' columns couple.
    active, passive, _ = pair
    D, M = mortar_matrices(active, passive, "dual", ends=False)
    Ds, _ = mortar_matrices(active, passive, ends=False)
    assert offdiag_ratio(D) < 1e-12
    assert Ds.nnz == 0 or offdiag_ratio(Ds) > 1e-3  # the standard D is a genuine band
    d = D.diagonal()
    ref = np.asarray(Ds.sum(axis=1)).ravel()  # int N_j over the overlap
    np.testing.assert_allclose(d, ref, rtol=1e-12, atol=1e-13 * ref.max(initial=0))
    # sum_A N_A = 1 on the passive side: the M row sums are int psi_j = int N_j as well.
    np.testing.assert_allclose(
        np.asarray(M.sum(axis=1)).ravel(), d, rtol=1e-12, atol=1e-13 * d.max(initial=0)
    )


@FAST
@given(pairs)
def test_merged_dual_D_is_diagonal_on_the_rows_nodes(pair):
    # End rows (operator.end_rows): a merged node has no row, and its column holds the
    # anchor's int psi_anchor N_o; on the nodes that keep rows D stays diagonal, and every
    # row sum is int psi_j = int N_j of the merged (standard) basis.
    active, passive, nd = pair
    D, _ = mortar_matrices(active, passive, "dual")
    Ds, _ = mortar_matrices(active, passive)
    rows = contact_operator(active, passive, nd, "dual").rows
    assert offdiag_ratio(D[rows][:, rows].tocsr()) < 1e-12
    ref = np.asarray(Ds.sum(axis=1)).ravel()
    d = np.asarray(D.sum(axis=1)).ravel()
    np.testing.assert_allclose(d, ref, rtol=1e-12, atol=1e-13 * ref.max(initial=0))


@FAST
@given(pairs)
def test_biorthogonality_by_brute_force_quadrature(pair):
    # psi from the public coefficients, integrated by an 8-point rule on every sub-segment.
    active, passive, _ = pair
    A, usable = dual_coefficients(active, passive)
    for e, intervals in sub_intervals(active, passive).items():
        assert usable[e]
        psi_n, n_int = np.zeros((2, 2)), np.zeros(2)
        for lo, hi in intervals:
            x, w = gauss(lo, hi)
            n = hats(x)
            psi_n += np.einsum("p,pj,pk->jk", w, n @ A[e].T, n)
            n_int += w @ n
            assert np.allclose((n @ A[e].T).sum(axis=1), 1.0, rtol=0, atol=1e-12)
        size = sum(hi - lo for lo, hi in intervals)
        np.testing.assert_allclose(psi_n, np.diag(n_int), rtol=0, atol=1e-12 * size)


@FAST
@given(pairs)
def test_coefficients_equal_D_M_inverse_in_exact_rationals(pair):
    active, passive, _ = pair
    A, _ = dual_coefficients(active, passive)
    for e, intervals in sub_intervals(active, passive).items():
        assert_same_psi(A[e], reference_dual(intervals), intervals, 1e-10)


def test_full_segments_get_the_textbook_duals_partial_ones_do_not():
    xp = np.linspace(0.0, 1.0, 9)
    xa = np.array([-0.23, 0.11, 0.3, 0.47, 0.66, 0.9, 1.17])
    active, passive, _ = flat_pair(xp, xa, 0.01 + 0 * xa)
    A, usable = dual_coefficients(active, passive)
    assert usable.all()
    np.testing.assert_allclose(A[1:-1], np.tile([[2.0, -1.0], [-1.0, 2.0]], (4, 1, 1)), atol=1e-13)
    # Ends: overlap [0.23/0.34, 1] and [0, 0.1/0.27]; consistent duals from D_e M_e^-1 there.
    for e, (lo, hi) in [(0, (0.23 / 0.34, 1.0)), (5, (0.0, 0.1 / 0.27))]:
        np.testing.assert_allclose(A[e], reference_dual([(lo, hi)]), rtol=1e-12)
        assert np.abs(A[e] - [[2, -1], [-1, 2]]).max() > 1.0


@FAST
@given(st.integers(0, 2**32 - 1), st.sampled_from(["flat", "tilted", "wavy"]), st.floats(-0.1, 0.1))
def test_rigid_normal_translation_changes_gap_by_delta_times_weights(seed, kind, delta):
    # Straight passive line (any orientation) moved along its normal by delta: the gap drops
    # by delta everywhere, so every weighted gap drops by delta * int psi_j = delta * weights.
    rng = np.random.default_rng(seed)
    active, passive, nd = line_pair(rng, "tilted" if kind == "tilted" else "flat")
    if kind == "wavy":  # wavy active surface over the straight passive one
        x = active.x + 0.02 * rng.uniform(-1, 1, active.x.shape)
        active = make_surface(x, active.normals[0], 2 * passive.n_nodes)
    n = passive.normals[0]
    moved = Surface(passive.x + delta * n, passive.segments, passive.normals, passive.dofs)
    op, op2 = (
        contact_operator(active, passive, nd, "dual"),
        contact_operator(active, moved, nd, "dual"),
    )
    std = contact_operator(active, passive, nd)
    scale = 1e-12 * max(op.weights.max(), 1e-300)
    np.testing.assert_allclose(op.weights, std.weights, rtol=1e-12, atol=scale)
    np.testing.assert_allclose(op2.weights, op.weights, rtol=1e-12, atol=scale)
    np.testing.assert_allclose(op2.gap - op.gap, -delta * op.weights, rtol=0, atol=scale)
    u = dof_vector(nd, lambda x: np.broadcast_to(delta * n, x.shape), passive)
    np.testing.assert_allclose(op.B @ u, -delta * op.weights, rtol=0, atol=scale)


@FAST
@given(st.integers(0, 2**32 - 1), st.floats(-0.05, 0.05), st.floats(0.005, 0.05))
def test_dual_gap_is_weight_times_nodal_gap_for_linear_gaps(seed, slope, g0):
    # Biorthogonality: for g = sum_k g_k N_k, int psi_j g = g_j int N_j, also on end segments.
    rng = np.random.default_rng(seed)
    xp = steps(rng, rng.integers(3, 10), 0.0)
    xa = steps(rng, rng.integers(3, 10), rng.uniform(-0.6, 0.4))
    ya = g0 + slope * xa + 0.02 * rng.uniform(-1, 1, len(xa)) * rng.integers(0, 2)
    active, passive, nd = flat_pair(xp, xa, ya)
    # The consistent dual basis before the end modification (ends=False); merged end rows
    # weight several nodal gaps (tests/contact/test_passive_ends.py).
    op = contact_operator(active, passive, nd, "dual", ends=False)
    # dGamma on a tilted active segment is stretch * dx; hats integrate to the clipped lengths.
    lo, hi = xp.min(), xp.max()
    length = np.hypot(np.diff(xa), np.diff(ya))
    w_ref = np.zeros(len(xa))
    for k in range(len(xa) - 1):
        part = clipped_hat_integrals(xa[k : k + 2], lo, hi)
        w_ref[k : k + 2] += part * length[k] / (xa[k + 1] - xa[k])
    np.testing.assert_allclose(op.weights, w_ref, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(op.gap, w_ref * ya, rtol=1e-12, atol=1e-14)


@FAST
@given(pairs, st.integers(0, 2**32 - 1))
def test_linear_field_summed_over_rows_matches_standard(pair, seed):
    # sum_j psi_j = sum_j N_j = 1: both row sums are int (u_a - u_p) . n over the overlap.
    active, passive, nd = pair
    rng = np.random.default_rng(seed)
    c, G = rng.normal(size=2), rng.normal(size=(2, 2))
    u = dof_vector(nd, lambda x: c + x @ G.T, active, passive)
    dual, std = contact_operator(active, passive, nd, "dual"), contact_operator(active, passive, nd)
    total = np.abs(std.B.toarray()).sum(axis=0) @ np.abs(u)  # round-off scale
    assert abs((dual.B @ u).sum() - (std.B @ u).sum()) < 1e-12 * max(total, 1e-300)


def test_linear_field_rows_against_independent_integral():
    # Straight tilted active line over a flat passive one: row j = int psi_j G11 y_a(x) dGamma,
    # psi from D_e M_e^-1 of the x-range overlap; rows sum to int G11 y_a dGamma.
    xp = np.array([0.0, 0.13, 0.3, 0.42, 0.61, 0.77, 0.9, 1.0])
    xa = np.array([-0.12, 0.2, 0.37, 0.55, 0.8, 1.08])
    g0, slope = 0.01, 0.03
    active, passive, nd = flat_pair(xp, xa, g0 + slope * xa)
    G = np.array([[0.3, -0.7], [0.4, 1.3]])
    u = dof_vector(nd, lambda x: x @ G.T, active, passive)
    stretch = np.sqrt(1 + slope**2)
    ref = np.zeros(len(xa))
    for k, (lo, hi) in enumerate(flat_overlap(xa, xp)):
        h = xa[k + 1] - xa[k]
        x, w = gauss(lo, hi)
        psi = hats(x) @ reference_dual([(lo, hi)]).T
        ref[k : k + 2] += stretch * h * (w * G[1, 1] * (g0 + slope * (xa[k] + h * x))) @ psi
    op = contact_operator(active, passive, nd, "dual", ends=False)  # the unmodified dual basis
    np.testing.assert_allclose(op.B @ u, ref, rtol=1e-12, atol=1e-16)
    # The gap is linear on each segment, so the dual weighted gap is weight * nodal gap; the
    # standard one mixes neighbouring nodal gaps.
    np.testing.assert_allclose(op.gap, op.weights * (g0 + slope * xa), rtol=1e-13)
    std = contact_operator(active, passive, nd, ends=False)
    assert np.max(np.abs(std.gap - std.weights * (g0 + slope * xa))) > 1e-5
    x0, x1 = 0.0, 1.0
    total = stretch * G[1, 1] * (g0 * (x1 - x0) + slope * (x1**2 - x0**2) / 2)
    np.testing.assert_allclose(ref.sum(), total, rtol=1e-13)


@pytest.mark.parametrize("gap", [0.0, 0.004])
def test_patch_test_constant_multiplier_flat_non_matching(gap):
    # B^T lambda: active nodes get lambda int N_k, passive nodes -lambda int N_A (y components),
    # integrals over the overlap [0, 1]; both ends of the active line straddle a passive end.
    xp = np.array([0.0, 0.13, 0.3, 0.42, 0.61, 0.77, 0.9, 1.0])
    xa = np.array([-0.12, 0.2, 0.37, 0.55, 0.8, 1.08])
    active, passive, nd = flat_pair(xp, xa, gap + 0 * xa)
    lam = 2.5
    f_dual = contact_operator(active, passive, nd, "dual").B.transpose_matmul(np.full(len(xa), lam))
    f_std = contact_operator(active, passive, nd).B.transpose_matmul(np.full(len(xa), lam))
    np.testing.assert_allclose(f_dual, f_std, rtol=0, atol=1e-12 * lam)
    ref = np.zeros(nd)
    ref[active.dofs[:, 1]] = lam * clipped_hat_integrals(xa, 0.0, 1.0)
    ref[passive.dofs[:, 1]] = -lam * clipped_hat_integrals(xp, -0.12, 1.08)
    np.testing.assert_allclose(f_dual, ref, rtol=0, atol=1e-12 * lam)


@FAST
@given(pairs, st.floats(0.1, 10.0))
def test_patch_test_constant_multiplier_random_surfaces(pair, lam):
    active, passive, nd = pair
    ones = np.full(active.n_nodes, lam)
    f_dual = contact_operator(active, passive, nd, "dual").B.transpose_matmul(ones)
    f_std = contact_operator(active, passive, nd).B.transpose_matmul(ones)
    np.testing.assert_allclose(f_dual, f_std, rtol=0, atol=1e-12 * lam)


def test_flat_normal_part_is_D_minus_M():
    xp = np.array([0.0, 0.13, 0.3, 0.42, 0.61, 0.77, 0.9, 1.0])
    xa = np.array([-0.1, 0.2, 0.37, 0.55, 0.8, 1.05])
    active, passive, nd = flat_pair(xp, xa, 0.01 + 0 * xa)
    B = contact_operator(active, passive, nd, "dual").B.toarray()
    D, M = mortar_matrices(active, passive, "dual")
    np.testing.assert_allclose(B[:, active.dofs[:, 1]], D.toarray(), atol=1e-15)
    np.testing.assert_allclose(B[:, passive.dofs[:, 1]], -M.toarray(), atol=1e-15)
    assert np.all(B[:, active.dofs[:, 0]] == 0) and np.all(B[:, passive.dofs[:, 0]] == 0)


@FAST
@given(pairs, st.integers(0, 2**32 - 1))
def test_invariant_under_reversal_permutation_and_renumbering(pair, seed):
    active, passive, nd = pair
    rng = np.random.default_rng(seed)
    order = rng.permutation(active.n_nodes)
    active2 = renumbered(reshuffled(active, seed), order)
    passive2 = renumbered(reshuffled(passive, seed + 1), rng.permutation(passive.n_nodes))
    op, op2 = (
        contact_operator(a, p, nd, "dual") for a, p in [(active, passive), (active2, passive2)]
    )
    np.testing.assert_allclose(op2.B.toarray(), op.B.toarray()[order], atol=1e-12)
    np.testing.assert_allclose(op2.gap, op.gap[order], atol=1e-13)
    np.testing.assert_allclose(op2.weights, op.weights[order], atol=1e-13)
    D, _ = mortar_matrices(active, passive, "dual")
    D2, _ = mortar_matrices(active2, passive2, "dual")
    np.testing.assert_allclose(D2.diagonal(), D.diagonal()[order], atol=1e-13)


def test_end_nodes_rows_and_weights():
    # Passive [0, 1]; active nodes every 0.3 from -0.7: [-0.7, -0.4] lies wholly outside, the
    # segment [-0.1, 0.2] straddles x = 0 and [0.8, 1.1] straddles x = 1.
    xp = np.linspace(0.0, 1.0, 6)
    xa = np.linspace(-0.7, 1.1, 7)
    active, passive, nd = flat_pair(xp, xa, 0.01 + 0 * xa)
    op = contact_operator(active, passive, nd, "dual")
    std = contact_operator(active, passive, nd)
    # End rows: nodes 2, 6 lie beyond the ends, 3 and 5 are the last reached: only node 4's
    # support [0.2, 0.8] is wholly covered, and it takes every row (psi_4 = 1 on [0, 1]).
    np.testing.assert_array_equal(op.rows, [4])
    np.testing.assert_array_equal(op.rows, std.rows)
    np.testing.assert_allclose(op.weights, [0, 0, 0, 0, 1.0, 0, 0], rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(op.B.toarray(), std.B.toarray(), atol=1e-14)
    # Without the modification every node facing the surface keeps a row.
    raw = contact_operator(active, passive, nd, "dual", ends=False)
    np.testing.assert_array_equal(raw.rows, [2, 3, 4, 5, 6])
    assert raw.B.rows(np.array([0, 1])).nnz == 0 and np.all(raw.weights[:2] == 0)
    edge, inner = 0.02 / 0.3, 0.04 / 0.3 + 0.15
    np.testing.assert_allclose(raw.weights, [0, 0, edge, inner, 0.3, inner, edge], rtol=1e-13)
    np.testing.assert_allclose(raw.B.toarray().sum(axis=0), op.B.toarray()[4], atol=1e-14)
    A, usable = dual_coefficients(active, passive)
    assert usable.tolist() == [False, False, True, True, True, True]
    ends = sub_intervals(active, passive)
    for e in (2, 5):
        assert_same_psi(A[e], reference_dual(ends[e]), ends[e], 1e-12)
    np.testing.assert_allclose(ends[2][0][0], 1 / 3, rtol=1e-14)  # only [0, 0.2] of [-0.1, 0.2]
    D, _ = mortar_matrices(active, passive, "dual", ends=False)
    assert offdiag_ratio(D) < 1e-13


@pytest.mark.parametrize("length, kept", [(1e-1, True), (1e-3, True), (1e-6, False)])
def test_inner_sliver_kept_or_dropped(length, kept):
    # A passive surface much shorter than the active segment [0, 1] holding it: the overlap lies
    # inside the segment, away from both nodes, and M_e tends to singular as it shrinks.
    xp = 0.37 + length * np.array([0.0, 0.4, 1.0])
    xa = np.array([-1.0, 0.0, 1.0, 2.0])
    active, passive, nd = flat_pair(xp, xa, 0.01 + 0 * xa)
    A, usable = dual_coefficients(active, passive)
    c = 0.37 + length / 2
    kappa = c * (1 - c) * np.sqrt(12) / length  # N_0 N_1 at the centroid over std(xi)
    assert (kappa <= DUAL_MAX_DIPOLE) == kept
    assert usable.tolist() == [False, kept, False]
    op = contact_operator(active, passive, nd, "dual")
    std = contact_operator(active, passive, nd)
    assert np.all(std.weights[[1, 2]] > 0)
    D, M = mortar_matrices(active, passive, "dual")
    if kept:
        overlap = [(0.37, 0.37 + length)]
        assert_same_psi(A[1], reference_dual(overlap), overlap, 1e-9)
        np.testing.assert_allclose(op.weights, std.weights, rtol=1e-12)
        assert offdiag_ratio(D) < 1e-12
    else:  # dropped: no row, no weight, nothing in D or M
        assert op.B.nnz == 0 and np.all(op.weights == 0) and np.all(op.gap == 0)
        assert D.nnz == 0 and M.nnz == 0


def test_standard_is_default_and_unknown_basis_rejected():
    active, passive, nd = build_pair(5, "wavy")
    a, b = contact_operator(active, passive, nd), contact_operator(active, passive, nd, "standard")
    assert np.array_equal(a.B.toarray(), b.B.toarray()) and np.array_equal(a.gap, b.gap)
    with pytest.raises(ValueError, match="unknown multiplier basis"):
        contact_operator(active, passive, nd, "lumped")
    with pytest.raises(ValueError, match="unknown multiplier basis"):
        mortar_matrices(active, passive, "Dual")
