"""The scene file's keys in one table: the parser checks a file against it, the docs print it.

Each section (the top level, `[bodies.NAME]`, each `[[...]]` array, each reference type)
lists its keys with a type, a default (None: the key is required) and what else is refused.
`scene_file.py` takes the allowed and the required keys from here, and the scene-file
reference page (`reference_markdown`, docs/reference/scene_file.md) is generated from the
same table, so a key added here is checked and documented at once.
"""

from __future__ import annotations

from dataclasses import dataclass

from .model import Model
from .obstacle import OBSTACLE_SHAPES


@dataclass(frozen=True)
class Key:
    """One key of a scene-file section.

    Attributes:
        name: the key as written in the file.
        type: one of TYPE_ERRORS' names (how the value is read).
        default: the value an omitted key takes, as text; None when the key is required.
        meaning: what the key gives.
        refused: what is refused beyond a wrong type ("" when the type is all).
    """

    name: str
    type: str
    default: str | None
    meaning: str
    refused: str = ""


# The message after "WHERE: " when a value has the wrong type (scene_file.py raises these).
TYPE_ERRORS = {
    "number": "expected a number",
    "integer": "expected an integer index",
    "string": "expected a string",
    "group": "expected a group name (a string)",
    "path": "expected a mesh file path (a string)",
    "name": "expected a name (a string)",
    "model": "expected one of {models} (a string)",
    "unit": "expected a unit name (a string)",
    "bool": "expected true or false",
    "bool or number": "expected true, false or a number > 0",
    "vector": "expected a vector [x, y]",
    "points": "expected a list of points [[x, y], ...]",
    "tensor": "sigma must be [[sxx, sxy], [syx, syy]]",
    "table": "expected a table of keys",
    "tables": "expected one or more [[NAME]] tables",
}

_GROUP = "group"
_MODELS = ", ".join(m.value for m in Model)
TYPE_ERRORS["model"] = TYPE_ERRORS["model"].format(models=_MODELS)

