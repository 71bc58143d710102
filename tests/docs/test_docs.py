"""The documentation's generated parts: the MkDocs hook (docs/_hooks/studies.py),
the asset copier (docs/gen_studies.py) and the consistency of mkdocs.yml with
the pages and modules. The site build itself (`make docs`, mkdocs --strict)
runs in CI; these tests need no docs extra and take well under a second.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from file_module import load_file

from hhscatter.studies.provenance import sealed

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


_load = load_file


@pytest.fixture(scope="module")
def hook():
    return _load(DOCS / "_hooks" / "studies.py", "hh_docs_hook")


@pytest.fixture(scope="module")
def gen():
    return _load(DOCS / "gen_studies.py", "hh_docs_gen")


# -- number formatting ----------------------------------------------------------
@pytest.mark.parametrize(
    "v, err, want",
    [
        (0.12345, 0.00678, "0.123 ± 0.007"),  # err to 1 significant digit (2 if it starts with 1 or 2), v alike
        (13.63, 1.234, "13.6 ± 1.2"),
        (1.41, 0.05, "1.41 ± 0.05"),
        (-0.00017021, 0.00106, "-0.0002 ± 0.0011"),
        (250.0, 31.0, "250 ± 31"),
        (0.5, None, "0.5"),
        (0.5, 0.0, "0.5"),  # an error of exactly 0 is not written: never "± 0"
        (0.0, 0.0, "0"),
    ],
)
def test_fmt_err(hook, v, err, want):
    assert hook.fmt_err(v, err) == want


def test_fmt_value_shapes(hook):
    assert hook.fmt_value({"value": 0.339, "lo": 0.3285, "hi": 0.3497}) == "0.339 [0.3285, 0.3497]"
    assert hook.fmt_value({"value": None, "err": None}) == "—"
    assert hook.fmt_value([1.03, 1.1]) == "[1.03, 1.1]"
    assert "20 entries" in hook.fmt_value(list(range(20)))
    assert hook.fmt_num(2.5e-9) == "2.500×10<sup>-9</sup>"
    assert hook.fmt_num(True) == "true"


def test_comparison_table_escapes_pipes_and_keeps_every_row(hook):
    rows = [
        {"quantity": "a | b", "ours": 1.0, "err": 0.1, "paper": 1.1, "verdict": "agrees within 2σ", "note": "n"},
        {"quantity": "c", "ours": "yes", "err": None, "paper": "yes", "verdict": None, "note": ""},
    ]
    table = hook.comparison_table(rows)
    lines = table.strip().splitlines()
    assert len(lines) == 2 + len(rows)
    assert "a \\| b" in lines[2] and "1.00 ± 0.10" in lines[2]
    # every body row has as many cells as the header
    n = lines[0].count(" | ")
    assert all(line.replace("\\|", "").count(" | ") == n for line in lines[2:])


# -- the CLI reference ------------------------------------------------------------
def test_cli_reference_lists_every_flag_of_every_subcommand(hook):
    import argparse

    from hhscatter.cli import build_parser

    parser = build_parser()
    text = hook.cli_reference(parser)
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    assert set(sub.choices) >= {"simulate", "survival", "study"}
    for name, p in sub.choices.items():
        assert f"## `hhscatter {name}`" in text
        for a in p._actions:
            for opt in a.option_strings:
                if opt not in ("-h", "--help"):
                    assert f"`{opt}" in text or f", {opt}" in text, (name, opt)


# -- study pages: present and missing assets ---------------------------------------
def _page(tmp_path, hook, text, src_uri="studies/x.md"):
    docs = tmp_path / "docs"
    (docs / "studies" / "assets").mkdir(parents=True, exist_ok=True)
    (tmp_path / "mkdocs.yml").write_text("site_name: t\n")

    class File:
        pass

    class Page:
        file = File()

    Page.file.src_uri = src_uri
    config = {"docs_dir": str(docs), "config_file_path": str(tmp_path / "mkdocs.yml")}
    return hook.on_page_markdown(text, page=Page(), config=config, files=None), docs


def test_missing_assets_give_a_note_not_a_link(tmp_path, hook):
    md = "\n".join(f"<!-- hh:{k} fig2 -->" for k in ("study-params", "study-figure", "study-numbers", "study-module"))
    md += "\n<!-- hh:bench bench -->\n<!-- hh:comparison-all -->\n"
    (tmp_path / "studies" / "figx").mkdir(parents=True)  # a study folder (the list comes from the folders)
    (tmp_path / "studies" / "figx" / "study.toml").write_text("[scene]\nn = 1\n")
    out, _ = _page(tmp_path, hook, md)
    assert "<!-- hh:" not in out
    assert out.count('"Not yet generated"') == 5  # params, figure, numbers, module, bench
    assert "assets/" not in out  # no link to a file that is not there
    assert "*Not yet generated: [figx](figx.md).*" in out  # comparison-all lists the study folders without numbers


def test_present_assets_render_figure_numbers_and_params(tmp_path, hook):
    (tmp_path / "studies" / "fig2").mkdir(parents=True)
    (tmp_path / "studies" / "fig2" / "study.toml").write_text("[scene]\nn = 10  # orbits\n")
    docs = tmp_path / "docs"
    assets = docs / "studies" / "assets"
    assets.mkdir(parents=True)
    (assets / "fig2.png").write_bytes(b"\x89PNG")
    doc = {
        "study": "fig2",
        "scale": "quick",
        "a": {"value": 13.1, "err": 0.52},
        "tau0_rule": "τ0 is where the local slope settles within 10 % of its plateau (documented rule)",
        "per_gamma": [{"gamma": 0.01, "tau1": {"value": 17.2, "err": 1.0}}, {"gamma": 0.02, "tau1": None}],
        "paper_comparison": [
            {
                "quantity": "a",
                "ours": 13.1,
                "err": 0.52,
                "paper": 13.63,
                "unit": "",
                "verdict": "agrees within 2σ",
                "note": "",
            }
        ],
        "config": {},
        "provenance": {"hhscatter": "0.1.0", "git_commit": "0123456789abcdef"},
    }
    (assets / "fig2.json").write_text(json.dumps(sealed(doc)))
    md = "<!-- hh:study-params fig2 -->\n<!-- hh:study-figure fig2 -->\n<!-- hh:study-numbers fig2 -->\n"
    out, _ = _page(tmp_path, hook, md)
    assert "n = 10  # orbits" in out
    assert "](assets/fig2.png)" in out
    assert "| a | 13.1 ± 0.5 | 13.63 | agrees (z = −1.0) |" in out  # −0.53/√(0.52² + 0.005²): the one rule
    assert "    `tau0_rule`\n    :   τ0 is where" in out  # the rules, folded
    assert "| `gamma` | `tau1` |" in out and "| 0.01 | 17.2 ± 1.0 |" in out
    assert "scale **quick**" in out and "commit `0123456789ab`" in out
    assert "](assets/fig2.json)" in out


def test_a_figure_with_panels_shows_each_at_its_natural_width_the_composite_folded(tmp_path, hook):
    (tmp_path / "studies" / "fig5").mkdir(parents=True)
    assets = tmp_path / "docs" / "studies" / "assets"
    (assets / "paper").mkdir(parents=True)
    for f in ("fig5.png", "fig5_panel_a.png", "fig5_panel_b.png"):
        (assets / "paper" / f).write_bytes(b"\x89PNG")
    (assets / "fig5.png").write_bytes(b"\x89PNG")  # the quick scale: no panels, the composite
    out, _ = _page(tmp_path, hook, "<!-- hh:study-figure fig5 -->\n")
    head, folded = out.split("??? note", 1)
    assert head.count('class="hh-figure hh-panel"') == 2 and "](assets/paper/fig5_panel_a.png){ .hh-zoom }" in head
    assert "(a) paper scale" in head and "(b) paper scale" in head and "assets/paper/fig5.png" not in head
    assert '"The panels in one image (click to open)"' in folded and "](assets/paper/fig5.png){ .hh-zoom }" in folded
    assert "](assets/fig5.png){ .hh-zoom }" in folded  # the quick scale below, folded too


def test_generated_tables_refuse_an_edited_numbers_json(tmp_path, hook):
    """The generated tables read a study's JSON as the number references do: one whose content no longer matches
    the hash it was written with (a number edited by hand), or one never sealed, fails the build."""
    from mkdocs.exceptions import PluginError

    (tmp_path / "studies" / "fig2").mkdir(parents=True)
    (tmp_path / "studies" / "fig2" / "study.toml").write_text("[scene]\nn = 10\n")
    assets = tmp_path / "docs" / "studies" / "assets"
    assets.mkdir(parents=True)
    row = {"quantity": "a", "ours": 13.1, "err": 0.52, "paper": 13.63, "verdict": None, "note": ""}
    doc = sealed({"study": "fig2", "scale": "quick", "a": 13.1, "paper_comparison": [row], "config": {}})
    out, _ = _page(tmp_path, hook, "<!-- hh:study-numbers fig2 -->\n")
    assert "13.1 ± 0.5" not in out  # nothing written yet: a note, not a table
    (assets / "fig2.json").write_text(json.dumps(doc))
    assert "| a | 13.1 ± 0.5 | 13.63 |" in _page(tmp_path, hook, "<!-- hh:study-numbers fig2 -->\n")[0]
    edited = json.loads((assets / "fig2.json").read_text())
    edited["paper_comparison"][0]["ours"] = 13.5
    (assets / "fig2.json").write_text(json.dumps(edited))
    with pytest.raises(PluginError, match="not as its study wrote it"):
        _page(tmp_path, hook, "<!-- hh:study-numbers fig2 -->\n")
    (assets / "fig2.json").write_text(json.dumps({k: v for k, v in doc.items() if k != "sha256"}))
    with pytest.raises(PluginError, match="not as its study wrote it"):
        _page(tmp_path, hook, "<!-- hh:study-numbers fig2 -->\n")


def test_claims_table_is_claims_by_systems_paper_scale_first(tmp_path, hook):
    """hh:claims-table: one row per (claim, quantity), one column per system, each cell value ± err: verdict;
    a system without a record for a row is "—"; the paper scale leads and the quick scale is folded below."""
    assets = tmp_path / "docs" / "studies" / "assets"
    (assets / "paper").mkdir(parents=True)

    def doc(scale, kappa):
        return {
            "study": "gx",
            "scale": scale,
            "provenance": {"git_commit": "abcdef0123456789"},
            "systems": {"hh": {"n_exits": 3, "E_c": 1 / 6}, "two": {"n_exits": 2, "E_c": 0.5}},
            "claims": [
                {
                    "claim": "1",
                    "quantity": "κ0",
                    "system": "hh",
                    "value": kappa,
                    "err": 0.0123,
                    "verdict": "agrees (z = +0.1)",
                },
                {
                    "claim": "1",
                    "quantity": "κ0",
                    "system": "two",
                    "value": None,
                    "err": None,
                    "verdict": "undetermined: 97% trapped",
                },
                {"claim": "3", "quantity": "μ", "system": "two", "value": 0.98, "err": None, "verdict": "measured"},
                {"claim": "2", "quantity": "κ_cm", "system": "hh", "value": 0.1, "err": None, "verdict": "ok"},
            ],
        }

    (assets / "gx.json").write_text(json.dumps(sealed(doc("quick", 0.3))))
    out, _ = _page(tmp_path, hook, "<!-- hh:claims-table gx -->\n")
    assert "| claim | quantity | hh (3 exits, E_c = 0.1667) | two (2 exits, E_c = 0.5) |" in out
    assert "| 1 | κ0 | 0.300 ± 0.012: agrees (z = +0.1) | n/a: undetermined: 97% trapped |" in out
    assert "| 3 | μ | — | 0.98: measured |" in out
    assert out.index("| 1 | κ0 |") < out.index("| 2 | κ_cm |") < out.index("| 3 | μ |")  # by claim
    assert "Scale **quick**" in out and "???" not in out
    (assets / "paper" / "gx.json").write_text(json.dumps(sealed(doc("paper", 0.25))))
    out, _ = _page(tmp_path, hook, "<!-- hh:claims-table gx -->\n")
    first, folded = out.split("???", 1)
    assert "0.250 ± 0.012" in first and "Scale **paper**" in first and "0.300" not in first
    assert "0.300 ± 0.012" in folded and "Scale **quick**" in folded


def test_unknown_marker_fails_the_build(tmp_path, hook):
    with pytest.raises(ValueError, match="hh:no-such-thing"):
        _page(tmp_path, hook, "<!-- hh:no-such-thing -->\n")


def test_embedded_summary_links_are_rebased_or_dropped(tmp_path, hook):
    assets = tmp_path / "assets" / "bench"
    assets.mkdir(parents=True)
    (assets / "wp.png").write_bytes(b"")
    text = "# Title\n![plot](wp.png) and [the csv](missing.csv) and [web](https://example.org)\n"
    out = hook._embed_markdown(text, assets, lambda p: "assets/bench/" + p.name)
    assert out.startswith("### Title")
    assert "![plot](assets/bench/wp.png)" in out
    assert "the csv" in out and "missing.csv" not in out
    assert "[web](https://example.org)" in out


def test_sphinx_roles_become_inline_code():
    pytest.importorskip("griffe")
    roles = _load(DOCS / "_hooks" / "griffe_roles.py", "hh_docs_roles")
    text = "see :func:`survival_curve`, :class:`~hhscatter.scene.scene.Scene` and ``x``"
    assert roles.roles_to_code(text) == "see `survival_curve`, `Scene` and ``x``"


def test_embedded_summary_tables_survive_abs_bars_and_plain_text(hook, tmp_path):
    text = (
        "| case | finding |\n|---|---|\n| drift | max |ΔH|/H = 4.5e-10 |\n\n"
        "         tol     t\n1.0e-09   1.0\n1.0e-12   2.0\n"
    )
    out = hook._embed_markdown(text, tmp_path, lambda p: p.name)
    rows = out.splitlines()
    assert rows[2] == "| drift | max \\|ΔH\\|/H = 4.5e-10 |"  # still 2 cells
    assert rows[1] == "|---|---|"
    i = rows.index("```text")
    assert rows[i + 1].strip().startswith("tol") and rows[i + 3] == "1.0e-12   2.0" and rows[i + 4] == "```"


# -- the asset copier ---------------------------------------------------------------
def test_gen_studies_copies_what_exists_and_reports_the_rest(tmp_path, gen, monkeypatch):
    monkeypatch.setattr(gen, "ROOT", tmp_path)
    monkeypatch.setattr(gen, "DOCS", tmp_path / "docs")
    out = tmp_path / "studies" / "fig3" / "out" / "quick"
    out.mkdir(parents=True)
    (out / "fig3.png").write_bytes(b"png")
    (out / "fig3.json").write_text("{}")
    (out.parents[1] / "study.toml").write_text("[scene]\nn = 1\n")  # a study is a folder with a study.toml
    bench = tmp_path / "benchmarks" / "out" / "bench" / "full"
    bench.mkdir(parents=True)
    (bench / "summary.md").write_text("# s\n")
    (bench / "big.csv").write_bytes(b"x" * (gen.CSV_MAX_BYTES + 1))
    (bench / "ref.npz").write_bytes(b"")
    assert gen.main(["--scale", "quick"]) == 0
    assets = tmp_path / "docs" / "studies" / "assets"
    assert sorted(p.name for p in assets.iterdir()) == ["fig3.json", "fig3.png"]
    assert sorted(p.name for p in (tmp_path / "docs" / "benchmarks" / "assets" / "bench").iterdir()) == ["summary.md"]
    assert gen.main(["--check"]) == 0
    (out / "fig3.json").write_text('{"changed": 1}')
    assert gen.main(["--check"]) == 1


def test_gen_studies_puts_another_scale_in_its_own_folder_with_the_costs(tmp_path, gen, monkeypatch):
    monkeypatch.setattr(gen, "ROOT", tmp_path)
    monkeypatch.setattr(gen, "DOCS", tmp_path / "docs")
    out = tmp_path / "studies" / "fig3" / "out" / "paper"
    out.mkdir(parents=True)
    for name, text in (("fig3.png", "png"), ("fig3.json", "{}"), ("cost.json", '{"simulate": []}')):
        (out / name).write_text(text)
    (out.parents[1] / "study.toml").write_text("[scene]\nn = 1\n")
    assert gen.main(["--scale", "paper"]) == 0
    paper = tmp_path / "docs" / "studies" / "assets" / "paper"
    assert sorted(p.name for p in paper.iterdir()) == ["fig3.cost.json", "fig3.json", "fig3.png"]
    assert not (tmp_path / "docs" / "benchmarks").exists()  # the benchmarks have scales of their own
    assert not any(p.is_file() for p in (tmp_path / "docs" / "studies" / "assets").iterdir())


def test_gen_studies_copies_the_panels_once_and_drops_those_of_an_earlier_layout(tmp_path, gen, monkeypatch):
    monkeypatch.setattr(gen, "ROOT", tmp_path)
    monkeypatch.setattr(gen, "DOCS", tmp_path / "docs")
    out = tmp_path / "studies" / "fig5" / "out" / "paper"
    out.mkdir(parents=True)
    for name in ("fig5.png", "fig5_panel_a.png", "fig5_panel_b.png", "fig5.json"):
        (out / name).write_text(name)
    (out.parents[1] / "study.toml").write_text("[scene]\nn = 1\n")
    paper = tmp_path / "docs" / "studies" / "assets" / "paper"
    paper.mkdir(parents=True)
    (paper / "fig5_panel_c.png").write_text("a panel the plot stage no longer writes")
    (paper / "fig6_panel_a.png").write_text("another study's panel: kept")
    pairs, _ = gen.plan("paper")
    assert len(pairs) == len(set(pairs)) == 4  # each file once
    assert gen.main(["--scale", "paper"]) == 0
    assert sorted(p.name for p in paper.iterdir()) == [
        "fig5.json",
        "fig5.png",
        "fig5_panel_a.png",
        "fig5_panel_b.png",
        "fig6_panel_a.png",
    ]


# -- mkdocs.yml against the pages and the package -------------------------------------
def test_nav_pages_and_api_modules_exist():
    yaml = pytest.importorskip("yaml")
    cfg = yaml.safe_load((ROOT / "mkdocs.yml").read_text())

    def pages(node):
        if isinstance(node, str):
            yield node
        elif isinstance(node, list):
            for x in node:
                yield from pages(x)
        elif isinstance(node, dict):
            for x in node.values():
                yield from pages(x)

    nav = list(pages(cfg["nav"]))
    for p in nav:
        assert (DOCS / p).exists(), p
    for md in DOCS.rglob("*.md"):
        for mod in re.findall(r"^::: ([\w.]+)", md.read_text(), flags=re.M):
            path = ROOT / Path(*mod.split("."))
            assert path.with_suffix(".py").exists() or (path / "__init__.py").exists(), (md, mod)
    assert cfg["theme"]["font"] is False  # no Google Fonts: the build and the site stay offline


def test_study_pages_put_the_figure_first_and_fold_the_configuration(hook):
    page = (
        "# Fig 9\n\nintro line\n\n## What it computes\n\nprose\n\n```text\n## not a heading\n```\n\n"
        "## Parameters\n\n<!-- hh:study-params fig9 -->\n\n## Figure\n\n<!-- hh:study-figure fig9 -->\n\n"
        "## Numbers\n\n<!-- hh:study-numbers fig9 -->\n\n## Implementation\n\n<!-- hh:study-module fig9 -->\n"
    )
    out = hook.figure_first(page, "what fig 9 shows")
    order = [
        out.index(s)
        for s in (
            "intro line",
            "**What it shows:** what fig 9 shows.",
            "## Figure",
            "## What it computes",
            "## not a heading",
            "## Numbers",
            "## Parameters",
            "## Implementation",
        )
    ]
    assert order == sorted(order), out
    assert sorted(out.split("\n")) == sorted((page + "\n**What it shows:** what fig 9 shows.\n\n").split("\n"))
    assert hook.figure_first("# no sections\n") == "# no sections\n"
    r = hook.Renderer(ROOT, DOCS, DOCS / "studies")
    folded = r.study_params("fig2")
    assert folded.startswith('??? abstract "Configuration: `studies/fig2/study.toml`')
    assert all(not line or line.startswith("    ") for line in folded.splitlines()[1:])  # all of it inside


def test_citation_and_licence_agree_with_pyproject():
    import tomllib

    yaml = pytest.importorskip("yaml")
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0" and cff["type"] == "software" and cff["authors"]
    assert cff["version"] == project["version"] and cff["license"] == project["license"] == "MIT"
    paper = cff["references"][0]
    assert paper["title"] == "Probabilistic description of dissipative chaotic scattering"
    assert [a["family-names"] for a in paper["authors"]] == ["Burton", "Dullin", "Altmann"]
    assert "doi" not in paper  # none is known (add it when published)
    assert {"type": "other", "value": "arXiv:2308.13555"}.items() <= paper["identifiers"][0].items()
    assert paper["url"] == "https://arxiv.org/abs/2308.13555" and paper["year"] == 2023
    for where in ("README.md", "docs/index.md"):  # the paper by its arXiv id wherever it is cited first
        assert "arXiv:2308.13555" in (ROOT / where).read_text() and ".tex" not in (ROOT / where).read_text()
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")


def test_every_library_module_has_an_api_page():
    """A study page may link any analysis function; mkdocs --strict fails on a module without a page (seen:
    two new modules linked from a study page), so every module of the layers has one."""
    documented = set(_load(DOCS / "_hooks" / "api_pages.py", "hh_api_pages").api_pages().values())
    for md in DOCS.rglob("*.md"):
        documented |= set(re.findall(r"^::: ([\w.]+)", md.read_text(), flags=re.M))
    missing = []
    for p in (ROOT / "hhscatter").rglob("*.py"):
        parts = list(p.relative_to(ROOT).with_suffix("").parts)
        if any(x.startswith("_") and x != "__init__" for x in parts) or parts[1:2] == ["cli"]:
            continue  # private modules; the CLI has its own page (cli.md)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if parts[:2] == ["hhscatter", "api"] and "hhscatter.api" in documented:
            continue  # the notebook API's modules: its page shows every public name of the package
        if len(parts) > 1 and ".".join(parts) not in documented and ".".join(parts) != "hhscatter.analysis":
            missing.append(".".join(parts))
    assert not missing, f"modules without an API page (docs/api/...md with '::: module'): {missing}"


def test_api_pages_and_their_navigation_are_generated_from_the_package(tmp_path):
    """A new module gets a page and a navigation line without a file under docs/; the layers keep their order."""
    gen = _load(DOCS / "_hooks" / "api_pages.py", "hh_api_pages")
    pkg = tmp_path / "pkg"
    for rel in (
        "__init__.py",
        "cli.py",
        "errors.py",
        "_private.py",
        "analysis/__init__.py",
        "analysis/survival/__init__.py",
        "analysis/survival/rates.py",
        "analysis/stats/__init__.py",
        "analysis/stats/intervals.py",
        "analysis/_exports.py",
        "model/__init__.py",
        "model/base.py",
    ):
        (pkg / rel).parent.mkdir(parents=True, exist_ok=True)
        (pkg / rel).write_text("")
    pages = gen.api_pages(tmp_path, "pkg")
    assert pages == {
        "api/errors.md": "pkg.errors",
        "api/analysis/index.md": "pkg.analysis",
        "api/analysis/stats/index.md": "pkg.analysis.stats",
        "api/analysis/stats/intervals.md": "pkg.analysis.stats.intervals",
        "api/analysis/survival/index.md": "pkg.analysis.survival",
        "api/analysis/survival/rates.md": "pkg.analysis.survival.rates",
        "api/model/index.md": "pkg.model",
        "api/model/base.md": "pkg.model.base",
    }
    order = ["errors", "model", "analysis", "analysis.stats", "analysis.survival"]
    assert gen.api_nav(pages, order, "pkg") == [
        "api/index.md",
        {"pkg.errors": "api/errors.md"},
        {"pkg.model": ["api/model/index.md", {"base": "api/model/base.md"}]},
        {
            "pkg.analysis": [
                "api/analysis/index.md",
                {"stats": ["api/analysis/stats/index.md", {"intervals": "api/analysis/stats/intervals.md"}]},
                {"survival": ["api/analysis/survival/index.md", {"rates": "api/analysis/survival/rates.md"}]},
            ]
        },
    ]
    assert (
        gen.page_text("api/model/base.md", "pkg.model.base")
        == "::: pkg.model.base\n    options:\n      heading_level: 1\n"
    )
    assert "members: false" in gen.page_text("api/model/index.md", "pkg.model")


@pytest.mark.parametrize(
    "value, goal, want",
    [
        (1.32, "≤ 1 (0.8)", False),
        (0.9, "≤ 1 (0.8)", True),
        (1.04, "≥ 2", False),
        (2.0, "≥ 2", True),
        (3.0, "fast", None),
    ],
)
def test_a_benchmark_goal_is_read_from_its_text(hook, value, goal, want):
    assert hook.goal_met(value, goal) is want


def test_benchmarks_page_opens_with_goals_and_a_count(tmp_path, hook):
    eng = tmp_path / "docs" / "benchmarks" / "assets" / "engine"
    eng.mkdir(parents=True)
    (eng / "engine.csv").write_text(
        "target,measure,value,goal,note\nbare,engine µs/orbit,10.0,,\n"
        "bare,engine / yardstick,1.32,≤ 1 (0.8),\nrec,marginal,1.9,≤ 2,\n"
    )
    out, _ = _page(tmp_path, hook, "<!-- hh:bench-goals -->\n")
    assert "**1 of 2 goals met**" in out
    assert (
        "| bare | engine / yardstick | ≤ 1 (0.8) | 1.32 | **no** |" in out
        and "| rec | marginal | ≤ 2 | 1.9 | yes |" in out
    )


def test_study_figure_is_the_paper_scale_at_full_width_and_the_quick_one_folded(tmp_path, hook):
    (tmp_path / "studies" / "fig2").mkdir(parents=True)
    assets = tmp_path / "docs" / "studies" / "assets"
    (assets / "paper").mkdir(parents=True)
    (assets / "fig2.png").write_bytes(b"\x89PNG")
    (assets / "paper" / "fig2.png").write_bytes(b"\x89PNG")
    out, _ = _page(tmp_path, hook, "<!-- hh:study-figure fig2 -->\n")
    main, folded = out.split("??? note")
    assert 'class="hh-figure"' in main and "(assets/paper/fig2.png){ .hh-zoom }" in main
    assert "(assets/fig2.png){ .hh-zoom }" in folded and "quick scale" in folded


def test_a_further_figure_names_the_make_target_of_its_study(tmp_path, hook):
    """`<study>_<part>.png` is drawn by study <study>: its caption's command is `make <study>`, which exists."""
    (tmp_path / "studies" / "operator").mkdir(parents=True)
    (tmp_path / "studies" / "operator" / "study.toml").write_text('[about]\ntitle = "Transfer operators"\n')
    assets = tmp_path / "docs" / "studies" / "assets"
    (assets / "paper").mkdir(parents=True)
    (assets / "paper" / "operator_dissipative.png").write_bytes(b"\x89PNG")
    (assets / "operator_dissipative.png").write_bytes(b"\x89PNG")
    out, _ = _page(tmp_path, hook, "<!-- hh:study-figure operator_dissipative -->\n")
    assert "<code>make operator SCALE=paper</code>" in out and "<code>make operator</code>" in out
    assert "make operator_dissipative" not in out


