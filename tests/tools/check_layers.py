#!/usr/bin/env python3
"""Checks snell's include rule: no layer includes a layer above it.

The layers, bottom to top, are the folders of docs/architecture.md; a file
may include its own layer and any layer below. Run by ctest (Layers.*) over
the source tree; prints each include that breaks the rule and exits 1.
"""

from __future__ import annotations

import re
import sys
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


# Leaf headers of the public API that state shared defaults and include
# nothing: they sit in the bottom layer, so any layer may include them.
SHARED_PUBLIC = {"snell/defaults.h"}


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


def violations(root: Path) -> list[str]:
    """Every include in the tree that reaches above its own layer."""
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


def main() -> int:
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2]
    found = violations(root)
    for line in found:
        print(line)
    if found:
        print(f"{len(found)} include(s) break the layer rule of docs/architecture.md")
        return 1
    print(f"every include keeps to its layer ({', '.join(name for name, _ in LAYERS)}, bottom to top)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
