"""A prototype frictional solve with the kernel (contact/friction.py), not a user feature.

A chain of N nodes on a rigid floor (y = 0), tied by horizontal springs k_h, and hung from a
rigid plate by a vertical spring k_v[i] and a shear spring k_s per node. The plate is pressed
down by delta, then moved sideways by s in load steps. The semismooth Newton with the three
sets solves each step on the unknowns (u, lambda_n, lambda_t); the answers a hand derivation
gives (uy and ux decouple):

- lambda_n[i] = k_v[i] delta in every step (uy = 0);
- while every node sticks, ux = 0 and lambda_t[i] = k_s s: the first node slips at
  s = mu min(k_v) delta / k_s; with equal k_v the whole block sticks until Q = sum lambda_t
  reaches mu P, and then slips with lambda_t = mu lambda_n at every node;
- in gross slip, lambda_t = mu lambda_n and K_x ux = k_s s - mu lambda_n.
"""

import numpy as np
import pytest
from conftest import polyline

from contactfx.contact import contact_operator
from contactfx.contact.friction import Status, displacement_rows, linearize
from contactfx.contact.sparse import CSR

N = 6
K_H, K_S = 3.0, 1.0
DELTA = 0.1


def chain_stiffness(k_v: np.ndarray) -> np.ndarray:
    """Stiffness of the chain, dofs (ux_0, uy_0, ux_1, uy_1, ...)."""
    K = np.zeros((2 * N, 2 * N))
    for i in range(N - 1):
        a, b = 2 * i, 2 * (i + 1)
        K[np.ix_([a, b], [a, b])] += K_H * np.array([[1.0, -1.0], [-1.0, 1.0]])
    K[np.arange(0, 2 * N, 2), np.arange(0, 2 * N, 2)] += K_S
    K[np.arange(1, 2 * N, 2), np.arange(1, 2 * N, 2)] += k_v
    return K


def nodal_rows() -> tuple[np.ndarray, np.ndarray]:
    """Hand-written rows: gap = uy (floor normal +y, weight 1), slip along t = +x."""
    Bn = np.zeros((N, 2 * N))
    Bn[np.arange(N), 2 * np.arange(N) + 1] = 1.0
    Bt = np.zeros((N, 2 * N))
    Bt[np.arange(N), 2 * np.arange(N)] = 1.0
    return Bn, Bt


def kernel_rows(kernel: str, **options: str) -> tuple[np.ndarray, np.ndarray]:
    """The library's normal and tangential rows of the chain (active, nodes 0..N-1 at y = 0) on
    a floor surface (passive, held fixed: its columns dropped)."""
    floor = polyline(np.array([-1.0, 2.3, N + 0.0]), np.zeros(3), True, 2 * N)
    chain = polyline(np.arange(N, dtype=float), np.zeros(N), False, 0)
    nd = 2 * N + 6
    Bn = contact_operator(kernel, chain, floor, nd, **options).B.toarray()[:, : 2 * N]
    Bt = contact_operator(kernel, chain, floor, nd, direction="tangent", **options)
    return Bn, Bt.B.toarray()[:, : 2 * N]


