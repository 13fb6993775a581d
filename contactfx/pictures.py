"""Pictures of fields on the deformed mesh (pyvista, off-screen), like the paper's Fig. 3."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .postprocess import sigma_field
from .solution import Solution


def deformed_fields(sol: Solution, path: Path, scale: float = 100.0) -> Path | None:
    """Save u_y and sigma_yy on the mesh deformed `scale` times; serial runs only."""
    if sol.scene.mesh.comm.size > 1:
        return None
    import pyvista
    from dolfinx import plot

    pyvista.OFF_SCREEN = True
    V = sol.elasticity.V
    # vtk_mesh is a singledispatch function: mypy sees only its Mesh signature.
    topology, cell_types, x = plot.vtk_mesh(V)  # type: ignore[arg-type]
    grid = pyvista.UnstructuredGrid(topology, cell_types, x)
    u = sol.u.x.array.reshape(-1, 2)
    grid.point_data["u_y"] = u[:, 1]
    grid.point_data["u"] = np.column_stack([u, np.zeros(len(u))])
    s = sigma_field(sol).x.array.reshape(-1, 4)
    # DG0 dofs follow the cell order of vtk_mesh(V) (both enumerate local cells).
    grid.cell_data["sigma_yy"] = s[: grid.n_cells, 3]
    warped = grid.warp_by_vector("u", factor=scale)
    # pyvista annotates window_size as list[int]; it takes any sequence (as BasePlotter says).
    plotter = pyvista.Plotter(shape=(1, 2), window_size=(1600, 600), off_screen=True)  # type: ignore[arg-type]
    for col, (name, label) in enumerate((("u_y", "u_y (cm)"), ("sigma_yy", "sigma_yy (MPa)"))):
        plotter.subplot(0, col)
        plotter.add_mesh(
            warped,
            scalars=name,
            cmap="turbo",
            show_edges=False,
            scalar_bar_args={
                "title": label,
                "vertical": True,
                "position_x": 0.86,
                "position_y": 0.15,
            },
        )
        plotter.add_text(f"{label}, deformation x{scale:g}", font_size=10)
        plotter.view_xy()  # type: ignore[call-arg]  # pyvista's functools.wraps confuses mypy
    path.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(path))
    plotter.close()
    return path
