"""Static layout checks of the contactfx package: python3 tools/layout_check.py 400 250 120

Reads every module under contactfx/ with ast (nothing is imported or run) and prints one line per
problem: import cycles between modules (function-local imports count, TYPE_CHECKING blocks do not),
imports of the CLI from the library, PETSc/DOLFINx imports in the pure kernels (contactfx/contact/),
and files, classes and functions over the hard size limits (500 / 320 / 150 lines, or the three
numbers after the first three): these fail. Over the first three numbers a size is a warning
only, a prompt to split by responsibility when a change gives a reason, never for the count.
"""
import ast
import sys
from pathlib import Path

WARN = tuple(int(a) for a in sys.argv[1:4])
FAIL = tuple(int(a) for a in sys.argv[4:7]) if len(sys.argv) >= 7 else (500, 320, 150)
root = Path("contactfx")
mods = {}
for p in sorted(root.rglob("*.py")):
    parts = list(p.with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    mods[".".join(parts)] = p


def resolve(name, level, here, is_pkg):
    if level == 0:
        return name
    base = here.split(".")
    base = base if is_pkg else base[:-1]
    base = base[: len(base) - (level - 1)]
    return ".".join(base + ([name] if name else []))


def in_type_checking(node, parents):
    while node in parents:
        node = parents[node]
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            return True
    return False


edges, problems, warnings = {}, [], []


def size(where, what, n, i):
    """A problem over the hard limit FAIL[i], a warning over WARN[i]."""
    if n > FAIL[i]:
        problems.append(f"{where}: {what} {n} lines (> {FAIL[i]})")
    elif n > WARN[i]:
        warnings.append(f"warning: {where}: {what} {n} lines (> {WARN[i]})")



for mod, path in mods.items():
    src = path.read_text()
    tree = ast.parse(src)
    parents = {c: n for n in ast.walk(tree) for c in ast.iter_child_nodes(n)}
    is_pkg = path.name == "__init__.py"
    out = set()
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = resolve(node.module or "", node.level, mod, is_pkg)
            targets = [base] + [f"{base}.{a.name}" for a in node.names]
        if not targets or in_type_checking(node, parents):
            continue
        for t in targets:
            if mod.startswith("contactfx.contact") and t.split(".")[0] in ("dolfinx", "petsc4py", "ufl", "basix"):
                problems.append(f"{path}: the pure kernels import {t.split('.')[0]}")
            hit = t if t in mods else None
            if hit and hit != mod and not mod.startswith(hit + ".") and hit != "contactfx":
                out.add(hit)
    edges[mod] = out
    size(path, "file", src.count("\n") + 1, 0)
    for node in ast.walk(tree):
        if isinstance(node, ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            n = node.end_lineno - node.lineno + 1
            if isinstance(node, ast.ClassDef):
                size(f"{path}:{node.lineno}", f"class {node.name}", n, 1)
            else:
                size(f"{path}:{node.lineno}", f"function {node.name}", n, 2)
cli = [m for m in mods if m == "contactfx.cli" or m.startswith("contactfx.cli.")]
for mod, out in edges.items():
    if mod in cli or mod == "contactfx.__main__":
        continue
    for t in out:
        if t in cli:
            problems.append(f"{mods[mod]}: the library imports the command line ({t})")
# cycles: strongly connected components of more than one module (Tarjan)
index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]
sys.setrecursionlimit(10000)


def strong(v):
    index[v] = low[v] = counter[0]; counter[0] += 1; stack.append(v); on.add(v)
    for w in edges.get(v, ()):
        if w not in index:
            strong(w); low[v] = min(low[v], low[w])
        elif w in on:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        comp = []
        while True:
            w = stack.pop(); on.discard(w); comp.append(w)
            if w == v:
                break
        if len(comp) > 1:
            comps.append(sorted(comp))


for v in edges:
    if v not in index:
        strong(v)
for c in comps:
    problems.append("import cycle: " + " <-> ".join(c))
# The wheel's package list (pyproject.toml names them, to map meshes/ in) against the tree.
import tomllib  # noqa: E402

listed = set(tomllib.loads(Path("pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
found = {".".join(p.parent.parts) for p in root.rglob("__init__.py")} | {"contactfx.meshes.geo"}
for name in sorted(found ^ listed):
    problems.append(f"pyproject.toml: package {name} {'not listed' if name in found else 'not found'}")
for p in warnings + problems:
    print(p)
print(
    f"layout: {len(mods)} modules, {sum(map(len, edges.values()))} imports, {len(comps)} cycles, "
    f"{len(problems)} problems, {len(warnings)} size warnings"
)
sys.exit(1 if problems else 0)
