"""The estimators' layer speaks of general concepts: no module of ``hhscatter.analysis`` is named after a figure,
a study or the paper, and no docstring's first line (module, class or function, private ones too) names one.
What assembles a figure or compares with the paper lives in ``hhscatter.reproduction``."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import hhscatter.analysis

ROOT = Path(hhscatter.analysis.__file__).parent
#: a figure ("Fig. 2", "fig2", "figure 3"), a study or studies, the paper, its arXiv number
NAMES = re.compile(r"\bpaper\b|\bfig(?:ure)?s?\.?\s*\d|fig\d|\bstud(?:y|ies)\b|arxiv|2308\.13555", re.IGNORECASE)
MODULES = sorted(ROOT.rglob("*.py"))


def first_lines(source: str):
    """(line number, name, first line) of the docstring of the module and of every class and function."""
    tree = ast.parse(source)
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=True)
            if doc:
                yield getattr(node, "lineno", 1), getattr(node, "name", "<module>"), doc.strip().splitlines()[0]


def test_the_check_finds_what_it_looks_for():
    hits = [
        line
        for _, _, line in first_lines('"""Escape rate (paper Sec. II)."""\ndef f():\n    """The Fig. 2b windows."""\n')
        if NAMES.search(line)
    ]
    assert len(hits) == 2
    assert not NAMES.search("the figure of merit; a steady state; the escape-rate law")


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_module_name_or_first_docstring_line_names_a_figure_study_or_the_paper(path):
    rel = path.relative_to(ROOT)
    assert not any(NAMES.search(part) for part in rel.with_suffix("").parts), rel
    bad = [f"{rel}:{n} {name}: {line}" for n, name, line in first_lines(path.read_text()) if NAMES.search(line)]
    assert not bad, "\n".join(bad)
