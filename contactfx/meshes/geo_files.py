"""The built-in scenes' geometry: the parametrized gmsh .geo files of the top-level meshes/.

One definition of each geometry: a user opens the file in gmsh, the builders of this package
merge it into the current model with the scene's parameters (gmsh's parser variables, which
the file's DefineConstant defaults give way to). In a source checkout the files are read from
meshes/ beside the package; an installed wheel carries them as contactfx/meshes/geo/
(pyproject.toml maps the folder in).
"""

from pathlib import Path

_HERE = Path(__file__).resolve().parent
# The installed copy first, then the checkout's top-level folder.
_FOLDERS = (_HERE / "geo", _HERE.parents[1] / "meshes")


def geo_path(name: str) -> Path:
    """The .geo file `name` of the built-in scenes (FileNotFoundError if not shipped)."""
    for folder in _FOLDERS:
        path = folder / name
        if path.is_file():
            return path
    raise FileNotFoundError(f"{name}: not in {' or '.join(str(f) for f in _FOLDERS)}")


def merge_geo(name: str, **numbers: float) -> None:
    """Merge the .geo file `name` into the current gmsh model with these parameters set.

    The parser's variables are cleared first: a DefineConstant keeps a value set before it,
    so a parameter left over from an earlier scene would otherwise win over the default.
    """
    import gmsh  # only to mesh (first-answer time: docs/scale.md)

    gmsh.parser.clear()
    for key, value in numbers.items():
        gmsh.parser.setNumber(key, [float(value)])
    gmsh.merge(str(geo_path(name)))
