#!/usr/bin/env python3
"""Checks snell's layer rules: no layer reaches a layer above it.

The rules of docs/architecture.md, three of them:

- C++: the layers, bottom to top, are the folders of its table; a file may
  include its own layer and any layer below, and a host sees only the public
  API.
- Python: snell.usd (python/snell/usd) imports nothing of Blender's, neither
  bpy nor the add-on; the core package (the rest of python/snell) does not
  import snell.usd, the layer above it, nor Blender; the add-on (blender/) and
  the examples import snell through its public modules only (snell,
  snell.usd), never a private one (snell._snell, snell.usd._reader); and the
  add-on's modules (blender/snell_blender) import one another in no cycle.
  Imports inside functions count as well, since the add-on imports lazily.
- Shaders: shaders/shared includes only shared; shaders/common, common and
  shared; a pass's folder (comp, comp/bvh, raster, rt, viewer), itself, its
  own subfolders, common and shared, never another pass's folder nor its
  parent's.

Run by ctest (Layers.*) over the source tree; prints each include or import
that breaks a rule and exits 1. tests/tools/test_check_layers.py holds each
rule to a small tree of its own.
"""

from __future__ import annotations

import ast
import posixpath
import re
import sys
from dataclasses import dataclass
from pathlib import Path

# Bottom to top. Each entry: the layer's name, the folders that hold it.
LAYERS: list[tuple[str, tuple[str, ...]]] = [
    ("shared", ("shaders/shared",)),
    ("vk", ("src/vk",)),
    ("scene", ("src/scene",)),
    ("io", ("src/io",)),
    ("farm", ("src/farm",)),
    ("peer", ("src/peer",)),
    ("ref", ("src/ref",)),
    ("render", ("src/render",)),
    ("bake", ("src/bake",)),
    ("stress", ("src/stress",)),
    ("api", ("src/api", "include/snell")),
    ("cli", ("src/cli",)),
    ("viewer", ("viewer",)),
]
# The Python module and the examples are hosts: they see the public API only.
HOSTS = ("python", "examples")
INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^">]+)[">]', re.MULTILINE)
SOURCE_SUFFIXES = {".h", ".hpp", ".cpp", ".c", ".glsl"}


def layer_of_folder(relative: str) -> int | None:
    """The rank of the layer whose folder holds `relative`, or None."""
    for rank, (_, folders) in enumerate(LAYERS):
        if any(relative == f or relative.startswith(f + "/") for f in folders):
            return rank
    return None


# Leaf headers of the public API that every layer shares (the defaults, and
# the handles of a host's device), including none of snell's: they sit in the
# bottom layer, so any layer may include them.
SHARED_PUBLIC = {"snell/defaults.h", "snell/host_device.h"}


def layer_of_include(target: str) -> int | None:
    """The rank of the layer an include names ("render/bvh.h": render), or None."""
    if target in SHARED_PUBLIC:
        return 0
    head = target.split("/", 1)[0]
    if head == "snell" and "/" in target:
        return next(r for r, (name, _) in enumerate(LAYERS) if name == "api")
    for rank, (name, _) in enumerate(LAYERS):
        if name == head and "/" in target:
            return rank
    return None


def cpp_violations(root: Path) -> list[str]:
    """Every C++ include in the tree that reaches above its own layer."""
    found: list[str] = []
    for path in sorted(root.rglob("*")):
        if path.suffix not in SOURCE_SUFFIXES or not path.is_file():
            continue
        relative = path.relative_to(root).as_posix()
        if relative.startswith(("build/", ".")):
            continue
        own = layer_of_folder(relative)
        is_host = relative.split("/", 1)[0] in HOSTS
        if own is None and not is_host:
            continue
        for target in INCLUDE.findall(path.read_text(encoding="utf-8", errors="replace")):
            rank = layer_of_include(target)
            if rank is None:
                continue
            name = LAYERS[rank][0]
            if is_host and name != "api":
                found.append(f"{relative}: includes {target}, but a host sees only <snell/snell.h>")
            elif not is_host and rank > own:
                found.append(f"{relative}: includes {target}: the {LAYERS[own][0]} layer may not include "
                             f"the {name} layer above it")
    return found


# --- Python ---------------------------------------------------------------

