"""Checks of a Scene against its mesh: groups exist with the right dimension, pairs join bodies.

All checks are collective and raise the same typed error on every rank.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from mpi4py import MPI

from ..errors import InputError, MeshError
from .model import (
    Body,
    CattaneoReference,
    HertzReference,
    LameReference,
    Model,
    PushoutReference,
    Scene,
    SpenceReference,
)
from .obstacle import Shape
from .steps import check_steps, load_names


def _global_count(scene: Scene, local: int) -> int:
    return int(scene.comm.allreduce(int(local)))


def body_of_curve(scene: Scene, name: str) -> Body:
    """The one body whose cells carry the facets of curve group `name`."""
    msh = scene.mesh
    tdim = msh.topology.dim
    tag = scene.curve_tag(name, f"curve group '{name}'")
    if scene.facet_tags is None:
        raise MeshError(f"the mesh has no curve groups (needed: '{name}')")
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets = scene.facet_tags.find(tag)
    f2c = msh.topology.connectivity(tdim - 1, tdim)
    cells = f2c.array[f2c.offsets[facets]] if facets.size else np.zeros(0, np.int32)
    cell_values = np.full(
        msh.topology.index_map(tdim).size_local + msh.topology.index_map(tdim).num_ghosts,
        -1,
        dtype=np.int64,
    )
    cell_values[scene.cell_tags.indices] = scene.cell_tags.values
    local = set(np.unique(cell_values[cells]).tolist())
    found = set().union(*scene.comm.allgather(local))
    names = [b for b in scene.bodies if scene.body_tag(b) in found]
    if not names:
        raise MeshError(f"curve group '{name}' has no facet on the boundary of any body")
    if len(names) > 1:
        raise MeshError(
            f"curve group '{name}' lies on several bodies "
            f"({', '.join(b.name for b in names)}): give one group per body"
        )
    return names[0]


def _check_bodies(scene: Scene) -> None:
    if len(scene.bodies) < (1 if scene.obstacles else 2):
        raise InputError(
            f"a contact scene needs at least two bodies, or one and an [[obstacle]] "
            f"(got {len(scene.bodies)} bodies)"
        )
    known = set()
    for body in scene.bodies:
        tag = scene.body_tag(body)
        known.add(tag)
        if _global_count(scene, len(scene.cell_tags.find(tag))) == 0:
            raise MeshError(f"body '{body.name}': its physical surface group has no cells")
    surfaces = {n: t for n, (d, t) in scene.groups.by_name.items() if d == 2}
    extra = [n for n, t in surfaces.items() if t not in known]
    if extra:
        raise InputError(
            f"physical surface group '{extra[0]}' is not a body of the scene: "
            f"give it a material ([bodies.{extra[0]}] with E and nu)"
        )


def _check_pairs(scene: Scene) -> dict[str, str]:
    """Check every pair joins two bodies; return each contact curve's body name."""
    if not scene.contacts and not scene.obstacles:
        raise InputError("the scene has no contact pair (add a [[contact]] or [[obstacle]] entry)")
    found: dict[str, str] = {}
    for k, pair in enumerate(scene.contacts):
        for curve in (pair.active, pair.passive):
            if curve not in found:
                found[curve] = body_of_curve(scene, curve).name
        if found[pair.active] == found[pair.passive]:
            raise InputError(
                f"contact pair {k}: '{pair.active}' and '{pair.passive}' lie on "
                f"the same body '{found[pair.active]}' (self-contact is not supported)"
            )
    return found


def _check_obstacles(scene: Scene, known: dict[str, str]) -> dict[str, str]:
    """Check every obstacle's surface is a curve of one body; return those curves' bodies."""
    found: dict[str, str] = {}
    names: set[str] = set()
    for k, obstacle in enumerate(scene.obstacles):
        where = f"obstacle {k} ('{obstacle.name}')"
        if obstacle.name in names:
            raise InputError(f"{where}: two obstacles are called '{obstacle.name}'")
        if obstacle.name in scene.groups.by_name:
            raise InputError(
                f"{where}: '{obstacle.name}' is also a physical group of the mesh: "
                "give the obstacle another name"
            )
        names.add(obstacle.name)
        scene.curve_tag(obstacle.surface, f"{where}: surface")
        if obstacle.surface not in known and obstacle.surface not in found:
            found[obstacle.surface] = body_of_curve(scene, obstacle.surface).name
    return found


