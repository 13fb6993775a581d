"""The mesh cache of built-in scenes: a cached mesh is the fresh mesh, bit for bit.

The cache replays gmsh's answers to DOLFINx's model_to_mesh (contactfx/scenes/mesh_cache.py):
the node coordinates, cells, tags, physical groups and (under mpirun) the partition must be
those of meshing again, and the solution the same; any change of the recipe, of the mesh
code or of a version gives another key.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from functools import partial
from pathlib import Path

import numpy as np
import pytest
from dolfinx.io.gmsh import MeshData
from mpi4py import MPI

from contactfx.meshes import build_blocks, build_hertz
from contactfx.scenes import mesh_cache
from contactfx.scenes.gmsh_io import balanced_partitioner, to_dolfinx
from contactfx.scenes.mesh_cache import cache_path, cached_to_dolfinx

HERTZ = (60.0, 60.0, 60.0, 0.2, 2.0)  # R, width, height, h_contact, r_refine
BLOCKS = (10.0, 6.0, 3.0, 3.0, 0.25, 0.25, 1.0, 1.0)


def arrays(md: MeshData) -> dict[str, np.ndarray]:
    """Everything a solve reads from the mesh data, as arrays."""
    mesh = md.mesh
    assert md.cell_tags is not None and md.facet_tags is not None
    groups = sorted((k, g.dim, g.tag) for k, g in md.physical_groups.items())
    return {
        "x": mesh.geometry.x,
        "dofmap": mesh.geometry.dofmaps[0],
        "input_index": mesh.geometry.input_global_indices,
        "original_cells": mesh.topology.original_cell_index,
        "cell_tags": np.column_stack([md.cell_tags.indices, md.cell_tags.values]),
        "facet_tags": np.column_stack([md.facet_tags.indices, md.facet_tags.values]),
        "groups": np.array([f"{k}:{d}:{t}" for k, d, t in groups]),
    }


def same(a: MeshData, b: MeshData) -> None:
    """a and b are the same mesh: equal arrays, bit for bit."""
    ra, rb = arrays(a), arrays(b)
    for key in ra:
        assert ra[key].dtype == rb[key].dtype, key
        assert np.array_equal(ra[key], rb[key]), key


@pytest.fixture
def cache_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.delenv("CONTACTFX_MESH_CACHE", raising=False)
    return tmp_path


def _no_meshing(*args: object, **kwargs: object) -> MeshData:
    raise AssertionError("meshed although the mesh is cached")


@pytest.mark.parametrize("build", [partial(build_hertz, *HERTZ), partial(build_blocks, *BLOCKS)])
def test_cached_mesh_is_the_fresh_mesh(
    build: partial[None], cache_home: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    comm = MPI.COMM_SELF
    fresh = to_dolfinx(comm, build, balanced_partitioner())
    path = cache_path(build)
    assert path is not None and not path.exists()
    first = cached_to_dolfinx(comm, build)  # meshes and writes the cache
    assert path.is_file() and path.is_relative_to(cache_home / "contactfx" / "meshes")
    monkeypatch.setattr(mesh_cache, "to_dolfinx", _no_meshing)
    again = cached_to_dolfinx(comm, build)  # from the cache
    same(fresh, first)
    same(fresh, again)


def test_the_key_follows_recipe_code_and_versions(
    cache_home: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    base = cache_path(partial(build_hertz, *HERTZ))
    assert base is not None and base == cache_path(partial(build_hertz, *HERTZ))
    others = [
        partial(build_hertz, *HERTZ[:-1], 2.0 + 1e-12),  # any digit of any argument
        partial(build_hertz, *HERTZ, slope=0.2),
        partial(build_hertz, *HERTZ, edge=(1.4, 0.1)),
        partial(build_blocks, *BLOCKS),
    ]
    paths = [cache_path(b) for b in others]
    assert None not in paths and len({base, *paths}) == 1 + len(others)
    # An adaptive size field (arrays) or a builder that is not a plain recipe: not cached.
    field = (np.zeros((1, 4, 2)), np.ones(4))
    assert cache_path(partial(build_hertz, *HERTZ, size_field=field)) is None
    assert cache_path(lambda: None) is None
    with monkeypatch.context() as m:
        m.setenv("CONTACTFX_MESH_CACHE", "0")
        assert cache_path(partial(build_hertz, *HERTZ)) is None
    # Another contactfx (or gmsh) version, or other mesh code: another key.
    source = Path(mesh_cache.__file__).read_bytes()
    changes = [
        (mesh_cache, "version", lambda dist: "0.0.0-other"),
        (Path, "read_bytes", lambda self: source + b"# edited\n"),
    ]
    for target, name, value in changes:
        mesh_cache._code_versions.cache_clear()
        try:
            with monkeypatch.context() as m:
                m.setattr(target, name, value)
                assert cache_path(partial(build_hertz, *HERTZ)) != base, name
        finally:
            mesh_cache._code_versions.cache_clear()


def test_an_unreadable_cache_file_is_meshed_again(cache_home: Path) -> None:
    build = partial(build_blocks, *BLOCKS)
    path = cache_path(build)
    assert path is not None
    path.parent.mkdir(parents=True)
    path.write_bytes(b"not a mesh")
    fresh = cached_to_dolfinx(MPI.COMM_SELF, build)
    same(fresh, to_dolfinx(MPI.COMM_SELF, build, balanced_partitioner()))
    with np.load(path) as stored:  # rewritten: a readable cache now
        assert "index" in stored


def test_a_cache_file_missing_an_answer_is_meshed_again(cache_home: Path) -> None:
    build = partial(build_hertz, *HERTZ)
    fresh = cached_to_dolfinx(MPI.COMM_SELF, build)
    path = cache_path(build)
    assert path is not None
    calls = mesh_cache._load(path)
    assert calls is not None
    missing = next(k for k in calls if k.startswith("getPhysicalName"))
    del calls[missing]
    mesh_cache._save(path, calls)
    same(fresh, cached_to_dolfinx(MPI.COMM_SELF, build))
    rewritten = mesh_cache._load(path)
    assert rewritten is not None and missing in rewritten


def test_a_large_mesh_is_not_kept(cache_home: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    build = partial(build_blocks, *BLOCKS)
    monkeypatch.setattr(mesh_cache, "MAX_BYTES", 1000)
    cached_to_dolfinx(MPI.COMM_SELF, build)
    path = cache_path(build)
    assert path is not None and not path.parent.exists()


def _solve_json(tmp_path: Path, name: str, env: dict[str, str]) -> dict:
    out = tmp_path / f"{name}.json"
    cmd = [sys.executable, "-m", "contactfx", "solve", "hertz", "--refine", "0.1", "-q"]
    proc = subprocess.run(
        [*cmd, "--json", str(out)], env=env, cwd=tmp_path, capture_output=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    return dict(json.loads(out.read_text()))


def test_solution_from_the_cached_mesh(tmp_path: Path) -> None:
    cache = tmp_path / "cache"  # not tmp_path/contactfx: the cwd, `python -m` would import it
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "XDG_CACHE_HOME": str(cache)}
    # The user's (warm) FFCx cache in this one: only the mesh cache starts empty.
    fenics = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "fenics"
    cache.mkdir()
    if fenics.is_dir():
        (cache / "fenics").symlink_to(fenics)
    fresh = _solve_json(tmp_path, "fresh", {**env, "CONTACTFX_MESH_CACHE": "0"})
    assert not (cache / "contactfx").exists()  # (the FFCx cache is there too)
    _solve_json(tmp_path, "first", env)
    assert len(list((cache / "contactfx" / "meshes").glob("*.npz"))) == 1
    cached = _solve_json(tmp_path, "cached", env)
    for key in ("dofs", "multipliers", "elements", "iterations", "active_nodes"):
        assert cached[key] == fresh[key], key
    a, b = fresh["contacts"][0]["interface"], cached["contacts"][0]["interface"]
    for key in ("x", "y", "pressure", "gap", "sigma_nn_active"):
        assert np.allclose(a[key], b[key], rtol=1e-12, atol=1e-12 * np.abs(a[key]).max()), key


MPI_SCRIPT = """
import os
os.environ["XDG_CACHE_HOME"] = "{cache}"
from functools import partial
import numpy as np
from mpi4py import MPI
from contactfx.meshes import build_hertz
from contactfx.scenes import mesh_cache
from contactfx.scenes.gmsh_io import balanced_partitioner, to_dolfinx
from contactfx.scenes.mesh_cache import cached_to_dolfinx