# The folders that are on sys.path when their modules run: the snell package
# (python/snell), the add-on and Blender scripts (blender/), the examples.
PYTHON_ROOTS = ("python", "blender", "examples/python")
USD = "python/snell/usd"
CORE = "python/snell"
ADD_ON = "blender/snell_blender"
# Blender's own modules, which exist only inside Blender: a layer that may not
# depend on Blender may import none of them, bpy first.
BLENDER_MODULES = ("bpy", "bpy_extras", "bmesh", "mathutils", "gpu", "gpu_extras", "blf", "bgl", "addon_utils")


@dataclass(frozen=True)
class Import:
    """One import of a module: where it is, as written, and the dotted names it binds."""

    line: int
    text: str  # "from .sync import SceneSync", for the message
    targets: tuple[str, ...]  # absolute: ("snell_blender.sync.SceneSync",)


@dataclass(frozen=True)
class Module:
    """A Python file of the tree, under the name it is imported by."""

    name: str  # "snell.usd._reader"; a package's __init__.py is the package, "snell.usd"
    relative: str  # "python/snell/usd/_reader.py"
    is_package: bool


def python_modules(root: Path) -> list[Module]:
    """Every .py file under the Python roots, named as imported from its root."""
    modules: list[Module] = []
    for folder in PYTHON_ROOTS:
        base = root / folder
        if not base.is_dir():
            continue
        for path in sorted(base.rglob("*.py")):
            parts = list(path.relative_to(base).with_suffix("").parts)
            is_package = parts[-1] == "__init__"
            if is_package:
                parts.pop()
            if parts and all(p.isidentifier() for p in parts):
                modules.append(Module(".".join(parts), path.relative_to(root).as_posix(), is_package))
    return modules


def absolute(module: Module, level: int, name: str | None) -> str | None:
    """The absolute name a relative import means ("from ..x": level 2, "x"), or None above the top."""
    if level == 0:
        return name
    package = module.name.split(".") if module.is_package else module.name.split(".")[:-1]
    if not package or level > len(package):
        return None
    base = package[:len(package) - (level - 1)]
    return ".".join(base + ([name] if name else []))


def imports_of(module: Module, tree: ast.AST) -> list[Import]:
    """Every import of a parsed module at any depth, lazy ones in functions too.

    A literal importlib.import_module("...") or __import__("...") counts as
    well: the add-on loads snell that way (runtime.py).
    """
    found: list[Import] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.append(Import(node.lineno, ast.unparse(node), tuple(a.name for a in node.names)))
        elif isinstance(node, ast.ImportFrom):
            base = absolute(module, node.level, node.module)
            if base is None:
                continue
            # "from P import n" binds P.n, a submodule or a name of P; naming it so lets one
            # check catch both a private module and a private name ("from snell import _snell").
            targets = tuple(base if a.name == "*" else f"{base}.{a.name}" for a in node.names)
            found.append(Import(node.lineno, ast.unparse(node), targets))
        elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
            function = node.func
            called = function.attr if isinstance(function, ast.Attribute) else getattr(function, "id", None)
            target = node.args[0].value
            if called in ("import_module", "__import__") and isinstance(target, str) and target[:1] != ".":
                found.append(Import(node.lineno, ast.unparse(node), (target,)))
    return sorted(found, key=lambda i: i.line)


def is_within(name: str, package: str) -> bool:
    """Whether the dotted `name` is `package` or lies inside it ("snell.usd._x" in "snell.usd")."""
    return name == package or name.startswith(package + ".")


def private_part(name: str) -> str | None:
    """The first private part of a name under snell ("snell.usd._reader": "_reader"), or None.

    Dunders (snell.__version__) are public.
    """
    for part in name.split(".")[1:]:
        if part.startswith("_") and not (part.startswith("__") and part.endswith("__")):
            return part
    return None


def is_under(relative: str, folder: str) -> bool:
    """Whether the file `relative` lies in `folder` or below it."""
    return relative.startswith(folder + "/")


def python_violations(root: Path) -> list[str]:
    """Every Python import in the tree that breaks a rule, and every import cycle of the add-on."""
    modules = python_modules(root)
    # Blender's side as top-level names: the add-on, and the scripts beside it in blender/.
    blender_side = sorted({m.name.split(".")[0] for m in modules if is_under(m.relative, "blender")})
    not_blender = BLENDER_MODULES + tuple(blender_side)
    found: list[str] = []
    parsed: dict[Module, list[Import]] = {}
    for module in modules:
        try:
            tree = ast.parse((root / module.relative).read_text(encoding="utf-8"), module.relative)
        except (SyntaxError, UnicodeDecodeError) as error:
            # An unreadable file would hide its imports; say so rather than pass it.
            found.append(f"{module.relative}:{getattr(error, 'lineno', 0) or 0}: cannot be parsed ({error}), "
                         f"so its imports go unchecked")
            continue
        parsed[module] = imports_of(module, tree)
    for module, imports in parsed.items():
        for item in imports:
            for target in item.targets:
                rule = python_rule_broken(module.relative, target, not_blender)
                if rule:
                    found.append(f"{module.relative}:{item.line}: imports {target} ({item.text}): {rule}")
    found += cycle_violations({m: i for m, i in parsed.items() if is_under(m.relative, ADD_ON)})
    return found


