"""A summary embedded in a page keeps every cell, in tables no wider than a page's text column."""

from __future__ import annotations

import re
from pathlib import Path

from hhscatter.publish.formatting import embed_markdown

ROOT = Path(__file__).resolve().parents[2]
SUMMARY = ROOT / "docs" / "benchmarks" / "assets" / "bench" / "summary.md"


def _tables(text: str) -> list[list[list[str]]]:
    out, cur = [], []
    for line in text.split("\n") + [""]:
        if line.startswith("|"):
            cur.append([c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]])
        elif cur:
            out.append(cur)
            cur = []
    return out


def test_the_benchmark_summary_embeds_as_tables_of_at_most_eight_columns_with_every_cell():
    raw = SUMMARY.read_text()
    wide = [t for t in _tables(raw) if len(t[0]) > 8]
    assert wide and len(wide[0][0]) == 15  # the work–precision table as the benchmark writes it
    embedded = _tables(embed_markdown(raw))
    assert max(len(t[0]) for t in embedded) <= 8
    head = wide[0][0]
    parts = [t for t in embedded if t[0][:3] == head[:3] and len(t) == len(wide[0])]
    assert [c for t in parts for c in t[0][3:]] == head[3:]  # every column once, after the label columns
    for i, row in enumerate(wide[0]):
        if i == 1:
            continue  # the |---| line
        assert all(t[i][:3] == row[:3] for t in parts)  # each part keeps the row's labels
        assert [c for t in parts for c in t[i][3:]] == row[3:]