def solve_steps(
    k_v: np.ndarray,
    mu: float,
    pushes: np.ndarray,
    c: float = 1.0,
    rows_B: tuple[np.ndarray, np.ndarray] | None = None,
):
    """Semismooth Newton per load step; returns per step (u, lambda_n, lambda_t, status, its)."""
    K = chain_stiffness(k_v)
    Bn, Bt = nodal_rows() if rows_B is None else rows_B
    Bn_csr, Bt_csr = (CSR.from_coo(*np.nonzero(B), B[B != 0], B.shape) for B in (Bn, Bt))
    u, lam_n, lam_t = np.zeros(2 * N), np.zeros(N), np.zeros(N)
    out = []
    for s in pushes:
        f = np.zeros(2 * N)
        f[0::2] = K_S * s
        f[1::2] = -k_v * DELTA
        u_prev = u.copy()
        for its in range(1, 40):  # noqa: B007  (its: the count of the last step)
            g, ut = Bn @ u, Bt @ (u - u_prev)
            rows = linearize(lam_n, lam_t, g, ut, mu, c, c)
            # Equilibrium: K u = f + Bn^T lambda_n - Bt^T lambda_t (friction opposes the slip).
            r = np.concatenate([K @ u - f - Bn.T @ lam_n + Bt.T @ lam_t, rows.cn, rows.ct])
            # The kernel's sparse rows, checked against the dense product of the set's rows.
            jn, jt = (j.toarray() for j in displacement_rows(rows, Bn_csr, Bt_csr))
            np.testing.assert_array_equal(jn, rows.dn[:, 2:3] * Bn + rows.dn[:, 3:4] * Bt)
            np.testing.assert_array_equal(jt, rows.dt[:, 2:3] * Bn + rows.dt[:, 3:4] * Bt)
            J = np.block(
                [
                    [K, -Bn.T, Bt.T],
                    [
                        jn,
                        np.diag(rows.dn[:, 0]),
                        np.diag(rows.dn[:, 1]),
                    ],
                    [
                        jt,
                        np.diag(rows.dt[:, 0]),
                        np.diag(rows.dt[:, 1]),
                    ],
                ]
            )
            if np.linalg.norm(r) <= 1e-12 * (1.0 + np.linalg.norm(f)):
                break
            d = np.linalg.solve(J, -r)
            u, lam_n, lam_t = u + d[: 2 * N], lam_n + d[2 * N : 3 * N], lam_t + d[3 * N :]
        else:
            raise AssertionError(f"no convergence at s={s}")
        out.append((u.copy(), lam_n.copy(), lam_t.copy(), rows.status.copy(), its))
    return out


def test_block_sticks_until_mu_p_then_slips_everywhere():
    """Equal normal springs: stick (ux = 0, lambda_t = k_s s) below Q = mu P, full slip above."""
    mu = 0.4
    k_v = np.full(N, 2.0)
    s_slip = mu * 2.0 * DELTA / K_S  # k_s s = mu lambda_n at every node at once
    pushes = s_slip * np.array([0.25, 0.5, 0.9, 1.1, 1.5, 2.0])
    for s, (u, lam_n, lam_t, status, its) in zip(pushes, solve_steps(k_v, mu, pushes), strict=True):
        np.testing.assert_allclose(lam_n, 2.0 * DELTA, rtol=1e-12)
        np.testing.assert_allclose(u[1::2], 0.0, atol=1e-14)
        P, Q = lam_n.sum(), lam_t.sum()
        if s < s_slip:
            assert np.all(status == Status.STICK)
            np.testing.assert_allclose(u[0::2], 0.0, atol=1e-14)
            np.testing.assert_allclose(lam_t, K_S * s, rtol=1e-12)
            assert Q < mu * P
        else:
            assert np.all(status == Status.SLIP)
            np.testing.assert_allclose(lam_t, mu * lam_n, rtol=1e-12)
            np.testing.assert_allclose(Q, mu * P, rtol=1e-12)
            # Uniform slip: every node moves by s - mu lambda_n / k_s (the chain stays unstretched).
            np.testing.assert_allclose(u[0::2], s - mu * 2.0 * DELTA / K_S, rtol=1e-12)
        assert its <= 4  # a piecewise-linear C: Newton ends once the sets are found


