"""The built pages and the reproduction report read alike: a negative number is written with the minus sign "−" in
every table cell (one function, :func:`hhscatter.publish.formatting.typographic_minus`), Markdown never reads the
stars of a formula as emphasis (:func:`hhscatter.publish.formatting.formula_stars`), and a paper-vs-ours row shows the
same text on the studies index and in the report."""

from __future__ import annotations

import re
from html.parser import HTMLParser
from pathlib import Path

#: a hyphen-minus as the sign of a number ("-0.003", "(z = -1.1)") or of an exponent ("2.6e-05"); a hyphen inside a
#: word ("Wasserstein-1", "E0-E_c") or between two numbers (a range "0.2-0.5", a date) is not a sign
SIGN_HYPHEN = re.compile(r"(?<![\w])-\.?\d|(?<=\d[eE])-\d")
#: emphasis that opens or closes against a letter or a bracket: the stars of "E(t*) … τ*" read as emphasis
EATEN_STAR = re.compile(r"[\w)\]]<(em|strong)>|</(em|strong)>[\w(]")
_HIDDEN = re.compile(r"<(script|style|pre|code)\b.*?</\1>", re.S)
#: a breakable space between a number and its "±", comparison sign or "%" inside a table cell
LOOSE = re.compile(r"[±<>≤≥] (?=[\d−+.])|\d (?=%)")
_TD = re.compile(r"<t[dh]\b[^>]*>(.*?)</t[dh]>", re.S)


class _Cells(HTMLParser):
    """The text of every table cell, code left out; ``rows``: the cells of every row of every table."""

    def __init__(self):
        super().__init__()
        self.rows, self._row, self._cell, self._code = [], None, None, 0

    def handle_starttag(self, tag, attrs):
        if tag in ("code", "pre", "script", "style"):
            self._code += 1
        elif tag == "tr":
            self._row = []
        elif tag in ("td", "th") and self._row is not None:
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("code", "pre", "script", "style"):
            self._code -= 1
        elif tag in ("td", "th") and self._cell is not None:
            self._row.append(" ".join("".join(self._cell).split()))
            self._cell = None
        elif tag == "tr" and self._row is not None:
            self.rows.append(self._row)
            self._row = None

    def handle_data(self, data):
        if self._cell is not None and not self._code:
            self._cell.append(data)


def _rows(html: str) -> list[list[str]]:
    parser = _Cells()
    parser.feed(html)
    return parser.rows


def _reading_pages(site: Path):
    """The pages a reader reads: every page but the API reference (docstrings) and the notebook (its outputs)."""
    skip = ("api", "assets", "tutorial.html")
    return [p for p in sorted(Path(site).rglob("*.html")) if p.relative_to(site).parts[0] not in skip]


def _signs(html: str) -> list[str]:
    return [c for row in _rows(html) for c in row if SIGN_HYPHEN.search(c)]


def test_the_scans_find_a_hyphen_sign_and_an_eaten_star():
    """The checks themselves, on the faults they look for."""
    assert _signs("<table><tr><td>-0.003 [-0.010, +0.002]</td><td>2.6e-05</td></tr></table>") == [
        "-0.003 [-0.010, +0.002]",
        "2.6e-05",
    ]
    fine = "<table><tr><td>−0.003</td><td>2.6e−05</td><td>SW-1</td><td>0.2-0.5</td><td><code>x[-1]</code></td></tr>"
    assert _signs(fine + "</table>") == []
    assert EATEN_STAR.search("time at which E(t<em>) = E1; not τ</em>, the onset")
    assert not EATEN_STAR.search("<p><em>a caption</em>, and <strong>bold</strong> (x)</p>")


def test_no_table_cell_writes_a_negative_number_with_a_hyphen(built_site, paper_report_html):
    site = Path(built_site)
    found = {p.relative_to(site).as_posix(): _signs(p.read_text(errors="replace")) for p in _reading_pages(site)}
    found["report.html"] = _signs(paper_report_html)
    found = {k: v[:4] for k, v in found.items() if v}
    assert not found, found
    assert "−" in paper_report_html and "−" in (site / "studies" / "index.html").read_text()


def test_markdown_never_eats_a_star_of_a_formula(built_site, paper_report_html):
    site = Path(built_site)
    pages = {p.relative_to(site).as_posix(): p.read_text(errors="replace") for p in _reading_pages(site)}
    pages["report.html"] = paper_report_html
    eaten = {
        name: [html[max(0, m.start() - 40) : m.end() + 40] for m in EATEN_STAR.finditer(_HIDDEN.sub("", html))][:3]
        for name, html in pages.items()
    }
    eaten = {k: v for k, v in eaten.items() if v}
    assert not eaten, eaten
    assert "E(t*)" in pages["equations.html"]  # the glossary's t*: shown as written


def _index_rows(html: str) -> set[tuple[str, ...]]:
    """The paper-vs-ours rows of the studies index as the report writes them: its quantity cell "fig1: κ …" split
    into the study and the quantity."""
    out = set()
    for row in _rows(html):
        study, sep, quantity = row[0].partition(": ") if row else ("", "", "")
        if sep and len(row) >= 5:
            out.add((study, quantity, *row[1:]))
    return out


def test_a_row_reads_the_same_on_the_studies_index_and_in_the_report(built_site, paper_report_html):
    """Every paper-vs-ours row of the report that the site's studies index shows too (study, quantity, ours,
    convention, paper, verdict, note) has the same text in both: symbols, minus signs and stars alike."""
    site_rows = _index_rows((Path(built_site) / "studies" / "index.html").read_text())
    keys = {r[:2] for r in site_rows}
    compared = [tuple(r) for r in _rows(paper_report_html) if tuple(r[:2]) in keys and len(r) >= 6]
    assert len(compared) >= 50, len(compared)
    differ = [r for r in compared if r not in site_rows]
    assert not differ, "\n".join(" | ".join(r) for r in differ[:5])


def _loose_cells(html: str) -> list[str]:
    import html as h

    cells = (h.unescape(re.sub(r"<[^>]+>", "", c)) for c in _TD.findall(_HIDDEN.sub("", html)))
    return [c for c in cells if LOOSE.search(c)]


def test_a_table_cell_never_breaks_a_number_from_its_sign_or_unit(built_site):
    """In a narrow column of the site "0.9338 ± 0.0025" wraps before "±", never after it, and "< 3.0e−4 (95 %)" keeps
    "<" and "%" with their numbers: the spaces there are no-break spaces (hhscatter.publish.formatting.keep_together).
    The report's wider page keeps plain spaces (its Markdown is read as text too)."""
    assert _loose_cells("<table><tr><td>0.9 ± 0.1</td><td>&lt; 3e−4 (95 %)</td><td>0.9 ±\u00a00.1</td></tr>") == [
        "0.9 ± 0.1",
        "< 3e−4 (95 %)",
    ]
    site = Path(built_site)
    pages = {p.relative_to(site).as_posix(): p.read_text(errors="replace") for p in _reading_pages(site)}
    loose = {name: _loose_cells(html)[:3] for name, html in pages.items()}
    loose = {k: v for k, v in loose.items() if v}
    assert not loose, loose
