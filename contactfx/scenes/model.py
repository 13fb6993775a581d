"""A scene as data: bodies, contact pairs, supports, loads, references and the distributed mesh.

Everything downstream (elasticity, contact, active set, output) reads only these fields; a
scene's name is a label for the JSON and never steers the computation.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any, Protocol

import dolfinx
import numpy as np
from dolfinx.io.gmsh import PhysicalGroup
from mpi4py import MPI

from ..errors import InputError, MeshError
from ..meshes import GridLines
from .fits import LameReference, PushoutReference, check_friction, check_interference, check_thermal
from .obstacle import Obstacle
from .probe import Probe


class Model(StrEnum):
    """The 2D model of the bodies: plane strain, plane stress, or axisymmetric.

    Axisymmetric: x is the radius r >= 0 and y the axis direction (the axis is x = 0).
    """

    PLANE_STRAIN = "plane_strain"
    PLANE_STRESS = "plane_stress"
    AXISYMMETRIC = "axisymmetric"

    @classmethod
    def parse(cls, value: Model | str, where: str = "model") -> Model:
        """The model named `value` (InputError naming the choices otherwise)."""
        try:
            return cls(value)
        except ValueError:
            choices = ", ".join(m.value for m in cls)
            raise InputError(f"{where}: unknown model '{value}' (choose {choices})") from None


@dataclass(frozen=True)
class Units:
    """The names of the scene's units of length and stress (labels only: nothing converts).

    A scene that names none is drawn with the axes "length" and "stress".
    """

    length: str = "length"
    stress: str = "stress"


# Young's moduli of solids in any unit system (kPa to dyn/cm^2) lie far inside; beyond, the
# stiffness and the loads' lifting overflow or underflow double precision.
E_RANGE = (1e-10, 1e15)


@dataclass(frozen=True)
class Material:
    """Isotropic linear elasticity: Young's modulus and Poisson ratio.

    `alpha` (thermal expansion coefficient) and `dT` (a uniform temperature change) give the
    body the eigenstrain alpha dT I (discretize/thermal.py); both or neither.
    """

    E: float
    nu: float
    alpha: float | None = None
    dT: float | None = None

    @property
    def thermal_strain(self) -> float:
        """The eigenstrain alpha dT (0 without a thermal load)."""
        return 0.0 if self.alpha is None or self.dT is None else self.alpha * self.dT

    def check(self, where: str) -> None:
        """Raise InputError unless E > 0, -1 < nu < 0.5, and alpha and dT come together."""
        if not (math.isfinite(self.E) and self.E > 0):
            raise InputError(f"{where}: Young's modulus must be > 0 (got E = {self.E})")
        if not E_RANGE[0] <= self.E <= E_RANGE[1]:
            raise InputError(
                f"{where}: Young's modulus E = {self.E:g} is outside {E_RANGE[0]:g} to "
                f"{E_RANGE[1]:g}, where every solid lies in any units (steel: 2.1e5 MPa, "
                "2.1e11 Pa): check its units"
            )
        if not (math.isfinite(self.nu) and -1.0 < self.nu < 0.5):
            raise InputError(f"{where}: Poisson ratio must lie in (-1, 0.5) (got nu = {self.nu})")
        check_thermal(self.alpha, self.dT, where)


@dataclass(frozen=True)
class Body:
    """One elastic body: a named physical surface group and its material."""

    name: str
    material: Material


@dataclass(frozen=True)
class ContactPair:
    """One contact pair: curve groups on the active (slave) and the passive (master) body.

    `interference`: False (the default) for bodies that must not overlap as drawn; True for
    an interference fit drawn overlapping (the overlap is the fit, the solve resolves it);
    a number D > 0 for bodies drawn touching, with the overlap D prescribed along the normal
    (the gap g becomes g - D).
    `mu`: Coulomb's friction coefficient (0, the default: frictionless, today's model exactly).
    """

    active: str
    passive: str
    interference: bool | float = False
    mu: float = 0.0

    def __post_init__(self) -> None:
        where = f"contact '{self.active}' on '{self.passive}'"
        object.__setattr__(self, "interference", check_interference(self.interference, where))
        object.__setattr__(self, "mu", check_friction(self.mu, where))

    @property
    def prescribed_overlap(self) -> float:
        """The overlap prescribed along the normal (length units), or 0.

        ``interference = D`` (a number D > 0: bodies drawn touching) prescribes D;
        ``interference = true`` (bodies drawn overlapping) or ``false`` prescribes nothing:
        the gap is the drawn one, and this is 0.
        """
        d = self.interference
        return 0.0 if isinstance(d, bool) else d


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed displacement components on a named curve or point group (None = free).

    `name`: what a load step's factor calls it (scenes/steps.py); None: in full in every step.
    """

    group: str
    ux: float | None = None
    uy: float | None = None
    name: str | None = None

    def components(self) -> list[tuple[int, float]]:
        """(component, value) pairs that are prescribed."""
        return [(c, v) for c, v in ((0, self.ux), (1, self.uy)) if v is not None]


