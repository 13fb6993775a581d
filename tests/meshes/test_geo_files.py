"""The top-level meshes/*.geo files: gmsh alone meshes them, and they are the builders' geometry."""

from __future__ import annotations

import gmsh
import numpy as np
import pytest

from contactfx.meshes import QUAD4, build_blocks, build_hertz
from contactfx.meshes.geo_files import geo_path

GROUPS = {"body1", "body2", "contact1", "contact2", "symmetry", "support", "load"}


def _mesh(build) -> tuple[np.ndarray, set[str], list[int]]:
    """Node coordinates, physical group names and 2D element types of what `build` meshes."""
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("m")
        build()
        _, x, _ = gmsh.model.mesh.getNodes()
        names = {gmsh.model.getPhysicalName(d, t) for d, t in gmsh.model.getPhysicalGroups()}
        types = [int(t) for t in gmsh.model.mesh.getElements(2)[0]]
        return np.asarray(x).reshape(-1, 3), names, types
    finally:
        gmsh.finalize()


def _plain_gmsh(name: str, **numbers: float) -> None:
    """The file as gmsh reads it on its own (`gmsh -setnumber ...`), meshed."""
    for key, value in numbers.items():
        gmsh.parser.setNumber(key, [value])
    gmsh.merge(str(geo_path(name)))
    gmsh.model.mesh.generate(2)


@pytest.mark.parametrize(
    ("name", "numbers", "build"),
    [
        ("blocks.geo", {"size1": 0.5, "size2": 0.25},
         lambda: build_blocks(10.0, 6.0, 3.0, 3.0, 0.5, 0.25)),
        ("hertz.geo", {"h_contact": 0.2, "h_far": 10.0, "extent": 15.0},
         lambda: build_hertz(60.0, 60.0, 60.0, 0.2, 1.4)),
    ],
)  # fmt: skip
def test_gmsh_alone_meshes_the_builders_geometry(name, numbers, build) -> None:
    """gmsh without contactfx meshes the file into quads with the scene's named groups; with
    the builder's parameters the nodes are the builder's, bit for bit."""
    x, names, types = _mesh(lambda: _plain_gmsh(name, **numbers))
    assert names == GROUPS and types == [QUAD4]
    y, built_names, _ = _mesh(build)
    assert built_names == GROUPS
    assert np.array_equal(x, y)


def test_geo_files_import_nothing() -> None:
    """A user's file: gmsh syntax only, no Python and no path into the package."""
    for name in ("blocks.geo", "hertz.geo"):
        text = geo_path(name).read_text()
        assert "import" not in text and "contactfx/" not in text.replace("contactfx/meshes/", "")
