"""gmsh models into DOLFINx: a body-balancing partitioner, quad checks, and Scene.from_gmsh.

gmsh runs on rank 0 only; every failure there is broadcast so that all ranks raise the same
typed error (no rank is left waiting in a collective call).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from dolfinx.cpp.mesh import cell_num_vertices
from dolfinx.graph import adjacencylist
from dolfinx.io.gmsh import MeshData, model_to_mesh
from mpi4py import MPI

from ..errors import ContactFxError, InputError, MeshError, error_type
from ..meshes.size_field import apply_size_view, restore_options
from .checks import check_scene
from .gmsh_checks import check_quadrilaterals, check_separate_bodies
from .model import (
    Body,
    ContactPair,
    Dirichlet,
    Groups,
    Load,
    Material,
    Model,
    Obstacle,
    Reference,
    Scene,
    SizeField,
    Units,
)
from .probe import Probe


def _gmsh_node_coordinates() -> np.ndarray:
    """The current gmsh model's node coordinates, row i = node tag i + 1."""
    import gmsh  # only to mesh (first-answer time: docs/scale.md)

    if not gmsh.isInitialized():
        raise MeshError("balanced_partitioner needs node coordinates: no gmsh session is open")
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    return node_coordinates(tags, xyz)


def node_coordinates(tags: np.ndarray, xyz: np.ndarray) -> np.ndarray:
    """Node coordinates from gmsh's getNodes() arrays, row i = node tag i + 1."""
    x = np.zeros((int(tags.max()) if len(tags) else 0, 3))
    x[tags.astype(np.int64) - 1] = xyz.reshape(-1, 3)
    return x


# -- cell partitions: equal-count strips per body, or every cell kept where it was made ------
# The strips spread every body over all ranks (gmsh scenes); the structured Hertz grid is
# generated on every rank already cut so (`meshes.hertz_grid_part`) and stays.


def body_strips(dest: np.ndarray, cell_label: np.ndarray, mid: np.ndarray, nparts: int) -> None:
    """Within each body (`cell_label`), equal-count strips by midpoint x (then y), into `dest`.

    The contact line of each body is spread over all ranks, and the strips of the bodies
    overlap.
    """
    for label in np.unique(cell_label):
        ids = np.flatnonzero(cell_label == label)
        order = ids[np.lexsort((mid[ids, 1], mid[ids, 0]))]
        dest[order] = (np.arange(len(order)) * nparts) // len(order)


def cell_arrays(cell_types: list[Any], cells: list[Any]) -> list[np.ndarray]:
    """A partitioner's flat cell lists as (cells, vertices) int64 arrays, one per cell type."""
    return [
        np.asarray(c, dtype=np.int64).reshape(-1, cell_num_vertices(ct))
        for ct, c in zip(cell_types, cells, strict=True)
    ]


def stay_on_rank(comm: MPI.Comm, nparts: int, cell_types: list[Any], cells: list[Any]) -> Any:
    """Every cell stays on the rank that passed it to create_mesh (input made distributed)."""
    num_cells = sum(len(c) for c in cell_arrays(cell_types, cells))
    return adjacencylist(np.full(num_cells, comm.rank, dtype=np.int32))._cpp_object


def balanced_partitioner(coordinates: np.ndarray | None = None) -> Callable[..., Any]:
    """A cell partitioner that splits every body (connected component) over all ranks."""

    def partition(comm: MPI.Comm, nparts: int, cell_types: list[Any], cells: list[Any]) -> Any:
        # Cells of one type per list entry, flattened; node index = gmsh node tag - 1.
        conn = cell_arrays(cell_types, cells)
        num_cells = sum(len(c) for c in conn)
        dest = np.zeros(num_cells, dtype=np.int32)
        if num_cells == 0 or nparts == 1:
            return adjacencylist(dest)._cpp_object
        # scipy.sparse.csgraph only when a mesh is split over ranks (docs/scale.md).
        from scipy.sparse import coo_array
        from scipy.sparse.csgraph import connected_components

        x = _gmsh_node_coordinates() if coordinates is None else np.asarray(coordinates)
        mid = np.vstack([x[c, :2].mean(axis=1) for c in conn])
        # Bodies share no node, so the connected components of the node graph are the
        # bodies: linking each cell's first vertex to its others is enough to find them.
        first = np.concatenate([np.repeat(c[:, 0], c.shape[1]) for c in conn])
        other = np.concatenate([c.ravel() for c in conn])
        n = int(max(first.max(), other.max())) + 1
        graph = coo_array((np.ones(len(first)), (first, other)), shape=(n, n))
        _, node_label = connected_components(graph, directed=False)
        cell_label = node_label[np.concatenate([c[:, 0] for c in conn])]
        body_strips(dest, cell_label, mid, nparts)
        return adjacencylist(dest)._cpp_object

    return partition


