"""The property tests share one hypothesis profile (conftest.py): derandomized, without an example database or a
deadline; a test module sets only its number of examples, never its own copy of the rest."""

from __future__ import annotations

import ast
from pathlib import Path

from hypothesis import settings

TESTS = Path(__file__).resolve().parent
#: what the profile alone sets
SHARED = {"deadline", "derandomize", "database", "suppress_health_check"}


def own_profile_settings(source: str) -> list[tuple[int, str]]:
    """(line, keyword) of every ``settings(...)`` call that sets what the shared profile sets."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call):
            name = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
            if name == "settings":
                out += [(node.lineno, k.arg) for k in node.keywords if k.arg in SHARED]
    return out


def test_the_suite_runs_under_the_shared_profile():
    s = settings.default
    assert settings.get_current_profile_name() == "hhscatter"
    assert s.derandomize is True and s.database is None and s.deadline is None


def test_the_check_sees_a_module_of_its_own_profile():
    source = "from hypothesis import settings\nP = settings(max_examples=5, derandomize=True)\nQ = settings(max_examples=9)\n"
    assert own_profile_settings(source) == [(2, "derandomize")]


def test_no_test_module_repeats_the_profile():
    bad = [
        f"{path.relative_to(TESTS)}:{n} {kw}"
        for path in sorted(TESTS.rglob("*.py"))
        if path.name != "conftest.py"
        for n, kw in own_profile_settings(path.read_text())
    ]
    assert not bad, bad
