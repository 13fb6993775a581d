"""Two stacked elastic blocks, half model by symmetry (scenes S1-S4)."""

import numpy as np

from .size_field import apply_size_view, restore_options

# Unstructured quads (adaptive remeshing): Frontal-Delaunay for quads + Blossom recombination.
_QUAD_OPTIONS = {"Mesh.Algorithm": 8, "Mesh.RecombinationAlgorithm": 3, "Mesh.RecombineAll": 1}


def _divisions(length: float, size: float) -> int:
    """Return the number of elements along an edge of `length` for target size `size`."""
    return max(1, round(length / size))


def _body(
    xs: list[float], y0: float, y1: float, size: float, grading: float
) -> tuple[list[int], dict[str, list[int]], list[tuple[int, int, float]], list[list[int]]]:
    """Add a row of rectangles [xs[i], xs[i+1]] x [y0, y1] sharing their vertical curves.

    Returns the surfaces, the boundary curves by side, the transfinite curve data
    (tag, number of nodes, progression) and the corner points of each surface.
    """
    import gmsh  # only to mesh (first-answer time: docs/scale.md)

    geo = gmsh.model.geo
    bottom_pts = [geo.addPoint(x, y0, 0.0) for x in xs]
    top_pts = [geo.addPoint(x, y1, 0.0) for x in xs]
    # All horizontal curves run left to right and all vertical ones bottom to top, so
    # opposite sides of every rectangle carry the same progression without inversion.
    bottoms = [geo.addLine(bottom_pts[i], bottom_pts[i + 1]) for i in range(len(xs) - 1)]
    tops = [geo.addLine(top_pts[i], top_pts[i + 1]) for i in range(len(xs) - 1)]
    verticals = [geo.addLine(bottom_pts[i], top_pts[i]) for i in range(len(xs))]
    ny = _divisions(y1 - y0, size)
    constraints = [(v, ny + 1, 1.0) for v in verticals]
    surfaces, corners = [], []
    for i in range(len(xs) - 1):
        nx = _divisions(xs[i + 1] - xs[i], size)
        constraints += [(bottoms[i], nx + 1, grading), (tops[i], nx + 1, grading)]
        loop = geo.addCurveLoop([bottoms[i], verticals[i + 1], -tops[i], -verticals[i]])
        surfaces.append(geo.addPlaneSurface([loop]))
        corners.append([bottom_pts[i], bottom_pts[i + 1], top_pts[i + 1], top_pts[i]])
    sides = {"bottom": bottoms, "top": tops, "left": [verticals[0]], "right": [verticals[-1]]}
    return surfaces, sides, constraints, corners


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

    Structured (transfinite) by default; with `size_field` = (quads, sizes) unstructured
    quads sized by it (meshes.size_field: the adaptive loop's background mesh).
    """
    import gmsh

    if min(l1, l2, h1, h2, size1, size2, grading1, grading2) <= 0.0:
        raise ValueError("block dimensions, mesh sizes and gradings must be positive")
    half1, half2 = 0.5 * l1, 0.5 * l2
    # The narrower body's corner must be a node of the wider body's contact edge, so the
    # wider body is built from two rectangles split there (conforming inside the body).
    xs1 = [0.0, half2, half1] if half2 < half1 else [0.0, half1]
    xs2 = [0.0, half1, half2] if half1 < half2 else [0.0, half2]
    s1, sides1, cons1, corners1 = _body(xs1, 0.0, h1, size1, grading1)
    s2, sides2, cons2, corners2 = _body(xs2, h1, h1 + h2, size2, grading2)
    gmsh.model.geo.synchronize()

    # Mesh constraints only after the last synchronize: gmsh drops them otherwise.
    saved: dict[str, float] = {}
    if size_field is None:
        for tag, nodes, ratio in cons1 + cons2:
            gmsh.model.mesh.setTransfiniteCurve(tag, nodes, "Progression", ratio)
        for surf, corners in zip(s1 + s2, corners1 + corners2, strict=True):
            gmsh.model.mesh.setTransfiniteSurface(surf, cornerTags=corners)
    else:
        saved = {name: gmsh.option.getNumber(name) for name in _QUAD_OPTIONS}
        for name, value in _QUAD_OPTIONS.items():
            gmsh.option.setNumber(name, value)
        saved.update(apply_size_view(*size_field))
    for surf in s1 + s2:
        gmsh.model.mesh.setRecombine(2, surf)

    groups = [
        (2, s1, "body1"),
        (2, s2, "body2"),
        (1, sides1["top"], "contact1"),
        (1, sides2["bottom"], "contact2"),
        (1, sides1["left"] + sides2["left"], "symmetry"),
        (1, sides1["bottom"], "support"),
        (1, sides2["top"], "load"),
    ]
    for dim, tags, name in groups:
        gmsh.model.addPhysicalGroup(dim, tags, name=name)
    try:
        gmsh.model.mesh.generate(2)
    finally:
        restore_options(saved)