def _run_on_root(
    comm: MPI.Comm, build: Callable[[], None], own_session: bool
) -> tuple[bool | None, str | None]:
    """Open a model on rank 0 and run `build` there; the error text is broadcast."""
    import gmsh

    error = ""
    fresh, previous = None, None
    if comm.rank == 0:
        if own_session:
            fresh = not gmsh.isInitialized()
            if fresh:
                # gmsh's SIGINT handler can only be installed from the main thread.
                gmsh.initialize(interruptible=threading.current_thread() is threading.main_thread())
                gmsh.option.setNumber("General.Terminal", 0)
            else:
                previous = gmsh.model.getCurrent()
            gmsh.model.add(f"contactfx-{id(build)}")
        try:
            build()
            check_quadrilaterals()
            check_separate_bodies()
        except ContactFxError as exc:
            error = f"{type(exc).__name__}:{exc}"
        except ValueError as exc:  # a geometry builder's parameter check
            error = f"InputError:{exc}"
        except Exception as exc:  # gmsh raises plain Exceptions
            error = f"MeshError:gmsh failed: {exc}"
    error = comm.bcast(error, root=0)
    if error:
        if comm.rank == 0 and own_session:
            _close(fresh, previous)
        kind, _, text = error.partition(":")
        raise error_type(kind)(text)  # the type raised on rank 0, on every rank
    return fresh, previous


def _close(fresh: bool | None, previous: str | None) -> None:
    import gmsh

    if fresh:
        gmsh.finalize()
    else:
        gmsh.model.remove()
        if previous:
            gmsh.model.setCurrent(previous)


def to_dolfinx(
    comm: MPI.Comm,
    build: Callable[[], None],
    partitioner: Callable[..., Any] | None = None,
    own_session: bool = True,
    model: Any = None,
) -> MeshData:
    """Run `build` on rank 0 (in a fresh gmsh model) and return the distributed MeshData.

    `model`: what DOLFINx reads the mesh from on rank 0 (default: gmsh.model; the mesh
    cache passes a recorder of it, scenes/mesh_cache.py).
    """
    import gmsh

    fresh, previous = _run_on_root(comm, build, own_session)
    try:
        return mesh_from_model(model if model is not None else gmsh.model, comm, partitioner)
    finally:
        if comm.rank == 0 and own_session:
            _close(fresh, previous)


def mesh_from_model(model: Any, comm: MPI.Comm, partitioner: Callable[..., Any] | None) -> MeshData:
    """DOLFINx's model_to_mesh of `model` (read on rank 0), its check as a MeshError."""
    try:
        return model_to_mesh(
            model if comm.rank == 0 else None, comm, 0, gdim=2, partitioner=partitioner
        )
    except RuntimeError as exc:  # raised on every rank alike (DOLFINx broadcasts the check)
        raise MeshError(
            f"the gmsh mesh cannot be loaded: {exc} (every cell must belong to "
            "exactly one physical surface group)"
        ) from None


def open_mesh_file(
    path: Path, size_factor: float = 1.0, size_field: SizeField | None = None
) -> Callable[[], None]:
    """A build step that reads a .msh, or meshes a .geo in 2D with sizes times `size_factor`.

    `size_field` (a .geo only): gmsh meshes with these sizes times `size_factor`, in place
    of the .geo's own (its transfinite curves and surfaces keep their node counts).
    """
    suffix = path.suffix.lower()
    if suffix not in (".msh", ".geo"):
        raise InputError(f"mesh file {path}: expected a gmsh .msh or .geo file")
    if path.is_dir():
        raise InputError(f"mesh file {path} is a directory: give the path of a .msh or .geo file")
    if not path.is_file():
        raise InputError(f"mesh file {path} does not exist")
    if suffix == ".msh" and (size_factor != 1.0 or size_field is not None):
        raise InputError(f"mesh file {path} is a .msh: it cannot be refined (give a .geo)")

    def build() -> None:
        import gmsh

        try:
            gmsh.open(str(path))
        except Exception as exc:
            raise MeshError(f"cannot read mesh file {path}: {exc}") from None
        if suffix == ".geo" and size_field is not None:
            saved = apply_size_view(size_field.quads, size_field.sizes * size_factor)
            try:
                gmsh.model.mesh.clear()
                gmsh.model.mesh.generate(2)
            finally:
                restore_options(saved)
        elif suffix == ".geo":
            factor = gmsh.option.getNumber("Mesh.MeshSizeFactor")
            gmsh.option.setNumber("Mesh.MeshSizeFactor", factor * size_factor)
            try:
                gmsh.model.mesh.generate(2)
            finally:
                gmsh.option.setNumber("Mesh.MeshSizeFactor", factor)

    return build


