"""A scene as data: bodies, contact pairs, supports, loads, references and the distributed mesh.

Everything downstream (elasticity, contact, active set, output) reads only these fields; a
scene's name is a label for the JSON and never steers the computation.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import dolfinx
from mpi4py import MPI

from ..errors import InputError, MeshError


@dataclass(frozen=True)
class Material:
    """Isotropic linear elasticity in plane strain: Young's modulus and Poisson ratio."""

    E: float
    nu: float

    def check(self, where: str) -> None:
        """Raise InputError unless E > 0 and -1 < nu < 0.5 (finite)."""
        if not (math.isfinite(self.E) and self.E > 0):
            raise InputError(f"{where}: Young's modulus must be > 0 (got E = {self.E})")
        if not (math.isfinite(self.nu) and -1.0 < self.nu < 0.5):
            raise InputError(f"{where}: Poisson ratio must lie in (-1, 0.5) (got nu = {self.nu})")


@dataclass(frozen=True)
class Body:
    """One elastic body: a named physical surface group and its material."""

    name: str
    material: Material


@dataclass(frozen=True)
class ContactPair:
    """One contact pair: curve groups on the active (slave) and the passive (master) body."""

    active: str
    passive: str


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed displacement components on a named curve or point group (None = free)."""

    group: str
    ux: float | None = None
    uy: float | None = None

    def components(self) -> list[tuple[int, float]]:
        """(component, value) pairs that are prescribed."""
        return [(c, v) for c, v in ((0, self.ux), (1, self.uy)) if v is not None]


@dataclass(frozen=True)
class Pressure:
    """Normal pressure on a named curve group, positive pushing into the body."""

    group: str
    p: float


@dataclass(frozen=True)
class Traction:
    """Traction vector (force per unit length) on a named curve group."""

    group: str
    t: tuple[float, float]


Load = Pressure | Traction


@dataclass(frozen=True)
class HertzReference:
    """Plane-strain Hertz line contact on one pair: effective radius R, full line load P.

    `symmetric`: the model is a half model cut through the contact centre (which is then the
    end of the active surface nearest the symmetry line); otherwise the centre is the
    pressure's centroid.
    """

    pair: int
    R: float
    P: float
    symmetric: bool = True


@dataclass(frozen=True)
class UniformStress:
    """Patch test: the exact stress is this constant tensor in every body."""

    sigma: tuple[tuple[float, float], tuple[float, float]]


Reference = HertzReference | UniformStress


@dataclass(frozen=True)
class Groups:
    """Physical groups of the mesh by name: (dimension, tag)."""

    by_name: dict[str, tuple[int, int]]

    def tag(self, name: str, dim: int, what: str) -> int:
        """The tag of group `name`, which must have dimension `dim`; MeshError otherwise."""
        if name not in self.by_name:
            have = ", ".join(sorted(self.by_name)) or "none"
            raise MeshError(f"{what}: the mesh has no physical group '{name}' (it has: {have})")
        gdim, tag = self.by_name[name]
        if gdim != dim:
            kinds = {0: "point", 1: "curve", 2: "surface"}
            raise MeshError(
                f"{what}: physical group '{name}' is a {kinds.get(gdim, gdim)} "
                f"group, a {kinds[dim]} group is needed"
            )
        return tag


@dataclass(frozen=True)
class Scene:
    """A scene ready to solve: the distributed mesh with its tags, and the problem as data."""

    mesh: dolfinx.mesh.Mesh
    cell_tags: dolfinx.mesh.MeshTags
    facet_tags: dolfinx.mesh.MeshTags | None
    point_tags: dolfinx.mesh.MeshTags | None
    groups: Groups
    bodies: tuple[Body, ...]
    contacts: tuple[ContactPair, ...]
    dirichlet: tuple[Dirichlet, ...] = ()
    loads: tuple[Load, ...] = ()
    references: tuple[Reference, ...] = ()
    name: str = "scene"
    params: dict[str, Any] = field(default_factory=dict)
    # Built-in scenes with one horizontal contact line also write the paper's x-sorted
    # `interface` block (sigma_yy of both bodies), which their charts and tests read.
    cartesian_interface: bool = False
    # The same scene with every mesh size times a factor (None: cannot be remeshed). Used
    # by the coarse predictor and by refinement studies.
    resize: Callable[[float], Scene] | None = field(default=None, compare=False, repr=False)
    # Which body each curve group lies on, found once (a collective pass over the mesh);
    # not an init field, so dataclasses.replace (other groups) starts a fresh one.
    _curve_bodies: dict[str, Body] = field(
        default_factory=dict, init=False, compare=False, repr=False
    )

    @property
    def comm(self) -> MPI.Comm:
        """The scene's communicator."""
        return self.mesh.comm

    def body_tag(self, body: Body) -> int:
        """Cell tag of `body`."""
        return self.groups.tag(body.name, 2, f"body '{body.name}'")

    def curve_tag(self, name: str, what: str) -> int:
        """Facet tag of the curve group `name`."""
        return self.groups.tag(name, 1, what)

    def body_of_curve(self, name: str) -> Body:
        """The body whose cells own the facets of curve group `name` (MeshError if several)."""
        from .checks import body_of_curve

        if name not in self._curve_bodies:
            self._curve_bodies[name] = body_of_curve(self, name)
        return self._curve_bodies[name]

    def params_dict(self) -> dict[str, Any]:
        """Parameters for the JSON summary."""
        return dict(self.params)

    @classmethod
    def from_gmsh(
        cls,
        model_or_path: Any,
        *,
        bodies: dict[str, Material | dict[str, float]],
        contacts: list[tuple[str, str]] | list[ContactPair],
        dirichlet: list[Dirichlet] | None = None,
        loads: list[Load] | None = None,
        references: list[Reference] | None = None,
        comm: MPI.Comm = MPI.COMM_WORLD,
        name: str | None = None,
    ) -> Scene:
        """A Scene from a gmsh model (the gmsh module's current model) or a .msh/.geo path."""
        from .gmsh_io import scene_from_gmsh

        mats = {
            k: v if isinstance(v, Material) else Material(float(v["E"]), float(v["nu"]))
            for k, v in bodies.items()
        }
        pairs = [p if isinstance(p, ContactPair) else ContactPair(*p) for p in contacts]
        label = name or (
            Path(model_or_path).stem if isinstance(model_or_path, str | Path) else "gmsh-model"
        )
        return scene_from_gmsh(
            model_or_path,
            mats,
            pairs,
            list(dirichlet or []),
            list(loads or []),
            list(references or []),
            comm,
            label,
        )
