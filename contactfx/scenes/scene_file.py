"""Scene files: a TOML description of bodies, pairs, supports and loads next to a gmsh mesh.

Every key is checked: an unknown or misspelled one is an InputError naming it and the keys
allowed there (the keys, types and defaults: schema.py, printed in docs/reference/scene_file.md).
"""

from __future__ import annotations

import math
import os
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from mpi4py import MPI

from ..errors import InputError
from .gmsh_io import SceneParts, scene_from_parts
from .model import (
    CattaneoReference,
    ContactPair,
    Dirichlet,
    HertzContact,
    HertzReference,
    LameReference,
    Load,
    Material,
    Model,
    Obstacle,
    Pressure,
    PushoutReference,
    Reference,
    Scene,
    SpenceReference,
    Traction,
    UniformStress,
    Units,
)
from .obstacle import OBSTACLE_SHAPES, Shape
from .probe import Probe, ProbeKind
from .schema import SECTIONS, TYPE_ERRORS, allowed, required
from .steps import check_steps

# The allowed keys of each section, from the one table the reference page is generated from.
TOP_KEYS = allowed("")
SECTION_KEYS = {section: allowed(section) for section in SECTIONS if section}


def _keys(where: str, table: Any, allowed: set[str], required: set[str]) -> dict[str, Any]:
    if not isinstance(table, dict):
        raise InputError(f"{where}: {TYPE_ERRORS['table']}")
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise InputError(
            f"{where}: unknown key '{unknown[0]}' (allowed: {', '.join(sorted(allowed))})"
        )
    missing = sorted(required - set(table))
    if missing:
        raise InputError(f"{where}: missing key '{missing[0]}'")
    return table


def _section(where: str, table: Any, section: str) -> dict[str, Any]:
    """The keys of `table` checked against the schema's section (allowed and required)."""
    return _keys(where, table, allowed(section), required(section))


