"""The strings a module may print and the strings a JSON record holds, for the tests that check their words."""

import ast
import re
from pathlib import Path


def literal_strings(path: Path) -> list[tuple[int, str]]:
    """(line, text) of every literal string and literal part of an f-string in the module at ``path``, except its
    docstrings and bare identifiers (a column or JSON key such as ``trapped_fraction`` is read, not printed)."""
    tree = ast.parse(path.read_text())
    docs = {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, (ast.Module, ast.FunctionDef, ast.ClassDef))
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
    return [
        (node.lineno, node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and id(node) not in docs
        and not re.fullmatch(r"\w+", node.value)
    ]


def json_strings(node, where: str = ""):
    """(where, text) of every string leaf of a JSON document (``where``: its path of keys and indices)."""
    if isinstance(node, str):
        yield where, node
    elif isinstance(node, dict):
        for k, v in node.items():
            yield from json_strings(v, f"{where}.{k}")
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from json_strings(v, f"{where}[{i}]")
