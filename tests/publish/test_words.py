"""The words the studies write into their numbers for the orbits still inside at t_max: the glossary's "censored",
never "KAM-trapped" or "trapped", in the text the code writes and in every committed record as the pages read it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from strings_of import json_strings, literal_strings

from hhscatter.publish.numbers import read_numbers_file
from hhscatter.publish.words import OLD_PHRASES, in_glossary_words

ROOT = Path(__file__).resolve().parents[2]
#: "trapped" or "KAM-trapped", said of an orbit still inside at t_max or of the dissipative mixture's share that
#: settles instead of escaping (the glossary's never-escaping share φ, fractions f_ne,k): "trapped" has no meaning left
OLD = re.compile(r"\bKAM-trapped\b|\btrapped\b", re.I)
#: the modules that write text into the numbers JSON: the estimators, what assembles the studies' numbers, the studies
WRITERS = sorted(
    [*(ROOT / "hhscatter" / "analysis").rglob("*.py"), *(ROOT / "hhscatter" / "reproduction").rglob("*.py")]
    + list((ROOT / "studies").glob("*/study.py"))
)
#: a message about rows below E_c that never had an outcome ("trapped from t = 0"), not about a censored orbit
ELSEWHERE = {"they are trapped from t = 0"}


def test_the_writers_are_found():
    names = {p.name for p in WRITERS}
    assert {"kappa_conventions.py", "fig2.py", "cmeasure.py", "study.py"} <= names


@pytest.mark.parametrize("path", WRITERS, ids=lambda p: str(p.relative_to(ROOT)))
def test_the_code_writes_censored_not_trapped(path):
    bad = [
        (line, text)
        for line, text in literal_strings(path)
        if OLD.search(text) and not any(e in text for e in ELSEWHERE)
    ]
    assert not bad, f"{path.relative_to(ROOT)} writes the old words: {bad}"


def test_the_pattern_finds_trapped_for_a_censored_orbit_and_for_the_mixtures_share():
    assert OLD.search("κ(E) points ill-defined by the trapped plateau")
    assert OLD.search("μ_c: KAM-trapped orbits dropped")
    assert OLD.search("same number of free parameters (one trapped fraction φ)")
    assert not OLD.search("4 censored; n_trapped, trapped_fraction")


def test_the_mixtures_share_that_never_escapes_is_named_as_the_glossary_names_phi():
    """fig6's mixture rows written before say "one trapped fraction φ" / "K trapped fractions f_ne,k"; the glossary
    names φ and f_ne the share that never escapes (settles), so the rows are read in those words."""
    doc = {
        "note": "same data selection; same number of free parameters (one trapped fraction φ); rms a: 1.0 → 2.0",
        "other": "same data selection; K trapped fractions f_ne,k: K − 1 more parameters; rms a: 1.0 → 2.0",
    }
    out = in_glossary_words(doc)
    assert (
        out["note"]
        == "same data selection; same number of free parameters (one never-escaping share φ); rms a: 1.0 → 2.0"
    )
    assert (
        out["other"]
        == "same data selection; K never-escaping fractions f_ne,k: K − 1 more parameters; rms a: 1.0 → 2.0"
    )
    glossary = (ROOT / "docs" / "equations.md").read_text()
    assert "| φ | the share of each sub-ensemble that never escapes" in glossary


COMMITTED = sorted(
    p for p in (ROOT / "docs" / "studies" / "assets").rglob("*.json") if not p.name.endswith(".cost.json")
)


@pytest.mark.parametrize("path", COMMITTED, ids=lambda p: str(p.relative_to(ROOT / "docs" / "studies" / "assets")))
def test_a_committed_record_reads_censored_on_the_pages(path):
    """Records written before the studies said "censored" (the paper scale's, which a re-run would take hours to
    remake) are read in the glossary's words; their keys stay."""
    bad = sorted({t for _, t in json_strings(read_numbers_file(path)) if OLD.search(t)})
    assert not bad, bad[:5]