def load_meshdata(
    model_or_path: Any,
    comm: MPI.Comm,
    size_factor: float = 1.0,
    size_field: SizeField | None = None,
) -> MeshData:
    """Distributed MeshData of a gmsh .msh/.geo path, or of the gmsh module's current model."""
    if isinstance(model_or_path, str | Path):
        build = open_mesh_file(Path(model_or_path), size_factor, size_field)
        return to_dolfinx(comm, build, balanced_partitioner())

    # A model the user built with the gmsh API: mesh it if it has no 2D elements yet.
    def mesh_model() -> None:
        import gmsh

        if not len(gmsh.model.mesh.getElements(2)[0]):
            gmsh.model.mesh.generate(2)

    return to_dolfinx(comm, mesh_model, balanced_partitioner(), own_session=False)


@dataclass(frozen=True)
class SceneParts:
    """What a scene is made of besides its mesh: bodies, pairs, supports, loads, references."""

    bodies: Mapping[str, Material]
    contacts: tuple[ContactPair, ...]
    dirichlet: tuple[Dirichlet, ...] = ()
    loads: tuple[Load, ...] = ()
    references: tuple[Reference, ...] = ()
    name: str = "scene"
    obstacles: tuple[Obstacle, ...] = ()
    model: Model = Model.PLANE_STRAIN
    units: Units = field(default_factory=Units)
    probes: tuple[Probe, ...] = ()
    steps: tuple[Mapping[str, float], ...] = ()


@dataclass(frozen=True)
class GeoRecipe:
    """A scene whose mesh gmsh makes from a .geo file, with Mesh.MeshSizeFactor scaled."""

    path: Path
    parts: SceneParts
    size_factor: float = 1.0
    params: Mapping[str, Any] | None = None
    size_field: SizeField | None = None  # set: the .geo meshed with these sizes

    def resized(self, factor: float) -> GeoRecipe:
        """The same .geo meshed with every size times `factor`."""
        return replace(self, size_factor=self.size_factor * factor)

    def adapted(self, field: SizeField) -> GeoRecipe:
        """The same .geo meshed with the sizes of `field` (times no factor)."""
        return replace(self, size_field=field, size_factor=1.0)

    def build(self, comm: MPI.Comm) -> Scene:
        """Mesh the .geo and return the checked Scene."""
        return scene_from_parts(
            self.path, self.parts, comm, self.size_factor, self.params, self.size_field
        )


def scene_from_parts(
    model_or_path: Any,
    parts: SceneParts,
    comm: MPI.Comm,
    size_factor: float = 1.0,
    params: Mapping[str, Any] | None = None,
    size_field: SizeField | None = None,
) -> Scene:
    """The checked Scene of `parts` on the mesh of `model_or_path` (see `scene_from_gmsh`).

    Scene files (scene_file.py) and GeoRecipe.build come here with their parts made.
    """
    for body, mat in parts.bodies.items():
        mat.check(f"body '{body}'")
    data = load_meshdata(model_or_path, comm, size_factor, size_field)
    assert data.cell_tags is not None  # one cell type (all quads, checked on rank 0): tagged
    path = Path(model_or_path) if isinstance(model_or_path, str | Path) else None
    recipe = (
        GeoRecipe(path, parts, size_factor, params, size_field)
        if path is not None and path.suffix.lower() == ".geo"
        else None
    )
    scene = Scene(
        data.mesh,
        data.cell_tags,
        data.facet_tags,
        data.ridge_tags,
        Groups.of(data.physical_groups),
        tuple(Body(k, m) for k, m in parts.bodies.items()),
        parts.contacts,
        parts.dirichlet,
        parts.loads,
        parts.references,
        name=parts.name,
        params={
            "mesh": str(path) if path is not None else "gmsh model",
            "size_factor": size_factor,
            "model": parts.model.value,
            **(params or {}),
        },
        recipe=recipe,
        obstacles=parts.obstacles,
        model=parts.model,
        units=parts.units,
        probes=parts.probes,
        steps=parts.steps,
    )
    return check_scene(scene)


