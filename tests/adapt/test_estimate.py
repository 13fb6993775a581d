"""The residual error estimate: zero on an exact solution, reliable against an overkill one."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import cli

import contactfx
from contactfx.adapt.estimate import BULK_TERMS, CONTACT_TERMS, estimate
from contactfx.adapt.facet_jumps import FacetTraction, jump_term
from contactfx.adapt.true_error import energy_error
from contactfx.scenes import BlockParams, HertzParams, blocks, hertz


def _hertz(h: float, slope: float = 0.3) -> contactfx.Scene:
    return hertz(HertzParams(refine=h, refine_edge=0.0, slope=slope))


def test_patch_test_has_no_residual() -> None:
    """Equal widths: mortar is exact (uniform stress), so every residual term vanishes."""
    sol = contactfx.solve(blocks(BlockParams(l2=10.0, size1=0.5, size2=0.4)), "mortar")
    est = estimate(sol)
    assert est.energy > 0
    # Every residual at round-off; complementarity is the square root of p times a gap
    # at round-off (1e-16 cm), hence larger.
    rel = {k: v / est.energy for k, v in est.terms.items()}
    assert all(v < 1e-11 for k, v in rel.items() if k != "complementarity"), rel
    assert rel["complementarity"] < 1e-7, rel


def test_parts_add_up_and_json() -> None:
    sol = contactfx.solve(_hertz(0.1), "mortar")
    est = estimate(sol)
    s = est.summary().to_json()
    assert set(s["terms"]) == set(BULK_TERMS) | set(CONTACT_TERMS)
    assert np.isclose(s["total"] ** 2, s["bulk"] ** 2 + s["contact"] ** 2)
    assert np.isclose(sum(v**2 for v in s["terms"].values()), s["total"] ** 2)
    # The cell indicators sum to the total.
    eta = est.eta.x.array
    assert np.isclose(np.sqrt(np.sum(eta**2)), est.total, rtol=1e-10)
    # Converged active set: the penetration at the nodes vanishes.
    assert s["terms"]["gap"] < 1e-6 * s["total"]
    # p_h g_h^+ lives on the segments across the zone's edge, where p_h falls from the last
    # active node and g_h rises to the first open one: by hand, int of two linear functions.
    pv = sol.pairs[0]
    surf = pv.active.surface
    p, g = np.zeros(surf.n_nodes), np.zeros(surf.n_nodes)
    p[pv.nodes], g[pv.nodes] = sol.pressure[pv.rows], np.maximum(sol.gap[pv.rows], 0.0)
    a, b = surf.segments[:, 0], surf.segments[:, 1]
    length = np.linalg.norm(surf.x[b, :2] - surf.x[a, :2], axis=1)
    mixed = (p[a] * g[b] + p[b] * g[a]) / 6
    by_hand = np.sum(length * (p[a] * g[a] / 3 + mixed + p[b] * g[b] / 3))
    assert by_hand > 0.0
    assert (s["terms"]["complementarity"] * est.energy) ** 2 == pytest.approx(by_hand, rel=1e-8)


def test_effectivity_against_overkill() -> None:
    """Three meshes: estimate / true energy error within [1, 10], spread within 3."""
    ref = contactfx.solve(hertz(HertzParams(refine=0.01, refine_edge=0.0, h_far=4.0)), "mortar")
    effs, ests = [], []
    for h in (0.1, 0.05):
        sol = contactfx.solve(_hertz(h, 0.2), "mortar")
        est = estimate(sol)
        err = energy_error(sol, ref)
        assert err is not None
        effs.append(est.total / err["error"])
        ests.append(est.relative)
    assert all(1.0 < e < 10.0 for e in effs), effs
    assert max(effs) / min(effs) < 3.0, effs


def test_hand_jumps_equal_the_ds_form() -> None:
    """The process-boundary path, run here on every interior facet from both of its cells,
    gives the dS form's jump term: same Gauss points, normals and pairing of the points."""
    sol = contactfx.solve(_hertz(0.1), "mortar")
    est = estimate(sol)
    msh = sol.scene.mesh
    msh.topology.create_connectivity(1, 2)
    msh.topology.create_connectivity(2, 1)
    f2c = msh.topology.connectivity(1, 2)
    c2f = msh.topology.connectivity(2, 1).array.reshape(-1, 4)
    facets = np.flatnonzero(np.diff(f2c.offsets) == 2)
    cells = f2c.array.reshape(-1)[f2c.offsets[facets][:, None] + np.arange(2)]
    traction = FacetTraction(sol)
    sides = [traction(cells[:, k], np.argmax(c2f[cells[:, k]] == facets[:, None], axis=1))
             for k in range(2)]  # fmt: skip
    (t0, e0, len0), (t1, e1, len1) = sides
    assert np.allclose(len0, len1, rtol=1e-14)
    # The two cells' points are the same physical points: t0 + t1 is small where sigma
    # is smooth; pairing point q with point nq - 1 - q instead changes the total.
    per_facet = jump_term(t0 + t1, 0.5 * (e0 + e1), len0, traction.weights)
    # Each facet's term goes to both of its cells.
    assert np.isclose(2 * per_facet.sum(), est.terms["jump"] ** 2, rtol=1e-12, atol=0)
    flipped = jump_term(t0 + t1[:, ::-1], 0.5 * (e0 + e1), len0, traction.weights)
    assert not np.isclose(2 * flipped.sum(), est.terms["jump"] ** 2, rtol=1e-3)