def test_an_indented_marker_is_rendered_indented(tmp_path, hook):
    out, _ = _page(tmp_path, hook, '??? note "x"\n\n    <!-- hh:verdict-rule -->\n')
    assert "\n    !!! info" in out and "both uncertainties" in out


def test_the_outcomes_and_the_study_list_come_from_the_code(tmp_path, hook):
    import hhscatter.outcomes as oc
    from hhscatter.studies.graph import studies

    out = hook.Renderer(ROOT, DOCS, DOCS / "concepts").outcomes()
    assert [line.split("`")[1] for line in out.splitlines()] == list(oc.OUTCOMES)
    assert "- `stopped`: stopped early" in out and "(censors the lifetime)" in out
    names = hook.Renderer(ROOT, DOCS, DOCS).study_names()
    assert all(f"[{s.name}](studies/{s.name}.md)" in names for s in studies(ROOT / "studies"))
    assert f"builds {len(studies(ROOT / 'studies'))} studies" in names


def test_evidence_tables_render_the_records_at_the_headline_scale(tmp_path, hook):
    """hh:evidence-tables: the regular fraction as E/E_c × systems (per IC convention, in %), the long-time fits
    and the r_esc rows, from the paper-scale JSON when committed."""
    assets = tmp_path / "docs" / "studies" / "assets"
    (assets / "paper").mkdir(parents=True)
    doc = {
        "study": "gx",
        "scale": "paper",
        "regular_fraction": [
            {"label": "two", "ics": "disk/tangential", "e_ratio": r, "fraction": f, "err": 0.01, "syst": 0.05}
            for r, f in ((1.05, 0.75), (1.5, 0.1))
        ]
        + [
            {"label": "two", "ics": "disk/tangential", "e_ratio": 2.0, "fraction": 0.0, "err": None}
            | {"fraction_upper": 0.0015, "fraction_cl": 0.95, "syst": 0.0}
        ],
        "survival_long": [
            {"label": "two", "e_ratio": 1.05, "t": 800.0, "P": 0.8, "P_err": 0.004},
            {"label": "two", "e_ratio": 1.05, "t": 2000.0, "P": 0.0, "P_err": None, "P_upper": 3e-4, "P_cl": 0.95},
        ],
        "long_time": [
            {
                "label": "two",
                "e_ratio": 1.05,
                "ics": "disk/tangential",
                "P_inf": 0.751,
                "P_inf_err": 0.005,
                "kappa_inf": 0.00092,
                "kappa_inf_err": 0.00004,
            }
        ],
        "resc": [
            {
                "label": "hh",
                "r_esc": 1.03,
                "default": False,
                "window": [0, 200],
                "mu_measured": {"value": 0.95, "err": 0.001},
                "mu_predicted": {"value": 0.94, "err": 0.002},
                "mu_own_K": {"value": 0.951, "err": 0.001},
                "moment_test": {"value": 0.011, "err": 0.002},
                "kinetic_at_E0": {"value": 1.018, "err": 0.002},
                "kinetic_at_E0_interpolated_without_E0": 1.0,
            }
        ],
    }
    (assets / "paper" / "gx.json").write_text(json.dumps(sealed(doc)))
    out, _ = _page(tmp_path, hook, "<!-- hh:evidence-tables gx -->\n")
    assert "| E/E_c | two<br>disk/tangential |" in out  # energies down, (system, ICs) across
    assert "| 1.05 | 75.0 ± 1.0 ± 5.0 % |" in out and "| 1.5 | 10.0 ± 1.0 ± 5.0 % |" in out
    assert "| 2 | < 0.15 % (95 %) |" in out
    assert "| 0.800 ± 0.004 | < 3.0e−4 (95 %) |" in out  # a P of 0: its bound, never 0 ± 0
    assert "0.751 ± 0.005" in out and "| 1.03 | [0, 200] |" in out and "Scale **paper**" in out