def _material(name: str, values: object) -> Material:
    """A Material from {"E": ..., "nu": ...} (and "alpha", "dT"); InputError on other keys."""
    if isinstance(values, Material):
        return values
    if not isinstance(values, Mapping):
        raise InputError(
            f"bodies['{name}']: expected a Material or a dict like {{'E': 200e3, 'nu': 0.3}}, "
            f"got {type(values).__name__}"
        )
    unknown = sorted(set(values) - {"E", "nu", "alpha", "dT"})
    if unknown or not {"E", "nu"} <= set(values):
        what = f"unknown key '{unknown[0]}'" if unknown else "E and nu are required"
        raise InputError(f"body '{name}': {what} (keys: E, nu, alpha, dT)")
    thermal = {k: float(values[k]) for k in ("alpha", "dT") if k in values}
    return Material(float(values["E"]), float(values["nu"]), **thermal)


def scene_from_gmsh(
    model_or_path: Any,
    *,
    bodies: Mapping[str, Material | Mapping[str, float]],
    contacts: list[tuple[str, str]] | list[ContactPair] | None = None,
    dirichlet: list[Dirichlet] | None = None,
    loads: list[Load] | None = None,
    references: list[Reference] | None = None,
    comm: MPI.Comm = MPI.COMM_WORLD,
    name: str | None = None,
    obstacles: list[Obstacle] | None = None,
    model: Model | str = Model.PLANE_STRAIN,
    probes: list[Probe] | None = None,
    steps: list[Mapping[str, float]] | None = None,
) -> Scene:
    """A Scene from a gmsh model (the gmsh module's current model) or a .msh/.geo path.

    Args:
        model_or_path: A .msh or .geo path, or anything else for gmsh's current model
            (meshed in 2D here if it has no 2D elements yet).
        bodies: Material (or {"E": ..., "nu": ...}, with "alpha" and "dT" for a thermal
            strain) per physical surface group.
        contacts: (active, passive) curve groups of every contact pair, or ContactPairs
            (with `interference` for a fit).
        dirichlet: Prescribed displacement components on curve or point groups.
        loads: Pressures and tractions on curve groups.
        references: Analytic references (HertzReference, UniformStress) to report.
        comm: The communicator the mesh is distributed over.
        name: The scene's label (default: the file's stem, or "gmsh-model").
        obstacles: Rigid obstacles (Obstacle), each against one curve group of a body.
        model: plane_strain (default), plane_stress or axisymmetric (x = r >= 0, y the axis).
        probes: Values read off the solution (Probe), printed and in the JSON.
        steps: Load steps in order, each {load name: factor} on named loads (a named load
            keeps its last factor, 0 before its first; unnamed loads act in full).

    Returns:
        The checked Scene; a .geo scene can be remeshed (coarse predictor, studies).
    """
    if not isinstance(bodies, Mapping) or not bodies:
        raise InputError(
            "bodies: expected a dict of body names (the mesh's physical surface groups) to "
            f"materials, e.g. {{'block': {{'E': 200e3, 'nu': 0.3}}}}, got {type(bodies).__name__}"
        )
    mats = {str(k): _material(str(k), v) for k, v in bodies.items()}
    label = name or (
        Path(model_or_path).stem if isinstance(model_or_path, str | Path) else "gmsh-model"
    )
    parts = SceneParts(
        mats,
        tuple(p if isinstance(p, ContactPair) else ContactPair(*p) for p in contacts or ()),
        tuple(dirichlet or ()),
        tuple(loads or ()),
        tuple(references or ()),
        label,
        tuple(obstacles or ()),
        Model.parse(model),
        probes=tuple(probes or ()),
        steps=tuple(steps or ()),
    )
    return scene_from_parts(model_or_path, parts, comm)