SECTIONS: dict[str, tuple[Key, ...]] = {
    "": (
        Key("mesh", "path", None, "gmsh .msh, or .geo (meshed in 2D), relative to the file"),
        Key("name", "name", "the file name", "label of the scene in the JSON"),
        Key("model", "model", Model.PLANE_STRAIN.value, f"the 2D model: {_MODELS}"),
        Key(
            "units",
            "table",
            '{length = "length", stress = "stress"}',
            "names of the length and stress units, for the pictures' axes (nothing converts)",
        ),
        Key("bodies", "table", None, "one [bodies.NAME] table per body", "no body"),
        Key("contact", "tables", "none", "contact pairs", "neither contact nor obstacle"),
        Key("obstacle", "tables", "none", "rigid obstacles", "neither contact nor obstacle"),
        Key("dirichlet", "tables", "none", "prescribed displacement components"),
        Key("pressure", "tables", "none", "normal pressures on curve groups"),
        Key("traction", "tables", "none", "traction vectors on curve groups"),
        Key("reference", "tables", "none", "analytic references the run is checked against"),
        Key("probe", "tables", "none", "values read off a pair: printed and in the JSON"),
        Key(
            "step",
            "tables",
            "one step, every load in full",
            "load steps in order, each NAME = factor on named loads (a named load keeps its "
            "last factor, 0 before its first; a load without a name acts in full)",
            "an unknown load name; a factor that is not a number",
        ),
    ),
    "bodies": (
        Key("E", "number", None, "Young's modulus", "E <= 0"),
        Key("nu", "number", None, "Poisson ratio", "nu outside (-1, 0.5)"),
        Key("alpha", "number", "none", "thermal expansion coefficient", "alpha without dT"),
        Key("dT", "number", "none", "uniform temperature change", "dT without alpha"),
    ),
    "contact": (
        Key("active", _GROUP, None, "curve group on the active (slave) body: the multipliers"),
        Key("passive", _GROUP, None, "curve group on the passive (master) body"),
        Key(
            "interference",
            "bool or number",
            "false",
            "true: a fit drawn overlapping; D > 0: an overlap D prescribed along the normal",
            "true on bodies that do not overlap; D <= 0",
        ),
        Key(
            "mu",
            "number",
            "0",
            "Coulomb friction coefficient (0: frictionless)",
            "mu < 0; mu > 0 with sts, penalty, schwarz, fieldsplit, condensed but not dual mortar",
        ),
    ),
    "dirichlet": (
        Key("group", _GROUP, None, "curve or point group"),
        Key("ux", "number", "free", "prescribed x displacement", "neither ux nor uy"),
        Key("uy", "number", "free", "prescribed y displacement", "neither ux nor uy"),
        Key("name", "string", "none", "what a [[step]] calls it (its factor there)"),
    ),
    "pressure": (
        Key("group", _GROUP, None, "curve group"),
        Key("p", "number", None, "normal pressure, positive pushing into the body"),
        Key("name", "string", "none", "what a [[step]] calls it (its factor there)"),
    ),
    "traction": (
        Key("group", _GROUP, None, "curve group"),
        Key("t", "vector", None, "traction vector [tx, ty], force per unit length"),
        Key("name", "string", "none", "what a [[step]] calls it (its factor there)"),
    ),
    "reference.hertz": (
        Key(
            "type",
            "string",
            None,
            '"hertz": Hertz on one pair (a line contact in a plane model, a sphere in an '
            "axisymmetric one)",
        ),
        Key("pair", "integer", "0", "index into [[contact]], then the [[obstacle]]s"),
        Key("R", "number", None, "effective radius, 1/R = 1/R1 + 1/R2", "R <= 0"),
        Key("P", "number", "the pair's force", "line load of the full contact", "P <= 0"),
        Key(
            "symmetric",
            "bool",
            "false",
            "a half model cut through the contact centre (a sphere's is the axis: either)",
            "with a ring's line contact",
        ),
        Key(
            "contact",
            "string",
            "the model's",
            '"line" (a cylinder; axisymmetric: a ring, P over 2 pi r_c) or "point" (a sphere)',
            '"point" in a plane model',
        ),
    ),
    "reference.cattaneo": (
        Key(
            "type",
            "string",
            None,
            '"cattaneo": Cattaneo-Mindlin on one frictional pair (a plane line contact)',
        ),
        Key("pair", "integer", "0", "index into [[contact]]", "a frictionless pair"),
        Key("R", "number", None, "effective radius, 1/R = 1/R1 + 1/R2", "R <= 0"),
        Key("mu", "number", "the pair's mu", "friction coefficient", "mu <= 0"),
    ),
    "reference.pushout": (
        Key(
            "type",
            "string",
            None,
            '"pushout": a press fit pushed out (axisymmetric): axial force against mu N',
        ),
        Key("pair", "integer", "0", "index into [[contact]]", "a frictionless pair"),
        Key("mu", "number", "the pair's mu", "friction coefficient", "mu <= 0"),
        Key("a", "number", "none", "Lame's rings for the fit (step 1): the inner bore"),
        Key("b", "number", "none", "the interface radius (with a and c)"),
        Key("c", "number", "none", "the outer radius of the outer ring (with a and b)"),
        Key("delta", "number", "the pair's interference D", "radial interference", "delta <= 0"),
    ),
    "reference.spence": (
        Key(
            "type",
            "string",
            None,
            '"spence": Spence\'s stick ratio c/a under a rigid circle obstacle pressed with '
            "friction (plane strain)",
        ),
        Key(
            "pair",
            "integer",
            "0",
            "index into [[contact]], then [[obstacle]]",
            "a pair that is not a frictional circle obstacle",
        ),
        Key("symmetric", "bool", "false", "a half model cut through the contact centre"),
        Key("mu", "number", "the obstacle's mu", "friction coefficient", "mu <= 0"),
    ),
    "reference.lame": (
        Key("type", "string", None, '"lame": a shrink fit of two concentric rings'),
        Key("pair", "integer", "0", "index into [[contact]]"),
        Key("a", "number", None, "inner radius of the inner ring"),
        Key("b", "number", None, "the interface radius"),
        Key("c", "number", None, "outer radius of the outer ring"),
        Key("delta", "number", "the pair's interference D", "radial interference"),
        Key("center", "vector", "[0, 0]", "the rings' centre"),
    ),
    "probe": (
        Key("type", "string", None, '"pressure", "mean_pressure" or "peak_sigma_nn"'),
        Key("pair", "integer", "0", "index into [[contact]], then the [[obstacle]]s"),
        Key("name", "string", "its type and pair", "label in the terminal and the JSON"),
        Key("at", "vector", "none", "pressure: the surface point nearest [x, y]", "elsewhere"),
        Key("start", "vector", "none", "mean_pressure, peak_sigma_nn: the window's first end"),
        Key("end", "vector", "none", "mean_pressure, peak_sigma_nn: the window's other end"),
        Key("side", "string", '"active"', "peak_sigma_nn: whose FE stress", "not active/passive"),
    ),
    "reference.uniform_stress": (
        Key("type", "string", None, '"uniform_stress": a patch test'),
        Key("sigma", "tensor", None, "the stress exact in every body", "an unsymmetric sigma"),
    ),
    "obstacle": (
        Key("name", "name", "obstacleK", "label in the JSON and the output files"),
        Key("shape", "string", None, f"one of {', '.join(OBSTACLE_SHAPES)}", "another shape"),
        Key("surface", _GROUP, None, "the body's curve group that may touch it"),
        Key("displacement", "vector", "[0, 0]", "prescribed rigid motion (`name` in [[step]])"),
        Key("mu", "number", "0", "Coulomb friction coefficient (0: frictionless)", "mu < 0"),
    ),
}

