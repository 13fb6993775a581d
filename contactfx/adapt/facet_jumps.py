"""The estimate's traction jumps on the facets DOLFINx's dS cannot reach: process boundaries.

The scenes' meshes have no ghost cells (scenes/gmsh_io.py's partitioner), so a facet whose
two cells are on two ranks has one cell on each and no interior-facet integral. Here each
side evaluates its one-sided traction sigma(u_h) n at the same Gauss points as the dS form,
the two are summed through a facet vector's scatter (a neighbourhood exchange), and each
rank adds 0.5 h_e |[sigma n]|^2 / avg(E) to its own cell. The same rule on both paths makes
a 2-rank estimate equal the serial one to round-off.
"""

from __future__ import annotations

import basix
import numpy as np
import ufl
from dolfinx import fem, la, mesh

from ..discretize.elasticity import measure
from ..methods.solution import Solution
from ..results.stress import stress_of

# The jumps' quadrature degree: UFL's own estimate for the integrand (so the serial numbers
# are those of the estimated rule), fixed because the facets on process boundaries are
# integrated by hand (process_boundary_jumps) and must use the same Gauss rule.
JUMP_DEGREE = 7
# DOLFINx's reference quadrilateral: its vertices, and the two vertices of each local facet.
_QUAD_VERTICES = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
_QUAD_FACETS = np.array([[0, 1], [0, 2], [1, 3], [2, 3]])


def facet_rule() -> tuple[np.ndarray, np.ndarray]:
    """The jumps' Gauss rule on [0, 1]: points (nq,) and weights (nq,), summing to 1."""
    s, wts = basix.make_quadrature(basix.CellType.interval, JUMP_DEGREE)
    return s[:, 0], wts


class FacetTraction:
    """sigma(u_h) n of one cell on one of its facets, at the jump rule's points (collective).

    The points run along the facet from its vertex of lower global index to the other, so
    that the two cells of a facet, even on two ranks, list the same physical points.
    """

    def __init__(self, sol: Solution) -> None:
        msh = sol.scene.mesh
        self.msh = msh
        s, self.weights = facet_rule()
        ends = _QUAD_VERTICES[_QUAD_FACETS]  # (4 facets, 2 ends, 2)
        X = ends[:, :1] + s[None, :, None] * (ends[:, 1:] - ends[:, :1])
        self.nq = len(s)
        sig = stress_of(sol)
        # The model's measure (2 pi r in axisymmetric) at the points: the tractions carry its
        # square root, so that |[sigma n]|^2 is weighted as the dS form weights it.
        m = measure(msh, sol.scene.model)
        values = ufl.as_vector([sig[0, 0], sig[0, 1], sig[1, 0], sig[1, 1], sol.fields.E, m])
        self.expr = fem.Expression(values, X.reshape(-1, 2))

    def __call__(
        self, cells: np.ndarray, local_facets: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Tractions (n, nq, 2), E (n,) and lengths (n,) of facet `local_facets` of each cell."""
        msh, nq = self.msh, self.nq
        n = len(cells)
        vals = self.expr.eval(msh, cells.astype(np.int32)).reshape(n, 4, nq, 6)
        vals = vals[np.arange(n), local_facets]  # (n, nq, 6)
        msh.topology.create_connectivity(2, 0)
        c2v = msh.topology.connectivity(2, 0).array.reshape(-1, 4)[cells]
        x = msh.geometry.x[msh.geometry.dofmaps[0][cells], :2]  # Q1: nodes are the vertices
        ab = _QUAD_FACETS[local_facets]
        rows = np.arange(n)[:, None]
        xa, xb = x[rows, ab].transpose(1, 0, 2)
        t = xb - xa
        length = np.linalg.norm(t, axis=1)
        normal = np.column_stack([t[:, 1], -t[:, 0]]) / length[:, None]
        outward = np.einsum("ij,ij->i", normal, 0.5 * (xa + xb) - x.mean(axis=1))
        normal[outward < 0] *= -1.0
        sig = vals[:, :, :4].reshape(n, nq, 2, 2)
        trac = np.einsum("nqij,nj->nqi", sig, normal) * np.sqrt(vals[:, :, 5:6])
        gv = msh.topology.index_map(0).local_to_global(c2v[rows, ab].ravel().astype(np.int32))
        flip = gv.reshape(n, 2)[:, 0] > gv.reshape(n, 2)[:, 1]
        trac[flip] = trac[flip, ::-1]
        return trac, vals[:, 0, 4], length


def jump_term(
    jump: np.ndarray, avg_e: np.ndarray, length: np.ndarray, weights: np.ndarray
) -> np.ndarray:
    """Per facet: 0.5 h_e int_e |[sigma n]|^2 / avg(E), from the jump at the rule's points.

    A Q1 facet is straight: h_e is its length and ds = length * weight.
    """
    return 0.5 * length**2 * np.sum(weights * np.sum(jump**2, axis=2), axis=1) / avg_e


def two_cell_facets(msh: mesh.Mesh) -> mesh.MeshTags:
    """The interior facets with both cells on this rank, tagged 1: the jumps' dS domain.

    DOLFINx refuses an untagged dS on a mesh with facets on process boundaries and no
    ghost cells; those facets are process_boundary_jumps' business.
    """
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    nfac = msh.topology.index_map(tdim - 1).size_local
    # Owned only: on a mesh ghosted by facet, each shared facet counts once, on its owner.
    facets = np.flatnonzero(np.diff(f2c.offsets)[:nfac] == 2).astype(np.int32)
    return mesh.meshtags(msh, tdim - 1, facets, np.ones(len(facets), dtype=np.int32))


def process_boundary_jumps(sol: Solution, traction: FacetTraction) -> np.ndarray:
    """Per owned cell: the jump term of its facets on process boundaries (collective).

    DOLFINx's dS skips a facet whose other cell is on another rank (the scenes' meshes have
    no ghost cells). Each rank puts its cell's one-sided traction on the facet's entry of a
    facet vector; a reverse (add) then forward scatter gives both ranks t_self + t_other.
    """
    msh = sol.scene.mesh
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    msh.topology.create_connectivity(tdim, tdim - 1)
    nloc = msh.topology.index_map(tdim).size_local
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    facets = msh.topology.interprocess_facets()
    cells = f2c.array[f2c.offsets[facets]]  # their only local cell
    # A ghost cell's facet is the owning rank's business (none with the scenes' meshes).
    facets, cells = facets[cells < nloc], cells[cells < nloc]
    c2f = msh.topology.connectivity(tdim, tdim - 1).array.reshape(-1, 4)
    local = np.argmax(c2f[cells] == facets[:, None], axis=1)
    trac, E, length = traction(cells, local)
    nq = traction.nq
    bs = 2 * nq + 1
    vec = la.vector(msh.topology.index_map(tdim - 1), bs)
    data = vec.array.reshape(-1, bs)
    data[facets, : 2 * nq] = trac.reshape(len(facets), 2 * nq)
    data[facets, -1] = E
    vec.scatter_reverse(la.InsertMode.add)
    vec.scatter_forward()
    both = vec.array.reshape(-1, bs)[facets]
    jump = both[:, : 2 * nq].reshape(-1, nq, 2)
    out = np.zeros(nloc)
    np.add.at(out, cells, jump_term(jump, 0.5 * both[:, -1], length, traction.weights))
    return out