def python_rule_broken(relative: str, target: str, not_blender: tuple[str, ...]) -> str | None:
    """The rule that importing `target` from the file `relative` breaks, or None."""
    blender = next((b for b in not_blender if is_within(target, b)), None)
    if is_under(relative, USD):
        if blender:
            return (f"snell.usd ({USD}/) may not import Blender or the add-on ({blender}): it reads USD "
                    f"for every host, and the add-on sits above it")
    elif is_under(relative, CORE):
        if is_within(target, "snell.usd"):
            return "the core snell package may not import snell.usd, the layer above it"
        if blender:
            return f"the core snell package may not import Blender or the add-on ({blender}), which sit above it"
    elif is_within(target, "snell") and private_part(target):
        host = "the add-on" if is_under(relative, ADD_ON) else "a host script"
        return (f"{host} imports snell only through its public modules (snell, snell.usd), "
                f"not the private {private_part(target)}")
    return None


def cycle_violations(imports: dict[Module, list[Import]]) -> list[str]:
    """One message per knot of add-on modules that import one another in a cycle."""
    by_name = {m.name: m for m in imports}
    # Module -> module it imports, with the first import that does. The package's own
    # __init__, which Python runs before any of its modules, is not counted as imported
    # by them: every module would close a cycle through it.
    edges: dict[str, dict[str, Import]] = {name: {} for name in by_name}
    for module, items in imports.items():
        for item in items:
            for target in item.targets:
                reached = longest_module(target, by_name)
                if reached and reached != module.name:
                    edges[module.name].setdefault(reached, item)
    found: list[str] = []
    for knot in strongly_connected(edges):
        if len(knot) < 2:
            continue
        cycle = shortest_cycle(min(knot), edges, set(knot))
        steps = [(a, b, edges[a][b]) for a, b in zip(cycle, cycle[1:])]
        short = {name: short_name(by_name[name]) for name in knot}
        how = "; ".join(f"{by_name[a].relative}:{i.line} {i.text}" for a, _, i in steps)
        others = sorted(short[n] for n in knot if n not in cycle)
        rest = f" (caught in it too: {', '.join(others)})" if others else ""
        found.append(f"{by_name[cycle[0]].relative}: import cycle {' -> '.join(short[n] for n in cycle)}{rest} "
                     f"({how}): the add-on's modules may not import one another in a cycle, "
                     f"lazy imports in functions included")
    return found


def short_name(module: Module) -> str:
    """A module's name in its package, for a cycle's message: "engine", or "__init__" for the package."""
    return "__init__" if module.is_package else module.name.rsplit(".", 1)[-1]


def longest_module(target: str, names: dict[str, Module]) -> str | None:
    """The module of `names` that importing `target` runs: its longest leading part that is one."""
    parts = target.split(".")
    for end in range(len(parts), 0, -1):
        if ".".join(parts[:end]) in names:
            return ".".join(parts[:end])
    return None