def _check_lame(scene: Scene, ref: LameReference) -> None:
    if not 0 <= ref.pair < len(scene.contacts):
        raise InputError(
            f"lame reference: pair {ref.pair} is not one of the {len(scene.contacts)} "
            "[[contact]] pairs (a shrink fit joins two bodies)"
        )
    if ref.delta is None and not scene.contacts[ref.pair].prescribed_overlap:
        raise InputError(
            f"lame reference: give delta (pair {ref.pair} has no interference = D to take it from)"
        )


def _check_conditions(scene: Scene) -> None:
    for bc in scene.dirichlet:
        if bc.group not in scene.groups.by_name:
            scene.curve_tag(bc.group, "dirichlet")  # raises, listing the groups
        dim = scene.groups.by_name[bc.group][0]
        if dim not in (0, 1):
            raise MeshError(f"dirichlet: group '{bc.group}' must be a curve or point group")
        if not bc.components():
            raise InputError(f"dirichlet on '{bc.group}': give ux and/or uy")
        for c, v in bc.components():
            if not math.isfinite(v):
                raise InputError(f"dirichlet on '{bc.group}': {'xy'[c]} value must be finite")
    for load in scene.loads:
        scene.curve_tag(load.group, "load")
        values = [load.p] if hasattr(load, "p") else list(load.t)
        if not all(math.isfinite(float(v)) for v in values):
            raise InputError(f"load on '{load.group}': values must be finite")
        stiffest = max(b.material.E for b in scene.bodies)
        if max(abs(float(v)) for v in values) > stiffest:
            # The stiffest body strained beyond 100 %: units, not a load (1e300 overflowed
            # the solve into a DIVERGED_NANORINF that named no load).
            key = "p" if hasattr(load, "p") else "t"
            raise InputError(
                f"load on '{load.group}': {key} = {_text(values)} exceeds the largest Young's "
                f"modulus of the bodies ({stiffest:g}), a strain beyond 100 % (contactfx is "
                "a small-strain code): check its units"
            )
    for ref in [*scene.references, *scene.probes]:
        pair = getattr(ref, "pair", 0)
        if isinstance(ref, LameReference):
            _check_lame(scene, ref)
        if isinstance(ref, HertzReference):
            ref.contact_in(scene.model)
        if isinstance(ref, CattaneoReference):
            _check_cattaneo(scene, ref)
        if isinstance(ref, PushoutReference):
            _check_pushout(scene, ref)
        if isinstance(ref, SpenceReference):
            _check_spence(scene, ref)
        if not 0 <= pair < len(scene.contacts) + len(scene.obstacles):
            what = "probe" if ref in scene.probes else "reference"
            raise InputError(
                f"{what}: pair {pair} does not exist (the scene has "
                f"{len(scene.contacts)} contact pairs and {len(scene.obstacles)} obstacles)"
            )


def _check_cattaneo(scene: Scene, ref: CattaneoReference) -> None:
    """InputError for a Cattaneo reference the scene cannot be checked against."""
    where = f"cattaneo reference (pair {ref.pair})"
    if not (ref.R > 0 and (ref.mu is None or ref.mu > 0)):
        raise InputError(f"{where}: R and mu must be positive (got R = {ref.R}, mu = {ref.mu})")
    if not 0 <= ref.pair < len(scene.contacts):
        raise InputError(
            f"{where}: pair {ref.pair} is not one of the {len(scene.contacts)} contact pairs "
            "(Cattaneo-Mindlin is two elastic bodies)"
        )
    if scene.contacts[ref.pair].mu <= 0:
        raise InputError(f"{where}: the pair is frictionless: give it mu > 0 in its [[contact]]")
    if scene.model is Model.AXISYMMETRIC:
        raise InputError(
            f"{where}: a line contact of a plane model only (the axisymmetric sphere's "
            "Cattaneo-Mindlin check is not implemented): use plane_strain or plane_stress"
        )


def _check_pushout(scene: Scene, ref: PushoutReference) -> None:
    """InputError for a push-out reference the scene cannot be checked against."""
    where = f"pushout reference (pair {ref.pair})"
    if not 0 <= ref.pair < len(scene.contacts):
        raise InputError(
            f"{where}: pair {ref.pair} is not one of the {len(scene.contacts)} contact pairs "
            "(a push-out is a shaft and a hub)"
        )
    if scene.contacts[ref.pair].mu <= 0:
        raise InputError(f"{where}: the pair is frictionless: give it mu > 0 in its [[contact]]")
    if scene.model is not Model.AXISYMMETRIC:
        raise InputError(
            f"{where}: a shaft pushed out of a hub is an axisymmetric scene (its axial force "
            f"against mu times the revolved normal force): set model = 'axisymmetric'"
        )
    if len(scene.steps) < 2:
        raise InputError(
            f"{where}: give [[step]] tables, the fit first and then the push (the scene has "
            f"{len(scene.steps)}): friction depends on the load path"
        )
    pair = scene.contacts[ref.pair]
    if ref.rings is not None and ref.delta is None and not pair.prescribed_overlap > 0:
        raise InputError(
            f"{where}: give delta for Lame's rings (the pair has no interference = D to take "
            "it from)"
        )


