"""A residual a posteriori error estimate of a multiplier-method solve, cell by cell.

The estimator of Hild & Nicaise (2007) and Wohlmuth (2007) for frictionless contact in
plane-strain elasticity, in the energy scaling (each squared term divided by the cell's
Young's modulus, so that it has the units of the energy a(u, u)):

    eta_K^2 = h_K^2 |div sigma(u_h)|^2_K / E                          element residual
            + sum_{interior e in dK} h_e / 2 |[sigma(u_h) n]|^2_e / E  traction jumps
            + sum_{boundary e in dK} h_e |M (sigma(u_h) n - t)|^2_e / E  Neumann residual
            + sum_{contact e in dK} h_e (sigma_nn + p_h)^2_e / E       normal stress vs. multiplier
            + sum_{contact e in dK} h_e (sigma_nt + s_h)^2_e / E        shear vs. multiplier
            + int_{contact e} p_h g_h^+                                complementarity
            + int_{contact e} E g_h^-^2 / h_e                          gap (penetration)

M masks the components a Dirichlet condition prescribes (rollers leave the other one
traction-free); sigma_nn, sigma_nt are each body's own traction on the contact frame (the
passive normal nu the multipliers act along, as results/interface.py resolves it), p_h the
piecewise-linear interpolant of the multipliers on the active surface and, on the passive
surface, at the projection of each passive node. With friction s_h is the shear lambda_t
interpolated the same way (0 without friction: the frictionless estimator's sigma_nt = 0),
and sigma_nt is read along T = (-N_y, N_x), N the contact normal of that surface: the
traction the multipliers put on either body is -p_h N - s_h T (contact/friction.py's t is T
on the active surface and -T on the passive one, where the shear acts oppositely). The
estimate is that of the solution handed in: a stepped solve's last step, whose multipliers
and displacement it reads together. docs/adapt.md has the references and the
measured effectivity. The jumps across process boundaries, which DOLFINx's dS does not
reach on the scenes' unghosted meshes, come from results/facet_jumps.py.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import ufl
from dolfinx import fem, la, mesh
from mpi4py import MPI

from ..contact.geometry import nodal_normals
from ..contact.search import project
from ..discretize.elasticity import energy_form, measure, radius, sigma_zz
from ..discretize.mesh_utils import vertex_to_block
from ..discretize.thermal import thermal_zz
from ..methods.solution import Solution
from ..results.records import EstimateSummary
from ..results.stress import stress_of
from ..scenes import Model, Pressure
from .facet_jumps import JUMP_DEGREE, FacetTraction, process_boundary_jumps, two_cell_facets
from .pressure_estimate import PressureEstimate, pressure_estimate

BULK_TERMS = ("element", "jump", "neumann")
CONTACT_TERMS = ("normal", "tangential", "complementarity", "gap")
_CONTACT_TAG0 = 1000  # facet tags of the contact surfaces start here


@dataclass
class Estimate:
    """The cell indicators and their sums; every number relative to the energy norm too."""

    eta: fem.Function  # DG0: eta_K, all terms of cell K
    terms: dict[str, float]  # sqrt of the sum over the cells of each term
    energy: float  # ||u_h||_E = sqrt(a(u_h, u_h))
    # Per owned cell: the sum of its contact terms (squared units, as eta_K^2).
    contact_cells: np.ndarray | None = None
    pressure: PressureEstimate | None = None  # the contact pressure's L2 error estimate

    def marking(self, contact_weight: float = 1.0) -> np.ndarray:
        """Per owned cell: eta_K with the contact terms times `contact_weight` (for sizing)."""
        Q = self.eta.function_space
        nloc = Q.mesh.topology.index_map(Q.mesh.topology.dim).size_local
        eta = self.eta.x.array[Q.dofmap.list[:nloc, 0]]
        if contact_weight == 1.0 or self.contact_cells is None:
            return eta
        return np.sqrt(eta**2 + (contact_weight**2 - 1.0) * self.contact_cells)

    @property
    def bulk(self) -> float:
        """The element, jump and Neumann terms together."""
        return float(np.sqrt(sum(self.terms[k] ** 2 for k in BULK_TERMS)))

    @property
    def contact(self) -> float:
        """The contact terms together."""
        return float(np.sqrt(sum(self.terms[k] ** 2 for k in CONTACT_TERMS)))

    @property
    def total(self) -> float:
        """The whole estimate, sqrt(sum_K eta_K^2)."""
        return float(np.hypot(self.bulk, self.contact))

    @property
    def relative(self) -> float:
        """Total / ||u_h||_E."""
        return self.total / self.energy

    def summary(self) -> EstimateSummary:
        """The record of the JSON block `estimate`: relative total, parts and each term."""
        e = self.energy
        return EstimateSummary(
            total=self.relative,
            contact=self.contact / e,
            bulk=self.bulk / e,
            terms={k: v / e for k, v in self.terms.items()},
            absolute=self.total,
            energy_norm=e,
            pressure=self.pressure.relative if self.pressure is not None else None,
        )


def _surface_nodes(sol: Solution, gblock: np.ndarray, S: fem.FunctionSpace) -> np.ndarray:
    """Local dofs of the scalar Q1 space S at global nodes `gblock` of V (-1 if not here)."""
    V = sol.fields.V
    local = V.dofmap.index_map.global_to_local(gblock.astype(np.int64))
    v2b = vertex_to_block(V)
    block_to_vertex = np.full(v2b.max() + 1, -1, dtype=np.int64)
    block_to_vertex[v2b[v2b >= 0]] = np.flatnonzero(v2b >= 0)
    s_of_v = vertex_to_block(S)
    out = np.full(len(gblock), -1, dtype=np.int64)
    ok = local >= 0
    out[ok] = s_of_v[block_to_vertex[local[ok]]]
    return out


class _ContactFields:
    """Q1 fields on the contact surfaces: frame normal N, multipliers p and s, gap terms.

    s is the shear (0 without friction).
    """

    def __init__(self, sol: Solution) -> None:
        msh = sol.scene.mesh
        self.S = fem.functionspace(msh, ("Lagrange", 1))
        self.p = fem.Function(self.S)
        self.s = fem.Function(self.S)  # the shear lambda_t (contact/friction.py)
        self.g = fem.Function(self.S)  # the multiplier rows' gaps at the active nodes
        self.pen = fem.Function(self.S)  # (g^-)^2 at the active nodes
        self.N = [fem.Function(self.S), fem.Function(self.S)]
        for k in range(len(sol.pairs)):
            self._pair(sol, k)

    def _set(self, f: fem.Function, dofs: np.ndarray, values: np.ndarray) -> None:
        ok = dofs >= 0
        f.x.array[dofs[ok]] = values[ok]

    def _pair(self, sol: Solution, k: int) -> None:
        pv = sol.pairs[k]
        surf = pv.active.surface
        p_nodes = pv.nodal(sol.pressure)
        fr = sol.friction
        s_nodes = pv.nodal(fr.shear) if fr is not None else np.zeros_like(p_nodes)
        normal = nodal_normals(surf)
        normal[pv.nodes] = pv.frame[0]
        gap = sol.gap[pv.rows]
        dofs = _surface_nodes(sol, pv.active.gblock, self.S)
        self._set(self.p, dofs, p_nodes)
        self._set(self.s, dofs, s_nodes)
        for c in range(2):
            self._set(self.N[c], dofs, normal[:, c])
        rows = dofs[pv.nodes]
        self._set(self.g, rows, gap)
        self._set(self.pen, rows, np.minimum(gap, 0.0) ** 2)
        if pv.passive is None:
            return
        # The passive side carries the multiplier at the projection of each of its nodes.
        ps = pv.passive.surface
        seg, xi, found = project(ps.x, surf)
        ends = surf.segments[seg]
        dofs_p = _surface_nodes(sol, pv.passive.gblock, self.S)
        for f, v in ((self.p, p_nodes), (self.s, s_nodes)):
            at = (1 - xi) * v[ends[:, 0]] + xi * v[ends[:, 1]]
            self._set(f, dofs_p, np.where(found, at, 0.0))
        normal_p = nodal_normals(ps)
        for c in range(2):
            self._set(self.N[c], dofs_p, normal_p[:, c])


def _boundary_tags(sol: Solution) -> tuple[mesh.MeshTags, list[tuple[int, Any, Any]], list[int]]:
    """Tags of the exterior facets: contact surfaces, and one class per (mask, load).

    Returns the tags, the Neumann classes (tag, mask, load or None) and the contact tags.
    """
    scene = sol.scene
    msh = scene.mesh
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    nfac = msh.topology.index_map(tdim - 1).size_local
    ext = mesh.exterior_facet_indices(msh.topology)
    ext = ext[ext < nfac]
    tags = scene.facet_tags

    def find(group: str) -> np.ndarray:
        dim, tag = scene.groups.by_name[group]
        if dim != tdim - 1 or tags is None:
            return np.zeros(0, dtype=np.int32)
        return tags.find(tag)

    mask = np.full(nfac, 3, dtype=np.int64)  # bit c set: component c is traction-free/loaded
    for bc in scene.dirichlet:
        facets = find(bc.group)
        facets = facets[facets < nfac]
        for comp, _ in bc.components():
            mask[facets] &= ~(1 << comp)
    load = np.full(nfac, -1, dtype=np.int64)
    for i, ld in enumerate(scene.loads):
        facets = find(ld.group)
        load[facets[facets < nfac]] = i
    value = np.zeros(nfac, dtype=np.int32)
    nl = len(scene.loads) + 1
    value[ext] = 1 + mask[ext] * nl + load[ext] + 1
    value[ext[mask[ext] == 0]] = 0  # fully prescribed: no residual
    groups = sorted(
        {
            g
            for pv in sol.pairs
            for g in (pv.pair.active, pv.pair.passive)
            if g in scene.groups.by_name
        }
    )
    contact_tags = []
    for j, group in enumerate(groups):
        facets = find(group)
        value[facets[facets < nfac]] = _CONTACT_TAG0 + j
        contact_tags.append(_CONTACT_TAG0 + j)
    keep = np.flatnonzero(value > 0).astype(np.int32)
    mt = mesh.meshtags(msh, tdim - 1, keep, value[keep])
    classes = []
    for tag in np.unique(value[(value > 0) & (value < _CONTACT_TAG0)]):
        m, k = divmod(int(tag) - 1, nl)
        classes.append((int(tag), (m & 1, (m >> 1) & 1), scene.loads[k - 1] if k else None))
    return mt, classes, contact_tags


def equilibrium_residual(sol: Solution, sig: Any) -> Any:
    """Div sigma of the in-plane stress `sig`; in axisymmetric the cylindrical divergence.

    Axisymmetric (x = r): (d_r s_rr + d_z s_rz + (s_rr - s_tt) / r, d_r s_rz + d_z s_zz + s_rz / r),
    s_tt the hoop stress (a thermal strain's own part taken off, as in `sig`).
    """
    div = ufl.div(sig)
    if sol.scene.model is not Model.AXISYMMETRIC:
        return div
    el = sol.fields
    hoop = sigma_zz(sol.u, el.E, el.nu, Model.AXISYMMETRIC)
    thermal = thermal_zz(sol.scene, el.E, el.nu)
    if thermal is not None:
        hoop = hoop - thermal
    r = radius(sol.scene.mesh)
    # Off the axis only: at r = 0 the terms are 0/0 (their limits are the gradients'); the
    # quadrature points of a cell never lie on the axis.
    return div + ufl.as_vector([(sig[0, 0] - hoop) / r, sig[0, 1] / r])


def estimate(sol: Solution) -> Estimate:
    """The residual estimate of a multiplier-method (or penalty) solution (collective)."""
    scene = sol.scene
    msh = scene.mesh
    u, E, nu = sol.u, sol.fields.E, sol.fields.nu
    Q = fem.functionspace(msh, ("DG", 0))
    w = ufl.TestFunction(Q)
    n = ufl.FacetNormal(msh)
    hK = ufl.CellDiameter(msh)
    # A Q1 facet is straight and its reference edge has length 1: |J_f| is its length.
    he: Any = abs(ufl.geometry.FacetJacobianDeterminant(msh))
    sig = stress_of(sol)
    tn = ufl.dot(sig, n)
    # Every integral of the model: 2 pi r in axisymmetric (a revolved body), else 1.
    m = measure(msh, scene.model)
    res = equilibrium_residual(sol, sig)
    mt, classes, contact_tags = _boundary_tags(sol)
    ds = ufl.Measure("ds", domain=msh, subdomain_data=mt)
    cf = _ContactFields(sol)
    traction = FacetTraction(sol)
    N = ufl.as_vector([cf.N[0], cf.N[1]])
    N = N / ufl.sqrt(ufl.dot(N, N) + 1e-300)
    forms: dict[str, Any] = {
        "element": hK**2 * ufl.inner(res, res) / E * m * w * ufl.dx,
        "jump": 0.5
        * ufl.avg(he)
        * ufl.inner(ufl.jump(sig, n), ufl.jump(sig, n))
        / ufl.avg(E)
        * (ufl.avg(m) if scene.model is Model.AXISYMMETRIC else 1.0)
        * (w("+") + w("-"))
        * ufl.dS(
            1, subdomain_data=two_cell_facets(msh), metadata={"quadrature_degree": JUMP_DEGREE}
        ),
    }
    neumann = fem.Constant(msh, 0.0) * w * ufl.dx
    for tag, (mx, my), load in classes:
        if load is None:
            t = ufl.as_vector([0.0, 0.0])
        elif isinstance(load, Pressure):
            t = -load.p * n
        else:
            t = ufl.as_vector(list(load.t))
        r = tn - t
        neumann += he * (mx * r[0] ** 2 + my * r[1] ** 2) / E * m * w * ds(tag)
    forms["neumann"] = neumann
    dsc = ds(tuple(contact_tags)) if contact_tags else ds(_CONTACT_TAG0)
    tnn = ufl.dot(tn, N)
    # The shear's direction (docstring): the multipliers' traction is -p N - s T.
    tnt = ufl.dot(tn, ufl.as_vector([-N[1], N[0]]))
    forms["normal"] = he * (tnn + cf.p) ** 2 / E * m * w * dsc
    forms["tangential"] = he * (tnt + cf.s) ** 2 / E * m * w * dsc
    # The interpolants' product, not the nodal one: p_h g_h^+ vanishes at every node of a
    # converged set but not in the cell across the zone's edge, where p_h falls from its
    # last active node and g_h rises to its first inactive one.
    forms["complementarity"] = cf.p * ufl.max_value(cf.g, 0.0) * m * w * dsc
    forms["gap"] = E * cf.pen / he * m * w * dsc
    nloc = msh.topology.index_map(msh.topology.dim).size_local
    cell_dof = Q.dofmap.list[:nloc, 0]
    total, contact = np.zeros(nloc), np.zeros(nloc)
    terms = {}
    for key, form in forms.items():
        vec = fem.assemble_vector(fem.form(form))
        vec.scatter_reverse(la.InsertMode.add)
        vals = vec.array[cell_dof]
        if key == "jump":
            vals = vals + process_boundary_jumps(sol, traction)
        vals = np.maximum(vals, 0.0)
        total += vals
        if key in CONTACT_TERMS:
            contact += vals
        terms[key] = float(np.sqrt(msh.comm.allreduce(float(vals.sum()), op=MPI.SUM)))
    eta = fem.Function(Q, name="eta")
    eta.x.array[cell_dof] = np.sqrt(total)
    eta.x.scatter_forward()
    # ||u_h||_E^2 = a(u_h, u_h), the model's own bilinear form.
    a_uu = fem.form(energy_form(u, u, E, nu, scene.model))
    energy = float(np.sqrt(msh.comm.allreduce(fem.assemble_scalar(a_uu), op=MPI.SUM)))
    return Estimate(eta, terms, energy, contact, pressure_estimate(sol))
