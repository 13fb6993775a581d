"""The paper's scenes as small functions returning a Scene: blocks (S1-S4) and Hertz (S5)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from functools import partial
from typing import Any

from dolfinx.io.gmsh import MeshData
from mpi4py import MPI

from ..errors import InputError
from ..meshes import build_blocks, build_hertz
from .checks import check_scene
from .mesh_cache import cached_to_dolfinx
from .model import (
    Body,
    ContactPair,
    Dirichlet,
    Groups,
    HertzReference,
    Material,
    Model,
    Pressure,
    Reference,
    Scene,
    SizeField,
    UniformStress,
    Units,
)
from .structured import build_hertz_structured


@dataclass(frozen=True)
class BlockParams:
    """Two blocks, half model (SPEC S1-S4); lengths in cm, E and p in MPa."""

    l1: float = 10.0
    l2: float = 6.0
    h1: float = 3.0
    h2: float = 3.0
    E1: float = 70000.0
    E2: float = 70000.0
    nu1: float = 0.3
    nu2: float = 0.3
    p: float = 50.0
    size1: float = 0.125
    size2: float = 0.125
    grading1: float = 1.0
    grading2: float = 1.0
    model: Model = Model.PLANE_STRAIN  # axisymmetric: two stacked cylinders (x = r)
    mu: float = 0.0  # Coulomb friction on the pair (0: frictionless)


@dataclass(frozen=True)
class HertzParams:
    """Cylinder on a block, half model (SPEC S5); P is the force per unit thickness (MPa*cm)."""

    R: float = 60.0
    P: float = 100.0
    E1: float = 7000.0
    E2: float = 7000.0
    nu1: float = 0.23
    nu2: float = 0.23
    refine: float = 0.02  # element size on the contact zone, x <= r_refine (cm)
    r_refine: float | None = None  # end of the refined zone; None: 1.4 a (Hertz's half-width)
    refine_edge: float = 0.005  # element size at x = a, the pressure's sqrt edge; 0 = off
    slope: float = 0.1  # growth of the element size per unit distance
    width: float = 60.0
    height: float = 60.0
    mesh: str = "gmsh"  # "gmsh" (graded unstructured quads) or "structured" (large runs)
    h_far: float | None = None  # largest element size (cm); None: R / 6
    # Axisymmetric: a (hemi)sphere on a cylindrical block, P the total force (MPa*cm^2).
    model: Model = Model.PLANE_STRAIN
    mu: float = 0.0  # Coulomb friction on the pair (0: frictionless)


#: The Hertz scene's meshers (`--mesh`).
MESHERS = ("gmsh", "structured")

#: The paper's block scenes S1-S4 (`--preset`): their parameters over the defaults.
BLOCK_SCENES: dict[str, BlockParams] = {
    "S1": BlockParams(),
    "S2": BlockParams(size1=0.08, size2=0.1),
    "S3": BlockParams(E1=700000.0, size1=0.08, size2=0.1),
    "S4": BlockParams(l2=10.0, E1=700000.0, size1=0.12, size2=0.15, grading1=1.01, grading2=0.99),
}


def hertz_exact(params: HertzParams) -> dict[str, float]:
    """Hertz (Johnson sec. 4.2, 3.2): E*, half-width (radius) a and peak pressure p0.

    Line contact in plane strain and plane stress (E* with E instead of E/(1 - nu^2));
    a sphere's point contact in axisymmetric (P the total force).
    """
    if params.model is Model.PLANE_STRESS:
        inv = 1.0 / params.E1 + 1.0 / params.E2
    else:
        inv = (1 - params.nu1**2) / params.E1 + (1 - params.nu2**2) / params.E2
    e_star = 1.0 / inv
    if params.model is Model.AXISYMMETRIC:
        a = (3 * params.P * params.R / (4 * e_star)) ** (1.0 / 3.0)
        return {"E_star": e_star, "a": a, "p0": 3 * params.P / (2 * math.pi * a * a)}
    a = math.sqrt(4 * params.P * params.R / (math.pi * e_star))
    return {"E_star": e_star, "a": a, "p0": 2 * params.P / (math.pi * a)}


def validate(params: BlockParams | HertzParams) -> None:
    """Raise InputError naming the first parameter out of its range."""
    Model.parse(params.model)
    Material(params.E1, params.nu1).check("body 1")
    Material(params.E2, params.nu2).check("body 2")
    positive = {
        BlockParams: ("l1", "l2", "h1", "h2", "size1", "size2", "grading1", "grading2"),
        HertzParams: ("R", "P", "refine", "slope", "width", "height"),
    }[type(params)]
    for key in positive:
        value = getattr(params, key)
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"{key} must be a positive number (got {value})")
    if isinstance(params, BlockParams):
        if params.l2 > params.l1:
            raise InputError(
                f"l2 = {params.l2} > l1 = {params.l1}: the top block must not overhang the base"
            )
        for key, length in (("size1", params.l1), ("size2", params.l2)):
            if getattr(params, key) > length / 2:
                raise InputError(f"{key} = {getattr(params, key)} is larger than the half width")
        if not math.isfinite(params.p):
            raise InputError(f"p must be finite (got {params.p})")
        if abs(params.p) > max(params.E1, params.E2):
            raise InputError(
                f"p = {params.p:g} exceeds the larger Young's modulus {max(params.E1, params.E2):g}"
                " (a strain beyond 100 %: contactfx is a small-strain code)"
            )
    else:
        if params.refine > params.R / 10:
            raise InputError(f"refine = {params.refine} is too coarse for R = {params.R}")
        a = hertz_exact(params)["a"]
        if not a < params.R:
            raise InputError(
                f"P = {params.P:g} gives a Hertz contact half-width a = {a:.3g} beyond the radius "
                f"R = {params.R:g}: far beyond small strain (lower P)"
            )
        if params.mesh not in MESHERS:
            raise InputError(f"unknown mesh '{params.mesh}' (choose {' or '.join(MESHERS)})")
        if params.r_refine is not None and not (
            math.isfinite(params.r_refine) and params.r_refine > 0
        ):
            raise InputError(f"r_refine must be positive (got {params.r_refine}; None: 1.4 a)")
        if not (math.isfinite(params.refine_edge) and params.refine_edge >= 0):
            raise InputError(f"refine_edge must be >= 0 (got {params.refine_edge})")
        if params.h_far is not None and not (math.isfinite(params.h_far) and params.h_far > 0):
            raise InputError(f"h_far must be positive (got {params.h_far}; None: R / 6)")


@dataclass(frozen=True)
class BuiltinRecipe:
    """A built-in scene by its parameters: remade by scaling its mesh sizes."""

    params: BlockParams | HertzParams
    active: int = 2
    size_field: SizeField | None = None  # set: the gmsh geometry meshed with these sizes

    def resized(self, factor: float) -> BuiltinRecipe:
        """Blocks: both element sizes times f; Hertz: contact, edge and far sizes times f.

        An adapted recipe scales its size field instead.
        """
        if self.size_field is not None:
            return replace(self, size_field=self.size_field.scaled(factor))
        p = self.params
        if isinstance(p, BlockParams):
            scaled: BlockParams | HertzParams = replace(
                p, size1=p.size1 * factor, size2=p.size2 * factor
            )
        else:
            scaled = replace(
                p,
                refine=p.refine * factor,
                refine_edge=p.refine_edge * factor,
                h_far=None if p.h_far is None else p.h_far * factor,
            )
        return replace(self, params=scaled)

    def adapted(self, field: SizeField) -> BuiltinRecipe:
        """The same scene meshed by gmsh with the sizes of `field` (not the structured mesh)."""
        if isinstance(self.params, HertzParams) and self.params.mesh != "gmsh":
            raise InputError(
                "the structured Hertz mesh cannot be adapted: use --mesh gmsh (gmsh "
                "remeshes the geometry from a size field)"
            )
        return replace(self, size_field=field)

    def build(self, comm: MPI.Comm) -> Scene:
        """Mesh the scene."""
        if isinstance(self.params, BlockParams):
            return blocks(self.params, self.active, comm, self.size_field)
        return hertz(self.params, self.active, comm, self.size_field)


def _two_body_scene(
    data: MeshData,
    params: BlockParams | HertzParams,
    load: float,
    active: int,
    name: str,
    references: tuple[Reference, ...],
    extra: dict[str, Any],
    size_field: SizeField | None = None,
) -> Scene:
    """The common shape of the paper's scenes: body1 below, body2 on top, rollers, one load."""
    if active not in (1, 2):
        raise InputError(f"active body must be 1 or 2 (got {active})")
    bodies = (
        Body("body1", Material(params.E1, params.nu1)),
        Body("body2", Material(params.E2, params.nu2)),
    )
    pair = ContactPair(f"contact{active}", f"contact{3 - active}", mu=params.mu)
    # Rollers, as in the paper: u_x = 0 on the symmetry axis, u_y = 0 on the base only.
    supports = (Dirichlet("symmetry", ux=0.0), Dirichlet("support", uy=0.0))
    assert data.cell_tags is not None  # both meshers tag every cell with its body
    scene = Scene(
        data.mesh,
        data.cell_tags,
        data.facet_tags,
        None,
        Groups.of(data.physical_groups),
        bodies,
        (pair,),
        supports,
        (Pressure("load", load),),
        references,
        name=name,
        params={**asdict(params), "model": params.model.value, "active": active, **extra},
        recipe=BuiltinRecipe(params, active, size_field),
        units=Units("cm", "MPa"),  # the paper's
        model=params.model,
    )
    return check_scene(scene)


