"""A docstring of the package, and a page of the docs or of a study, states what was checked, not where the test
lives: no docstring, no attribute comment (``#:``, rendered in the API pages) and no page's text cites a file of
the test suite. A command a user types (``pytest tests/...``) may name one; an HTML comment of a page (a note to
whoever edits it, not rendered) is not read."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import hhscatter

PACKAGE = Path(hhscatter.__file__).parent
ROOT = PACKAGE.parent
PAGES = sorted([*(ROOT / "docs").rglob("*.md"), *(ROOT / "studies").glob("*/page.md")])
TEST_FILE = re.compile(r"\btests/[\w/.-]*\.py\b")
COMMAND = re.compile(r"\bpytest\b")
HTML_COMMENT = re.compile(r"<!--.*?-->", re.S)


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


def cited_tests_on_page(text: str) -> list[tuple[int, str]]:
    """(line, path) of every test file a page's text cites outside a pytest command and outside HTML comments."""
    shown = HTML_COMMENT.sub(lambda m: "\n" * m.group(0).count("\n"), text)  # keep the line numbers
    return [
        (n, m.group(0))
        for n, line in enumerate(shown.splitlines(), 1)
        if not COMMAND.search(line)
        for m in TEST_FILE.finditer(line)
    ]


def test_the_check_finds_a_test_file_cited_by_a_page():
    text = (
        "# Title\n\nThe identity holds (`tests/integrate/test_flux.py`).\n"
        "<!-- made by a tool;\ntests/docs/test_page.py checks it -->\n"
        "Run `pytest tests/docs -q`.\nChecked by tests/test_layers.py\n"
    )
    assert cited_tests_on_page(text) == [(3, "tests/integrate/test_flux.py"), (7, "tests/test_layers.py")]


def test_no_page_cites_a_test_file():
    assert PAGES, "no page found"
    bad = [
        f"{page.relative_to(ROOT)}:{n} {what}" for page in PAGES for n, what in cited_tests_on_page(page.read_text())
    ]
    assert not bad, "\n".join(bad)
