"""Linear elasticity of every body: space, materials, loads, Dirichlet conditions.

The 2D model (scenes.Model) decides the law and the measure: plane strain (eps_zz = 0),
plane stress (sigma_zz = 0: the in-plane law with lambda* = 2 lambda mu / (lambda + 2 mu)),
axisymmetric (x = r, y the axis; the hoop strain u_r / r, and every integral over the
revolved body: 2 pi r dx in the volume, 2 pi r ds on the loaded curves). docs/models.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, cast

import dolfinx.la.petsc
import numpy as np
import ufl
from dolfinx import fem, mesh
from dolfinx.cpp.fem import petsc as cpp_petsc
from mpi4py import MPI
from petsc4py import PETSc

from ..errors import MeshError
from ..scenes import Model, Pressure, Scene
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


def lame(E: ufl.core.expr.Expr, nu: ufl.core.expr.Expr, model: Model) -> tuple[Any, Any]:
    """(lambda, mu) of the model's law; plane stress: lambda* = 2 lambda mu / (lambda + 2 mu)."""
    mu = E / (2 * (1 + nu))
    if model is Model.PLANE_STRESS:
        return E * nu / (1 - nu * nu), mu
    return E * nu / ((1 + nu) * (1 - 2 * nu)), mu


def radius(msh: mesh.Mesh) -> ufl.core.expr.Expr:
    """The radius r = x of an axisymmetric model (a UFL expression on the mesh)."""
    return ufl.SpatialCoordinate(msh)[0]


def hoop_strain(u: ufl.core.expr.Expr, msh: mesh.Mesh, at_nodes: bool = True) -> ufl.core.expr.Expr:
    """eps_theta = u_r / r; with `at_nodes`, on the axis (r = 0) its limit d u_r / d r.

    `at_nodes` is for expressions evaluated at cell vertices (collective: "on the axis" is up
    to round-off of the mesh size, gmsh writes 1e-17 for 0); forms, whose quadrature points
    lie inside the cells, take plain u_r / r (FFCx cannot factor a conditional of arguments).
    """
    r = radius(msh)
    if not at_nodes:
        return u[0] / r
    extent = float(np.max(np.abs(msh.geometry.x[:, 0]), initial=0.0))
    tol = 1e-12 * msh.comm.allreduce(extent, op=MPI.MAX)
    return ufl.conditional(ufl.gt(r, tol), u[0] / r, ufl.grad(u)[0, 0])


def strain(u: ufl.core.expr.Expr, model: Model, at_nodes: bool = True) -> ufl.core.expr.Expr:
    """The 3 x 3 strain of the displacement u: in-plane sym(grad u), eps_zz in (2, 2).

    eps_zz is 0 in plane strain, the hoop strain u_r / r in axisymmetric (`hoop_strain`); in
    plane stress it is not a kinematic quantity (sigma_zz = 0 fixes it) and is left 0
    (`stress` ignores it).
    """
    e = ufl.sym(ufl.grad(u))
    msh = u.ufl_function_space().mesh
    ezz = hoop_strain(u, msh, at_nodes) if model is Model.AXISYMMETRIC else 0.0
    return ufl.as_matrix([[e[0, 0], e[0, 1], 0.0], [e[1, 0], e[1, 1], 0.0], [0.0, 0.0, ezz]])


def stress(
    eps: ufl.core.expr.Expr, E: ufl.core.expr.Expr, nu: ufl.core.expr.Expr, model: Model
) -> ufl.core.expr.Expr:
    """Cauchy stress of a strain tensor under the 2D model: THE constitutive law.

    A stable entry point: its name and signature stay, so that eigenstrains (thermal
    strain, interference) enter as `stress(eps - eps0, E, nu, model)`.

    `eps` is either 3 x 3 (in-plane block, out-of-plane zero, eps_zz in (2, 2): the hoop
    strain in axisymmetric, the out-of-plane strain in plane strain, ignored in plane
    stress), giving the 3 x 3 stress with sigma_zz (sigma_theta in axisymmetric; 0 in
    plane stress); or 2 x 2 in-plane (eps_zz = 0), giving the in-plane 2 x 2 stress.
    Plane strain and axisymmetric use the 3D law; plane stress the in-plane law with
    lambda* = 2 lambda mu / (lambda + 2 mu).
    """
    lmbda, mu = lame(E, nu, model)
    dim = eps.ufl_shape[0]
    if dim == 2 or model is not Model.PLANE_STRESS:
        return 2 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(dim)
    tr2 = eps[0, 0] + eps[1, 1]
    s = [[2 * mu * eps[i, j] + (lmbda * tr2 if i == j else 0.0) for j in (0, 1)] for i in (0, 1)]
    return ufl.as_matrix([[s[0][0], s[0][1], 0.0], [s[1][0], s[1][1], 0.0], [0.0, 0.0, 0.0]])


