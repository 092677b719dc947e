"""The package's layers as a contract, read from its imports (every ``import`` statement, a
function's own included), on the installed names (``damage_dolfinx.forms`` is the checkout's
``forms/``).

    python tests/layers.py            # the import picture: floors, rooms, imports that run up, circles

Each floor may import only the floors below it; the folders of one floor do not import each
other; no module takes part in a circle of imports. ``tests/test_layers.py`` holds the package
to it.
"""
from __future__ import annotations

import ast
import importlib.util
import sys
from collections import defaultdict
from pathlib import Path

PACKAGE = "damage_dolfinx"

#: the floors, lowest first; a floor of several folders keeps them independent of each other.
#: "" is the package's face (its __init__.py), which may import everything.
LAYERS = (
    ("core",),        # errors, parameters, tags, the geometry type, argument checks
    ("compat",),      # DOLFINx version differences, gmsh
    ("forms",),       # the weak forms and constitutive maps in UFL
    ("numerics",),    # solvers, damage step, friction, stability, norms
    ("viz",),         # drawing
    ("models",),      # the seven models, the building blocks, damage laws
    ("problem",),     # the run description, its stages and checks
    ("runtime",),     # the time loop, the run folder, records
    ("geometries",),  # the thesis geometries (clients of the problem layer)
    ("catalogue", "studies"),
    ("api",),         # run, steps, converge, sweep, read_run
    ("cli",),         # the command line
    ("",),
)


#: the loose modules of earlier layouts -> the folder that holds them now: run with an older
#: checkout's interpreter, this file draws that checkout's picture on today's floors
OLD_NAMES = {"errors": "core", "parameters": "core", "departures": "core", "validation": "core",
             "validation_problem": "problem", "validation_scalars": "problem",
             "blocks": "models", "laws": "models", "problem": "problem",
             "description": "problem", "meshes": "problem", "workflow": "api",
             "results": "api", "model_check": "api"}


def floor_of(folder: str) -> int:
    folder = OLD_NAMES.get(folder, folder) if folder not in FOLDERS else folder
    for i, names in enumerate(LAYERS):
        if folder in names:
            return i
    raise KeyError(folder)


FOLDERS = {n for names in LAYERS for n in names}


def package_files() -> dict:
    """{module name: source path} of every module of the installed package."""
    spec = importlib.util.find_spec(PACKAGE)
    roots = {PACKAGE: Path(spec.origin).parent}
    for sub in ("forms", "geometries"):
        sub_spec = importlib.util.find_spec(f"{PACKAGE}.{sub}")
        roots[f"{PACKAGE}.{sub}"] = Path(sub_spec.origin).parent
    modules = {}
    for name, root in roots.items():
        for path in sorted(root.rglob("*.py")):
            rel = path.relative_to(root).with_suffix("")
            parts = [p for p in rel.parts if p != "__init__"]
            if name == PACKAGE and parts and parts[0] in ("forms", "geometries"):
                continue  # an editable install's mapped folders are read from their own roots
            modules[".".join([name, *parts])] = path
    return modules


def imports_of(name: str, source: str, is_package: bool, known) -> list:
    """[(imported module, line)] of the package's modules that ``source`` imports."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".")
                base = base[:len(base) - node.level + (1 if is_package else 0)]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            targets = [f"{module}.{a.name}" if f"{module}.{a.name}" in known else module
                       for a in node.names]
        else:
            continue
        for target in targets:
            while target and target not in known:  # a name inside a module -> the module
                target = target.rpartition(".")[0]
            if target.startswith(PACKAGE) and target != name:
                out.append((target, node.lineno))
    return out


def edges(modules=None, extra=()) -> list:
    """[(importer, imported, line)] over the package, plus ``extra`` planted edges."""
    modules = modules or package_files()
    out = []
    for name, path in modules.items():
        for target, line in imports_of(name, path.read_text(), path.name == "__init__.py",
                                       modules):
            out.append((name, target, line))
    return out + list(extra)


def folder(module: str) -> str:
    """The module's folder (its room on a floor); a loose module of an earlier layout is its own
    room, on the floor of the folder that holds it now (OLD_NAMES)."""
    parts = module.split(".")
    if len(parts) == 2 and parts[1] in OLD_NAMES:
        return parts[1]
    return parts[1] if len(parts) > 1 else ""


def upward(all_edges) -> list:
    """The imports that break the floors: to a higher floor, or across one floor's folders."""
    bad = []
    for a, b, line in all_edges:
        fa, fb = folder(a), folder(b)
        if fa == fb:
            continue
        if fb == "" and fa != "":
            bad.append((a, b, line, "imports the package's face"))
        elif floor_of(fb) > floor_of(fa):
            bad.append((a, b, line, "imports a higher floor"))
        elif floor_of(fb) == floor_of(fa):
            bad.append((a, b, line, "imports a folder of its own floor"))
    return bad


def circles(all_edges) -> list:
    """Strongly connected groups of more than one module (Tarjan)."""
    graph = defaultdict(set)
    for a, b, _ in all_edges:
        if not b.startswith(a + ".") and not a.startswith(b + "."):  # a package and its own parts
            graph[a].add(b)
            graph[b]  # every module a node
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                out.append(sorted(group))

    sys.setrecursionlimit(10000)
    for v in list(graph):
        if v not in index:
            visit(v)
    return out


def main() -> int:
    modules = package_files()
    all_edges = edges(modules)
    rooms = defaultdict(list)
    for name in modules:
        rooms[folder(name)].append(name)
    print(f"{len(modules)} modules, {len(all_edges)} imports, {len(LAYERS)} floors")
    for i, names in reversed(list(enumerate(LAYERS))):
        here = [n for n in rooms if floor_of(n) == i]
        cells = ", ".join(f"{n or '(face)'} {len(rooms[n])}" for n in sorted(here, key=str))
        print(f"  floor {i:2d}: {cells}")
    loose = [m for m, path in modules.items() if m.count(".") == 1 and path.name != "__init__.py"
             and m.split(".")[1] not in ("forms", "geometries")]
    print(f"loose modules at the package root: {len(loose)} {loose if loose else ''}")
    bad = upward(all_edges)
    pairs = {}
    for a, b, line, why in bad:
        pairs.setdefault((a, b), (line, why))
    by_reason = {}
    for line, why in pairs.values():
        by_reason[why] = by_reason.get(why, 0) + 1
    print(f"imports that run up or across: {len(pairs)} module pairs "
          f"({', '.join(f'{n} {why}' for why, n in sorted(by_reason.items())) or 'none'})")
    for (a, b), (line, why) in sorted(pairs.items()):
        print(f"  {a}:{line} -> {b} ({why})")
    groups = circles(all_edges)
    print(f"circles: {len(groups)}")
    for g in groups:
        print("  " + " <-> ".join(g))
    return 1 if bad or groups or loose else 0


if __name__ == "__main__":
    sys.exit(main())
