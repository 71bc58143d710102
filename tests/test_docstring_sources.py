"""A docstring of the package states what was checked, not where the test lives: no docstring and no attribute
comment (``#:``, rendered in the API pages) cites a file of the test suite. A command a user types (``pytest
tests/...``) may name one."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import hhscatter

PACKAGE = Path(hhscatter.__file__).parent
TEST_FILE = re.compile(r"\btests/[\w/.-]*\.py\b")
COMMAND = re.compile(r"\bpytest\b")


def cited_tests(source: str) -> list[tuple[int, str]]:
    """(line, path) of every test file a docstring or a ``#:`` comment cites outside a pytest command."""
    hits = []
    tree = ast.parse(source)
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=False)
            if not doc:
                continue
            start = node.body[0].lineno
            for i, line in enumerate(doc.splitlines()):
                if not COMMAND.search(line):
                    hits += [(start + i, m.group(0)) for m in TEST_FILE.finditer(line)]
    for n, line in enumerate(source.splitlines(), 1):
        if line.lstrip().startswith("#:") and not COMMAND.search(line):
            hits += [(n, m.group(0)) for m in TEST_FILE.finditer(line)]
    return sorted(hits)


def test_the_check_finds_a_cited_test_file():
    source = (
        '"""Checked in tests/test_model.py.\n\nRun ``pytest tests/test_model.py -q`` to see it."""\n'
        "#: the bound is checked (tests/bench/test_stress.py)\nX = 1\n"
        'def f():\n    """Validated against an independent integration."""\n'
    )
    assert cited_tests(source) == [(1, "tests/test_model.py"), (4, "tests/bench/test_stress.py")]


def test_no_docstring_cites_a_test_file():
    bad = [
        f"{path.relative_to(PACKAGE.parent)}:{n} {what}"
        for path in sorted(PACKAGE.rglob("*.py"))
        for n, what in cited_tests(path.read_text())
    ]
    assert not bad, "\n".join(bad)
