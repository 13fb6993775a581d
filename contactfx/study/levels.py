"""Refinement levels of a scene: level k has every mesh size of the scene times f_k.

f_k = size_factor / ratio**k: level 0 is the scene as given (times --size-factor), each
further level refines the whole mesh by `ratio`. What "the whole mesh" means per scene:
- built-in Hertz: the contact size, the edge size and the far size with f, the grading slope
  with sqrt(f) (demo_hertz.py's graded(h_edge): the 2D field decays like 1/r, so the slope
  sets the bulk's share of the error like s^2 while h_e sets the edge's like h_e; refining
  both so keeps them balanced). Refining the contact sizes only plateaus near 0.3 % L2.
- built-in blocks: both element sizes with f, each grading ratio g with g**f (the same size
  profile along x with 1/f times the elements).
- a scene file: gmsh's Mesh.MeshSizeFactor = f on its .geo (a .msh cannot be remeshed).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path

from mpi4py import MPI

from ..errors import InputError
from ..scenes import BlockParams, HertzParams, Scene, build_scene, load_scene_file, validate

# Coarsest grading slope that coarsening applies (demo_hertz.py's graded() caps it there:
# steeper gradings make poorly shaped quads around the contact zone).
SLOPE_CAP = 0.3


@dataclass(frozen=True)
class Level:
    """One refinement level: its size factor, the sizes it uses, and how to mesh it."""

    index: int
    factor: float
    sizes: dict[str, float]
    build: Callable[[], Scene] = field(compare=False, repr=False)
    # The paper's x-sorted `interface` block in the summaries (built-in scenes).
    paper_interface: bool = False


def size_factors(levels: int, ratio: float, size_factor: float = 1.0) -> list[float]:
    """Mesh-size factors of the levels, coarsest first: size_factor / ratio**k."""
    if levels < 2:
        raise InputError(f"a study needs at least 2 levels (got --levels {levels})")
    if not (math.isfinite(ratio) and ratio > 1.0):
        raise InputError(f"--ratio must be a number > 1 (got {ratio})")
    if not (math.isfinite(size_factor) and size_factor > 0.0):
        raise InputError(f"--size-factor must be a positive number (got {size_factor})")
    return [size_factor / ratio**k for k in range(levels)]


def hertz_at(params: HertzParams, f: float) -> HertzParams:
    """The Hertz mesh with sizes times f and the slope times sqrt(f) (capped when coarsening)."""
    slope = params.slope * math.sqrt(f)
    if f > 1.0:
        slope = min(slope, max(SLOPE_CAP, params.slope))
    # h_far None means R / 6, a cap that the slope leaves inactive; a given far size is a
    # bulk size like the slope's and follows it.
    return replace(
        params,
        refine=params.refine * f,
        refine_edge=params.refine_edge * f,
        slope=slope,
        h_far=None if params.h_far is None else params.h_far * math.sqrt(f),
    )


def blocks_at(params: BlockParams, f: float) -> BlockParams:
    """The block meshes with sizes times f and gradings g**f (same profile, 1/f the elements)."""
    return replace(
        params,
        size1=params.size1 * f,
        size2=params.size2 * f,
        grading1=params.grading1**f,
        grading2=params.grading2**f,
    )


def builtin_sizes(params: HertzParams | BlockParams) -> dict[str, float]:
    """The sizes a built-in scene's level uses, for the report."""
    if isinstance(params, HertzParams):
        keys = ["refine", "refine_edge", "slope"] + (["h_far"] if params.h_far else [])
    else:
        keys = ["size1", "size2", "grading1", "grading2"]
    return {k: float(getattr(params, k)) for k in keys}


def builtin_levels(
    kind: str,
    params: HertzParams | BlockParams,
    factors: list[float],
    active: int = 2,
    comm: MPI.Comm = MPI.COMM_WORLD,
) -> list[Level]:
    """Levels of a built-in scene ("hertz" or "blocks") from its parameters (factor 1)."""
    # Bad input is the user's, reported before anything runs; a level that its factor
    # makes too coarse fails on its own and the study goes on.
    validate(params)
    at = hertz_at if isinstance(params, HertzParams) else blocks_at
    out = []
    for k, f in enumerate(factors):
        p = at(params, f)  # type: ignore[arg-type]
        out.append(
            Level(
                k,
                f,
                builtin_sizes(p),
                partial(build_scene, kind, p, active=active, comm=comm),
                paper_interface=True,
            )
        )
    return out


def check_refinable(path: Path) -> None:
    """InputError unless the scene file's mesh is a .geo that gmsh can remesh."""
    from ..scenes.scene_file import parse_scene_file

    mesh = parse_scene_file(path)[0]
    if mesh.suffix.lower() != ".geo":
        raise InputError(
            f"scene {path.name}: its mesh {mesh.name} is a {mesh.suffix} file, "
            "which cannot be refined; a study needs a .geo mesh (gmsh remeshes "
            "it at every level)"
        )


def scene_file_levels(
    path: Path, factors: list[float], comm: MPI.Comm = MPI.COMM_WORLD
) -> list[Level]:
    """Levels of a scene file whose mesh is a .geo: gmsh's MeshSizeFactor per level."""
    check_refinable(path)
    return [
        Level(k, f, {"size_factor": f}, partial(load_scene_file, path, comm, size_factor=f))
        for k, f in enumerate(factors)
    ]
