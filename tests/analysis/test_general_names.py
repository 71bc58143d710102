"""The estimators' layer speaks of general concepts: no module of ``hhscatter.analysis`` is named after a figure,
a study or the paper, and no docstring (module, class or function, private ones too), first line or body, names
one. What assembles a figure or compares with the paper lives in ``hhscatter.reproduction``; an estimator may cite
the literature it implements by its authors (an equation's or a section's source)."""

from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest
from _walk import SUBPACKAGES, docstring_ids

import hhscatter.analysis
from hhscatter.studies import study_names

ROOT = Path(hhscatter.analysis.__file__).parent
#: a figure ("Fig. 2", "fig2", "figure 3"), a study or studies, the paper, its arXiv number
NAMES = re.compile(r"\bpaper\b|\bfig(?:ure)?s?\.?\s*\d|fig\d|\bstud(?:y|ies)\b|arxiv|2308\.13555", re.IGNORECASE)
MODULES = sorted(ROOT.rglob("*.py"))
#: study names that are also the general concept an estimator measures (noise, basins, the chaotic saddle, the
#: transfer operator): as words they say what is measured, not which study measures it
CONCEPTS = {"noise", "basins", "saddle", "operator"}
#: the other study names ("generality", "resc", …), as whole words or inside a name (``generality_rows``)
STUDIES = re.compile("|".join(sorted(set(study_names()) - CONCEPTS)), re.IGNORECASE)
#: the same inside an identifier, where ``_`` joins the words (``PAPER_KAPPA``, ``fig2_rows``)
IN_A_NAME = re.compile(r"paper|fig(?:ure)?_?\d|stud(?:y|ies)|arxiv", re.IGNORECASE)


def _exported_names() -> list[tuple[str, str]]:
    out = []
    for sub in SUBPACKAGES:
        pkg = importlib.import_module(f"hhscatter.analysis.{sub}")
        out += [(sub, name) for name in pkg._EXPORTS]
    return out


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
    assert not any(NAMES.search(part) or STUDIES.search(part) for part in rel.with_suffix("").parts), rel
    bad = [
        f"{rel}:{n} {name}: {line}"
        for n, name, line in first_lines(path.read_text())
        if NAMES.search(line) or STUDIES.search(line)
    ]
    assert not bad, "\n".join(bad)


#: a study's name as a word or joined by ``_`` to others ("the resc record", ``fig2_rows``), not inside a word
#: ("rescales")
STUDY_WORDS = re.compile(r"(?<![^\W_])(?:" + STUDIES.pattern + r")(?![^\W_\d])", re.IGNORECASE)
#: the survival model's escape factor taken literally is the API value ``hazard="paper"``: a value a caller passes,
#: not a reference to the paper (the same exception as for the keys below)
HAZARD_VALUE = re.compile(r"""(["'])paper\1""")


def docstring_lines(source: str):
    """(line number, name, line) of every line of the docstring of the module and of every class and function."""
    tree = ast.parse(source)
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=True)
            for line in (doc or "").splitlines():
                yield getattr(node, "lineno", 1), getattr(node, "name", "<module>"), line.strip()


def _names_one(line: str) -> bool:
    line = HAZARD_VALUE.sub("", line)
    return bool(NAMES.search(line) or STUDY_WORDS.search(line))


def test_the_body_check_finds_what_it_looks_for():
    source = (
        '"""Escape rate.\n\nAs in the paper\'s Fig. 2b.\n"""\n'
        'def f():\n    """The decay.\n\n    The resc record; the fig3 study.\n    """\n'
        'def g():\n    """A fit.\n\n    Rescales χ²; hazard="paper" (the literal factor); Burton, Dullin & Altmann (2023).\n    """\n'
    )
    hits = [(name, line) for _, name, line in docstring_lines(source) if _names_one(line)]
    assert hits == [("<module>", "As in the paper's Fig. 2b."), ("f", "The resc record; the fig3 study.")]
    assert _names_one('the literal ("paper") factor, as the paper says') and STUDY_WORDS.search("generality_rows")


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_docstring_body_names_a_figure_study_or_the_paper(path):
    """An estimator's docstring says what it estimates on any run; the figure or study it serves is told where
    that figure or study is assembled."""
    bad = [
        f"{path.relative_to(ROOT)}:{n} {name}: {line}"
        for n, name, line in docstring_lines(path.read_text())
        if _names_one(line)
    ]
    assert not bad, "\n".join(bad)


def test_the_analysis_api_page_describes_each_module_by_what_it_estimates():
    """The hand-written API page of the estimators' layer lists its modules with the equations they implement and
    what they estimate, never the figure, study or paper they serve."""
    page = ROOT.parents[1] / "docs" / "api" / "analysis" / "index.md"
    rows = [line for line in page.read_text().splitlines() if line.startswith("| [`")]
    assert len(rows) >= 30
    bad = [row.split(" | ")[0] for row in rows if NAMES.search(row) or STUDIES.search(row)]
    assert not bad, bad


def test_the_study_check_knows_the_studies():
    assert STUDIES.search("fig2_kappa") and STUDIES.search("the resc record") and not STUDIES.search("κ(E) law")
    assert {"fig2", "generality"} <= set(study_names())
    assert IN_A_NAME.search("PAPER_KAPPA") and IN_A_NAME.search("figure_2_rows") and not IN_A_NAME.search("fit_laws")


def test_no_exported_name_names_a_figure_study_or_the_paper():
    bad = [f"{sub}.{name}" for sub, name in _exported_names() if IN_A_NAME.search(name) or STUDIES.search(name)]
    assert not bad, bad


def _strings(source: str):
    """(line number, text) of every string constant that is not a docstring."""
    tree = ast.parse(source)
    docs = docstring_ids(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            yield node.lineno, node.value


#: a figure or a study in a key or a message an estimator writes ("fig2_kappa", "fig2's κ0"); the survival model's
#: hazard named "paper" (its literal form, beside "integrated") is a value of the API, not a reference
WRITTEN = re.compile(r"fig(?:ure)?s?\.?\s*_?\d|" + STUDIES.pattern, re.IGNORECASE)


def test_the_written_check_finds_a_figure_key():
    assert [
        s for _, s in _strings('"""Doc of fig2."""\nrec = {"fig2_kappa": 1, "kappa": 2}\n') if WRITTEN.search(s)
    ] == ["fig2_kappa"]


@pytest.mark.parametrize("path", MODULES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_key_or_message_names_a_figure_or_a_study(path):
    bad = [f"{path.relative_to(ROOT)}:{n} {s!r}" for n, s in _strings(path.read_text()) if WRITTEN.search(s)]
    assert not bad, "\n".join(bad)