def _number(where: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputError(f"{where}: {TYPE_ERRORS['number']}, got {value!r}")
    if not math.isfinite(float(value)):
        raise InputError(f"{where}: expected a finite number, got {value!r}")
    return float(value)


def _string(where: str, value: Any, kind: str = "group") -> str:
    """A non-empty string; `kind` (a TYPE_ERRORS key) says what the key wanted."""
    if not isinstance(value, str) or not value:
        raise InputError(f"{where}: {TYPE_ERRORS[kind]}, got {value!r}")
    return value


def _entries(doc: dict[str, Any], key: str) -> list[Any]:
    value = doc.get(key, [])
    if isinstance(value, dict):
        return [value]
    if not isinstance(value, list):
        raise InputError(f"{key}: {TYPE_ERRORS['tables'].replace('NAME', key)}")
    return value


def _vector(where: str, value: Any) -> tuple[float, float]:
    if not (isinstance(value, list) and len(value) == 2):
        raise InputError(f"{where}: {TYPE_ERRORS['vector']}, got {value!r}")
    return (_number(where, value[0]), _number(where, value[1]))


def _obstacle(k: int, entry: Any) -> Obstacle:
    given = entry.get("shape") if isinstance(entry, dict) else None
    if not isinstance(given, str) or given not in OBSTACLE_SHAPES:
        choices = ", ".join(f"'{s}'" for s in OBSTACLE_SHAPES)
        raise InputError(f"obstacle {k}: shape must be one of {choices} (got {given!r})")
    shape = Shape(given)
    where = f"obstacle {k} ({shape})"
    takes = set(OBSTACLE_SHAPES[shape])
    e = _keys(where, entry, SECTION_KEYS["obstacle"] | takes, required("obstacle") | takes)
    name = e.get("name", f"obstacle{k}")
    if not isinstance(name, str) or not name:
        raise InputError(f"{where}: name must be a non-empty string, got {name!r}")
    values: dict[str, Any] = {}
    for key in sorted(takes):
        if key == "radius":
            values[key] = _number(f"{where}.radius", e[key])
        elif key == "points":
            if not isinstance(e[key], list):
                raise InputError(f"{where}.points: {TYPE_ERRORS['points']}")
            values[key] = tuple(_vector(f"{where}.points", p) for p in e[key])
        else:
            values[key] = _vector(f"{where}.{key}", e[key])
    if "displacement" in e:
        values["displacement"] = _vector(f"{where}.displacement", e["displacement"])
    if "mu" in e:
        values["mu"] = _friction(f"{where}.mu", e["mu"])
    return Obstacle(name, shape, _string(f"{where}.surface", e["surface"]), **values)


def _lame(where: str, entry: Any) -> LameReference:
    e = _keys(where, entry, SECTION_KEYS["reference.lame"], {"type", "a", "b", "c"})
    pair = e.get("pair", 0)
    if isinstance(pair, bool) or not isinstance(pair, int):
        raise InputError(f"{where}: pair must be an integer index into [[contact]]")
    radii = [_number(f"{where}.{key}", e[key]) for key in ("a", "b", "c")]
    delta = _number(f"{where}.delta", e["delta"]) if "delta" in e else None
    center = _vector(f"{where}.center", e["center"]) if "center" in e else (0.0, 0.0)
    a, b, c = radii
    return LameReference(a, b, c, delta=delta, pair=pair, center=center)


def _interference(where: str, value: Any) -> bool | float:
    if isinstance(value, bool):
        return value
    d = _number(where, value)
    if d <= 0:
        raise InputError(f"{where}: must be true, false or a number > 0 (got {value!r})")
    return d


def _name(where: str, e: dict[str, Any]) -> str | None:
    """A load's optional name (what a [[step]] calls it)."""
    return _string(where, e["name"]) if "name" in e else None


def _steps(
    doc: dict[str, Any], bcs: list[Dirichlet], loads: list[Load], obstacles: list[Obstacle]
) -> tuple[Mapping[str, float], ...]:
    """The [[step]] tables, checked against the loads' names (before anything is meshed)."""
    names = {x.name for x in (*bcs, *loads) if x.name is not None}
    names |= {ob.name for ob in obstacles}  # an obstacle's name names its prescribed motion
    return check_steps(_entries(doc, "step"), names)


def _friction(where: str, value: Any) -> float:
    mu = _number(where, value)
    if mu < 0:
        raise InputError(f"{where}: must be a number >= 0, 0 for frictionless (got {value!r})")
    return mu


def _material(body: str, table: Any) -> Material:
    e = _section(f"bodies.{body}", table, "bodies")
    thermal = {k: _number(f"bodies.{body}.{k}", e[k]) for k in ("alpha", "dT") if k in e}
    mat = Material(
        _number(f"bodies.{body}.E", e["E"]), _number(f"bodies.{body}.nu", e["nu"]), **thermal
    )
    mat.check(f"bodies.{body}")
    return mat


def _cattaneo(where: str, entry: Any) -> CattaneoReference:
    e = _section(where, entry, "reference.cattaneo")
    pair = e.get("pair", 0)
    if isinstance(pair, bool) or not isinstance(pair, int):
        raise InputError(f"{where}: pair: {TYPE_ERRORS['integer']} into [[contact]]")
    R = _number(f"{where}.R", e["R"])
    mu = _number(f"{where}.mu", e["mu"]) if "mu" in e else None
    if R <= 0 or (mu is not None and mu <= 0):
        raise InputError(f"{where}: R and mu must be positive")
    return CattaneoReference(pair, R, mu)


def _pushout(where: str, entry: Any) -> PushoutReference:
    e = _section(where, entry, "reference.pushout")
    pair = e.get("pair", 0)
    if isinstance(pair, bool) or not isinstance(pair, int):
        raise InputError(f"{where}: pair: {TYPE_ERRORS['integer']} into [[contact]]")
    mu = _number(f"{where}.mu", e["mu"]) if "mu" in e else None
    given = [key for key in ("a", "b", "c") if key in e]
    if given and len(given) < 3:
        missing = next(key for key in ("a", "b", "c") if key not in e)
        raise InputError(f"{where}: Lame's rings need a, b and c: missing key '{missing}'")
    rings = tuple(_number(f"{where}.{key}", e[key]) for key in given) or None
    delta = _number(f"{where}.delta", e["delta"]) if "delta" in e else None
    return PushoutReference(pair, mu, rings, delta)  # type: ignore[arg-type]


def _spence(where: str, entry: Any) -> SpenceReference:
    e = _section(where, entry, "reference.spence")
    pair = e.get("pair", 0)
    if isinstance(pair, bool) or not isinstance(pair, int):
        raise InputError(
            f"{where}: pair: {TYPE_ERRORS['integer']} into [[contact]], then [[obstacle]]"
        )
    symmetric = e.get("symmetric", False)
    if not isinstance(symmetric, bool):
        raise InputError(f"{where}: symmetric: {TYPE_ERRORS['bool']}")
    mu = _number(f"{where}.mu", e["mu"]) if "mu" in e else None
    if mu is not None and mu <= 0:
        raise InputError(f"{where}: mu must be positive (got {mu:g})")
    return SpenceReference(pair, symmetric, mu)


def _reference(k: int, entry: Any, model: Model | None = None) -> Reference:
    kind = entry.get("type") if isinstance(entry, dict) else None
    if kind not in ("hertz", "uniform_stress", "lame", "cattaneo", "pushout", "spence"):
        raise InputError(
            f"reference {k}: type must be 'hertz', 'uniform_stress', 'lame', 'cattaneo', "
            f"'pushout' or 'spence' (got {kind!r})"
        )
    where = f"reference {k} ({kind})"
    if kind == "lame":
        return _lame(where, entry)
    if kind == "cattaneo":
        return _cattaneo(where, entry)
    if kind == "pushout":
        return _pushout(where, entry)
    if kind == "spence":
        return _spence(where, entry)
    if kind == "hertz":
        e = _section(where, entry, "reference.hertz")
        pair = e.get("pair", 0)
        if isinstance(pair, bool) or not isinstance(pair, int):
            raise InputError(
                f"{where}: pair: {TYPE_ERRORS['integer']} into [[contact]], then [[obstacle]]"
            )
        # An omitted `symmetric` takes the dataclass's default: one default for both APIs.
        flags = {"symmetric": e["symmetric"]} if "symmetric" in e else {}
        if not all(isinstance(v, bool) for v in flags.values()):
            raise InputError(f"{where}: symmetric: {TYPE_ERRORS['bool']}")
        # Without P (a displacement-controlled scene) the pair's computed force is the load.
        R = _number(f"{where}.R", e["R"])
        P = _number(f"{where}.P", e["P"]) if "P" in e else None
        if R <= 0 or (P is not None and P <= 0):
            raise InputError(f"{where}: R and P must be positive")
        contact = e.get("contact")
        if contact is not None and contact not in tuple(HertzContact):
            raise InputError(f'{where}: contact must be "line" or "point" (got {contact!r})')
        ref = HertzReference(pair, R, P, **flags, contact=contact)
        if model is not None:
            ref.contact_in(model)  # a point contact needs the axisymmetric model
        return ref
    e = _section(where, entry, "reference.uniform_stress")
    s = e["sigma"]
    if not (
        isinstance(s, list) and len(s) == 2 and all(isinstance(r, list) and len(r) == 2 for r in s)
    ):
        raise InputError(f"{where}: {TYPE_ERRORS['tensor']}")
    sig = tuple(tuple(_number(f"{where}.sigma", v) for v in row) for row in s)
    if sig[0][1] != sig[1][0]:
        raise InputError(f"{where}: sigma must be symmetric")
    return UniformStress(sig)  # type: ignore[arg-type]


def _probe(k: int, entry: Any) -> Probe:
    """A `[[probe]]` table: a value read off one pair (model.Probe)."""
    kind = entry.get("type") if isinstance(entry, dict) else None
    if kind not in tuple(ProbeKind):
        choices = ", ".join(f"'{p.value}'" for p in ProbeKind)
        raise InputError(f"probe {k}: type must be one of {choices} (got {kind!r})")
    where = f"probe {k} ({kind})"
    e = _section(where, entry, "probe")
    pair = e.get("pair", 0)
    if isinstance(pair, bool) or not isinstance(pair, int):
        raise InputError(
            f"{where}: pair: {TYPE_ERRORS['integer']} into [[contact]], then [[obstacle]]"
        )
    points = {key: _vector(f"{where}.{key}", e[key]) for key in ("at", "start", "end") if key in e}
    name = _string(f"{where}.name", e["name"]) if "name" in e else ""
    side = _string(f"{where}.side", e.get("side", "active"))
    return Probe(ProbeKind(kind), pair, side=side, name=name, **points)


def _units(table: Any) -> Units:
    """The `units` table: the names of the length and stress units (labels for pictures)."""
    e = _keys("units", table, {"length", "stress"}, set())
    return Units(**{k: _string(f"units.{k}", v, "unit") for k, v in e.items()})


def parse_scene_file(path: Path) -> tuple[Path, SceneParts]:
    """Read and check a scene file; return the mesh path and the scene's parts."""
    try:
        doc = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise InputError(f"scene file {path} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read scene file {path}: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"scene file {path} is not valid TOML: {exc}") from None
    _section(str(path.name), doc, "")
    if "contact" not in doc and "obstacle" not in doc:
        raise InputError(f"{path.name}: missing key 'contact' (or 'obstacle')")
    # Relative to the file; `..` collapsed (the demo scenes name ../../meshes/*.geo).
    mesh = Path(os.path.normpath(path.parent / _string("mesh", doc["mesh"], "path")))
    name = _string("name", doc.get("name", path.stem), "name")
    model = Model.parse(_string("model", doc.get("model", Model.PLANE_STRAIN.value), "model"))
    units = _units(doc.get("units", {}))
    if not isinstance(doc["bodies"], dict) or not doc["bodies"]:
        raise InputError("bodies: expected [bodies.NAME] tables with E and nu")
    bodies = {}
    for body, table in doc["bodies"].items():
        bodies[body] = _material(body, table)
    pairs = []
    for k, entry in enumerate(_entries(doc, "contact")):
        e = _section(f"contact {k}", entry, "contact")
        fit = _interference(f"contact {k}.interference", e.get("interference", False))
        pairs.append(
            ContactPair(
                _string(f"contact {k}.active", e["active"]),
                _string(f"contact {k}.passive", e["passive"]),
                fit,
                _friction(f"contact {k}.mu", e.get("mu", 0.0)),
            )
        )
    bcs = []
    for k, entry in enumerate(_entries(doc, "dirichlet")):
        e = _section(f"dirichlet {k}", entry, "dirichlet")
        comps = {c: _number(f"dirichlet {k}.{c}", e[c]) for c in ("ux", "uy") if c in e}
        if not comps:
            raise InputError(f"dirichlet {k} on '{e['group']}': give ux and/or uy")
        bcs.append(
            Dirichlet(
                _string(f"dirichlet {k}.group", e["group"]),
                **comps,
                name=_name(f"dirichlet {k}.name", e),
            )
        )
    loads: list[Load] = []
    for k, entry in enumerate(_entries(doc, "pressure")):
        e = _section(f"pressure {k}", entry, "pressure")
        loads.append(
            Pressure(
                _string(f"pressure {k}.group", e["group"]),
                _number(f"pressure {k}.p", e["p"]),
                _name(f"pressure {k}.name", e),
            )
        )
    for k, entry in enumerate(_entries(doc, "traction")):
        e = _section(f"traction {k}", entry, "traction")
        t = e["t"]
        if not (isinstance(t, list) and len(t) == 2):
            raise InputError(f"traction {k}.t: {TYPE_ERRORS['vector']}, got {t!r}")
        loads.append(
            Traction(
                _string(f"traction {k}.group", e["group"]),
                (_number(f"traction {k}.t", t[0]), _number(f"traction {k}.t", t[1])),
                _name(f"traction {k}.name", e),
            )
        )
    refs = [_reference(k, e, model) for k, e in enumerate(_entries(doc, "reference"))]
    probes = [_probe(k, e) for k, e in enumerate(_entries(doc, "probe"))]
    obstacles = [_obstacle(k, e) for k, e in enumerate(_entries(doc, "obstacle"))]
    parts = SceneParts(
        bodies,
        tuple(pairs),
        tuple(bcs),
        tuple(loads),
        tuple(refs),
        name,
        tuple(obstacles),
        model,
        units,
        tuple(probes),
        _steps(doc, bcs, loads, obstacles),
    )
    return mesh, parts


def load_scene_file(
    path: str | Path, comm: MPI.Comm = MPI.COMM_WORLD, size_factor: float = 1.0
) -> Scene:
    """The Scene of a TOML scene file (mesh path relative to the file)."""
    path = Path(path)
    mesh, parts = parse_scene_file(path)
    return scene_from_parts(mesh, parts, comm, size_factor, {"scene_file": str(path)})
