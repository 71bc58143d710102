"""Report and docs tables are rendered by a real Markdown library (Python-Markdown): every row of every table
in the generated HTML has as many cells as its header, also with |ΔH| in a cell (the benchmark summaries)."""

from __future__ import annotations

import json
import shutil
from html.parser import HTMLParser
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


class _Tables(HTMLParser):
    """Cell counts (colspan included) of every row of every <table>."""

    def __init__(self):
        super().__init__()
        self.tables, self._row = [], None

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.tables.append([])
        elif tag == "tr" and self.tables:
            self._row = 0
        elif tag in ("td", "th") and self._row is not None:
            self._row += int(dict(attrs).get("colspan") or 1)

    def handle_endtag(self, tag):
        if tag == "tr" and self._row is not None:
            self.tables[-1].append(self._row)
            self._row = None


def assert_rows_match_headers(page: str, at_least: int = 1) -> list:
    parser = _Tables()
    parser.feed(page)
    tables = [t for t in parser.tables if t]
    assert len(tables) >= at_least
    for i, rows in enumerate(tables):
        assert all(n == rows[0] for n in rows), f"table {i}: header has {rows[0]} cells, rows {rows}"
    return tables


def test_parser_sees_a_broken_table():
    with pytest.raises(AssertionError, match="header has 2 cells"):
        assert_rows_match_headers("<table><tr><th>a</th><th>b</th></tr><tr><td>1</td><td>2</td><td>3</td></tr></table>")


def _summaries(root: Path):
    """The committed benchmark and stress summaries (tables with |ΔH| cells, plain-text tables) as outputs."""
    for name in ("bench", "stress"):
        out = root.parent / "benchmarks" / "out" / name / "full"
        out.mkdir(parents=True)
        shutil.copy(DOCS / "benchmarks" / "assets" / name / "summary.md", out / "summary.md")


def test_report_html_tables_have_as_many_cells_as_their_headers(tmp_path):
    from hhscatter.publish.report import build_report

    root = tmp_path / "studies"
    _summaries(root)
    assert "|ΔH|" in (root.parent / "benchmarks" / "out" / "stress" / "full" / "summary.md").read_text()
    from hhscatter.studies import load_study
    from hhscatter.studies.provenance import config_sha256, sealed

    for name in ("tab2", "tabx"):  # not the names of the repository's studies (whose Params would check these)
        d = root / name / "out" / "quick"
        d.mkdir(parents=True)
        paper = "" if name == "tabx" else "Fig. 2"
        (root / name / "study.toml").write_text(
            f'[about]\ntitle = "{name}"\npaper = "{paper}"\nsummary = "s"\n[scene]\nn = 1\n'
        )
        rows = [
            {
                "quantity": "max |ΔH|/H | drift",
                "ours": 4.5e-10,
                "err": 1e-11,
                "paper": 0.0,
                "unit": "",
                "verdict": "differs",
                "note": "a | b",
            },
            {"quantity": "κ", "ours": "0.1 vs 0.2", "err": None, "paper": None, "verdict": None, "note": ""},
        ]
        config = load_study(name, "quick", root=root).config
        doc = {
            "kappa": {"value": 0.15, "err": 0.004},
            "paper_comparison": rows,
            "note|bar": "x|y",
            "config": config,
            "made_from": {"config_sha256": config_sha256(config), "upstream": {}, "raw_runs": {}},
        }
        (d / f"{name}.json").write_text(json.dumps(sealed(doc)))
    res = build_report("quick", out=tmp_path / "rep", root=root)
    tables = assert_rows_match_headers(res["html"].read_text(), at_least=6)
    assert [6, 6] in tables and [6] * 4 in tables  # the comparison tables: study, quantity, ours, paper, verdict, note
    # the Markdown report is the same text: Python-Markdown renders it with the same cells
    from hhscatter.publish.formatting import markdown_to_html

    assert_rows_match_headers(markdown_to_html(res["markdown"].read_text()), at_least=6)


def test_docs_pages_tables_have_as_many_cells_as_their_headers(tmp_path):
    markdown = pytest.importorskip("markdown")
    pytest.importorskip("pymdownx")
    from file_module import load_file

    hook = load_file(DOCS / "_hooks" / "studies.py", "hh_docs_hook_tables")
    extensions = [
        "admonition",
        "attr_list",
        "def_list",
        "footnotes",
        "md_in_html",
        "tables",
        "pymdownx.details",
        "pymdownx.superfences",
    ]
    pages = {f"studies/{p.parent.name}.md": p for p in sorted((ROOT / "studies").glob("*/page.md"))}
    pages.update(
        {
            "studies/index.md": DOCS / "studies" / "index.md",
            "benchmarks/index.md": DOCS / "benchmarks" / "index.md",
            "cli.md": DOCS / "cli.md",
        }
    )

    class File:
        pass

    class Page:
        file = File()

    config = {"docs_dir": str(DOCS), "config_file_path": str(ROOT / "mkdocs.yml")}
    n_tables = 0
    for uri, src in pages.items():
        Page.file.src_uri = uri
        text = hook.on_page_markdown(src.read_text(), page=Page(), config=config, files=None)
        html = markdown.markdown(text, extensions=extensions)
        n_tables += len(assert_rows_match_headers(html, at_least=0))
    assert n_tables >= 20