def test_evidence_tables_write_zero_counts_of_records_without_bounds_from_their_orbit_count(tmp_path, hook):
    """Records written before bounds were recorded (a P of 0 with error 0, a regular fraction of 0 with a Wilson
    error): the table gives the one-sided 95 % bound from the record's number of orbits, 1 − 0.05^(1/n)."""
    doc = {
        "regular_fraction": [
            {"id": "two-2-disk", "label": "two", "ics": "disk/tangential", "e_ratio": 2.0, "fraction": 0.0}
            | {"err": 0.00025, "n": 2000}
        ],
        "survival_long": [{"label": "two", "e_ratio": 2.0, "t": 800.0, "P": 0.0, "P_err": 0.0}],
        "long_time": [{"label": "two", "e_ratio": 2.0, "ics": "disk/tangential", "n": 2000}],
        "validity_map": [
            {"id": "two-2-disk", "label": "two", "e_ratio": 2.0, "regular_fraction": 0.0, "regular_err": 0.00025}
            | {"kappa0_defined": True, "claim2": None, "exponential": None, "plateau": None}
        ],
    }
    out = hook.evidence_tables(doc)
    assert "0 ± 0" not in out and "0.0 ± 0.0" not in out
    assert out.count("< 0.15 % (95 %)") == 2 and "| < 1.5e-3 (95 %) |" not in out and "| < 0.0015 (95 %) |" in out


