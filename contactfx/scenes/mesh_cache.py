"""A built-in scene's gmsh mesh, kept on disk keyed by its recipe (docs/scale.md).

Meshing is a large part of a small scene's first answer (docs/scale.md). The first run
records every answer gmsh gave DOLFINx's model_to_mesh (node coordinates, elements,
physical groups) into `$XDG_CACHE_HOME/contactfx/meshes/<key>.npz`; a later run replays them
to the same model_to_mesh, so the mesh, its tags and its partition are those of a fresh run
(tests/scenes/test_mesh_cache.py). The key hashes the recipe (the builder and its
arguments), the source of the mesh code, and the contactfx, gmsh, DOLFINx and numpy
versions. `CONTACTFX_MESH_CACHE=0` turns it off; a scene with a size field (the adaptive
loop) or meshed inside an open gmsh session is not cached.
"""

from __future__ import annotations

import copy
import hashlib
import json
import os
import sys
import zipfile
from collections.abc import Callable
from functools import cache, partial
from importlib.metadata import version
from pathlib import Path
from typing import Any

import dolfinx
import numpy as np
from dolfinx.io.gmsh import MeshData
from mpi4py import MPI

from ..logs import log
from ..meshes.geo_files import geo_path
from .gmsh_io import balanced_partitioner, mesh_from_model, node_coordinates, to_dolfinx

_NODES = "mesh.getNodes()"  # the call whose answer also gives the partitioner's coordinates
# Larger recordings are not kept: the cache is for the first answer of small scenes, and a
# sweep of large meshes would fill the user's cache directory (size per node: docs/usage.md).
MAX_BYTES = 64 << 20


class _Recorder:
    """gmsh.model (or a nested class of it) that records every call's arguments and answer."""

    def __init__(self, target: Any, prefix: str = "", calls: dict[str, Any] | None = None):
        self._target, self._prefix = target, prefix
        self.calls: dict[str, Any] = {} if calls is None else calls

    def __getattr__(self, name: str) -> Any:
        attr = getattr(self._target, name)
        if isinstance(attr, type):  # gmsh.model.mesh: a namespace class
            return _Recorder(attr, f"{self._prefix}{name}.", self.calls)

        def call(*args: Any, **kwargs: Any) -> Any:
            out = attr(*args, **kwargs)
            # A copy: model_to_mesh shifts getNodes()' tags in place.
            self.calls[_call_key(self._prefix + name, args, kwargs)] = copy.deepcopy(out)
            return out

        return call


class _Replay:
    """Serves the recorded answers under the same attribute paths as gmsh.model."""

    def __init__(self, calls: dict[str, Any], prefix: str = ""):
        self._calls, self._prefix = calls, prefix

    def __getattr__(self, name: str) -> Any:
        if name == "mesh":
            return _Replay(self._calls, f"{self._prefix}mesh.")

        def call(*args: Any, **kwargs: Any) -> Any:
            return copy.deepcopy(self._calls[_call_key(self._prefix + name, args, kwargs)])

        return call


def _call_key(name: str, args: tuple[Any, ...], kwargs: dict[str, Any]) -> str:
    words = [*map(repr, args), *(f"{k}={v!r}" for k, v in sorted(kwargs.items()))]
    return f"{name}({', '.join(words)})"


def _plain(v: object) -> bool:
    """A value whose repr identifies it: a number, a string, None, or a tuple of those."""
    if isinstance(v, tuple):
        return all(_plain(x) for x in v)
    return v is None or isinstance(v, bool | int | float | str | np.generic)


@cache
def _code_versions() -> str:
    """The mesh code's source and the versions of what turns it into a mesh."""
    root = Path(__file__).resolve().parents[1]
    geo = [geo_path(f"{name}.geo") for name in ("blocks", "hertz")]  # meshes/*.geo
    files = (
        sorted((root / "meshes").glob("*.py"))
        + geo
        + [root / "scenes" / n for n in ("gmsh_io.py", "gmsh_checks.py", "mesh_cache.py")]
    )
    h = hashlib.sha256()
    for f in files:
        h.update(f.read_bytes())
    vers = (version("contactfx"), version("gmsh"), dolfinx.__version__, np.__version__)
    return f"{h.hexdigest()} {vers}"