def strongly_connected(edges: dict[str, dict[str, Import]]) -> list[list[str]]:
    """Tarjan's strongly connected components of the import graph, each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    knots: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for nxt in sorted(edges[node]):
            if nxt not in index:
                visit(nxt)
                low[node] = min(low[node], low[nxt])
            elif nxt in on_stack:
                low[node] = min(low[node], index[nxt])
        if low[node] == index[node]:
            knot: list[str] = []
            while True:
                top = stack.pop()
                on_stack.discard(top)
                knot.append(top)
                if top == node:
                    break
            knots.append(sorted(knot))

    for node in sorted(edges):
        if node not in index:
            visit(node)
    return sorted(knots)


def shortest_cycle(start: str, edges: dict[str, dict[str, Import]], knot: set[str]) -> list[str]:
    """The shortest path from `start` back to itself within its knot: [start, ..., start]."""
    came_from: dict[str, str] = {}
    frontier = [start]
    while frontier:
        following: list[str] = []
        for node in frontier:
            for nxt in sorted(edges[node]):
                if nxt not in knot:
                    continue
                if nxt == start:
                    path = [node]
                    while path[-1] != start:
                        path.append(came_from[path[-1]])
                    return path[::-1] + [start]
                if nxt not in came_from:
                    came_from[nxt] = node
                    following.append(nxt)
        frontier = following
    return [start, start]  # not reached: a knot of two or more modules always leads back


# --- Shaders --------------------------------------------------------------

SHADERS = "shaders"
SHADER_SUFFIXES = {".glsl", ".h", ".comp", ".vert", ".frag", ".geom", ".tesc", ".tese", ".mesh", ".task",
                   ".rgen", ".rchit", ".rahit", ".rmiss", ".rint", ".rcall"}
# Only quoted includes are GLSL's (GL_GOOGLE_include_directive); the angle ones in
# shared/ are C++'s system headers, behind __cplusplus.
QUOTED_INCLUDE = re.compile(r'^[ \t]*#[ \t]*include[ \t]*"([^"]+)"', re.MULTILINE)
# The two folders below the passes: the layouts C++ reads too, and the GLSL several passes share.
SHADER_BASE = ("shared", "common")


def shader_may_include(folder: str, target: str) -> bool:
    """Whether a shader in `folder` may include a file in `target`, both folders of shaders/.

    shared includes only shared; common, common and shared. Every other folder
    is a pass's (comp, comp/bvh, raster, rt, viewer): it includes itself, its
    own subfolders (trace.comp reads comp/bvh's node layout), common and
    shared, but no other pass's folder, nor its parent's.
    """
    top = target.split("/", 1)[0]
    own_top = folder.split("/", 1)[0]
    if own_top == "shared":
        return top == "shared"
    if own_top == "common":
        return top in SHADER_BASE
    return top in SHADER_BASE or target == folder or target.startswith(folder + "/")


def shader_rule(folder: str) -> str:
    """The shader include rule of `folder`, as a message states it."""
    own_top = folder.split("/", 1)[0]
    name = f"shaders/{folder}/" if folder else "shaders/"
    if own_top == "shared":
        return "shaders/shared/ may include only shaders/shared/ (the layouts C++ reads too)"
    if own_top == "common":
        return "shaders/common/ may include only shaders/common/ and shaders/shared/"
    return (f"{name} may include only itself, its subfolders, shaders/common/ and shaders/shared/, "
            f"not another pass's folder nor its parent's")


def shader_violations(root: Path) -> list[str]:
    """Every quoted include of a shader that breaks the shader folders' rule."""
    found: list[str] = []
    base = root / SHADERS
    if not base.is_dir():
        return found
    for path in sorted(base.rglob("*")):
        if path.suffix not in SHADER_SUFFIXES or not path.is_file():
            continue
        relative = path.relative_to(root).as_posix()
        folder = path.parent.relative_to(base).as_posix()
        folder = "" if folder == "." else folder
        text = path.read_text(encoding="utf-8", errors="replace")
        for match in QUOTED_INCLUDE.finditer(text):
            target = match.group(1)
            line = text.count("\n", 0, match.start()) + 1
            # glslang resolves a quoted include against the including file's own folder.
            resolved = posixpath.normpath(posixpath.join(folder, target))
            if resolved == ".." or resolved.startswith("../") or posixpath.isabs(target):
                found.append(f'{relative}:{line}: includes "{target}", which lies outside shaders/: '
                             f"a shader includes only shaders/")
                continue
            target_folder = posixpath.dirname(resolved)
            if not shader_may_include(folder, target_folder):
                found.append(f'{relative}:{line}: includes "{target}" ({SHADERS}/{resolved}): '
                             f"{shader_rule(folder)}")
    return found


def violations(root: Path) -> list[str]:
    """Every include or import of the tree at `root` that breaks a layer rule."""
    return cpp_violations(root) + python_violations(root) + shader_violations(root)


def main() -> int:
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2]
    found = violations(root)
    for line in found:
        print(line)
    if found:
        print(f"{len(found)} include(s) or import(s) break the layer rules of docs/architecture.md")
        return 1
    print(f"every include keeps to its layer ({', '.join(name for name, _ in LAYERS)}, bottom to top), "
          f"every Python import to its package (snell, snell.usd, the add-on, with no cycle) "
          f"and every shader include to its folder (shared, common, the passes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