@pytest.mark.parametrize("c", [1e-2, 1.0, 1e2])
def test_partial_slip_obeys_coulomb_at_every_node(c):
    """Unequal normal springs: the lightly loaded nodes slip first; at every step and node the
    converged state satisfies Coulomb's law (checked from the law, not the kernel), the first
    slip comes at s = mu min(k_v) delta / k_s, and gross slip is the hand-derived state. The
    answer does not depend on the complementarity constant c."""
    mu = 0.3
    k_v = np.array([1.0, 1.5, 2.0, 2.5, 3.0, 4.0])
    s_first = mu * k_v.min() * DELTA / K_S
    pushes = s_first * np.array([0.5, 0.99, 1.2, 1.6, 2.2, 3.0, 4.0, 6.0])
    prev = np.zeros(2 * N)
    results = solve_steps(k_v, mu, pushes, c)
    for s, (u, lam_n, lam_t, status, _) in zip(pushes, results, strict=True):
        np.testing.assert_allclose(lam_n, k_v * DELTA, rtol=1e-12)
        slip = u[0::2] - prev[0::2]
        stick = status == Status.STICK
        np.testing.assert_allclose(slip[stick], 0.0, atol=1e-13)
        assert np.all(np.abs(lam_t[stick]) <= mu * lam_n[stick] + 1e-13)
        np.testing.assert_allclose(lam_t[~stick], mu * lam_n[~stick] * np.sign(slip[~stick]))
        assert np.all(slip[~stick] > 0)
        assert np.any(~stick) == (s > s_first)
        prev = u
    u, lam_n, lam_t, status, _ = results[-1]
    assert np.all(status == Status.SLIP)
    K_x = chain_stiffness(k_v)[0::2, 0::2]
    np.testing.assert_allclose(u[0::2], np.linalg.solve(K_x, K_S * pushes[-1] - mu * lam_n))
    # A partial-slip step lies between: some nodes stick and some slip.
    assert any(0 < np.sum(r[3] == Status.STICK) < N for r in results)


def test_frictionless_prototype():
    """mu = 0: lambda_t = 0, every contact node slips, and each node follows the plate freely."""
    k_v = np.array([1.0, 1.5, 2.0, 2.5, 3.0, 4.0])
    ((u, lam_n, lam_t, status, _),) = solve_steps(k_v, 0.0, np.array([0.05]))
    np.testing.assert_array_equal(lam_t, 0.0)
    assert np.all(status == Status.SLIP)
    np.testing.assert_allclose(u[0::2], 0.05, rtol=1e-12)
    np.testing.assert_allclose(lam_n, k_v * DELTA, rtol=1e-12)


@pytest.mark.parametrize(("kernel", "options"), [("nts", {}), ("mortar", {"basis": "dual"})])
def test_block_with_the_kernels_rows(kernel, options):
    """The same block with the library's rows (nts; dual mortar, whose D is diagonal): the
    multipliers are pressures, lambda_n = k_v delta / w_j with w_j the node's weight (1, 1/2 at
    the chain's ends), and the block still sticks until Q = sum w lambda_t reaches mu P, then
    slips with lambda_t = mu lambda_n at every node."""
    mu = 0.4
    Bn, Bt = kernel_rows(kernel, **options)
    w = np.r_[0.5, np.ones(N - 2), 0.5]
    np.testing.assert_allclose(Bn[np.arange(N), 2 * np.arange(N) + 1], w, rtol=1e-13)
    np.testing.assert_allclose(Bt[np.arange(N), 2 * np.arange(N)], w, rtol=1e-13)
    k_v = np.full(N, 2.0)
    s_slip = mu * 2.0 * DELTA / K_S
    pushes = s_slip * np.array([0.5, 0.95, 1.05, 1.5])
    for s, (_, lam_n, lam_t, status, _) in zip(
        pushes, solve_steps(k_v, mu, pushes, rows_B=(Bn, Bt)), strict=True
    ):
        np.testing.assert_allclose(lam_n, 2.0 * DELTA / w, rtol=1e-12)
        P, Q = w @ lam_n, w @ lam_t
        if s < s_slip:
            assert np.all(status == Status.STICK) and Q < mu * P
            np.testing.assert_allclose(lam_t, K_S * s / w, rtol=1e-12)
        else:
            assert np.all(status == Status.SLIP)
            np.testing.assert_allclose(lam_t, mu * lam_n, rtol=1e-12)
            np.testing.assert_allclose(Q, mu * P, rtol=1e-12)
