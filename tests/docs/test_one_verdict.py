"""One number, one verdict: every verdict the built site and the reproduction report show, read back from their
HTML, is the same wherever the same number of the same row appears (the claims table, the study's numbers table, the
studies index, the report), and it is the one rule's (hhscatter.reproduction.verdicts.row_verdict)."""

from __future__ import annotations

import re
from collections import defaultdict
from html.parser import HTMLParser
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
STUDIES = sorted(p.name for p in (ROOT / "studies").iterdir() if (p / "study.toml").is_file())


class _Tables(HTMLParser):
    """The text of every cell of every row of every <table>, header row first."""

    def __init__(self):
        super().__init__()
        self.tables, self._row, self._cell = [], None, None

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.tables.append([])
        elif tag == "tr" and self.tables:
            self._row = []
        elif tag in ("td", "th") and self._row is not None:
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self._row.append(" ".join("".join(self._cell).split()))
            self._cell = None
        elif tag == "tr" and self._row is not None:
            self.tables[-1].append(self._row)
            self._row = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def _study_and_quantity(cell: str, study: str):
    """'generality: [1] β … — hh' (the index links the study) -> ('generality', '[1] β … — hh')."""
    head, sep, rest = cell.partition(": ")
    return (head, rest) if sep and head in STUDIES else (study, cell)


def verdicts_shown(html: str, page: str) -> list[tuple[tuple[str, str, str], str]]:
    """[((study, quantity, our number), verdict)] of every table of a page that shows a verdict: paper-vs-ours
    tables (a 'verdict' column beside 'ours') and claims tables (cells 'value ± err: verdict')."""
    parser = _Tables()
    parser.feed(html)
    out = []
    for table in (t for t in parser.tables if len(t) > 1):
        head = [h.lower() for h in table[0]]
        v_col = next((i for i, h in enumerate(head) if h.startswith("verdict")), None)
        o_cols = [i for i, h in enumerate(head) if h.startswith("ours") and "quick" not in h]
        q_col = head.index("quantity") if "quantity" in head else None
        s_col = head.index("study") if "study" in head else None
        claims = head[:2] == ["claim", "quantity"]
        for row in table[1:]:
            if len(row) != len(head):
                continue
            if v_col is not None and o_cols and q_col is not None:
                study, qty = _study_and_quantity(row[q_col], row[s_col] if s_col is not None else page)
                out.extend(((study, qty, row[o]), row[v_col]) for o in o_cols if row[o] not in ("—", ""))
            if claims:
                for system, cell in zip(table[0][2:], row[2:], strict=True):
                    m = re.match(r"^(\S+ ± \S+): (.+)$", cell)
                    if m:
                        qty = f"[{row[0]}] {row[1]} — {system.split(' (')[0]}"
                        out.append(((page, qty, m.group(1)), m.group(2)))
    return out


def _conflicts(found) -> dict:
    seen = defaultdict(set)
    for key, verdict, where in found:
        seen[key].add((verdict, where))
    return {k: sorted(v) for k, v in seen.items() if len({x for x, _ in v}) > 1}


def test_the_reader_sees_two_verdicts_of_one_number():
    """The check itself: a claims cell and a numbers-table row of the same number with different verdicts."""
    claims = (
        "<table><tr><th>claim</th><th>quantity</th><th>hh (3 exits)</th></tr>"
        "<tr><td>1</td><td>β</td><td>1.46 ± 0.12: not quadratic (z = −4.5)</td></tr></table>"
    )
    numbers = (
        "<table><tr><th>quantity</th><th>ours</th><th>paper</th><th>verdict</th></tr>"
        "<tr><td>[1] β — hh</td><td>1.46 ± 0.12</td><td>2</td><td>agrees (z = −1.0)</td></tr></table>"
    )
    found = [(k, v, "a") for k, v in verdicts_shown(claims, "generality")]
    found += [(k, v, "b") for k, v in verdicts_shown(numbers, "generality")]
    assert list(_conflicts(found)) == [("generality", "[1] β — hh", "1.46 ± 0.12")]


@pytest.fixture(scope="module")
def report_html(paper_report_html):
    return paper_report_html  # tests/docs/conftest.py: built once per session


def test_a_number_has_one_verdict_on_the_site_and_in_the_report(built_site, report_html):
    found = []
    for path in sorted(Path(built_site).rglob("*.html")):
        page = path.stem if path.parent.name == "studies" else str(path.relative_to(built_site))
        found.extend((k, v, str(path.relative_to(built_site))) for k, v in verdicts_shown(path.read_text(), page))
    found.extend((k, v, "report.html") for k, v in verdicts_shown(report_html, "report"))
    keys = {k for k, _, _ in found}
    # the pages that compare: the claims of generality, its rows on the studies index, the report's rows
    assert {w for _, _, w in found} >= {"studies/generality.html", "studies/index.html", "report.html"}
    assert len(keys) > 200, len(keys)
    bad = _conflicts(found)
    assert not bad, "\n".join(f"{k}: {v}" for k, v in bad.items())


def test_the_generality_exponent_has_the_rule_of_an_exact_reference(built_site):
    """β below the break is compared with the exponent 2 of theory (exact), not with a printed digit ± 0.5: at
    each scale the page and the index show z = (β − 2)/σ_β."""
    from hhscatter.publish.numbers import load_numbers

    want = set()
    for scale in ("paper", "quick"):
        doc, _ = load_numbers(ROOT, "generality", scale)
        rec = next(c for c in doc["claims"] if c["id"] == "henon_heiles-1-2")
        assert rec["reference"] == 2.0 and "β below the break" in rec["quantity"]
        z = (rec["value"] - 2.0) / rec["err"]  # the reference is exact: our σ alone
        want.add(f"(z = {z:+.1f})".replace("-", "−"))
    shown = {
        v[v.index("(z = ") :]
        for p in ("studies/generality.html", "studies/index.html")
        for (_, q, _), v in verdicts_shown((Path(built_site) / p).read_text(), "generality")
        if q.startswith("[1] exponent β below the break") and q.endswith("henon_heiles")
    }
    assert shown == want, (shown, want)