comm = MPI.COMM_WORLD
build = partial(build_hertz, {args})
fresh = to_dolfinx(comm, build, balanced_partitioner())
first = cached_to_dolfinx(comm, build)
def no_meshing(*a, **k):
    raise AssertionError("meshed although cached")
mesh_cache.to_dolfinx = no_meshing
again = cached_to_dolfinx(comm, build)
for md in (first, again):
    for a, b in ((fresh.mesh.geometry.x, md.mesh.geometry.x),
                 (fresh.mesh.topology.original_cell_index, md.mesh.topology.original_cell_index),
                 (fresh.facet_tags.values, md.facet_tags.values),
                 (fresh.cell_tags.values, md.cell_tags.values)):
        assert a.dtype == b.dtype and np.array_equal(a, b), comm.rank
assert comm.size == 2 and fresh.mesh.topology.index_map(2).size_local > 0
print("OK", comm.rank, flush=True)
"""


@pytest.mark.mpi
def test_cached_partition_is_the_fresh_partition(tmp_path: Path, mpi_script) -> None:
    script = tmp_path / "cached.py"
    args = ", ".join(map(str, HERTZ))
    script.write_text(textwrap.dedent(MPI_SCRIPT.format(args=args, cache=tmp_path)))
    run = mpi_script(script, timeout=180)
    assert run.stdout.count("OK") == 2, run.stdout
