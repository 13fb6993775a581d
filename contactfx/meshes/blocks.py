"""Two stacked elastic blocks, half model by symmetry (scenes S1-S4): meshes/blocks.geo."""

import numpy as np

from .geo_files import merge_geo
from .size_field import apply_size_view, restore_options

# Unstructured quads (adaptive remeshing): Frontal-Delaunay for quads + Blossom recombination.
_QUAD_OPTIONS = {"Mesh.Algorithm": 8, "Mesh.RecombinationAlgorithm": 3, "Mesh.RecombineAll": 1}


def build_blocks(
    l1: float,
    l2: float,
    h1: float,
    h2: float,
    size1: float,
    size2: float,
    grading1: float = 1.0,
    grading2: float = 1.0,
    size_field: tuple[np.ndarray, np.ndarray] | None = None,
) -> None:
    """Add the two-block half model (S1-S4) to the current gmsh model and mesh it with quads.

    The geometry is meshes/blocks.geo with these parameters. Structured (transfinite) by
    default; with `size_field` = (quads, sizes) unstructured quads sized by it
    (meshes.size_field: the adaptive loop's background mesh).
    """
    import gmsh

    if min(l1, l2, h1, h2, size1, size2, grading1, grading2) <= 0.0:
        raise ValueError("block dimensions, mesh sizes and gradings must be positive")
    saved: dict[str, float] = {}
    if size_field is not None:
        saved = {name: gmsh.option.getNumber(name) for name in _QUAD_OPTIONS}
        for name, value in _QUAD_OPTIONS.items():
            gmsh.option.setNumber(name, value)
    try:
        numbers = dict(l1=l1, l2=l2, h1=h1, h2=h2, size1=size1, size2=size2)
        grading = dict(grading1=grading1, grading2=grading2)
        merge_geo("blocks.geo", **numbers, **grading, user_sizes=size_field is not None)
        if size_field is not None:
            saved.update(apply_size_view(*size_field))
        gmsh.model.mesh.generate(2)
    finally:
        restore_options(saved)
