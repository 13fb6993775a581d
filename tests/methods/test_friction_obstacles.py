"""Coulomb friction against rigid obstacles (methods/friction.py with contact/rigid_kernels.py).

A block (1 x 1, 6 x 6 quads; the base below it is held and touches nothing) on a rigid flat
floor at y = 1: the obstacle's rows follow its exact tangent, and its prescribed motion (its
`name` in the load steps) enters the slip. References: the uniform state of the frictional
patch test (exact) and Coulomb's law at every node with Q = mu P in full slip.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT
from test_friction import check_coulomb, forces

from contactfx import InputError, Obstacle, load_scene_file, scene_from_gmsh, solve
from contactfx.contact.friction import Status
from contactfx.errors import SingularSystemError
from contactfx.scenes import Dirichlet, Material, Pressure, Scene, Traction

PATCH = ROOT / "tests" / "scenes" / "friction_patch.geo"
FLOOR_TOML = ROOT / "tests" / "scenes" / "rigid_floor.toml"
MU, P = 0.3, 10.0
CASES = [("mortar", "standard"), ("mortar", "dual"), ("nts", "standard")]


def floor(mu: float, slide: float = 0.0) -> Obstacle:
    """The rigid floor under the block, moved by `slide` along x (its motion: 'floor')."""
    return Obstacle(
        "floor", "plane", "block_bottom", point=(0.0, 1.0), normal=(0.0, 1.0),
        displacement=(slide, 0.0), mu=mu,
    )  # fmt: skip


def on_floor(
    obstacle: Obstacle,
    dirichlet: list[Dirichlet],
    loads: list[Pressure | Traction],
    nu: float = 0.0,
    steps: list[dict[str, float]] | None = None,
) -> Scene:
    """The block on the rigid floor; the base is held and touches nothing."""
    return scene_from_gmsh(
        PATCH,
        bodies={"base": Material(1000.0, 0.0), "block": Material(1000.0, nu)},
        contacts=[],
        obstacles=[obstacle],
        dirichlet=[Dirichlet("base_bottom", ux=0.0, uy=0.0), *dirichlet],
        loads=loads,
        steps=steps or [],
    )


@pytest.mark.parametrize(("method", "basis"), CASES)
@pytest.mark.parametrize(
    ("tau", "delta", "status"),
    [(2.0, 0.0, Status.STICK), (MU * P, 0.01, Status.SLIP), (-MU * P, -0.01, Status.SLIP)],
)
def test_patch_test_on_a_moving_rigid_floor_is_exact(
    method: str, basis: str, tau: float, delta: float, status: Status
) -> None:
    """sigma = [[0, tau], [tau, -P]] in the block (nu = 0), imposed by consistent tractions on
    its sides; the floor slides by s = 0.02 and the top moves by the shear strain's u_x + s
    + delta. The uniform state is exact: pressure P and shear tau at every node to 1e-8, stick
    with no slip relative to the moving floor (the floor's motion enters the slip: read
    against the fixed floor it would be s), or slip by delta with |tau| = mu P."""
    s, gamma = 0.02, 2.0 * tau / 1000.0  # G = E / 2 at nu = 0
    scene = on_floor(
        floor(MU, s),
        [Dirichlet("block_top", ux=gamma + s + delta)],
        [Pressure("block_top", P), Traction("block_right", (0.0, tau)),
         Traction("block_left", (0.0, -tau))],
    )  # fmt: skip
    sol = solve(scene, method, basis=basis)
    fr = sol.friction
    assert fr is not None
    np.testing.assert_array_equal(fr.status, status)
    np.testing.assert_allclose(sol.pressure, P, rtol=1e-8)
    np.testing.assert_allclose(fr.shear, tau, rtol=1e-8)
    np.testing.assert_allclose(fr.slip, delta, rtol=0, atol=1e-10)


@pytest.mark.parametrize(("method", "basis"), CASES)
def test_block_on_a_sliding_floor_sticks_then_slips_at_mu_p(method: str, basis: str) -> None:
    """The block (nu = 0.3) pressed by P, its top held along x, the floor slid in steps
    (the obstacle's motion scaled by the steps): Coulomb's law at every node in every step,
    Q grows while nodes stick and stays below mu P, and once every contact node slips
    |shear| = mu p at every node and Q = mu P to 1e-10."""
    scene = on_floor(
        floor(MU, 0.05),
        [Dirichlet("block_top", ux=0.0)],
        [Pressure("block_top", P, name="press")],
        nu=0.3,
        steps=[{"press": 1.0}, {"floor": 0.04}, {"floor": 0.1}, {"floor": 1.0}],
    )
    sol = solve(scene, method, basis=basis)
    assert len(sol.steps) == 4
    qs = []
    for before, step in zip([None, *sol.steps[:-1]], sol.steps, strict=True):
        check_coulomb(step, MU, before)
        p_total, q_total = forces(step)
        assert p_total == pytest.approx(P, rel=1e-10)
        qs.append(q_total)
    assert abs(qs[0]) < 1e-10 * P  # pressed alone: the block is mirror-symmetric
    # The floor moves +x and drags the block's bottom: the traction on it is -lambda_t t.
    assert 0.0 > qs[1] > qs[2] > -MU * P
    for step in sol.steps[1:3]:
        assert step.friction is not None
        assert np.any(step.friction.status == Status.STICK)
    last = sol.steps[-1]
    assert last.friction is not None
    assert np.all(last.friction.status[last.active] == Status.SLIP)
    np.testing.assert_allclose(
        np.abs(last.friction.shear[last.active]), MU * last.pressure[last.active], rtol=1e-10
    )
    assert qs[-1] == pytest.approx(-MU * P, rel=1e-10)


def test_frictionless_obstacle_is_todays_model() -> None:
    """mu = 0 on an obstacle (the default) never enters the frictional path: the rigid floor
    patch test's answer bit for bit; a vanishing mu runs it and gives the same pressures."""
    plain = load_scene_file(FLOOR_TOML)
    sol = solve(plain, "mortar")
    assert sol.friction is None
    obstacles = tuple(
        Obstacle(o.name, o.shape, o.surface, point=o.point, normal=o.normal, mu=0.0)
        for o in plain.obstacles
    )
    zero = replace(plain, obstacles=obstacles)
    again = solve(zero, "mortar")
    np.testing.assert_array_equal(again.pressure, sol.pressure)
    np.testing.assert_array_equal(again.u.x.array, sol.u.x.array)
    tiny = solve(replace(plain, obstacles=tuple(replace(o, mu=1e-12) for o in obstacles)), "mortar")
    assert tiny.friction is not None
    np.testing.assert_allclose(tiny.pressure, sol.pressure, rtol=0, atol=1e-9 * P)


@pytest.mark.parametrize("mu", [-0.1, "a", float("nan")])
def test_bad_mu_on_an_obstacle_is_refused_in_one_line(mu: object, tmp_path: Path) -> None:
    """Obstacle(mu=...) and `mu` in an [[obstacle]] table: one line naming the obstacle."""
    with pytest.raises(InputError, match="obstacle 'floor': mu must be a number >= 0") as err:
        floor(mu)  # type: ignore[arg-type]
    assert "\n" not in str(err.value)
    text = FLOOR_TOML.read_text().replace('surface = "bottom"', f'surface = "bottom"\nmu = {mu!r}')
    geo = FLOOR_TOML.parent / "rigid_floor.geo"
    text = text.replace('mesh = "rigid_floor.geo"', f'mesh = "{geo}"')
    path = tmp_path / "s.toml"
    path.write_text(text)
    with pytest.raises(InputError, match="mu") as err:
        load_scene_file(path)
    assert "\n" not in str(err.value)


def test_summary_carries_the_shear_on_the_obstacle() -> None:
    """The JSON's obstacle pair in full slip: the floor drags the block by mu P along +x, the
    block holds the floor back by as much (the obstacle's force from its own columns, not
    from the body's), and the interface carries shear, slip and status."""
    from contactfx import SolveRequest, run_scene

    scene = on_floor(
        floor(MU, 0.05), [Dirichlet("block_top", ux=0.0)], [Pressure("block_top", P)], nu=0.3
    )
    _, run = run_scene(scene, SolveRequest.parse("mortar"))
    pair = run.to_json()["contacts"][0]
    assert pair["passive"] == "floor"
    np.testing.assert_allclose(pair["force"], [MU * P, P], rtol=1e-10)
    np.testing.assert_allclose(pair["force_passive"], [-MU * P, -P], rtol=1e-10)
    assert set(pair["interface"]["status"]) <= {"open", "slip"}
    assert "slip" in pair["interface"]["status"]


@pytest.mark.parametrize(("method", "basis"), CASES)
def test_a_block_held_sideways_by_a_frictional_floor_alone(method: str, basis: str) -> None:
    """The block pressed on the rigid floor and pulled sideways by a tenth of P, nothing else
    holding it along x: stick on the floor holds it (the free-body check counts the
    obstacle's tangential rows), the shear carries the whole pull, Coulomb's law at every
    node; frictionless, the same block is refused before any solve."""
    loads: list[Pressure | Traction] = [Pressure("block_top", P), Traction("block_top", (1.0, 0.0))]
    sol = solve(on_floor(floor(MU), [], loads), method, basis=basis)
    check_coulomb(sol, MU)
    fr = sol.friction
    assert fr is not None and np.any(fr.status == Status.STICK)
    # The pull over the block's top (width 1) is the shear's total.
    assert abs(float(sol.layout.weights @ fr.shear)) == pytest.approx(1.0, rel=1e-6)
    with pytest.raises(SingularSystemError, match="translation along x"):
        solve(on_floor(floor(0.0), [], loads), method, basis=basis)