@dataclass(frozen=True)
class Pressure:
    """Normal pressure on a named curve group, positive pushing into the body.

    `name`: as Dirichlet's.
    """

    group: str
    p: float
    name: str | None = None


@dataclass(frozen=True)
class Traction:
    """Traction vector (force per unit length) on a named curve group (`name`: as Dirichlet's)."""

    group: str
    t: tuple[float, float]
    name: str | None = None


Load = Pressure | Traction


class HertzContact(StrEnum):
    """Which of Hertz's contacts a reference is: a cylinder's line or a sphere's point."""

    LINE = "line"
    POINT = "point"


@dataclass(frozen=True)
class HertzReference:
    """Hertz contact on one pair: effective radius R, full load P.

    `contact` None (the default) takes the model's: the line contact of a cylinder (P per
    unit thickness) in plane strain and plane stress, the point contact of a sphere (P the
    total force; its centre is on the axis) in an axisymmetric scene. `contact = "line"` in
    an axisymmetric scene is a ring's line contact on a torus section (an O-ring between
    plates): P the total force over the turn, the line load P / (2 pi r_c) at the contact
    centre's radius r_c. A plane model has no point contact (InputError).

    `P` None (omitted): the load is the pair's computed contact force (twice it for a half
    model), which is what a displacement-controlled scene knows. `symmetric`: the model is a
    half model cut through the contact centre (which is then the end of the active surface
    nearest the symmetry line); otherwise (the default, in Python and in scene files alike)
    the centre is the first moment of the piecewise-linear pressure along the arc length.
    The sphere of an axisymmetric scene is measured from the axis with or without it (the
    axis is the symmetry line); a ring's line contact has no such cut (InputError).
    """

    pair: int
    R: float
    P: float | None = None
    symmetric: bool = False
    contact: HertzContact | None = None

    def __post_init__(self) -> None:
        if self.contact is not None:
            try:
                object.__setattr__(self, "contact", HertzContact(self.contact))
            except ValueError:
                raise InputError(
                    f"hertz reference: contact must be 'line' or 'point' (got {self.contact!r})"
                ) from None

    def contact_in(self, model: Model) -> HertzContact:
        """The contact this reference is in `model` (InputError where it has none)."""
        axi = model is Model.AXISYMMETRIC
        kind = self.contact or (HertzContact.POINT if axi else HertzContact.LINE)
        if kind is HertzContact.POINT and not axi:
            raise InputError(
                f"hertz reference (pair {self.pair}): contact = 'point' is a sphere's, which "
                f"needs model = 'axisymmetric' ({model.value} is a cylinder's line contact)"
            )
        if kind is HertzContact.LINE and axi and self.symmetric:
            raise InputError(
                f"hertz reference (pair {self.pair}): a ring's line contact in an axisymmetric "
                "scene has no half model (drop symmetric; the centre is read off the pressure)"
            )
        return kind


