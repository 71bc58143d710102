"""The words the study figures print for the orbits that stay: the glossary's (regular, chaotic but confined,
censored), never "trapped" or "KAM", which the pages once used for three different sets of orbits."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from strings_of import literal_strings

STUDIES = Path(__file__).resolve().parents[2] / "studies"
FIGURES = sorted(STUDIES.glob("*/figure.py"))
#: words of the old vocabulary, whatever their case
OLD_WORDS = re.compile(r"\btrapped\b|\bKAM\b|KAM-", re.I)


def test_the_figure_modules_are_found():
    assert {"fig2", "generality"} <= {p.parent.name for p in FIGURES}


@pytest.mark.parametrize("path", FIGURES, ids=lambda p: p.parent.name)
def test_a_figure_names_the_survivors_by_the_glossary(path):
    bad = [(line, text) for line, text in literal_strings(path) if OLD_WORDS.search(text)]
    assert not bad, f"{path.parent.name}/figure.py prints the old words: {bad}"
