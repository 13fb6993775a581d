"""Friction's pivots on the condensed path: one or two constraint rows per contact node.

With a diagonal D (dual mortar) every contact row touches one active node only, so the
active rows decouple node by node. A node in contact gives its normal row; a sticking
node also its tangential row, and then both of its displacements are pivots (a 2 x 2 block
[n; t] D_jj, invertible). Constraint rows C (B_n on the active nodes, B_t on the sticking
ones) give T = I + E_C, u = T v + t. The force rows G differ on slipping nodes only: there
the tangential multiplier is -mu s times the normal one (Coulomb's slip), so G_j = B_n,j -
mu s B_t,j carries the node's one multiplier. W = I + E_G is zero on G's rows (G W = 0) and
turns K u + G^T mu = f into W^T K T v = W^T (f - K t): unsymmetric where nodes slip. The
multipliers follow from the pivot rows: G_AP^T mu = (f - K u)_P, node by node.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from ..errors import SolverError
from .elimination import LocalRows, PivotRows
from .pivots import DIAGONAL_TOL


@dataclass(frozen=True)
class NodeBlocks:
    """The pivots of one frictional set (owned rows): E_C's and E_G's rows, the node blocks."""

    dofs: np.ndarray  # every pivot dof (global), node by node
    c_rows: PivotRows  # rows of E_C = T - I, by local row of the pivot dof
    g_rows: PivotRows  # rows of E_G = W - I
    shift_values: np.ndarray  # t at `dofs`: the constraints met with the free dofs at 0
    nodes: list[tuple[int, np.ndarray, np.ndarray, float]]  # (row, pivots, L_G, slip coef)
    m: int

    def multipliers(self, residual: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(mu_n, mu_t) of the owned rows from (f - K u) at `dofs` (in their order)."""
        mu_n, mu_t = np.zeros(self.m), np.zeros(self.m)
        at = 0
        for j, piv, LG, coef in self.nodes:
            k = len(piv)
            x = np.linalg.solve(LG.T, residual[at : at + k])
            at += k
            mu_n[j], mu_t[j] = (x[0], x[1]) if k == 2 else (x[0], coef * x[0])
        return mu_n, mu_t


def _dense(rows: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """Sparse rows as one dense block over the union of their columns (zeros dropped)."""
    cols = np.unique(np.concatenate([c[v != 0.0] for c, v in rows]))
    block = np.zeros((len(rows), len(cols)))
    for i, (c, v) in enumerate(rows):
        block[i, np.searchsorted(cols, c[v != 0.0])] = v[v != 0.0]
    return cols, block


def _own(own: np.ndarray, row: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """A row's coefficients on the node's two dofs (0 where absent: a prescribed dof)."""
    cols, vals = row
    out = np.zeros(2)
    for k, d in enumerate(own):
        out[k] = vals[cols == d].sum()
    return out


def _both_free(
    own: np.ndarray, n: tuple[np.ndarray, np.ndarray], t: tuple[np.ndarray, np.ndarray]
) -> bool:
    """Whether the normal and tangential rows can take both of the node's dofs as pivots."""
    L = np.vstack([_own(own, n), _own(own, t)])
    return bool(abs(np.linalg.det(L)) > DIAGONAL_TOL * np.abs(L).max() ** 2)


def node_blocks(
    Bn: LocalRows,
    Bt: LocalRows,
    active: np.ndarray,
    stick: np.ndarray,
    coef: np.ndarray,
    g: tuple[np.ndarray, np.ndarray],
    comm: MPI.Comm,
    r0: int,
) -> NodeBlocks:
    """The pivots of the set: `active` rows in contact, `stick` (of them) sticking.

    `coef` (owned rows): mu_t = coef mu_n on a slipping row (-mu s; 0: frictionless row);
    `g` = (g_n, g_t): the constraints B_n u = -g_n, B_t u = -g_t. SolverError if a row
    touches another node's pivot (D not diagonal: standard mortar, a curved passive face).
    """
    g_n, g_t = g
    dofs: list[np.ndarray] = []
    shift: list[np.ndarray] = []
    c_rows: PivotRows = {}
    g_rows: PivotRows = {}
    nodes: list[tuple[int, np.ndarray, np.ndarray, float]] = []
    touched: list[tuple[np.ndarray, np.ndarray, float]] = []
    # A row this rank cannot eliminate is said on every rank (raised by one alone, the others
    # would wait in the collectives below).
    prescribed = False
    for j in np.flatnonzero(active):
        cn, vn = Bn.row(j)
        ct, vt = Bt.row(j)
        own = Bn.node_dofs[j]
        # A node with a prescribed displacement (a symmetry line, the axis) has one free dof:
        # its normal row takes it, its tangential row is dropped (no shear there).
        if stick[j] and _both_free(own, (cn, vn), (ct, vt)):
            piv = np.asarray(own, dtype=np.int64)
            cols, C = _dense([(cn, vn), (ct, vt)])
            G, rhs = C, np.array([g_n[j], g_t[j]])
        else:
            mine = np.isin(cn, own) & (vn != 0.0)
            if not mine.any():
                prescribed = True
                continue
            k = np.flatnonzero(mine)[int(np.argmax(np.abs(vn[mine])))]
            piv = np.array([cn[k]], dtype=np.int64)
            cols, rows = _dense([(cn, vn), (ct, vt)])
            C, G = rows[:1], rows[:1] + (coef[j] if not stick[j] else 0.0) * rows[1:]
            rhs = np.array([g_n[j]])
        at = np.searchsorted(cols, piv)
        LC, LG = C[:, at], G[:, at]
        EC, EG = -np.linalg.solve(LC, C), -np.linalg.solve(LG, G)
        EC[:, at] = EG[:, at] = -np.eye(len(piv))  # exactly: T and W vanish on the pivots
        for i, p in enumerate(piv):
            c_rows[int(p - r0)] = (cols, EC[i])
            g_rows[int(p - r0)] = (cols, EG[i])
        dofs.append(piv)
        shift.append(-np.linalg.solve(LC, rhs))
        nodes.append((int(j), piv, LG, 0.0 if stick[j] else float(coef[j])))
        others = np.ones(len(cols), dtype=bool)
        others[at] = False
        scale = float(np.abs(LC).max())
        touched.append((cols[others], np.abs(np.vstack([C, G])[:, others]).max(axis=0), scale))
    if comm.allreduce(prescribed, op=MPI.LOR):
        raise SolverError(
            "the condensed solver cannot eliminate a contact row whose active node is "
            "fully prescribed: use --solver mumps"
        )
    piv_all = np.concatenate(comm.allgather(np.concatenate(dofs) if dofs else np.zeros(0, int)))
    coupled = any(
        np.any(vals[np.isin(cols, piv_all)] > DIAGONAL_TOL * scale) for cols, vals, scale in touched
    )
    if comm.allreduce(coupled, op=MPI.LOR):
        raise SolverError(
            "friction on the condensed solver needs the dual basis (a diagonal D): a contact "
            "row touches another contact node's displacement"
        )
    return NodeBlocks(
        np.concatenate(dofs) if dofs else np.zeros(0, dtype=np.int64),
        c_rows,
        g_rows,
        np.concatenate(shift) if shift else np.zeros(0),
        nodes,
        len(active),
    )
