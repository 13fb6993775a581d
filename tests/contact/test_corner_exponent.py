"""benchmarks/corner_exponent.py: the sharp edge's pressure exponent from the Williams
eigenproblem, checked against two classical corners and against Hooke's law."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))

from corner_exponent import (  # benchmarks/ is not a package: on sys.path above
    _fields,
    edge_exponent,
    free_corner_determinant,
    smallest_root,
)


def test_williams_fields_satisfy_hookes_law():
    # Strains of the displacement formulas (central differences) against the stresses.
    lam, nu, mu = 0.37, 0.3, 1.7
    c = np.random.default_rng(0).normal(size=4)

    def at(r, t):
        srr, stt, srt, ur, ut = _fields(lam, t, nu, mu)
        return [r ** (lam - 1) * (v @ c) for v in (srr, stt, srt)] + [
            r**lam * (v @ c) for v in (ur, ut)
        ]

    r, t, e = 1.3, 0.4, 1e-6
    srr, stt, srt, ur, ut = at(r, t)
    d_r = [(a - b) / (2 * e) for a, b in zip(at(r + e, t), at(r - e, t), strict=True)]
    d_t = [(a - b) / (2 * e) for a, b in zip(at(r, t + e), at(r, t - e), strict=True)]
    tr = srr + stt
    assert 2 * mu * d_r[3] == pytest.approx(srr - nu * tr, rel=1e-7)
    assert 2 * mu * (ur / r + d_t[4] / r) == pytest.approx(stt - nu * tr, rel=1e-7)
    assert mu * (d_t[3] / r + d_r[4] - ut / r) == pytest.approx(srt, rel=1e-7)


def test_free_270_degree_corner_is_williams():
    # Williams (1952): the re-entrant square corner, lam = 0.544484.
    lam = smallest_root(lambda v: free_corner_determinant(v, 1.5 * np.pi))
    assert lam == pytest.approx(0.5444837, abs=1e-6)


def test_rigid_square_edge_is_the_flat_punch():
    # A rigid wedge on the half-plane: the flat punch's inverse square root.
    assert edge_exponent(mu_ratio=1e9) == pytest.approx(0.5, abs=1e-6)


def test_same_material_square_edge_does_not_depend_on_nu():
    # Same material on both sides: kappa is common and leaves the determinant; the elastic
    # wedge yields, so the edge is milder than the rigid punch's 1/2. (The refinement study,
    # benchmarks/edge_refinement.py, measures the finite elements' growth against it.)
    s = [edge_exponent(nu1=nu, nu2=nu) for nu in (0.0, 0.3, 0.45)]
    np.testing.assert_allclose(s, s[1], rtol=1e-9)
    assert 0.2 < s[1] < 0.25
    # A softer wedge on a stiffer body has a weaker edge than a stiffer wedge.
    assert edge_exponent(mu_ratio=0.5) < s[1] < edge_exponent(mu_ratio=2.0)
