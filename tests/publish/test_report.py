"""The reproduction report tabulates exactly what the studies wrote, and says what is missing."""

import json

import pytest

from hhscatter.publish.formatting import format_value_err
from hhscatter.publish.report import build_report
from hhscatter.studies import load_study
from hhscatter.studies.provenance import config_sha256, sealed


def _sealed(root, name, doc, upstream=None):
    """The numbers JSON as the analyze stage writes it: with what it was made from and its own content hash."""
    config = load_study(name, "quick", root=root).config
    return sealed(
        {
            **doc,
            "config": config,
            "made_from": {"config_sha256": config_sha256(config), "upstream": upstream or {}, "raw_runs": {}},
        }
    )


def _fake_study(root, name, rows, with_figure=True, paper=None):
    d = root / name
    (d / "out" / "quick").mkdir(parents=True)
    paper = f"Fig. {name[-1]}" if paper is None else paper
    (d / "study.toml").write_text(
        f'[about]\ntitle = "{name} title"\npaper = "{paper}"\nsummary = "{name} caption"\n'
        "[scene]\nn = 10\nenergy = 0.3\n"
    )
    doc = {
        "study": name,
        "scale": "quick",
        "kappa": {"value": 0.153, "err": 0.004},
        "n_points": 31000,
        "paper_comparison": rows,
        "provenance": {"heyoka": "7.13.2"},
    }
    (d / "out" / "quick" / f"{name}.json").write_text(json.dumps(_sealed(root, name, doc)))
    if with_figure:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(2, 2))
        ax.plot([0, 1], [1, 0])
        fig.savefig(d / "out" / "quick" / f"{name}.png")
        plt.close(fig)


def test_report_tables_rows_embeds_figures_and_lists_missing(tmp_path):
    root = tmp_path / "studies"
    _fake_study(
        root,
        "rep2",
        [
            {
                "quantity": "κ fit a",
                "ours": 13.1,
                "err": 0.4,
                "paper": 13.63,
                "unit": "",
                "verdict": "agrees within 2σ",
                "note": "",
            },
            {
                "quantity": "break energy",
                "ours": 0.31,
                "err": 0.01,
                "paper": 0.27,
                "unit": "",
                "verdict": "differs",
                "note": "continuous fit",
            },
        ],
    )
    _fake_study(
        root,
        "rep3",
        [
            {
                "quantity": "μ on [0,200]",
                "ours": 0.905,
                "err": 0.003,
                "paper": 0.91,
                "verdict": "agrees within 2σ",
                "note": "",
            }
        ],
        with_figure=False,
    )
    _fake_study(
        root,
        "rescx",
        [
            {
                "quantity": "returns at r_esc=1.03",
                "ours": 0.011,
                "err": 0.0004,
                "paper": 0.0,
                "verdict": "differs",
                "note": "",
            }
        ],
        paper="",
    )
    _fake_study(root, "rep1", [], with_figure=False)
    (root / "rep1" / "out" / "quick" / "rep1.json").unlink()  # a study folder that has not run yet
    res = build_report("quick", out=tmp_path / "rep", root=root)
    page = res["html"].read_text()
    md = res["markdown"].read_text()
    assert res["rows"] == 4
    paper_part, beyond_part = md.split("## Beyond the paper: checks")[0], md.split("## Beyond the paper: checks")[1]
    assert "break energy" in paper_part and "returns at r_esc" not in paper_part
    assert "returns at r_esc" in beyond_part.split("## Figures of the paper")[0]
    assert "3 numbers: 2 agree, 1 differ" in paper_part
    assert "arXiv:2308.13555" in md.split("##")[0] and "both uncertainties" in md.split("##")[0]  # the header
    assert (
        "13.1 ± 0.4" in page and "13.63" in page and '<span class="bad">differs (z = +3.6)</span>' in page
    )  # the one rule: 0.04/√(0.01² + 0.005²)
    assert page.count("data:image/png;base64,") == 2  # rep2 and rescx; rep3 has numbers but no figure
    assert set(res["missing"]) == {"rep1", "rep3"}  # the study folders of the root without figure or numbers
    assert "### rep2 title (`make rep2`)" in md and "rep2 caption" in md  # titles and captions from [about]
    assert md.index("### rescx title") > md.index("## Beyond the paper\n")
    assert "| rep2 | break energy | 0.310 ± 0.010 | 0.27 | differs (z = +3.6) | continuous fit |" in md
    assert (tmp_path / "rep" / "assets" / "rep2.png").exists()
    assert "kappa | 0.153 ± 0.004" in md and "n_points | 31000" in md
    assert [r["study"] for r in json.loads((tmp_path / "rep" / "comparison.json").read_text())] == [
        "rep2",
        "rep2",
        "rep3",
        "rescx",
    ]


