"""Plane-strain linear elasticity of both bodies: space, materials, forms, Dirichlet conditions."""

from __future__ import annotations

from dataclasses import dataclass

import dolfinx.fem.petsc
import numpy as np
import ufl
from dolfinx import fem, mesh
from petsc4py import PETSc

from .errors import MeshError
from .scenes import Scene


@dataclass(frozen=True)
class Elasticity:
    """The assembled elastic problem of both bodies (K has identity rows at Dirichlet dofs)."""

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
    for body, mat in zip((1, 2), scene.materials, strict=True):
        cells = scene.cell_tags.find(scene.tags[f"body{body}"])
        dofs = Q.dofmap.list[cells].ravel()
        E.x.array[dofs] = mat.E
        nu.x.array[dofs] = mat.nu
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


def assemble_elasticity(scene: Scene) -> Elasticity:
    """Assemble K and f with roller supports, symmetry and the pressure load of the scene."""
    msh = scene.mesh
    check_quadrilateral(msh)
    for name in ("body1", "body2", "symmetry", "support", "load", "contact1", "contact2"):
        if name not in scene.tags:
            raise MeshError(f"the mesh has no physical group '{name}'")
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    E, nu = material_fields(scene)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=scene.facet_tags)
    p = fem.Constant(msh, PETSc.ScalarType(scene.pressure))
    n = ufl.FacetNormal(msh)
    a = fem.form(ufl.inner(sigma(u, E, nu), ufl.sym(ufl.grad(v))) * ufl.dx)
    L = fem.form(-p * ufl.dot(n, v) * ds(scene.tags["load"]))

    fdim = msh.topology.dim - 1
    sym_facets = scene.facet_tags.find(scene.tags["symmetry"])
    sup_facets = scene.facet_tags.find(scene.tags["support"])
    # Rollers, as in the paper: u_x = 0 on the symmetry axis, u_y = 0 on the base only.
    sym_dofs = fem.locate_dofs_topological(V.sub(0), fdim, sym_facets)
    sup_dofs = fem.locate_dofs_topological(V.sub(1), fdim, sup_facets)
    zero = PETSc.ScalarType(0)
    bcs = [fem.dirichletbc(zero, sym_dofs, V.sub(0)), fem.dirichletbc(zero, sup_dofs, V.sub(1))]

    K = dolfinx.fem.petsc.assemble_matrix(a, bcs=bcs)
    K.assemble()
    f = dolfinx.fem.petsc.assemble_vector(L)
    dolfinx.fem.petsc.apply_lifting(f, [a], bcs=[bcs])
    f.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    dolfinx.fem.petsc.set_bc(f, bcs)
    bc_dofs = np.unique(np.concatenate([bc.dof_indices()[0] for bc in bcs]))
    return Elasticity(V, K, f, bcs, bc_dofs, E, nu)