def _check_spence(scene: Scene, ref: SpenceReference) -> None:
    """InputError for a Spence reference the scene cannot be checked against."""
    where = f"spence reference (pair {ref.pair})"
    n = len(scene.contacts)
    if not n <= ref.pair < n + len(scene.obstacles):
        raise InputError(
            f"{where}: pair {ref.pair} is not one of the {len(scene.obstacles)} obstacles "
            f"(pairs {n} to {n + len(scene.obstacles) - 1}; Spence is a rigid cylinder)"
        )
    ob = scene.obstacles[ref.pair - n]
    if ob.shape is not Shape.CIRCLE:
        raise InputError(
            f"{where}: obstacle '{ob.name}' is a {ob.shape.value}; Spence's indenter is a "
            "cylinder: give it shape = 'circle'"
        )
    mu = ob.mu if ref.mu is None else ref.mu
    if not (ob.mu > 0 and mu > 0):
        raise InputError(
            f"{where}: obstacle '{ob.name}' is frictionless: give it mu > 0 in its [[obstacle]]"
        )
    if scene.model is not Model.PLANE_STRAIN:
        raise InputError(
            f"{where}: Spence's stick ratio is a plane-strain half-plane's; the scene's model "
            f"is {scene.model.value}: use plane_strain"
        )


def _text(values: list[float]) -> str:
    return f"{values[0]:g}" if len(values) == 1 else "[" + ", ".join(f"{v:g}" for v in values) + "]"


# The largest prescribed overlap relative to the model's size: the strain it makes is about
# that ratio, and contactfx is a small-strain code (the thermal strain's bound too: fits.py).
OVERLAP_MAX = 0.1


def _check_overlaps(scene: Scene) -> None:
    """InputError for an `interference = D` beyond OVERLAP_MAX of the model's extent."""
    given = [(k, p) for k, p in enumerate(scene.contacts) if p.prescribed_overlap > 0]
    if not given:
        return
    x = scene.mesh.geometry.x[:, :2]
    comm = scene.comm
    # Buffers, not pickled objects: a pickled MIN compares two arrays as one truth value.
    lo, hi = x.min(axis=0, initial=np.inf), x.max(axis=0, initial=-np.inf)
    comm.Allreduce(MPI.IN_PLACE, lo, op=MPI.MIN)
    comm.Allreduce(MPI.IN_PLACE, hi, op=MPI.MAX)
    extent = float(np.max(hi - lo))
    for k, pair in given:
        d = pair.prescribed_overlap
        if d > OVERLAP_MAX * extent:
            raise InputError(
                f"contact {k} ('{pair.active}' on '{pair.passive}'): interference = {d:g} is "
                f"more than {OVERLAP_MAX:g} of the model's size {extent:g} (a strain far "
                "beyond small strain): check its units"
            )


def _check_axis(scene: Scene) -> None:
    """Axisymmetric: x is the radius; a cell with a node at x < 0 (beyond round-off) is refused."""
    if scene.model is not Model.AXISYMMETRIC:
        return
    x = scene.mesh.geometry.x[:, :2]
    comm = scene.comm
    lo = comm.allreduce(float(x[:, 0].min(initial=np.inf)), op=MPI.MIN)
    extent = comm.allreduce(float(np.abs(x).max(initial=0.0)), op=MPI.MAX)
    if lo < -1e-9 * extent:
        raise InputError(
            f"model axisymmetric: x is the radius, but the mesh has a cell at x = {lo:.4g} < 0 "
            "(put the axis at x = 0 and the bodies on its right)"
        )


def check_scene(scene: Scene) -> Scene:
    """The scene with its contact curves' bodies found, once checked against its mesh.

    Raises InputError/MeshError naming the first inconsistency between scene and mesh.
    """
    for body in scene.bodies:
        body.material.check(f"body '{body.name}'")
    _check_bodies(scene)
    _check_axis(scene)
    curve_bodies = _check_pairs(scene)
    curve_bodies.update(_check_obstacles(scene, curve_bodies))
    _check_conditions(scene)
    _check_overlaps(scene)
    steps = check_steps(scene.steps, load_names(scene))
    return replace(scene, curve_bodies=curve_bodies, steps=steps)
