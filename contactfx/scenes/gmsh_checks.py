"""Checks of the gmsh model on rank 0 before it becomes a DOLFINx mesh.

All quadrilaterals (Q1 is what every method assumes), and bodies that share no mesh node
(contact needs the interface nodes duplicated).
"""

from __future__ import annotations

import numpy as np

from ..errors import MeshError
from ..meshes import QUAD4

# The other 2D element types of gmsh, named for the error message.
_GMSH_2D_NAMES = {
    2: "3-node triangles",
    9: "6-node triangles",
    10: "9-node quadrangles",
    16: "8-node quadrangles",
}


def check_quadrilaterals() -> None:
    """Raise MeshError unless the current gmsh model's 2D elements are all 4-node quads."""
    import gmsh  # only to mesh (first-answer time: docs/scale.md)

    types, tags, _ = gmsh.model.mesh.getElements(2)
    if not len(types):
        raise MeshError("the gmsh model has no 2D elements (mesh it in 2D, or give a .geo)")
    other = [(int(t), len(e)) for t, e in zip(types, tags, strict=True) if t != QUAD4]
    if other:
        what = ", ".join(f"{n} {_GMSH_2D_NAMES.get(t, f'type-{t} elements')}" for t, n in other)
        raise MeshError(
            f"contactfx needs an all-quadrilateral mesh (Q1 only), the mesh has "
            f"{what}: recombine it (Mesh.RecombineAll = 1, Mesh.Algorithm = 8)"
        )


def check_separate_bodies() -> None:
    """Raise MeshError if two physical surface groups (bodies) share mesh nodes.

    Contact needs the interface nodes duplicated: a single conforming mesh (shared points or
    curves, BooleanFragments, Coherence, or gmsh's automatic coherence after a geometry
    transformation such as Rotate) glues the bodies together where they touch.
    """
    import gmsh

    groups = gmsh.model.getPhysicalGroups(2)
    nodes = [gmsh.model.mesh.getNodesForPhysicalGroup(d, t)[0].astype(np.int64) for d, t in groups]
    top = max((int(n.max()) for n in nodes if n.size), default=0)
    owner = np.full(top + 1, -1, dtype=np.int64)
    for k, tags in enumerate(nodes):
        shared = tags[owner[tags] >= 0]
        if shared.size:
            names = [gmsh.model.getPhysicalName(*g) or f"surface group {g[1]}" for g in groups]
            x = gmsh.model.mesh.getNode(int(shared[0]))[0]
            raise MeshError(
                f"bodies '{names[owner[shared[0]]]}' and '{names[k]}' share {shared.size} mesh "
                f"node{'s' * (shared.size > 1)} (e.g. at ({x[0]:.4g}, {x[1]:.4g})): a single "
                "conforming mesh glues them together; contact needs each body built from its "
                "own points and curves, so that the interface nodes are duplicated (no shared "
                "points or curves, no BooleanFragments or Coherence; in a .geo with Rotate, "
                "Translate or other transformations set Geometry.AutoCoherence = 0)"
            )
        owner[tags] = k
