"""A count of 0 is written as its one-sided 95 % bound wherever a page or the report prints it: the comparison
rows, the folded table of all the numbers a study wrote, the report's headline numbers. Never "0 [0, hi]" (a
two-sided interval around a count of nothing) nor "0 ± 0"."""

from __future__ import annotations

import html
import re
from pathlib import Path

#: a count of 0 written as an interval or with a zero error (the text between the tags)
ZERO_AS_INTERVAL = re.compile(r"(?<![\w.,−-])0 \[0(?:\.0*)?, |(?<![\w.,−-])0 ± 0(?![\d.])")


def _text(page: str) -> str:
    return html.unescape(re.sub(r"<[^>]+>", " ", page))


def zeros_written_as_intervals(page: str) -> list[str]:
    """The places of a page (its text) that write a count of 0 as an interval, with some context."""
    text = _text(page)
    return [text[max(0, m.start() - 60) : m.end() + 20].replace("\n", " ") for m in ZERO_AS_INTERVAL.finditer(text)]


def test_the_pattern_finds_what_it_looks_for():
    page = "<td>0 [0, 1.667×10<sup>-5</sup>]</td><td>0 ± 0</td><td>0.0 [0.0, 0.1]</td>"
    assert len(zeros_written_as_intervals(page)) == 2
    fine = "<td>&lt; 5.0e-5 (95 %)</td><td>0.003 [0.0027, 0.0032]</td><td>10 [0, 3]</td><td>0 ± 0.003</td>"
    assert zeros_written_as_intervals(fine) == []


def test_no_count_of_zero_is_an_interval_on_the_site_or_in_the_report(built_site, paper_report_html):
    found = []
    for path in sorted(Path(built_site).rglob("*.html")):
        if path.relative_to(built_site).parts[0] == "api":
            continue  # the API reference explains the rule ("never 0 ± 0"), it prints no result
        found += [f"{path.relative_to(built_site)}: {c}" for c in zeros_written_as_intervals(path.read_text())]
    found += [f"report.html: {c}" for c in zeros_written_as_intervals(paper_report_html)]
    assert not found, "\n".join(found[:20])
