"""Scenes as data: the generic Scene, scene files, and the built-in scenes of the paper."""

from .builtin import (
    BLOCK_SCENES,
    MESHERS,
    BlockParams,
    HertzParams,
    blocks,
    build_scene,
    hertz,
    hertz_exact,
    validate,
)
from .model import (
    Body,
    ContactPair,
    Dirichlet,
    Groups,
    HertzReference,
    Load,
    Material,
    Pressure,
    Reference,
    Scene,
    Traction,
    UniformStress,
)
from .scene_file import load_scene_file

__all__ = [
    "BLOCK_SCENES",
    "MESHERS",
    "BlockParams",
    "Body",
    "ContactPair",
    "Dirichlet",
    "Groups",
    "HertzParams",
    "HertzReference",
    "Load",
    "Material",
    "Pressure",
    "Reference",
    "Scene",
    "Traction",
    "UniformStress",
    "blocks",
    "build_scene",
    "hertz",
    "hertz_exact",
    "load_scene_file",
    "validate",
]