def test_validity_map_states_each_cells_count_and_kappa0_rule_and_the_energies_a_scale_did_not_run(hook):
    """The validity map: a cell's regular count (k of n), κ0 with the numbers that decide "defined" and the stated
    rule of the record; an energy of the claims' grid without a cell (a record made before the map covered it) is a
    row "not run at this scale", never left out; κ0 at two escape radii with its shift, the shift's paired error and
    the quadrature error beside it, and the verdict."""
    cell = {"label": "b", "regular_err": None, "claim2": None, "exponential": None, "plateau": None}
    doc = {
        "config": {"study": {"ratios": [1.9, 2.2]}},
        "regular_fraction": [
            {"id": "b-1.9-disk", "label": "b", "ics": "disk/tangential", "e_ratio": 1.9, "fraction": 0.0012}
            | {"err": 0.0002, "n": 20000}
        ],
        "survival_long": [],
        "long_time": [],
        "validity_rules": {
            "regular_fraction": "k of n regular",
            "kappa0_defined": "κ0 defined iff f∞/P(t_hi) ≤ 10 %",
            "kappa0_source": "the claims' run",
        },
        "validity_map": [
            cell
            | {"id": "b-1.9-disk", "e_ratio": 1.9, "regular_fraction": 0.0012, "regular_err": 0.0002}
            | {"n": 20000, "n_regular": 24, "kappa0_defined": False, "kappa0": {"value": 0.021, "err": 0.001}}
            | {"plateau_bias": 0.84, "kappa0_verdict": "ill-defined: f∞/P(t_hi) = 84 % > 10 %"}
        ],
        "resc_kappa": [
            {"label": "b", "e_ratio": 1.8, "convention": "plateau", "r_esc_default": 2.598, "r_esc": 1.784}
            | {"r_esc_over_saddle": 1.03, "kappa_default": {"value": 0.05, "err": 0.001}}
            | {"kappa": {"value": 0.06, "err": 0.001}, "shift": {"value": 0.2, "err": 0.03}}
            | {"shift_err_unpaired": 0.0283, "verdict": "shifts (z = +6.7)"}
        ],
    }
    out = hook.evidence_tables(doc)
    assert "κ0: κ0 defined iff f∞/P(t_hi) ≤ 10 % (the claims' run)" in out
    assert "| b | 1.9 | 24 of 20000: 0.120 ± 0.020 % | ill-defined: f∞/P(t_hi) = 84 % > 10 % |" in out
    assert "| b | 2.2 | not run at this scale | not run at this scale |" in out
    assert "| b | 1.8 | all orbits | 2.6 | 0.0500 ± 0.0010 | 1.78 (1.03 r_s) | 0.0600 ± 0.0010 | 0.20 ± 0.03 |" in out
    assert "| 0.20 ± 0.03 | 0.028 | shifts (z = +6.7) |" in out
    assert "paired error: a bootstrap over the orbits" in out


