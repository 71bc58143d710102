"""A new built-in system is its entry in hhscatter/model/builtins.py and its derivation test: no other file of the
package, its tools or its tests names every built-in by hand (CONTRIBUTING.md, contributor paths)."""

from __future__ import annotations

from pathlib import Path

from hhscatter.model.builtins import BUILTINS

ROOT = Path(__file__).resolve().parents[2]


def _lists_of_every_builtin(root: Path) -> list[str]:
    """The lines of root's Python files (package, tools, tests) that name every built-in."""
    hits = []
    for folder in ("hhscatter", "tools", "tests"):
        for f in sorted((root / folder).rglob("*.py")):
            for i, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1):
                if all(name in line for name in BUILTINS):
                    hits.append(f"{f.relative_to(root)}:{i}")
    return hits


def test_only_the_registry_names_every_builtin():
    hits = [h for h in _lists_of_every_builtin(ROOT) if not h.startswith("hhscatter/model/builtins.py:")]
    assert hits == []


def test_the_scan_finds_a_hand_kept_list(tmp_path):
    (tmp_path / "tools").mkdir()
    (tmp_path / "tools" / "gallery.py").write_text(f"NAMES = {list(BUILTINS)!r}\n")
    assert _lists_of_every_builtin(tmp_path) == ["tools/gallery.py:1"]