@dataclass(frozen=True)
class UniformStress:
    """Patch test: the exact stress is this constant tensor in every body."""

    sigma: tuple[tuple[float, float], tuple[float, float]]


@dataclass(frozen=True)
class CattaneoReference:
    """Cattaneo-Mindlin on one frictional pair (a plane model's line contact, similar bodies).

    At each load step: Hertz's pressure under the pair's normal force P, the stick half-width
    c = a sqrt(1 - Q / (mu P)) and the closed-form shear, with P and Q the forces the pair's
    multipliers carry. `R` is the effective radius (1/R = 1/R1 + 1/R2); `mu` None takes the
    pair's. It holds where the approach makes no relative slip (mirrored bodies, or a
    frictionless approach); the summary says when the first step's shear says otherwise.
    A tangential push breaks a half model's mirror symmetry: full models only.
    """

    pair: int
    R: float
    mu: float | None = None


@dataclass(frozen=True)
class SpenceReference:
    """Spence's stick ratio on a rigid circle obstacle pressed with friction (plane strain).

    At each load step: the stick half-width c and the contact half-width a read from the
    statuses, against c/a = spence_stick_ratio(mu, nu) (Spence 1975: constant as the load
    grows), with the offset c - (c/a) a in contact cells. `pair` indexes [[contact]], then
    [[obstacle]], and must be a circle obstacle; `symmetric`: a half model cut through the
    contact centre (as HertzReference's); `mu` None takes the obstacle's, nu is the body's.
    Spence's analysis is the limit a/R -> 0 under a monotonic load in small steps.
    """

    pair: int
    symmetric: bool = False
    mu: float | None = None


Reference = (
    HertzReference
    | UniformStress
    | LameReference
    | CattaneoReference
    | PushoutReference
    | SpenceReference
)


@dataclass(frozen=True)
class Groups:
    """Physical groups of the mesh by name (dolfinx's PhysicalGroup: dimension and tag)."""

    by_name: Mapping[str, PhysicalGroup]

    def __post_init__(self) -> None:
        # Plain (dim, tag) pairs are accepted and stored as PhysicalGroups.
        groups = {k: PhysicalGroup(int(g[0]), int(g[1])) for k, g in self.by_name.items()}
        object.__setattr__(self, "by_name", groups)

    @classmethod
    def of(cls, groups: Mapping[str, Any]) -> Groups:
        """Groups from a name -> (dim, tag) mapping (PhysicalGroups or plain pairs)."""
        return cls(dict(groups))

    def dim(self, name: str) -> int | None:
        """The dimension of group `name`, or None if the mesh has no such group."""
        group = self.by_name.get(name)
        return None if group is None else group.dim

    def tag(self, name: str, dim: int, what: str) -> int:
        """The tag of group `name`, which must have dimension `dim`; MeshError otherwise."""
        if name not in self.by_name:
            have = ", ".join(sorted(self.by_name)) or "none"
            raise MeshError(f"{what}: the mesh has no physical group '{name}' (it has: {have})")
        group = self.by_name[name]
        if group.dim != dim:
            kinds = {0: "point", 1: "curve", 2: "surface"}
            raise MeshError(
                f"{what}: physical group '{name}' is a {kinds.get(group.dim, group.dim)} "
                f"group, a {kinds[dim]} group is needed"
            )
        return group.tag


@dataclass(frozen=True, eq=False)
class SizeField:
    """A mesh size given at the vertices of quadrilaterals: a background mesh for gmsh.

    `quads` (n, 4, 2) and `sizes` (n, 4) are the whole field on rank 0 (where gmsh runs);
    the other ranks hold empty arrays. The adaptive loop makes it (adapt/loop.py).
    """

    quads: np.ndarray
    sizes: np.ndarray

    def scaled(self, factor: float) -> SizeField:
        """Every size times `factor`."""
        return SizeField(self.quads, self.sizes * factor)