def test_the_regular_fraction_shows_both_systematics_and_the_validity_map_its_total_error(hook):
    """A record with a labelled set: the regular-fraction table writes value ± stat ± threshold ± indicator, the
    validity map the value ± the three in quadrature (its rule's error)."""
    doc = {
        "config": {"study": {"ratios": [1.05]}},
        "regular_fraction": [
            {"id": "b-1.05-disk", "label": "b", "ics": "disk/tangential", "e_ratio": 1.05, "fraction": 0.638}
            | {"err": 0.005, "syst": 0.03, "syst_indicator": 0.04, "err_total": 0.0502, "n": 10000}
        ],
        "survival_long": [],
        "long_time": [],
        "validity_map": [
            {"id": "b-1.05-disk", "label": "b", "e_ratio": 1.05, "regular_fraction": 0.638, "regular_err": 0.005}
            | {"regular_syst": 0.03, "regular_syst_indicator": 0.04, "regular_err_total": 0.0502, "n": 10000}
            | {"n_regular": 6380, "kappa0_defined": None, "claim2": None, "exponential": None, "plateau": None}
        ],
    }
    out = hook.evidence_tables(doc)
    assert "| 1.05 | 63.8 ± 0.5 ± 3.0 ± 4.0 % |" in out
    assert "Labelled sets" not in out  # no labelled set in the record: no table of them
    assert "| b | 1.05 | 6380 of 10000: 64 ± 5 % |" in out