def test_true_error_of_itself_is_zero() -> None:
    sol = contactfx.solve(_hertz(0.1), "mortar")
    err = energy_error(sol, sol)
    assert err is not None and err["relative"] < 1e-10


def test_solve_estimate_cli(tmp_path: Path) -> None:
    proc = cli(
        "solve",
        "hertz",
        "--refine",
        "0.1",
        "--estimate",
        "--json",
        str(tmp_path / "r.json"),
        "--out",
        str(tmp_path / "out"),
    )
    assert proc.returncode == 0, proc.stderr
    data = json.loads((tmp_path / "r.json").read_text())
    e = data["estimate"]
    assert 0 < e["contact"] < e["total"] and 0 < e["bulk"] <= e["total"]
    assert "estimate (relative to the energy norm)" in proc.stdout
    assert 0 < e["pressure"] < 1 and "pressure estimate (relative L2)" in proc.stdout
    pyvista = pytest.importorskip("pyvista")
    grid = pyvista.read(str(tmp_path / "out" / "fields.pvtu"))
    eta = np.asarray(grid.cell_data["eta"])
    assert eta.shape == (data["elements"],)
    assert np.isclose(np.sqrt(np.sum(eta**2)), e["absolute"], rtol=1e-8)


def test_schwarz_estimate_refused() -> None:
    proc = cli("solve", "blocks", "--method", "schwarz", "--estimate")
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "--estimate" in proc.stderr


@pytest.mark.serial
@pytest.mark.parametrize(("model", "rel"), [("plane_stress", 1e-10), ("axisymmetric", 1e-3)])
def test_true_error_norm_is_the_models_energy(model: str, rel: float) -> None:
    """The overkill measure's energy norm (numpy, 4 x 4 Gauss points) equals the model's
    assembled a(u, u) (UFL): exactly for plane stress (polynomial integrands); to the
    quadratures' difference in axisymmetric (the hoop term u_r^2 / r is not polynomial)."""
    from dataclasses import replace

    from dolfinx import fem
    from mpi4py import MPI

    from contactfx.discretize.elasticity import energy_form
    from contactfx.scenes import BLOCK_SCENES, Model

    params = replace(BLOCK_SCENES["S1"], model=Model(model), size1=0.5, size2=0.5)
    sol, _ = contactfx.run_case(
        "blocks", params, contactfx.SolveRequest.parse("mortar"), comm=MPI.COMM_SELF
    )
    el = sol.fields
    a_uu = fem.assemble_scalar(fem.form(energy_form(sol.u, sol.u, el.E, el.nu, Model(model))))
    got = energy_error(sol, sol)
    assert got is not None and got["relative"] < 1e-12  # the point location's round-off
    assert got["norm"] == pytest.approx(float(a_uu) ** 0.5, rel=rel)
