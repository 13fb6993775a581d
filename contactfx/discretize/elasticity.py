"""Plane-strain linear elasticity of every body: space, materials, loads, Dirichlet conditions."""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import dolfinx.fem.petsc
import numpy as np
import ufl
from dolfinx import fem, mesh
from petsc4py import PETSc

from ..errors import MeshError
from ..scenes import Pressure, Scene
from .thermal import thermal_load


@dataclass(frozen=True)
class Elasticity:
    """The assembled elastic problem of all bodies (K has identity rows at Dirichlet dofs)."""

    V: fem.FunctionSpace
    K: PETSc.Mat
    f: PETSc.Vec
    bcs: list[fem.DirichletBC]
    bc_dofs: np.ndarray
    E: fem.Function
    nu: fem.Function


def material_fields(scene: Scene) -> tuple[fem.Function, fem.Function]:
    """DG0 fields of E and nu from the body cell tags."""
    Q = fem.functionspace(scene.mesh, ("DG", 0))
    E, nu = fem.Function(Q, name="E"), fem.Function(Q, name="nu")
    for body in scene.bodies:
        dofs = Q.dofmap.list[scene.body_cells(body)].ravel()
        E.x.array[dofs] = body.material.E
        nu.x.array[dofs] = body.material.nu
    E.x.scatter_forward()
    nu.x.scatter_forward()
    return E, nu


def sigma(u: ufl.core.expr.Expr, E: fem.Function, nu: fem.Function) -> ufl.core.expr.Expr:
    """Plane-strain Cauchy stress of the displacement u."""
    lmbda = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    eps = ufl.sym(ufl.grad(u))
    return 2 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(2)


def check_quadrilateral(msh: mesh.Mesh) -> None:
    """Raise MeshError unless every cell is a quadrilateral (Q1 is what the methods assume)."""
    if msh.topology.cell_type != mesh.CellType.quadrilateral:
        name = msh.topology.cell_type.name
        raise MeshError(f"contactfx needs an all-quadrilateral mesh, got {name} cells")


def dirichlet_conditions(scene: Scene, V: fem.FunctionSpace) -> list[fem.DirichletBC]:
    """One DirichletBC per prescribed component of every [[dirichlet]] group (curve or point)."""
    msh = V.mesh
    bcs = []
    for bc in scene.dirichlet:
        dim, tag = scene.groups.by_name[bc.group]
        tags = scene.facet_tags if dim == msh.topology.dim - 1 else scene.point_tags
        if tags is None:
            raise MeshError(f"dirichlet: the mesh carries no entities of group '{bc.group}'")
        if dim == 0:
            msh.topology.create_connectivity(0, msh.topology.dim)
        entities = tags.find(tag)
        for comp, value in bc.components():
            dofs = fem.locate_dofs_topological(V.sub(comp), dim, entities)
            # The stub types ScalarType as a dtype instance; it is the scalar class.
            bcs.append(fem.dirichletbc(PETSc.ScalarType(value), dofs, V.sub(comp)))  # type: ignore[operator]
    return bcs


def load_form(scene: Scene, v: ufl.Argument) -> ufl.Form:
    """The external work of the scene's pressures and tractions (zero if there are none)."""
    msh = scene.mesh
    ds = ufl.Measure("ds", domain=msh, subdomain_data=scene.facet_tags)
    n = ufl.FacetNormal(msh)
    zero = fem.Constant(msh, np.zeros(2, dtype=PETSc.ScalarType))
    L = ufl.inner(zero, v) * ufl.dx
    for load in scene.loads:
        dsg = ds(scene.curve_tag(load.group, "load"))
        if isinstance(load, Pressure):
            L += -fem.Constant(msh, PETSc.ScalarType(load.p)) * ufl.dot(n, v) * dsg  # type: ignore[operator]
        else:
            t = fem.Constant(msh, np.asarray(load.t, dtype=PETSc.ScalarType))
            L += ufl.dot(t, v) * dsg
    return L


def assemble_elasticity(scene: Scene) -> Elasticity:
    """Assemble K and f of every body with the scene's supports and loads."""
    msh = scene.mesh
    check_quadrilateral(msh)
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    E, nu = material_fields(scene)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = fem.form(ufl.inner(sigma(u, E, nu), ufl.sym(ufl.grad(v))) * ufl.dx)
    thermal = thermal_load(scene, v, E, nu)
    L = fem.form(load_form(scene, v) if thermal is None else load_form(scene, v) + thermal)
    bcs = dirichlet_conditions(scene, V)

    K = dolfinx.fem.petsc.assemble_matrix(a, bcs=bcs)
    K.assemble()
    f = dolfinx.fem.petsc.assemble_vector(L)
    dolfinx.fem.petsc.apply_lifting(f, [a], bcs=[bcs])
    # The stub types the mode values as int but the parameters as the enum classes.
    f.ghostUpdate(
        addv=cast(PETSc.InsertMode, PETSc.InsertMode.ADD),
        mode=cast(PETSc.ScatterMode, PETSc.ScatterMode.REVERSE),
    )
    dolfinx.fem.petsc.set_bc(f, bcs)
    bc_dofs = (
        np.unique(np.concatenate([bc.dof_indices()[0] for bc in bcs]))
        if bcs
        else np.zeros(0, dtype=np.int32)
    )
    return Elasticity(V, K, f, bcs, bc_dofs, E, nu)
