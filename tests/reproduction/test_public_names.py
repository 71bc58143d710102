"""A module of hhscatter.reproduction that lists its names in ``__all__`` (the list its API page and ``import *``
follow) lists every public function and class it defines, so no assembly is defined but left out; a module without
``__all__`` exports every public name it defines (the package's lazy exports)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2] / "hhscatter" / "reproduction"
MODULES = sorted(p for p in ROOT.rglob("*.py") if p.name != "__init__.py" and "\n__all__ = " in p.read_text())


def _declared_and_defined(source: str):
    tree = ast.parse(source)
    declared = None
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "__all__" for t in node.targets):
            declared = set(ast.literal_eval(node.value))
    defined = {
        n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef)) and not n.name.startswith("_")
    }
    return declared, defined


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_public_function_and_class_is_declared(path):
    declared, defined = _declared_and_defined(path.read_text())
    assert defined <= declared, f"{path.name}: public but not in __all__: {sorted(defined - declared)}"


def test_the_check_sees_a_name_left_out():
    assert _declared_and_defined('__all__ = ["a"]\ndef a(): ...\ndef b(): ...\n') == ({"a"}, {"a", "b"})


def _listed_in_the_package_docstring() -> set[str]:
    doc = ast.get_docstring(ast.parse((ROOT / "__init__.py").read_text()))
    listed = set()
    for line in doc.splitlines():
        if line.startswith("* "):
            listed |= set(re.findall(r"``(\w+)``", line.split(" — ")[0]))
    return listed


def test_the_package_docstring_lists_every_module_of_reproduction():
    modules = {p.stem for p in ROOT.glob("*.py") if p.name != "__init__.py"}
    modules |= {p.parent.name for p in ROOT.glob("*/__init__.py")}
    assert _listed_in_the_package_docstring() == modules