def in_plane(t: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
    """The in-plane 2 x 2 block of a 3 x 3 tensor."""
    return ufl.as_matrix([[t[0, 0], t[0, 1]], [t[1, 0], t[1, 1]]])


def sigma(
    u: ufl.core.expr.Expr,
    E: fem.Function,
    nu: fem.Function,
    model: Model = Model.PLANE_STRAIN,
) -> ufl.core.expr.Expr:
    """The in-plane (2 x 2) Cauchy stress of the displacement u under the model."""
    if model is Model.AXISYMMETRIC:
        return in_plane(stress(strain(u, model), E, nu, model))
    return stress(ufl.sym(ufl.grad(u)), E, nu, model)


def sigma_zz(
    u: ufl.core.expr.Expr, E: fem.Function, nu: fem.Function, model: Model
) -> ufl.core.expr.Expr:
    """The out-of-plane stress: nu (sxx + syy) in plane strain, 0 in plane stress, sigma_theta."""
    return stress(strain(u, model), E, nu, model)[2, 2]


def measure(msh: mesh.Mesh, model: Model) -> ufl.core.expr.Expr | float:
    """The factor of every integral: 2 pi r in axisymmetric (a revolved body), else 1."""
    return 2 * math.pi * radius(msh) if model is Model.AXISYMMETRIC else 1.0


def energy_form(
    u: ufl.core.expr.Expr, v: ufl.core.expr.Expr, E: fem.Function, nu: fem.Function, model: Model
) -> ufl.Form:
    """The bilinear form a(u, v) = int sigma(u) : eps(v) (times 2 pi r in axisymmetric)."""
    if model is Model.AXISYMMETRIC:
        msh = v.ufl_function_space().mesh
        w = measure(msh, model)
        eps_u, eps_v = strain(u, model, at_nodes=False), strain(v, model, at_nodes=False)
        return ufl.inner(stress(eps_u, E, nu, model), eps_v) * w * ufl.dx
    return ufl.inner(sigma(u, E, nu, model), ufl.sym(ufl.grad(v))) * ufl.dx


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
    # Axisymmetric: the loads act on the revolved surface (2 pi r ds): totals over the turn.
    axi = scene.model is Model.AXISYMMETRIC
    w = measure(msh, scene.model)
    for load in scene.loads:
        dsg = ds(scene.curve_tag(load.group, "load"))
        v_w = v * w if axi else v
        if isinstance(load, Pressure):
            L += -fem.Constant(msh, PETSc.ScalarType(load.p)) * ufl.dot(n, v_w) * dsg  # type: ignore[operator]
        else:
            t = fem.Constant(msh, np.asarray(load.t, dtype=PETSc.ScalarType))
            L += ufl.dot(t, v_w) * dsg
    return L


# dolfinx.fem.petsc's assemble_matrix / assemble_vector + apply_lifting for one form, by the
# same calls in the same order (K and f equal bit for bit: tests/methods/test_assembly.py):
# importing dolfinx.fem.petsc builds a cffi parser of PETSc's C declarations (pycparser) that
# nothing here uses; its cost: docs/scale.md, "Time to the first answer".
def petsc_matrix(a: fem.Form, bcs: list[fem.DirichletBC]) -> PETSc.Mat:
    """The PETSc matrix of the form `a`, `bcs` rows and columns zeroed, 1 on their diagonal.

    Not finalized: the caller calls assemble() (as after dolfinx.fem.petsc.assemble_matrix).
    """
    cbcs = [bc._cpp_object for bc in bcs]
    A = cpp_petsc.create_matrix(a._cpp_object, None)
    constants, coeffs = fem.assemble.pack_constants(a), fem.assemble.pack_coefficients(a)
    cpp_petsc.assemble_matrix(A, a._cpp_object, constants, coeffs, cbcs)
    if a.function_spaces[0] is a.function_spaces[1]:
        A.assemblyBegin(PETSc.Mat.AssemblyType.FLUSH)
        A.assemblyEnd(PETSc.Mat.AssemblyType.FLUSH)
        cpp_petsc.insert_diagonal(A, a.function_spaces[0], cbcs, 1.0)
    return A


def petsc_vector(L: fem.Form, a: fem.Form, bcs: list[fem.DirichletBC]) -> PETSc.Vec:
    """The PETSc vector of the linear form `L`, lifted by `a` and `bcs` (ghosts not summed)."""
    V = L.function_spaces[0]
    b = dolfinx.la.petsc.create_vector([(V.dofmap.index_map, V.dofmap.index_map_bs)])
    with b.localForm() as local:
        local.set(0.0)
        fem.assemble_vector(local.array_w, L)  # type: ignore[arg-type]  # (array, form): dispatch
        fem.apply_lifting(local.array_w, [a], [bcs], [], 1.0)
    return b


def assemble_elasticity(scene: Scene) -> Elasticity:
    """Assemble K and f of every body with the scene's supports and loads."""
    msh = scene.mesh
    check_quadrilateral(msh)
    V = fem.functionspace(msh, ("Lagrange", 1, (2,)))
    E, nu = material_fields(scene)
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = fem.form(energy_form(u, v, E, nu, scene.model))
    thermal = thermal_load(scene, v, E, nu)
    L = fem.form(load_form(scene, v) if thermal is None else load_form(scene, v) + thermal)
    bcs = dirichlet_conditions(scene, V)

    K = petsc_matrix(a, bcs)
    K.assemble()
    f = petsc_vector(L, a, bcs)
    # The stub types the mode values as int but the parameters as the enum classes.
    f.ghostUpdate(
        addv=cast(PETSc.InsertMode, PETSc.InsertMode.ADD),
        mode=cast(PETSc.ScatterMode, PETSc.ScatterMode.REVERSE),
    )
    for bc in bcs:  # dolfinx.fem.petsc.set_bc(f, bcs)
        bc.set(f.array_w, None, 1.0)
    bc_dofs = (
        np.unique(np.concatenate([bc.dof_indices()[0] for bc in bcs]))
        if bcs
        else np.zeros(0, dtype=np.int32)
    )
    return Elasticity(V, K, f, bcs, bc_dofs, E, nu)
