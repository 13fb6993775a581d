"""Thermal strain: the eigenstrain alpha dT I of every body, as a load and in the stress.

With the eigenstrain eps0 = alpha dT I (3D, isotropic), the stress is sigma = C (eps - eps0)
= C eps - sigma0, where sigma0 = C eps0 is the stress the eigenstrain would carry if the
body could not move (`thermal_stress`). The weak form a(u, v) = L(v) gains the load
int sigma0 : eps(v) dx on its right-hand side (`thermal_load`); the stresses of a solution
subtract sigma0 (`thermal_correction`). In each 2D model (docs/models.md, "Thermal strain"):

- plane strain (eps_zz = 0 in total): in plane, sigma0 = (3 lambda + 2 mu) alpha dT I
  = E alpha dT / (1 - 2 nu) I, and sigma_zz = nu (sxx + syy) - E alpha dT;
- plane stress (sigma_zz = 0): sigma0 = C_ps alpha dT I = E alpha dT / (1 - nu) I;
- axisymmetric (r, z in plane, theta the hoop): the 3D law, sigma0 = E alpha dT / (1 - 2 nu)
  in rr, zz and theta-theta (the hoop term enters the load as sigma0_tt u_r / r).

A body without alpha and dT has sigma0 = 0: no form is added, so a scene without a thermal
load assembles exactly what it did before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import ufl
from dolfinx import fem, mesh

from ..scenes import Model, Scene

# A number or a UFL expression (the stub types UFL's arithmetic loosely).
Coefficient = Any


@dataclass(frozen=True)
class ThermalStress:
    """sigma0 = C eps0 of the isotropic eigenstrain eps0 = alpha dT I in one 2D model.

    `in_plane`: the coefficient s of the in-plane tensor s I (2x2); `out_of_plane`: the
    eigenstress's own zz (plane strain, axisymmetric: the hoop theta-theta) component, 0 in
    plane stress. The physical out-of-plane stress of plane strain is
    nu (sxx + syy) - E alpha dT (`plane_strain_szz`).
    """

    in_plane: Coefficient
    out_of_plane: Coefficient


def thermal_stress(
    E: Coefficient, nu: Coefficient, alpha: Coefficient, dT: Coefficient, model: Model
) -> ThermalStress:
    """The eigenstress C (alpha dT I) of `model` (numbers or UFL expressions alike)."""
    eps0 = alpha * dT
    if model is Model.PLANE_STRESS:
        # C_ps I = E / (1 - nu^2) ((1 - nu) I + nu tr(I) I) = E (1 + nu) / (1 - nu^2) I.
        return ThermalStress(E * eps0 / (1 - nu), 0.0)
    # Plane strain and axisymmetric: the 3D law, (3 lambda + 2 mu) eps0 = E eps0 / (1 - 2 nu)
    # in every normal direction (zz of plane strain, the hoop of the axisymmetric model).
    s = E * eps0 / (1 - 2 * nu)
    return ThermalStress(s, s)


def plane_strain_szz(
    sxx: Coefficient, syy: Coefficient, E: Coefficient, nu: Coefficient, eps0: Coefficient
) -> Coefficient:
    """Plane strain's out-of-plane stress with an eigenstrain eps0: nu (sxx + syy) - E eps0."""
    return nu * (sxx + syy) - E * eps0


def has_thermal_load(scene: Scene) -> bool:
    """Whether any body carries a thermal strain (alpha dT != 0)."""
    return any(b.material.thermal_strain != 0.0 for b in scene.bodies)


def thermal_strain_field(scene: Scene) -> fem.Function:
    """The DG0 field alpha dT of the bodies (collective)."""
    Q = fem.functionspace(scene.mesh, ("DG", 0))
    eps0 = fem.Function(Q, name="eps0")
    for body in scene.bodies:
        dofs = Q.dofmap.list[scene.body_cells(body)].ravel()
        eps0.x.array[dofs] = body.material.thermal_strain
    eps0.x.scatter_forward()
    return eps0


def axisymmetric_thermal_load(
    msh: mesh.Mesh, v: ufl.Argument, E: fem.Function, nu: fem.Function, eps0: fem.Function
) -> ufl.Form:
    """The axisymmetric load int sigma0 : eps(v) 2 pi r dx, x = r (the 3D law's eigenstress).

    eps(v) has eps_rr + eps_zz = tr(sym grad v) in plane and the hoop strain v_r / r, so
    sigma0 : eps(v) r = s0 (r tr(grad v) + v_r), s0 = E eps0 / (1 - 2 nu) (no 1/r left).
    `thermal_load` returns it for an axisymmetric scene; `thermal_zz` gives the hoop part
    of sigma0 that the reported hoop stress subtracts.
    """
    s0 = thermal_stress(E, nu, eps0, 1.0, Model.AXISYMMETRIC).in_plane
    r = ufl.SpatialCoordinate(msh)[0]
    return 2 * math.pi * s0 * (r * ufl.tr(ufl.grad(v)) + v[0]) * ufl.dx


def thermal_load(
    scene: Scene, v: ufl.Argument, E: fem.Function, nu: fem.Function
) -> ufl.Form | None:
    """The load int sigma0 : eps(v) dx of every body's eigenstrain; None without a thermal load."""
    if not has_thermal_load(scene):
        return None
    eps0 = thermal_strain_field(scene)
    if scene.model is Model.AXISYMMETRIC:
        return axisymmetric_thermal_load(scene.mesh, v, E, nu, eps0)
    s0 = thermal_stress(E, nu, eps0, 1.0, scene.model).in_plane
    return s0 * ufl.tr(ufl.sym(ufl.grad(v))) * ufl.dx


def thermal_correction(
    scene: Scene, E: fem.Function, nu: fem.Function
) -> ufl.core.expr.Expr | None:
    """sigma0 (2x2) to subtract from C eps(u) for the physical stress; None without one."""
    if not has_thermal_load(scene):
        return None
    eps0 = thermal_strain_field(scene)
    return thermal_stress(E, nu, eps0, 1.0, scene.model).in_plane * ufl.Identity(2)


def thermal_zz(scene: Scene, E: fem.Function, nu: fem.Function) -> Coefficient | None:
    """sigma0's out-of-plane (plane strain) or hoop (axisymmetric) part; None without one.

    The physical sigma_zz is the elastic C eps(u) one less this: in plane strain
    lambda tr(eps) - E alpha dT / (1 - 2 nu) = nu (sxx + syy) - E alpha dT with the
    physical in-plane stresses; 0 in plane stress.
    """
    if not has_thermal_load(scene):
        return None
    eps0 = thermal_strain_field(scene)
    return thermal_stress(E, nu, eps0, 1.0, scene.model).out_of_plane
