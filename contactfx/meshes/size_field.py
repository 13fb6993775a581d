"""A background mesh size for gmsh from sizes given at the vertices of quadrilaterals.

gmsh cannot drive a remesh of a model from a view on that model's own mesh, but a
list-based view works: one `SQ` record (4 x, 4 y, 4 z, 4 values) per quadrilateral, a
PostView field on it, set as the background mesh. The model's own size sources (points,
boundaries, curvature) are switched off so that the field alone sets the size.
"""

import numpy as np

# Set while a background field is active; restore_options puts the saved values back.
SIZE_OPTIONS = {
    "Mesh.MeshSizeExtendFromBoundary": 0,
    "Mesh.MeshSizeFromPoints": 0,
    "Mesh.MeshSizeFromCurvature": 0,
    "Mesh.MeshSizeFactor": 1,
}


def apply_size_view(quads: np.ndarray, sizes: np.ndarray) -> dict[str, float]:
    """Make the sizes (n, 4) at the quads' vertices (n, 4, 2) the current model's mesh size.

    Returns the options it changed, with their previous values (for restore_options).
    """
    import gmsh  # only to mesh (first-answer time: docs/scale.md)

    quads = np.asarray(quads, dtype=float).reshape(-1, 4, 2)
    sizes = np.asarray(sizes, dtype=float).reshape(-1, 4)
    if not len(quads) or not np.all(np.isfinite(sizes)) or np.any(sizes <= 0):
        raise ValueError("a size field needs quads and positive, finite sizes")
    z = np.zeros((len(quads), 4))
    data = np.hstack([quads[:, :, 0], quads[:, :, 1], z, sizes]).ravel()
    view = gmsh.view.add("contactfx-size")
    gmsh.view.addListData(view, "SQ", len(quads), data.tolist())
    field = gmsh.model.mesh.field.add("PostView")
    gmsh.model.mesh.field.setNumber(field, "ViewTag", view)
    gmsh.model.mesh.field.setAsBackgroundMesh(field)
    saved = {name: gmsh.option.getNumber(name) for name in SIZE_OPTIONS}
    for name, value in SIZE_OPTIONS.items():
        gmsh.option.setNumber(name, value)
    return saved


def restore_options(saved: dict[str, float]) -> None:
    """Put back the gmsh options apply_size_view changed."""
    import gmsh

    for name, value in saved.items():
        gmsh.option.setNumber(name, value)
