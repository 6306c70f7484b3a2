"""The .pyi stub editors read names exactly what the compiled module has."""

from __future__ import annotations

import ast
from pathlib import Path

import snell._snell as compiled

STUB = ast.parse((Path(compiled.__file__).parent / "_snell.pyi").read_text())


def public(names) -> set[str]:
    return {n for n in names if not n.startswith("_")}


def test_the_stub_names_every_class_function_and_constant_of_the_module():
    stubbed = {node.name for node in STUB.body if isinstance(node, (ast.ClassDef, ast.FunctionDef))}
    stubbed |= {node.target.id for node in STUB.body if isinstance(node, ast.AnnAssign)}
    assert stubbed == public(dir(compiled)) - {"Matrix"}


def test_the_stub_names_every_method_and_property_of_each_class():
    for node in STUB.body:
        if not isinstance(node, ast.ClassDef) or node.name == "Error":
            continue
        stubbed = public(n.name for n in node.body if isinstance(n, ast.FunctionDef))
        stubbed |= {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        assert stubbed == public(dir(getattr(compiled, node.name))), node.name
