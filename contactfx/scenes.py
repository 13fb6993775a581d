"""Scenes as data: parameters of the block (S1-S4) and Hertz (S5) problems, and the built mesh."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from typing import Any

import dolfinx
from mpi4py import MPI

from .errors import InputError


@dataclass(frozen=True)
class Material:
    """Isotropic linear elasticity in plane strain: Young's modulus (MPa) and Poisson ratio."""

    E: float
    nu: float


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


@dataclass(frozen=True)
class HertzParams:
    """Cylinder on a block, half model (SPEC S5); P is the force per unit thickness (MPa*cm)."""

    R: float = 60.0
    P: float = 100.0
    E1: float = 7000.0
    E2: float = 7000.0
    nu1: float = 0.23
    nu2: float = 0.23
    refine: float = 0.02        # element size on the contact zone, x <= r_refine (cm)
    r_refine: float = 0.0       # end of the refined zone; 0 = 1.4 a (Hertz's half-width)
    refine_edge: float = 0.005  # element size at x = a, the pressure's sqrt edge; 0 = off
    slope: float = 0.1          # growth of the element size per unit distance
    width: float = 60.0
    height: float = 60.0
    mesh: str = "gmsh"          # "gmsh" (graded unstructured quads) or "structured" (large runs)


MESHERS = ("gmsh", "structured")

BLOCK_SCENES: dict[str, BlockParams] = {
    "S1": BlockParams(),
    "S2": BlockParams(size1=0.08, size2=0.1),
    "S3": BlockParams(E1=700000.0, size1=0.08, size2=0.1),
    "S4": BlockParams(l2=10.0, E1=700000.0, size1=0.12, size2=0.15, grading1=1.01, grading2=0.99),
}


def hertz_exact(params: HertzParams) -> dict[str, float]:
    """Plane-strain line contact (Johnson sec. 4.2): E*, half-width a and peak pressure p0."""
    inv = (1 - params.nu1**2) / params.E1 + (1 - params.nu2**2) / params.E2
    e_star = 1.0 / inv
    a = math.sqrt(4 * params.P * params.R / (math.pi * e_star))
    return {"E_star": e_star, "a": a, "p0": 2 * params.P / (math.pi * a)}


def _check_material(name: str, E: float, nu: float) -> None:
    if not E > 0:
        raise InputError(f"{name}: Young's modulus must be > 0 (got E = {E})")
    if not -1.0 < nu < 0.5:
        raise InputError(f"{name}: Poisson ratio must lie in (-1, 0.5) (got nu = {nu})")


def validate(params: BlockParams | HertzParams) -> None:
    """Raise InputError naming the first parameter out of its range."""
    _check_material("body 1", params.E1, params.nu1)
    _check_material("body 2", params.E2, params.nu2)
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
            raise InputError(f"l2 = {params.l2} > l1 = {params.l1}: the top block must not "
                             "overhang the base")
        for key, length in (("size1", params.l1), ("size2", params.l2)):
            if getattr(params, key) > length / 2:
                raise InputError(f"{key} = {getattr(params, key)} is larger than the half width")
        if not math.isfinite(params.p):
            raise InputError(f"p must be finite (got {params.p})")
    else:
        if params.refine > params.R / 10:
            raise InputError(f"refine = {params.refine} is too coarse for R = {params.R}")
        if params.mesh not in MESHERS:
            raise InputError(f"unknown mesh '{params.mesh}' (choose {' or '.join(MESHERS)})")
        if params.r_refine < 0:
            raise InputError(f"r_refine must be >= 0 (got {params.r_refine})")
        if not (math.isfinite(params.refine_edge) and params.refine_edge >= 0):
            raise InputError(f"refine_edge must be >= 0 (got {params.refine_edge})")


@dataclass(frozen=True)
class Scene:
    """A built scene: the distributed mesh, its tags by name, the bodies and the contact pair."""

    name: str
    params: BlockParams | HertzParams
    mesh: dolfinx.mesh.Mesh
    cell_tags: dolfinx.mesh.MeshTags
    facet_tags: dolfinx.mesh.MeshTags
    tags: dict[str, int]
    materials: tuple[Material, Material]
    pressure: float
    active: int
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def passive(self) -> int:
        """The passive (master) body number."""
        return 3 - self.active

    def params_dict(self) -> dict[str, Any]:
        """Every parameter used, defaults included."""
        return {**asdict(self.params), "active": self.active, **self.extra}


def build_scene(kind: str, params: BlockParams | HertzParams, active: int = 2,
                comm: MPI.Comm = MPI.COMM_WORLD) -> Scene:
    """Validate the parameters, mesh the scene with gmsh and load it into DOLFINx."""
    from meshes import balanced_partitioner, build_blocks, build_hertz, to_dolfinx

    if active not in (1, 2):
        raise InputError(f"active body must be 1 or 2 (got {active})")
    validate(params)
    extra: dict[str, Any] = {}
    if kind == "blocks":
        assert isinstance(params, BlockParams)
        p = params

        def build() -> None:
            build_blocks(p.l1, p.l2, p.h1, p.h2, p.size1, p.size2, p.grading1, p.grading2)

        pressure = p.p
    elif kind == "hertz" and isinstance(params, HertzParams) and params.mesh == "structured":
        # Built directly in DOLFINx: gmsh's quad mesher is too slow for millions of DOFs.
        from meshes.hertz_structured import hertz_structured_scene

        return hertz_structured_scene(params, comm, slope=params.slope, active=active)
    elif kind == "hertz":
        assert isinstance(params, HertzParams)
        exact = hertz_exact(params)
        if params.r_refine == 0.0:
            # Refine where the contact zone will be: Hertz's a, with margin for the active set.
            params = replace(params, r_refine=round(1.4 * exact["a"], 6))
        h = params

        # The edge grading targets the Hertz estimate of a, as a user would plan a mesh.
        edge = (exact["a"], h.refine_edge) if h.refine_edge > 0 else None

        def build() -> None:
            build_hertz(h.R, h.width, h.height, h.refine, h.r_refine, slope=h.slope, edge=edge)

        pressure = h.P / (2 * h.R)
        extra["hertz_exact"] = exact
    else:
        raise InputError(f"unknown scene '{kind}' (choose blocks or hertz)")
    data = to_dolfinx(comm, build, partitioner=balanced_partitioner())
    groups = {name: tag for name, (dim, tag) in data.physical_groups.items()}
    materials = (Material(params.E1, params.nu1), Material(params.E2, params.nu2))
    return Scene(kind, params, data.mesh, data.cell_tags, data.facet_tags, groups, materials,
                 pressure, active, extra)