@pytest.mark.parametrize(
    "v,err,want",
    [
        (0.9123, 0.0031, "0.912 ± 0.003"),
        (0.31, 0.012, "0.310 ± 0.012"),
        (13.63, None, "13.63"),
        (2.5e-14, 1e-15, "2.5e-14 ± 1.0e-15"),
        (0.0, 8.3e-6, "0 ± 8.3e-06"),
        (-9.2e-4, 5.2e-4, "-0.0009 ± 0.0005"),
        (152.0, 7.0, "152 ± 7"),
    ],
)
def test_number_formatting_rounds_to_the_uncertainty(v, err, want):
    assert format_value_err(v, err) == want


def test_a_difference_only_in_our_convention_is_not_counted_as_one():
    from hhscatter.publish.report import verdict_counts

    rows = [
        {"verdict": "differs"},
        {"verdict": "differs in our convention only; agrees under the authors' ([0, 100])"},
        {"verdict": "differs in this convention only; within the spread across conventions"},
        {"verdict": "agrees within 2σ"},
    ]
    c = verdict_counts(rows)
    assert (c["bad"], c["meh"], c["ok"]) == (1, 2, 1)


def test_report_header_names_each_studys_commit_and_says_dirty_in_words():
    from hhscatter.publish.report import Section, commits_line

    secs = [
        Section(k, k, "", None, {"provenance": {"git_commit": c}})
        for k, c in (("fig1", "a" * 40 + "-dirty"), ("fig2", "b" * 40), ("fig3", "b" * 40), ("fig4", None))
    ]
    line = commits_line(secs)
    assert line == f"Numbers made at commit `{'b' * 12}`: fig2, fig3; `{'a' * 12}` (uncommitted changes): fig1."
    assert "-dirty" not in line and commits_line([]) == ""


def test_the_report_writes_a_negative_number_with_the_minus_sign(tmp_path):
    """A negative number of a study (value, error interval, z) is written "−" in report.md and report.html, as on
    the docs site; the study's own words keep their hyphens."""
    root = tmp_path / "studies"
    row = {"quantity": "κ shift (c-measure)", "ours": -0.0131, "err": 0.0004, "paper": 0.0, "verdict": "", "note": ""}
    _fake_study(root, "rep4", [row])
    res = build_report("quick", out=tmp_path / "rep", root=root)
    md, page = res["markdown"].read_text(), res["html"].read_text()
    assert "| rep4 | κ shift (c-measure) | −0.0131 ± 0.0004 | 0 | differs (z = −32.8) |" in md, md
    assert "−0.0131 ± 0.0004" in page and "-0.0131" not in md + page


def test_make_report_says_what_it_will_run_and_how_long(tmp_path):
    """Before any work: the studies without their figure at the quick scale, and their CPU time from the committed
    cost records over the cores; a study with its figure is not named; an unknown scale is refused."""
    from hhscatter.errors import StudyError
    from hhscatter.publish.report import plan_line

    root = tmp_path / "studies"
    _fake_study(root, "rep5", [], with_figure=False)
    _fake_study(root, "rep6", [], with_figure=True)
    assets = tmp_path / "docs" / "studies" / "assets"
    assets.mkdir(parents=True)
    run = {"wall_s": 1.0, "cpu_s": 600.0, "rss_self_mb": 1.0, "rss_children_mb": 1.0}
    (assets / "rep5.cost.json").write_text(json.dumps({"simulate": [run, run], "analyze": [{**run, "cpu_s": 120.0}]}))
    line = plan_line("quick", root=root, cores=2)
    # (600 + 600 + 120) CPU s over 2 cores = 11 min
    assert line.startswith("make report (SCALE=quick): runs 1 study first (rep5): about 11 min on 2 cores"), line
    assert "rep6" not in line
    with pytest.raises(StudyError, match="scale must be one of"):
        plan_line("bogus", root=root)


def test_the_report_html_numbers_equations_as_the_site(tmp_path):
    """The report's HTML writes the paper's equation labels as the docs site does, "(18)", from docs/equations.md,
    and a formula's ^{…} as a superscript."""
    root = tmp_path / "studies"
    row = {
        "quantity": "f_ne",
        "ours": 0.2,
        "err": 0.01,
        "paper": None,
        "verdict": "",
        "note": "Eq. (eqn:surv_prob_model), E0 e^{−μγt}",
    }
    _fake_study(root, "rep7", [row])
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "equations.md").write_text("### (18) Survival model {#eqn-surv_prob_model}\n")
    page = build_report("quick", out=tmp_path / "rep", root=root)["html"].read_text()
    assert "Eq. (18)" in page and "eqn:surv_prob_model" not in page
    assert "E0 e<sup>−μγt</sup>" in page and "^{" not in page


def test_a_star_of_a_formula_in_a_table_cell_stays_a_star():
    """Markdown never eats the * of t* in a generated cell (the claims table's "d(μ_c^E(t*)), E(t*) = …")."""
    from hhscatter.publish.formatting import markdown_to_html, md_cell

    page = markdown_to_html("| q |\n|---|\n| " + md_cell("d(μ_c^E(t*)), E(t*) = 1.5 E_c") + " |\n")
    assert "E(t*)) , E(t*)".replace(" ,", ",") in page and "<em>" not in page
