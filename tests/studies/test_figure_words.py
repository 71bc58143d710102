"""The words the study figures print for the orbits that stay: the glossary's (regular, chaotic but confined,
censored), never "trapped" or "KAM", which the pages once used for three different sets of orbits."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

STUDIES = Path(__file__).resolve().parents[2] / "studies"
FIGURES = sorted(STUDIES.glob("*/figure.py"))
#: words of the old vocabulary, whatever their case
OLD_WORDS = re.compile(r"\btrapped\b|\bKAM\b|KAM-", re.I)


def _printed_strings(path: Path) -> list[tuple[int, str]]:
    """(line, text) of every string a figure module may print: literal strings and the literal parts of f-strings,
    except a bare identifier (a column or JSON key such as ``trapped_fraction`` is read, not printed) and
    docstrings."""
    tree = ast.parse(path.read_text())
    docs = {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, (ast.Module, ast.FunctionDef, ast.ClassDef))
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            if not re.fullmatch(r"\w+", node.value):
                out.append((node.lineno, node.value))
    return out


def test_the_figure_modules_are_found():
    assert {"fig2", "generality"} <= {p.parent.name for p in FIGURES}


@pytest.mark.parametrize("path", FIGURES, ids=lambda p: p.parent.name)
def test_a_figure_names_the_survivors_by_the_glossary(path):
    bad = [(line, text) for line, text in _printed_strings(path) if OLD_WORDS.search(text)]
    assert not bad, f"{path.parent.name}/figure.py prints the old words: {bad}"
