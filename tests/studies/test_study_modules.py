"""The studies' code stays small and keeps its numbers in its configuration.

Every number that changes a study's results is a ``[study]`` key of its study.toml: the configuration's hash in
each numbers JSON (``made_from.config_sha256``) then changes with it, and a committed result made with another
value is found stale. A module-level numeric constant in a study.py would change the results without changing
the hash; only the constants of :data:`ALLOWED` (with their reason) are kept. And each study.py stays within
:data:`MAX_LINES` lines: the science goes into ``hhscatter.analysis``, the assembly of records into
``hhscatter.reproduction``.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MODULES = sorted((ROOT / "studies").glob("*/study.py"))

#: module-level numeric constants a study may keep: numbers the reference paper publishes (the study compares
#: with them, or falls back on them in development runs without the upstream study's numbers); they are not
#: settings of ours and never change
ALLOWED = {
    ("fig5", "PAPER_T_STAR"): "the paper's t* of Fig. 5",
    ("fig5", "PAPER_MU"): "the paper's μ, the development fallback for the upstream's",
    ("fig5", "PAPER_N_PLOTTED"): "the paper's count of plotted orbits",
    ("fig5", "PAPER_N"): "the paper's ensemble size",
    ("fig6", "DEV_TAU0"): "the development fallback for the upstream's τ0 (no published number)",
}

MAX_LINES = 500
#: studies longer than MAX_LINES, each at most as long as now: it may shrink, never grow (none now)
OVER_LIMIT: dict[str, int] = {}


def numeric_constants(source: str) -> list[str]:
    """The module-level names of ``source`` assigned an expression that holds a number literal (bools are not
    numbers here), upper case or not."""
    out = []
    for node in ast.parse(source).body:
        if isinstance(node, ast.Assign):
            targets, value = node.targets, node.value
        elif isinstance(node, ast.AnnAssign) and node.value is not None:
            targets, value = [node.target], node.value
        else:
            continue
        numbers = [
            c
            for c in ast.walk(value)
            if isinstance(c, ast.Constant) and isinstance(c.value, (int, float)) and not isinstance(c.value, bool)
        ]
        if numbers:
            out += [t.id for t in targets if isinstance(t, ast.Name)]
    return out


def test_the_check_finds_numeric_constants_and_nothing_else():
    source = (
        "import math\nTOP = 12.0\nGRID: int = 1201\n_HIDDEN = -0.3\nwidths = (1, 2)\nRATIO = 1 / 18\n"
        "NAME = 'rates.parquet'\nFLAG = True\nNONE = None\nKEYS = {'a': 'b'}\n"
        "class Params:\n    x: int = 4\ndef f():\n    LOCAL = 3\n"
    )
    assert numeric_constants(source) == ["TOP", "GRID", "_HIDDEN", "widths", "RATIO"]


@pytest.mark.parametrize("path", MODULES, ids=lambda p: p.parent.name)
def test_a_study_keeps_its_numbers_in_its_configuration(path):
    name = path.parent.name
    found = [c for c in numeric_constants(path.read_text(encoding="utf-8")) if (name, c) not in ALLOWED]
    assert not found, (
        f"studies/{name}/study.py defines module-level numeric constants {found}: make each a [study] key of "
        "its study.toml (declared in Params), so that the configuration's hash covers it"
    )


def test_every_allowed_constant_still_exists():
    defined = {(p.parent.name, c) for p in MODULES for c in numeric_constants(p.read_text(encoding="utf-8"))}
    assert set(ALLOWED) <= defined, sorted(set(ALLOWED) - defined)


@pytest.mark.parametrize("path", MODULES, ids=lambda p: p.parent.name)
def test_a_study_module_stays_within_its_line_limit(path):
    name = path.parent.name
    limit = max(MAX_LINES, OVER_LIMIT.get(name, 0))
    n = len(path.read_text(encoding="utf-8").splitlines())
    assert n <= limit, f"studies/{name}/study.py has {n} lines, more than {limit}"