def test_generated_text_writes_a_negative_number_with_the_minus_sign(hook):
    """The hook's output writes a number's sign "−" (as the verdicts and the [[…]] numbers do); code spans, maths,
    HTML attributes and ranges stay as written; the exponent of e-notation is signed "−" too."""
    text = (
        "| -0.26 ± 0.19 | (z = -1.1) | [-0.015, +0.029] | 10<sup>-10</sup> | `grid[-1]` | $x^{-1}$ | 2.7e-05 |"
        ' <img width="-1"> | x-1 | 0.2-0.5 |'
    )
    assert hook.typographic_minus(text) == (
        "| −0.26 ± 0.19 | (z = −1.1) | [−0.015, +0.029] | 10<sup>−10</sup> | `grid[-1]` | $x^{-1}$ | 2.7e−05 |"
        ' <img width="-1"> | x-1 | 0.2-0.5 |'
    )


def test_spec_tables_write_a_count_of_zero_as_its_bound(hook):
    """A record with a sibling <key>_upper (a count of 0) shows its one-sided bound, never "0 ± 0"."""
    recs = [{"t": 80.0, "sim": 0.25, "sim_err": 0.01}, {"t": 100.0, "sim": 0.0, "sim_err": None, "sim_upper": 3e-4}]
    out = hook.spec_table(recs, (("t", "t"), ("sim", "simulated")))
    assert "| 80 | 0.250 ± 0.010 |" in out and "| 100 | < 3.0×10<sup>-4</sup> (95 %) |" in out