class Recipe(Protocol):
    """How a scene's mesh was made, as data: remade with every mesh size times a factor.

    Built-in scenes keep their parameters (scenes/builtin.py), scene files their .geo
    (scenes/gmsh_io.py); the coarse predictor and refinement studies call `resized`, the
    adaptive loop `adapted`.
    """

    def resized(self, factor: float) -> Recipe:
        """The same recipe with every mesh size times `factor`."""
        ...

    def adapted(self, field: SizeField) -> Recipe:
        """The same geometry meshed with the sizes of `field` (InputError if it cannot be)."""
        ...

    def build(self, comm: MPI.Comm) -> Scene:
        """Mesh and return the scene (collective)."""
        ...


@dataclass(frozen=True)
class Scene:
    """A scene ready to solve: the distributed mesh with its tags, and the problem as data.

    `curve_bodies` maps every contact curve group to the body it lies on (found once, when
    the scene is checked against its mesh: scenes.checks.check_scene). `params` are labels
    for the JSON summary and never steer the computation. `obstacles` are rigid analytic
    surfaces; each makes one more pair after the `contacts` (pair index len(contacts) + i).
    """

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
    params: Mapping[str, Any] = field(default_factory=dict)
    recipe: Recipe | None = field(default=None, compare=False, repr=False)
    curve_bodies: Mapping[str, str] = field(default_factory=dict, compare=False, repr=False)
    obstacles: tuple[Obstacle, ...] = ()
    model: Model = Model.PLANE_STRAIN
    units: Units = field(default_factory=Units)
    # The lines of a structured mesh (its coarser grids: a geometric multigrid's levels).
    grid: GridLines | None = field(default=None, compare=False, repr=False)
    probes: tuple[Probe, ...] = ()  # values read off the solution (results/probes.py)
    # Load steps in order: factors on named loads (scenes/steps.py); () is one step in full.
    steps: tuple[Mapping[str, float], ...] = ()

    @property
    def comm(self) -> MPI.Comm:
        """The scene's communicator."""
        return self.mesh.comm

    @property
    def e_max(self) -> float:
        """The largest Young's modulus of the bodies."""
        return max(b.material.E for b in self.bodies)

    def body_tag(self, body: Body) -> int:
        """Cell tag of `body`."""
        return self.groups.tag(body.name, 2, f"body '{body.name}'")

    def body_cells(self, body: Body) -> np.ndarray:
        """Local cells (owned and ghost) of `body`."""
        return self.cell_tags.find(self.body_tag(body))

    def curve_tag(self, name: str, what: str) -> int:
        """Facet tag of the curve group `name`."""
        return self.groups.tag(name, 1, what)

    @property
    def can_remesh(self) -> bool:
        """Whether the scene knows how its mesh was made (a built-in scene or a .geo)."""
        return self.recipe is not None

    def remeshed(self, factor: float, comm: MPI.Comm | None = None) -> Scene:
        """The same scene with every mesh size times `factor` (InputError if it cannot be).

        On `comm` if given (a multigrid's levels: each rank alone), else on the scene's
        (collective).
        """
        return self.require_recipe().resized(factor).build(self.comm if comm is None else comm)

    def remeshed_to(self, field: SizeField) -> Scene:
        """The same scene's geometry meshed by gmsh with the sizes of `field` (collective)."""
        return self.require_recipe().adapted(field).build(self.comm)

    def require_recipe(self) -> Recipe:
        """The scene's recipe; InputError if it has none (nothing to remesh)."""
        if self.recipe is None:
            raise InputError(
                f"scene '{self.name}' cannot be remeshed: there is no geometry to remesh "
                "(a .msh or an in-memory gmsh model; only built-in scenes and .geo meshes can)"
            )
        return self.recipe

    def body_of_curve(self, name: str) -> Body:
        """The body that the contact curve group `name` lies on."""
        body = self.curve_bodies.get(name)
        if body is None:
            raise MeshError(f"curve group '{name}' is not a contact surface of this scene")
        return next(b for b in self.bodies if b.name == body)