def _field(size_field: SizeField | None) -> tuple[Any, Any] | None:
    """The (quads, sizes) a mesh builder takes, or None."""
    return None if size_field is None else (size_field.quads, size_field.sizes)


def blocks(
    params: BlockParams = BlockParams(),
    active: int = 2,
    comm: MPI.Comm = MPI.COMM_WORLD,
    size_field: SizeField | None = None,
) -> Scene:
    """Two stacked blocks (S1-S4): pressure p on top, rollers on the axis and the base.

    `size_field`: unstructured quads with these sizes instead of the transfinite mesh.
    """
    validate(params)
    p = params = replace(params, model=Model.parse(params.model))
    build = partial(
        build_blocks,
        p.l1,
        p.l2,
        p.h1,
        p.h2,
        p.size1,
        p.size2,
        p.grading1,
        p.grading2,
        size_field=_field(size_field),
    )
    data = cached_to_dolfinx(comm, build)
    # Equal widths make the stress uniaxial and uniform: the contact patch test.
    refs: tuple[Reference, ...] = (
        (UniformStress(((0.0, 0.0), (0.0, -p.p))),) if p.l1 == p.l2 else ()
    )
    return _two_body_scene(data, p, p.p, active, "blocks", refs, {}, size_field)


def hertz(
    params: HertzParams = HertzParams(),
    active: int = 2,
    comm: MPI.Comm = MPI.COMM_WORLD,
    size_field: SizeField | None = None,
) -> Scene:
    """A quarter cylinder on a block (S5), line load P, on the gmsh or the structured mesh.

    `size_field`: the gmsh geometry meshed with these sizes instead of the graded field.
    """
    validate(params)
    params = replace(params, model=Model.parse(params.model))
    exact = hertz_exact(params)
    if params.r_refine is None:
        # Refine where the contact zone will be: Hertz's a, with margin for the active set.
        params = replace(params, r_refine=round(1.4 * exact["a"], 6))
    h = params
    assert h.r_refine is not None  # set just above
    lines = None
    if h.mesh == "structured":
        # Built directly in DOLFINx: gmsh's quad mesher is too slow for millions of DOFs.
        data, lines = build_hertz_structured(
            comm, h.R, h.width, h.height, h.refine, h.r_refine, h.h_far, h.slope
        )
    else:
        # The edge grading targets the Hertz estimate of a, as a user would plan a mesh.
        edge = (exact["a"], h.refine_edge) if h.refine_edge > 0 else None
        build = partial(
            build_hertz,
            h.R,
            h.width,
            h.height,
            h.refine,
            h.r_refine,
            h_far=h.h_far,
            slope=h.slope,
            edge=edge,
            size_field=_field(size_field),
        )
        data = cached_to_dolfinx(comm, build)
    ref = (HertzReference(pair=0, R=h.R, P=h.P, symmetric=True),)
    # The JSON's params keep h_far 0 for the default far size (R / 6), as `--h-far 0` asks.
    extra: dict[str, Any] = {"h_far": h.h_far or 0.0, "hertz_exact": exact}
    # The load on the flat face: P over its width 2 R (a cylinder), or its disc pi R^2 (a sphere).
    load = h.P / (math.pi * h.R**2) if h.model is Model.AXISYMMETRIC else h.P / (2 * h.R)
    scene = _two_body_scene(data, h, load, active, "hertz", ref, extra, size_field)
    return scene if lines is None else replace(scene, grid=lines)


def build_scene(
    kind: str, params: BlockParams | HertzParams, active: int = 2, comm: MPI.Comm = MPI.COMM_WORLD
) -> Scene:
    """A built-in scene by name: 'blocks' with BlockParams or 'hertz' with HertzParams."""
    if kind == "blocks" and isinstance(params, BlockParams):
        return blocks(params, active, comm)
    if kind == "hertz" and isinstance(params, HertzParams):
        return hertz(params, active, comm)
    raise InputError(
        f"unknown scene '{kind}' with {type(params).__name__} "
        "(choose blocks with BlockParams or hertz with HertzParams)"
    )
