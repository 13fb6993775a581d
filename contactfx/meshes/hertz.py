"""Hertz scene (S5): quarter of a cylinder on an elastic block, half model by symmetry."""

import math

import numpy as np

from .size_field import apply_size_view, restore_options

# Growth of the element size with distance from the refined zone (size per unit distance).
# The elastic field decays like 1/r in 2D, so every decade of distance adds about the same
# discretization error: the slope, not the far size, sets the error in the compliance.
_SLOPE = 0.1
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
    # Plain floats: numpy scalars would print as np.float64(...) in the gmsh expression.
    R, height, h_contact, r_refine, h_far, slope = map(
        float, (R, height, h_contact, r_refine, h_far, slope)
    )
    edge = None if edge is None else (float(edge[0]), float(edge[1]))
    yc = height + R
    geo = gmsh.model.geo
    # Block: the top is split at the end of the contact zone.
    b00 = geo.addPoint(0.0, 0.0, 0.0)
    b10 = geo.addPoint(width, 0.0, 0.0)
    b11 = geo.addPoint(width, height, 0.0)
    bce = geo.addPoint(extent, height, 0.0)
    b01 = geo.addPoint(0.0, height, 0.0)
    support = geo.addLine(b00, b10)
    b_right = geo.addLine(b10, b11)
    b_top_free = geo.addLine(b11, bce)
    contact1 = geo.addLine(bce, b01)
    b_sym = geo.addLine(b01, b00)
    block = geo.addPlaneSurface([geo.addCurveLoop([support, b_right, b_top_free, contact1, b_sym])])

    # Quarter disc from its own points (same location as b01, distinct tag): the bodies
    # must not share nodes, contact needs duplicated interface nodes.
    centre = geo.addPoint(0.0, yc, 0.0)
    d_bot = geo.addPoint(0.0, height, 0.0)
    d_ce = geo.addPoint(extent, yc - math.sqrt(R * R - extent * extent), 0.0)
    d_right = geo.addPoint(R, yc, 0.0)
    contact2 = geo.addCircleArc(d_bot, centre, d_ce)
    arc_free = geo.addCircleArc(d_ce, centre, d_right)
    load = geo.addLine(d_right, centre)
    d_sym = geo.addLine(centre, d_bot)
    disc = geo.addPlaneSurface([geo.addCurveLoop([contact2, arc_free, load, d_sym])])
    geo.synchronize()

    # The size grows linearly (at `slope`) with the distance from the part of the contact
    # surfaces with x <= r_refine: fine where the pressure lives, coarse a few elements
    # deeper. Each body's distance is to its own surface (the line y = height, the arc);
    # the smaller of the two is the right one on both sides of the interface.
    d_line = f"Abs(y - {height!r})"
    d_arc = f"Abs({R!r} - Sqrt(x^2 + (y - {yc!r})^2))"
    dist = f"Sqrt(Max(x - {r_refine!r}, 0)^2 + Min({d_line}, {d_arc})^2)"
    size = f"{h_contact!r} + {slope!r} * {dist}"
    if edge is not None:
        xe, he = edge
        de = f"Sqrt((x - {xe!r})^2 + Min({d_line}, {d_arc})^2)"
        size = f"Min({size}, {he!r} + {slope!r} * {de})"
    size_saved = {}
    if size_field is None:
        field = gmsh.model.mesh.field.add("MathEval")
        gmsh.model.mesh.field.setString(field, "F", f"Min({h_far!r}, {size})")
        gmsh.model.mesh.field.setAsBackgroundMesh(field)
    else:
        size_saved = apply_size_view(*size_field)
    # The field alone sets the size: point sizes and curvature would override it.
    options = {
        "Mesh.MeshSizeExtendFromBoundary": 0,
        "Mesh.MeshSizeFromPoints": 0,
        "Mesh.MeshSizeFromCurvature": 0,
        # Frontal-Delaunay for quads + Blossom full-quad recombination: no triangle left.
        "Mesh.Algorithm": 8,
        "Mesh.RecombinationAlgorithm": 3,
        "Mesh.RecombineAll": 1,
    }
    # Options are global to the gmsh session: restore them so later models are unaffected.
    saved = {name: gmsh.option.getNumber(name) for name in options}
    for name, value in options.items():
        gmsh.option.setNumber(name, value)
    for surf in (block, disc):
        gmsh.model.mesh.setRecombine(2, surf)

    groups = [
        (2, [block], "body1"),
        (2, [disc], "body2"),
        (1, [contact1], "contact1"),
        (1, [contact2], "contact2"),
        (1, [b_sym, d_sym], "symmetry"),
        (1, [support], "support"),
        (1, [load], "load"),
    ]
    for dim, tags, name in groups:
        gmsh.model.addPhysicalGroup(dim, tags, name=name)
    try:
        gmsh.model.mesh.generate(2)
    finally:
        for name, value in saved.items():
            gmsh.option.setNumber(name, value)
        restore_options(size_saved)

    types, _, _ = gmsh.model.mesh.getElements(2)
    if any(t != QUAD4 for t in types):
        raise ValueError(f"Hertz mesh has non-quadrilateral elements (gmsh types {list(types)})")
