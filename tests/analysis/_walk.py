"""Walks shared by the tests of the estimators' layer: every public function and class of the modules of
``hhscatter.analysis``, and the docstrings of a parsed module."""

from __future__ import annotations

import ast
import importlib
import inspect
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

#: the subpackages of ``hhscatter.analysis`` that hold the estimators
SUBPACKAGES = ("stats", "survival", "dissipative", "noise", "geometry")


def public_callables() -> Iterator[tuple[str, ModuleType, str, str, object]]:
    """(subpackage, its package, module stem, name, object) of every public function and class defined in a public
    module of :data:`SUBPACKAGES` (a name a module imports from elsewhere is left to the module that defines it)."""
    for sub in SUBPACKAGES:
        pkg = importlib.import_module(f"hhscatter.analysis.{sub}")
        for path in sorted(Path(pkg.__file__).parent.glob("*.py")):
            if path.name.startswith("_"):
                continue
            module = importlib.import_module(f"{pkg.__name__}.{path.stem}")
            for name, obj in vars(module).items():
                if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
                    continue
                if inspect.isfunction(obj) or inspect.isclass(obj):
                    yield sub, pkg, path.stem, name, obj


def docstring_ids(tree: ast.AST) -> set[int]:
    """``id`` of the string node that is the docstring of the module, of a class or of a function in ``tree``."""
    return {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