# The keys of each obstacle shape (which shape takes which: model.OBSTACLE_SHAPES).
SHAPE_KEYS: dict[str, Key] = {
    "center": Key("center", "vector", None, "circle centre (the body lies outside)"),
    "radius": Key("radius", "number", None, "circle radius", "radius <= 0"),
    "point": Key("point", "vector", None, "a point of the plane"),
    "normal": Key("normal", "vector", None, "from the obstacle towards the body", "zero"),
    "points": Key(
        "points",
        "points",
        None,
        "in order, obstacle on the left; closed if the last repeats the first",
        "repeated points, a fold-back, a self-crossing",
    ),
}


def allowed(section: str) -> set[str]:
    """The keys a section accepts."""
    return {k.name for k in SECTIONS[section]}


def required(section: str) -> set[str]:
    """The keys a section needs (those without a default)."""
    return {k.name for k in SECTIONS[section] if k.default is None}


def _heading(section: str) -> str:
    if section == "":
        return "Top level"
    if section == "bodies":
        return "`[bodies.NAME]`"
    if section.startswith("reference."):
        return f'`[[reference]]` with `type = "{section.split(".", 1)[1]}"`'
    return f"`[[{section}]]`"


def _rows(keys: tuple[Key, ...] | list[Key]) -> list[str]:
    out = ["| key | type | default | meaning | refused |", "|---|---|---|---|---|"]
    for k in keys:
        default = "required" if k.default is None else f"`{k.default}`"
        refused = "; ".join(r for r in (TYPE_ERRORS[k.type], k.refused) if r)
        out.append(f"| `{k.name}` | {k.type} | {default} | {k.meaning} | {refused} |")
    return out


def reference_markdown() -> str:
    """The scene-file reference as Markdown: every section, key, type, default and refusal."""
    lines = [
        "Every key is checked: an unknown or misspelled one is refused with the keys allowed "
        "there, a missing required one is named. The `refused` column gives the message of a "
        "wrong type, then the values refused beyond it.",
        "",
    ]
    for section, keys in SECTIONS.items():
        lines += [f"## {_heading(section)}", "", *_rows(keys), ""]
    lines += ["## Obstacle shapes", ""]
    for shape, takes in OBSTACLE_SHAPES.items():
        lines += [f'### `shape = "{shape}"`', "", *_rows([SHAPE_KEYS[k] for k in takes]), ""]
    return "\n".join(lines)