def _notations(cell: str) -> set[str]:
    """The notations of the numbers of a rendered cell: "e" (2.6e-06), "×10" (2.6×10<sup>-6</sup>)."""
    out = {"e"} if re.search(r"(?<![\w.])\d+(?:\.\d+)?e[+-]?\d+", cell) else set()
    return out | ({"×10"} if "×10<sup>" in cell else set())


def test_a_rendered_study_table_writes_its_numbers_in_one_notation(hook):
    """Every record table a page asks for, rendered from the committed numbers at both scales, writes a power of
    ten one way: no table mixes e-notation (basins' cut-off table wrote "2.63e-06 ± 6.3e-08" and "ε_c < 1e-10" beside
    "2.56×10<sup>-6</sup>") with a×10<sup>b</sup>, in a value ± error or in a text cell."""
    mixed = []
    for table, spec in hook.STUDY_TABLES.items():
        name, key = table.split("@", 1)[0].split(".", 1)
        for base in (DOCS / "studies" / "assets", DOCS / "studies" / "assets" / "paper"):
            path = base / f"{name}.json"
            recs = hook._dig(json.loads(path.read_text()), key) if path.is_file() else None
            if not recs:
                continue
            rows = [r.split(" | ") for r in hook.spec_table(recs, spec).splitlines()[2:]]
            used = set().union(*(_notations(c) for r in rows for c in r))
            if len(used) > 1:
                mixed.append((table, base.name, sorted(used)))
    assert not mixed, mixed
    # the renderer's notation, in a value ± error and in a text cell
    out = hook.spec_table([{"x": 2.63e-6, "x_err": 6.3e-8, "s": "ε_c < 1e-10"}], (("x", "x"), ("s", "s")))
    assert "| (2.63 ± 0.06)×10<sup>-6</sup> | ε_c < 1×10<sup>-10</sup> |" in out


def test_the_reference_radius_difference_to_itself_reads_reference(hook):
    """The escape-criterion study's numbers at r_esc = r_ref: the differences of the reference run to itself
    (κ shift, MLE difference, flight time, mean end time; exactly 0 ± 0 in the JSON) read "reference", never a
    measured 0; the other radii keep their numbers."""
    r = hook.Renderer(ROOT, DOCS, DOCS / "studies")
    doc, _ = r._headline("resc")
    ref = f"r_esc={doc['r_ref']:g}"
    text = r.study_numbers("resc")
    for leaf in ("shift_vs_ref", "mle_difference_vs_ref", "flight_time_from_ref", "mean_t_end_difference"):
        for energy in doc["kappa"]:
            row = f"| `kappa.{energy}.{ref}.{leaf}` |"
            line = next(x for x in text.splitlines() if row in x)
            assert line.split("|")[-2].strip() == "reference", line
    other = next(x for x in text.splitlines() if "| `kappa.E=0.30.r_esc=1.5.shift_vs_ref` |" in x)
    assert "±" in other, other


def _studies_with_numbers():
    return sorted(p.stem for p in (DOCS / "studies" / "assets").glob("*.json") if not p.stem.endswith(".cost"))


@pytest.mark.parametrize("name", _studies_with_numbers())
def test_no_built_number_reads_plus_minus_zero(hook, name):
    """Every number a study page shows from the committed JSON (its references, its tables, all the numbers the
    study wrote, at both scales) and the report's headline numbers: a count of 0 is a bound, an exact number has
    no error written; never "± 0"."""
    from hhscatter.publish.numbers import load_numbers, render_refs
    from hhscatter.publish.report import headline_numbers

    r = hook.Renderer(ROOT, DOCS, DOCS / "studies")
    page = ROOT / "studies" / name / "page.md"
    text = [r.study_numbers(name)]
    if page.exists():
        src = page.read_text()
        text.append(render_refs(src, ROOT, where=name))
        text += [r.study_table(arg) for arg in re.findall(r"<!-- hh:study-table (\S+) -->", src)]
    for scale in ("quick", "paper"):
        try:
            doc = load_numbers(ROOT, name, scale)[0]
        except Exception:  # this study has no committed JSON at this scale
            continue
        text += [f"{k}: {v}" for k, v in headline_numbers(doc, limit=10**6)]
    zero = [m.group(0) for t in text for m in re.finditer(r".{0,40}± 0(?![.,\d]).{0,10}", t)]
    assert not zero, zero[:5]


