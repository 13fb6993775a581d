"""Hertz scene (S5): quarter of a cylinder on an elastic block, half model: meshes/hertz.geo."""

import numpy as np

from .geo_files import merge_geo
from .size_field import apply_size_view, restore_options

# Growth of the element size with distance from the refined zone (size per unit distance):
# meshes/hertz.geo says why the slope sets the error.
_SLOPE = 0.1
# The mesh options meshes/hertz.geo sets.
_OPTIONS = (
    "Mesh.MeshSizeExtendFromBoundary",
    "Mesh.MeshSizeFromPoints",
    "Mesh.MeshSizeFromCurvature",
    "Mesh.Algorithm",
    "Mesh.RecombinationAlgorithm",
    "Mesh.RecombineAll",
)
# gmsh element type of the 4-node quadrangle; anything else is a leftover triangle.
QUAD4 = 3


def build_hertz(
    R: float,
    width: float,
    height: float,
    h_contact: float,
    r_refine: float,
    h_far: float | None = None,
    contact_extent: float | None = None,
    slope: float = _SLOPE,
    edge: tuple[float, float] | None = None,
    size_field: tuple[np.ndarray, np.ndarray] | None = None,
) -> None:
    """Add the Hertz half model (quarter disc on a block) to the current gmsh model and mesh it.

    The geometry and its size field are meshes/hertz.geo with these parameters.
    Size h_contact on both contact surfaces for x <= r_refine, h_edge at x_edge if `edge` =
    (x_edge, h_edge) (the contact edge: the pressure's square-root singularity), growing by
    `slope` per unit distance; or, `size_field` = (quads, sizes), sizes at the vertices of
    quads (meshes.size_field: the adaptive loop's background mesh).
    """
    import gmsh  # only to mesh (first-answer time: docs/scale.md)

    h_far = R / 6.0 if h_far is None else h_far
    extent = min(width, R / 4.0) if contact_extent is None else contact_extent
    if min(R, width, height, h_contact, r_refine, h_far, slope) <= 0.0:
        raise ValueError("radius, block size, mesh sizes, r_refine and slope must be positive")
    if edge is not None and not (0.0 <= edge[0] < width and edge[1] > 0.0):
        raise ValueError(f"edge = {edge}: need 0 <= x_edge < width and h_edge > 0")
    if not 0.0 < extent < min(width, R):
        raise ValueError(f"contact_extent={extent} must lie in (0, min(width, R))")
    h_far = max(h_far, h_contact)
    # The options the file sets are global to the gmsh session: restored after meshing.
    saved = {name: gmsh.option.getNumber(name) for name in _OPTIONS}
    size_saved: dict[str, float] = {}
    try:
        numbers = dict(R=R, width=width, height=height, h_contact=h_contact, r_refine=r_refine)
        sizes = dict(h_far=h_far, extent=extent, slope=slope)
        at_edge = {} if edge is None else dict(edge=1, x_edge=edge[0], h_edge=edge[1])
        merge_geo("hertz.geo", **numbers, **sizes, **at_edge, user_sizes=size_field is not None)
        if size_field is not None:
            size_saved = apply_size_view(*size_field)
        gmsh.model.mesh.generate(2)
    finally:
        for name, value in saved.items():
            gmsh.option.setNumber(name, value)
        restore_options(size_saved)

    types, _, _ = gmsh.model.mesh.getElements(2)
    if any(t != QUAD4 for t in types):
        raise ValueError(f"Hertz mesh has non-quadrilateral elements (gmsh types {list(types)})")
