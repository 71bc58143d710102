"""The committed numbers name no place on the machine that made them: no string in a study's JSON is an absolute
path (a run is named by its key, a file by its name)."""

import json
import re
from pathlib import Path

from strings_of import json_strings

ASSETS = Path(__file__).resolve().parents[2] / "docs" / "studies" / "assets"
ABSOLUTE = re.compile(r"(?:^|[\s'\"(=])(?:/[\w.+-]+){2,}|\b[A-Za-z]:\\[\w.+-]+\\")


def test_the_pattern_finds_an_absolute_path_and_nothing_else():
    assert ABSOLUTE.search("in the snapshots table of /data/me/studies/out/raw/E0.30 (its points")
    assert ABSOLUTE.search(r"run C:\Users\me\runs")
    for text in ("κ/α against λ", "E/E_c = 1.5", "r < r_s/2", "1/γ = 33", "ln(E0/E_end)/(γ Σ t)", "docs/studies"):
        assert not ABSOLUTE.search(text), text


def test_no_committed_study_json_holds_an_absolute_path():
    found = [
        f"{path.relative_to(ASSETS)}:{where}: {text[:120]}"
        for path in sorted(ASSETS.rglob("*.json"))
        for where, text in json_strings(json.loads(path.read_text()))
        if ABSOLUTE.search(text)
    ]
    assert not found, "\n".join(found)