def test_the_heads_of_the_study_tables_wrap_into_short_words(hook):
    """A results table fits the text column by wrapping its heads: no head of the record tables the pages ask for
    holds a word longer than 16 characters ("log10(measured/predicted)" kept the cut-off table's reading column
    narrow)."""
    long_words = [
        (table, head)
        for table, spec in hook.STUDY_TABLES.items()
        for _, head, *_ in spec
        if max(len(w) for w in head.split()) > 16
    ]
    assert not long_words, long_words


def test_the_stress_summary_names_the_orbits_still_inside_censored(hook):
    """The energy-drift case runs orbits selected as still inside at t = 5000, not classified: the benchmarks page
    calls them censored, also in a summary written before the benchmarks used the glossary's words."""
    text = hook.Renderer(ROOT, DOCS, DOCS / "studies").bench("stress")
    assert "censored orbits (E=0.2, inside at t=5000)" in text
    assert not re.search(r"\bKAM-trapped\b", text)


def test_the_heads_of_the_study_tables_name_survivors_by_the_glossary(hook):
    """Orbits still inside are regular, chaotic but confined or censored (the glossary): no head of a record table
    says "trapped" (the operator's KAM-probe boxes are censored boxes, as its page says)."""
    heads = [head for spec in hook.STUDY_TABLES.values() for _, head, *_ in spec]
    assert not [h for h in heads if "trapped" in h.lower()]
    assert "censored boxes" in heads


def test_the_glossary_has_a_row_for_every_symbol_the_result_pages_define():
    """The symbols the study pages use for their results each head a row of the glossary, with one meaning (or its
    meanings told apart by where they appear)."""
    text = (DOCS / "equations.md").read_text()
    rows = text[text.index("## Glossary") :].splitlines()
    heads = {h.strip() for r in rows if r.startswith("| ") for h in r.split("|")[1].split(",")}
    wanted = {"κ∞", "κ_tail", "P∞", "S_b", "S_bb", "SW1", "β", "t0", "q", "λ̄", "λ∞", "D₁", "d₁", "δ", "z", "t*", "T"}
    assert wanted <= heads, sorted(wanted - heads)


#: Greek letters the study pages write as notation rather than as a symbol of their own, each with why it needs no row
GREEK_NOTATION = {
    "σ": "a standard error (a distance in σ), not a quantity",
    "χ": "χ², the goodness-of-fit statistic, named where it is used",
    "Σ": "a sum",
    "Δ": "a difference (ΔE, Δ = d(5b) − d(5a)), defined where it is used",
    "π": "the number π",
    "ψ": "the digamma function of the nearest-neighbour dimension estimate, named where it is used",
}


def _greek_symbols(text: str) -> set[str]:
    """Each Greek letter of ``text`` with the accents written on it (φ and φ̇ are two symbols)."""
    return set(re.findall(r"[\u0370-\u03ff][\u0300-\u036f]*", text))


def test_every_greek_symbol_of_the_study_pages_heads_a_glossary_row():
    """Every Greek symbol a study page uses (its page.md and its study module's docstring, shown on the page) heads a
    row of the glossary, unless it is notation (a sum, a difference, σ, χ², π, the digamma function): fig6's
    mixture share φ, the operator's Perron vector ν, the noise study's Υ(δ) and the saddle's log-stretch Λ each have
    their row."""
    import ast

    text = (DOCS / "equations.md").read_text()
    rows = text[text.index("## Glossary") :].splitlines()
    heads = set().union(*(_greek_symbols(r.split("|")[1]) for r in rows if r.startswith("| ")))
    missing = {}
    for folder in sorted(p for p in (ROOT / "studies").iterdir() if (p / "page.md").is_file()):
        used = _greek_symbols((folder / "page.md").read_text())
        used |= _greek_symbols(ast.get_docstring(ast.parse((folder / "study.py").read_text())) or "")
        for sym in sorted(used - heads - set(GREEK_NOTATION)):
            missing.setdefault(sym, []).append(folder.name)
    assert not missing, missing


def test_a_rate_symbol_of_one_study_is_not_reused_by_another():
    """κ∞ is Ulam's extrapolated rate (operator) only; generality's long-time fit calls the rate of its non-plateau
    orbits κ_tail, and the saddle's 1/T offset of λ̄ is Λ₀ (b is the paper's own symbol, in (19) and its κ(E) law)."""
    text = (DOCS / "equations.md").read_text()
    rows = {r.split("|")[1].strip(): r for r in text[text.index("## Glossary") :].splitlines() if r.startswith("| ")}
    assert "generality" not in rows["κ∞"], rows["κ∞"]
    assert "κ∞" not in (ROOT / "studies" / "generality" / "page.md").read_text()
    assert "b/T" not in (ROOT / "studies" / "saddle" / "page.md").read_text()


def test_the_labelled_sets_have_a_table_of_their_own_counts(hook):
    """Each cell with a labelled set is one row: its counts as the record holds them and both systematics."""
    L = {"t_label": 3000.0, "ftle_regular": 0.003, "ftle_chaotic": 0.005, "n_labelled": 500, "n_band": 5754}
    L |= {"n_band_labelled": 400, "n_undecided": 30, "disagree_to_chaotic": 10, "disagree_to_regular": 0}
    L |= {"disagree_outside": 2, "shift": -0.0144, "syst": 0.0144}
    doc = {
        "config": {"study": {"ratios": [1.05]}},
        "regular_fraction": [
            {"id": "b-1.05-disk", "label": "b", "ics": "disk/tangential", "e_ratio": 1.05, "fraction": 0.638}
            | {"err": 0.005, "syst": 0.043, "syst_indicator": 0.0144, "err_total": 0.046, "n": 10000, "labelled": L}
        ],
        "survival_long": [],
        "long_time": [],
    }
    out = hook.evidence_tables(doc)
    assert "to t = 3000 and labelled by the variational FTLE λ_T: regular below 0.003, chaotic above 0.005" in out
    assert "| b | 1.05 | 500 | 400 of 5754 | 30 | 10 | 0 | 2 | 1.44 % | 4.3 % |" in out
