"""Write a solution's mesh as a gmsh .msh (format 2.2): quads and tagged lines, with names.

The adaptive loop's final mesh, which a scene file can load again (`mesh = "mesh.msh"`):
every physical surface (body) and curve group keeps its name and tag. Gathered to rank 0.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..methods.solution import Solution


def _gathered(sol: Solution) -> tuple | None:
    """(node global ids, xy, quads (global ids), cell tags, lines, line tags) on rank 0."""
    scene = sol.scene
    msh = scene.mesh
    tdim = msh.topology.dim
    nloc = msh.topology.index_map(tdim).size_local
    gmap = msh.geometry.index_map()
    ngeo = gmap.size_local + gmap.num_ghosts
    gid = gmap.local_to_global(np.arange(ngeo, dtype=np.int32))
    geo = msh.geometry.dofmaps[0]
    quads = gid[geo[:nloc][:, [0, 1, 3, 2]]]  # gmsh goes round the quad
    ctag = np.zeros(nloc, dtype=np.int64)
    for body in scene.bodies:
        cells = scene.body_cells(body)
        ctag[cells[cells < nloc]] = scene.body_tag(body)
    # Facets: their vertices' geometry nodes (Q1: a cell's vertices are its nodes, in order).
    msh.topology.create_connectivity(tdim, 0)
    msh.topology.create_connectivity(tdim - 1, 0)
    c2v = msh.topology.connectivity(tdim, 0).array.reshape(-1, 4)
    v2g = np.zeros(
        msh.topology.index_map(0).size_local + msh.topology.index_map(0).num_ghosts, dtype=np.int64
    )
    v2g[c2v.ravel()] = geo[: c2v.shape[0]].ravel()
    lines, ltag = np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    nfac = msh.topology.index_map(tdim - 1).size_local
    if scene.facet_tags is not None:
        ft = scene.facet_tags
        own = ft.indices < nfac
        f2v = msh.topology.connectivity(tdim - 1, 0).array.reshape(-1, 2)
        lines = gid[v2g[f2v[ft.indices[own]]]]
        ltag = ft.values[own].astype(np.int64)
    xy = msh.geometry.x[: gmap.size_local, :2]
    parts = msh.comm.gather((gid[: gmap.size_local], xy, quads, ctag, lines, ltag), root=0)
    if parts is None:
        return None
    return tuple(np.concatenate([p[i] for p in parts]) for i in range(6))


def write_msh(sol: Solution, path: Path) -> Path | None:
    """Write the mesh of `sol` to `path` (collective; the file from rank 0, else None)."""
    data = _gathered(sol)
    if data is None:
        return None
    gids, xy, quads, ctag, lines, ltag = data
    names = sol.scene.groups.by_name
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(names))]
    out += [f'{g.dim} {g.tag} "{name}"' for name, g in sorted(names.items())]
    out += ["$EndPhysicalNames", "$Nodes", str(len(gids))]
    out += [f"{i + 1} {float(x)!r} {float(y)!r} 0" for i, (x, y) in zip(gids, xy, strict=True)]
    out += ["$EndNodes", "$Elements", str(len(lines) + len(quads))]
    k = 0
    for (a, b), t in zip(lines, ltag, strict=True):
        k += 1
        out.append(f"{k} 1 2 {t} {t} {a + 1} {b + 1}")
    for q, t in zip(quads, ctag, strict=True):
        k += 1
        out.append(f"{k} 3 2 {t} {t} " + " ".join(str(v + 1) for v in q))
    out.append("$EndElements")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(out) + "\n")
    return path