def cache_path(build: Callable[[], None]) -> Path | None:
    """Where the mesh of `build` is kept, or None if it is not cached."""
    if os.environ.get("CONTACTFX_MESH_CACHE", "1") == "0" or not isinstance(build, partial):
        return None
    if not all(_plain(v) for v in (*build.args, *build.keywords.values())):
        return None
    f = build.func
    recipe = repr((f.__module__, f.__qualname__, build.args, sorted(build.keywords.items())))
    key = hashlib.sha256(f"{recipe} {_code_versions()}".encode()).hexdigest()[:32]
    try:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    except RuntimeError:  # no home directory: no cache
        return None
    return base / "contactfx" / "meshes" / f"{key}.npz"


def _encode(v: Any, arrays: list[np.ndarray]) -> Any:
    if isinstance(v, np.ndarray | np.generic):
        arrays.append(np.asarray(v))
        return {"a" if isinstance(v, np.ndarray) else "s": len(arrays) - 1}
    if isinstance(v, tuple | list):
        return {"t" if isinstance(v, tuple) else "l": [_encode(x, arrays) for x in v]}
    if v is None or isinstance(v, bool | int | float | str):
        return {"v": v}
    raise TypeError(f"gmsh answered a {type(v).__name__}")


def _decode(v: dict[str, Any], arrays: Any) -> Any:
    ((kind, x),) = v.items()
    if kind == "a":
        return arrays[f"a{x}"]
    if kind == "s":
        return arrays[f"a{x}"][()]
    if kind in ("t", "l"):
        items = [_decode(y, arrays) for y in x]
        return tuple(items) if kind == "t" else items
    return x


def _save(path: Path, calls: dict[str, Any]) -> None:
    """Write the recorded answers (atomically: concurrent runs may write the same key)."""
    arrays: list[np.ndarray] = []
    try:
        index = json.dumps([[k, _encode(v, arrays)] for k, v in calls.items()])
        if sum(a.nbytes for a in arrays) > MAX_BYTES:
            log.debug("mesh cache: %s not written (over %d bytes)", path, MAX_BYTES)
            return
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        with open(tmp, "wb") as fh:
            payload: dict[str, Any] = {f"a{i}": a for i, a in enumerate(arrays)}
            np.savez(fh, index=np.array(index), **payload)
        os.replace(tmp, path)
    except (OSError, TypeError) as exc:  # no cache is a slower run, not an error
        log.debug("mesh cache: not written (%s)", exc)


def _load(path: Path) -> dict[str, Any] | None:
    """The recorded answers, or None if there are none (or they cannot be read)."""
    try:
        with np.load(path, allow_pickle=False) as arrays:
            calls = {k: _decode(v, arrays) for k, v in json.loads(str(arrays["index"][()]))}
    except FileNotFoundError:
        return None
    except (OSError, ValueError, KeyError, TypeError, AttributeError, zipfile.BadZipFile) as exc:
        log.debug("mesh cache: %s unreadable (%s), meshing", path, exc)
        return None
    return calls if _NODES in calls else None


def cached_to_dolfinx(comm: MPI.Comm, build: Callable[[], None]) -> MeshData:
    """gmsh_io.to_dolfinx(comm, build, balanced_partitioner()), from the cache if kept."""
    path, calls = None, None
    # gmsh is imported only to mesh: not imported means no session open.
    gmsh_module = sys.modules.get("gmsh")
    if comm.rank == 0 and not (gmsh_module is not None and gmsh_module.isInitialized()):
        path = cache_path(build)
        calls = _load(path) if path is not None else None
    if comm.bcast(calls is not None, root=0):
        coords = node_coordinates(*calls[_NODES][:2]) if calls is not None else None
        model = _Replay(calls) if calls is not None else None
        try:
            return mesh_from_model(model, comm, balanced_partitioner(coords))
        except KeyError as exc:
            # An answer missing from the file: one written by another model_to_mesh (the
            # DOLFINx version is in the key) or edited. Serial: mesh instead. Under mpirun
            # the other ranks would wait in DOLFINx's broadcasts, so the error stands.
            if comm.size > 1:
                raise
            log.debug("mesh cache: %s lacks %s, meshing", path, exc)
    import gmsh

    recorder = _Recorder(gmsh.model) if path is not None else None
    data = to_dolfinx(comm, build, balanced_partitioner(), model=recorder)
    if recorder is not None and path is not None:
        _save(path, recorder.calls)
    return data