def test_an_old_record_is_reworded_phrase_by_phrase_and_its_keys_stay():
    doc = {
        "trapped_fraction": 0.03,
        "rows": [
            {"quantity": "κ(E) points ill-defined by the trapped plateau", "ours": 2},
            {"quantity": "Fig. 5's distance (all conservative survivors, trapped kept) — barbanis"},
        ],
        "reason": "plateau: orbits still inside at t_max (KAM-trapped or sticky) are 3.17%, 100% of P at the window end",
    }
    out = in_glossary_words(doc)
    assert out["trapped_fraction"] == 0.03 and out["rows"][0]["ours"] == 2
    assert out["rows"][0]["quantity"] == "κ(E) points ill-defined by the plateau of censored orbits"
    assert out["rows"][1]["quantity"] == "Fig. 5's distance (all conservative survivors, censored kept) — barbanis"
    assert out["reason"].startswith("plateau: censored orbits (still inside at t_max) are 3.17%")
    assert all(not OLD.search(new) for _, new in OLD_PHRASES)


#: a study's sources as its page shows them (the parameters with their comments, the module with its docstrings)
SOURCES = sorted(p for name in ("study.toml", "study.py", "figure.py") for p in (ROOT / "studies").glob(f"*/{name}"))
#: a key or code name the records keep (``trapped``, `trapped`, 'trapped', codes.trapped): named, not said
KEY_NAME = re.compile(r"``trapped``|`trapped`|'trapped'|\"trapped\"|\.trapped\b")


def words_of_a_source(text: str) -> list[str]:
    """The lines of a source that say "trapped" (or "KAM-trapped") of an orbit, its key names left out."""
    return [line.strip() for line in text.splitlines() if OLD.search(KEY_NAME.sub(" ", line))]


def test_the_source_scan_tells_a_word_from_a_key_name():
    assert words_of_a_source("3 settled; 4 trapped (alive at t_max)\n# orbits trapped on tori") == [
        "3 settled; 4 trapped (alive at t_max)",
        "# orbits trapped on tori",
    ]
    assert words_of_a_source("4 censored (code name ``trapped``); codes.trapped; n_trapped; trapped_fraction") == []


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_the_studies_sources_on_the_pages_say_censored(path):
    """The comments of study.toml and the docstrings and comments of the study modules are shown on the study pages:
    they name an orbit still inside at t_max as the glossary does."""
    bad = words_of_a_source(path.read_text())
    assert not bad, f"{path.relative_to(ROOT)}: {bad}"


def test_the_neighbour_estimators_refusal_reads_as_a_reason_with_units_and_what_the_range_is():
    """A range [0.09, 0.29] above most neighbour distances (0.0018 … 0.11), and an empty range [220, 0.49]: each said
    as the point's reason for no d₁ with the units and what its ends are; other text untouched."""
    few = (
        "d1: points: fewer than 4 neighbour scales in [eps_min, eps_max] = [0.0913179, 0.294261] (the k-th "
        "neighbours of 3749 points lie at 0.00184 … 0.11): give more points or widen the range"
    )
    empty = few.replace("0.0913179", "220.287")
    doc = in_glossary_words({"notes": [few, empty, "d1: other"]})
    assert doc["notes"][0] == (
        "d1: no scaling range for d₁: the fit's scales run from the range's floor, eps_min = "
        "0.0913, to the largest scale, eps_max = 0.294 (position units), and hold fewer than 4 of the k-th neighbour "
        "distances of the 3749 section points, which lie at 0.00184 … 0.11"
    )
    assert doc["notes"][1] == (
        "d1: no scaling range for d₁: the range's floor, eps_min = 220, lies above the largest "
        "scale, eps_max = 0.294 (position units)"
    )
    assert doc["notes"][2] == "d1: other"


@pytest.mark.parametrize("scale", ["", "paper/"])
def test_no_committed_saddle_note_prints_the_estimators_raw_refusal(scale):
    """Read as the pages read them (the paper scale's notes were written before the study said them so)."""
    doc = read_numbers_file(ROOT / "docs" / "studies" / "assets" / f"{scale}saddle.json")
    assert not [t for _, t in json_strings(doc) if "fewer than 4 neighbour scales in [" in t]
