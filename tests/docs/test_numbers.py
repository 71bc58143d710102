"""Result numbers in prose come from the committed study JSON (hhscatter.publish.numbers, docs/_hooks/numbers.py).

* the reference syntax ``[[study[@scale]:path[|format]]]`` resolves and formats as documented
  (docs/studies/adding.md), against small JSON documents written here;
* every reference on every page of the repository resolves against the committed JSON (the docs build
  would fail on one that does not);
* no study page (and no page that reports results) types a number that is neither a reference, a
  parameter of the study, the paper's value, a small count nor a declared convention.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from hhscatter.publish import numbers as nb
from hhscatter.studies.provenance import sealed

ROOT = Path(__file__).resolve().parents[2]
STUDIES = sorted(p.parent.name for p in (ROOT / "studies").glob("*/page.md"))

DOC = {
    "kappa_fit": {"c": {"value": 1.4348590349, "err": 0.0170463952}, "chi2": 68.87144818141033, "dof": 17},
    "E0.30": {"mu": {"value": 0.0123456, "err": 0.00031}},
    "rows": [
        {"energy": 0.25, "kappa": 0.0912, "verdict": "agrees"},
        {"energy": 0.27, "kappa": 0.14516, "verdict": "differs"},
    ],
    "frac": {"value": 0.0623, "err": 0.0012},
    "big": 1234567,
    "tiny": 2.5e-9,
    "missing": {"value": float("nan"), "err": None},
    "interval": {"value": 0.339, "lo": 0.3285, "hi": 0.3497},
}


@pytest.mark.parametrize(
    "path, fmt, want",
    [
        ("kappa_fit.c", None, "1.435 ± 0.017"),  # two digits of an error that starts with 1; value alike
        ("kappa_fit.c", "value", "1.435"),
        ("kappa_fit.c", "err", "0.017"),
        ("kappa_fit.chi2", None, "68.87"),  # no error: 4 significant digits
        ("kappa_fit.chi2", ".1f", "68.9"),
        ("kappa_fit.dof", None, "17"),
        ("E0.30.mu", None, "0.0123 ± 0.0003"),  # a key holding a dot is found as it is
        ("rows[energy=0.27].kappa", ".3f", "0.145"),  # a record chosen by a field, numbers compared as numbers
        ("rows[energy=0.270].verdict", None, "differs"),
        ("rows[0].energy", None, "0.25"),
        ("rows[-1].verdict", None, "differs"),
        ("frac", "pct", "6.23 ± 0.12 %"),
        ("big", "int", "1\u2009234\u2009567"),
        ("tiny", None, "2.500×10⁻⁹"),
        ("tiny", "sci", "2.50×10⁻⁹"),
        ("interval", None, "0.339 [0.3285, 0.3497]"),
    ],
)
def test_a_reference_resolves_and_formats_as_documented(path, fmt, want):
    assert nb.format_leaf(nb.resolve(DOC, path), fmt) == want


@pytest.mark.parametrize(
    "path, fmt, says",
    [
        ("kappa_fit.d", None, "no key 'd'"),
        ("rows[energy=0.3].kappa", None, "0 records match"),
        ("rows[7]", None, "out of range"),
        ("kappa_fit", None, "name one of them"),
        ("missing", None, "no number"),  # NaN is an error, never "nan" on a page
        ("kappa_fit.dof", "err", "no uncertainty"),
        ("kappa_fit.chi2", "q", "bad format"),
    ],
)
def test_what_the_json_does_not_hold_is_an_error(path, fmt, says):
    with pytest.raises(nb.NumberRefError, match=says):
        nb.format_leaf(nb.resolve(DOC, path), fmt)


def _repo(tmp_path, quick=None, paper=None):
    assets = tmp_path / "docs" / "studies" / "assets"
    (assets / "paper").mkdir(parents=True)
    if quick is not None:
        (assets / "s.json").write_text(json.dumps(sealed(quick)))
    if paper is not None:
        (assets / "paper" / "s.json").write_text(json.dumps(sealed(paper)))
    return tmp_path


def test_a_number_from_an_edited_or_unsealed_json_is_refused(tmp_path):
    root = _repo(tmp_path, quick={"x": 1.5})
    assert nb.render_refs("[[s:x]]", root) == "1.5"
    path = root / "docs/studies/assets/s.json"
    doc = json.loads(path.read_text())
    doc["x"] = 1.6  # edited by hand
    path.write_text(json.dumps(doc, indent=1))
    with pytest.raises(nb.NumberRefError, match="not as its study wrote it"):
        nb.render_refs("[[s:x]]", root)
    path.write_text(json.dumps({"x": 1.6}))  # never sealed
    with pytest.raises(nb.NumberRefError, match="no content hash"):
        nb.render_refs("[[s:x]]", root)


def test_the_headline_is_the_paper_scale_where_committed(tmp_path):
    root = _repo(tmp_path, quick={"x": 1.5}, paper={"x": 2.5})
    assert nb.render_refs("x = [[s:x]], quick [[s@quick:x]]", root) == "x = 2.5, quick 1.5"
    (root / "docs/studies/assets/paper/s.json").unlink()
    assert nb.render_refs("x = [[s:x]]", root) == "x = 1.5"
    with pytest.raises(nb.NumberRefError, match="scale 'paper'"):
        nb.render_refs("[[s@paper:x]]", root)


def test_references_in_code_are_left_as_written_and_every_bad_one_is_named(tmp_path):
    root = _repo(tmp_path, quick={"x": 1.5})
    text = "a [[s:x]]\n\n```\n[[s:nope]]\n```\n\nand `[[s:nope]]` <!-- [[s:nope]] -->"
    assert nb.render_refs(text, root) == text.replace("a [[s:x]]", "a 1.5")
    with pytest.raises(nb.NumberRefError) as e:
        nb.render_refs("[[s:y]] and [[t:x]]", root)
    assert "[[s:y]]" in str(e.value) and "[[t:x]]" in str(e.value)


def test_stray_numbers_finds_typed_results_and_nothing_else():
    page = """# Fig 2 (Eq. (3), Fig. 2, Eqs. (14)–(16))

The rate is κ = 1.437 at E = [[fig2:e|.2f]], fitted on 4 windows over 10⁶ orbits
with r < 0.5 (a parameter) and a bias limit of 10 %. arXiv:2308.13555.
`kappa = 0.999` in code, [a link](../x_0.123.md), (eqn:kappa_hyperbolic).
<!-- conventions: 10 % (bias limit of choose_windows) -->
A 512² grid; and −0.0423 typed again.
"""
    assert nb.stray_numbers(page, {0.5, 512.0}) == [(3, "1.437"), (7, "−0.0423")]


# -- the repository's pages -----------------------------------------------------------------------------------------
def _pages():
    pages = sorted((ROOT / "docs").rglob("*.md")) + [ROOT / "studies" / s / "page.md" for s in STUDIES]
    pages.append(ROOT / "README.md")
    return [p for p in pages if "assets" not in p.relative_to(ROOT).parts]


def test_every_reference_on_every_page_resolves_against_the_committed_json():
    bad = []
    for page in _pages():
        try:
            nb.render_refs(page.read_text(), ROOT, where=str(page.relative_to(ROOT)))
        except nb.NumberRefError as e:
            bad.append(str(e))
    assert not bad, "\n".join(bad)


#: pages whose prose still types result numbers by hand; they are being moved to [[…]] references.
#: strict: a page that passes must leave this set (the test then fails to say so).
NOT_YET: set[str] = set()
RESULT_PAGES = [f"studies/{s}/page.md" for s in STUDIES] + [
    "docs/index.md",
    "docs/studies/index.md",
    "docs/studies/paper-scale.md",
]  # README.md: tests/docs/test_readme.py


@pytest.mark.parametrize(
    "page",
    [
        pytest.param(p, marks=pytest.mark.xfail(strict=True, reason="not yet moved")) if p in NOT_YET else p
        for p in RESULT_PAGES
    ],
)
def test_a_page_types_no_result_number(page):
    parts = Path(page).parts
    if parts[0] == "studies":
        allowed = nb.study_conventions(ROOT, parts[1])
    else:  # pages over all studies: any study's parameters and the paper's values
        allowed = set().union(*(nb.study_conventions(ROOT, s) for s in STUDIES))
    stray = nb.stray_numbers((ROOT / page).read_text(), allowed)
    assert not stray, (
        f"{page} types numbers by hand (line, number): {stray}. Render a result with "
        "[[study:path]]; declare a convention as <!-- conventions: value (reason) -->; "
        "see docs/studies/adding.md"
    )


def test_a_reference_the_syntax_cannot_read_is_an_error_not_left_as_text(tmp_path):
    root = _repo(tmp_path, quick={"rows": [{"q": "μ on [0, 200]", "v": 1.0}]})
    with pytest.raises(nb.NumberRefError, match="not a reference the syntax reads"):
        nb.render_refs("[[s:rows[q=μ on [0, 200]].v]]", root)


def test_a_row_verdict_follows_the_one_rule(tmp_path):
    row = {"quantity": "c (law, fit)", "ours": 1.435, "err": 0.017, "paper": 1.41, "verdict": "old words"}
    root = _repo(tmp_path, quick={"scale": "quick", "rows": [row]}, paper={"scale": "tiny", "rows": [row]})
    # selector values may hold commas and parentheses; 0.025/√(0.017² + 0.005²) = 1.41
    assert nb.render_refs("[[s@quick:rows[quantity=c (law, fit)]|verdict]]", root) == "agrees (z = +1.4)"
    assert nb.render_refs("[[s:rows[0]|verdict]]", root) == "no verdict (tiny scale: a smoke test)"


def test_every_committed_verdict_is_written_one_way():
    """Every "verdict" of the committed JSON writes a negative number (z, a shift, an interval's end) with "−" (as
    Verdict.text does), never an ASCII "-" (a hyphen in a word, "c-measure", stays)."""
    import re

    minus = re.compile(r"(?<![\w.])-\d")
    ascii_minus = []

    def walk(o, where):
        if isinstance(o, dict):
            for k, v in o.items():
                if k == "verdict" and isinstance(v, str) and minus.search(v):
                    ascii_minus.append(f"{where}: {v}")
                walk(v, where)
        elif isinstance(o, list):
            for v in o:
                walk(v, where)

    found = sorted((ROOT / "docs" / "studies" / "assets").rglob("*.json"))
    assert len(found) >= 11
    for f in found:
        walk(json.loads(f.read_text()), f.relative_to(ROOT).as_posix())
    assert not ascii_minus, "\n".join(ascii_minus)


def test_a_count_of_zero_is_written_as_its_one_sided_bound_never_zero_plus_minus_zero():
    from hhscatter.analysis.stats.intervals import fraction_with_bound

    doc = {"rows": [{"id": "a", **fraction_with_bound(0, 10000).record("P")}, {"id": "b", "P": 0.25, "P_err": 0.01}]}
    assert nb.format_ref(doc, "rows[id=a].P", ".4f") == "< 3.0e−4 (95 %)"
    assert nb.format_ref(doc, "rows[id=a].P", "pct") == "< 0.030 % (95 %)"
    assert nb.format_ref(doc, "rows[id=a].P") == "< 3.0e−4 (95 %)"
    assert nb.format_ref(doc, "rows[id=b].P", ".2f") == "0.25"  # a nonzero count keeps its number


def test_a_fraction_of_zero_recorded_without_its_bound_is_written_as_the_bound_from_n():
    """A record written before bounds were recorded (the paper-scale regular fractions: fraction 0 with a binomial
    err, no ``fraction_upper``) reads as the one-sided 95 % bound from its ``n``, never "0 %" or "0.00 %"; a
    fraction of all, as its lower bound. The bounds here are 1 − 0.05^(1/n) and 0.05^(1/n), worked by hand."""
    doc = {
        "regular_fraction": [
            {"id": "hh-1.5", "fraction": 0.0, "err": 5.0e-5, "n": 10000},
            {"id": "hh-1.05", "fraction": 0.0048, "err": 6.9e-4, "n": 10000},
            {"id": "all", "fraction": 1.0, "err": 0.0, "n": 20},
        ],
        "counts": {"n_regular": 0, "n": 10000},
    }
    assert nb.format_ref(doc, "regular_fraction[id=hh-1.5].fraction", "pct") == "< 0.030 % (95 %)"
    assert nb.format_ref(doc, "regular_fraction[id=hh-1.5].fraction", ".2f") == "< 3.0e−4 (95 %)"
    assert nb.format_ref(doc, "regular_fraction[id=all].fraction") == "> 0.86 (95 %)"
    assert nb.format_ref(doc, "regular_fraction[id=hh-1.05].fraction", "pct") == "0.48 %"  # not 0: its number
    assert nb.format_ref(doc, "counts.n_regular") == "0"  # a count is not a fraction: no bound made up for it


@pytest.mark.parametrize(
    "value, err, fmt, want",
    [
        (1.4348590349, 0.0170463952, "", "1.435 ± 0.017"),
        (1.4348590349, 0.0170463952, "value", "1.435"),
        (1.4348590349, 0.0170463952, "err", "0.017"),
        (0.0623, 0.0012, "pct", "6.23 ± 0.12 %"),
        (-0.00207, 0.00118, "", "\u22120.0021 ± 0.0012"),
        (0.9123, float("nan"), "", "0.9123"),  # not measured: the value alone
        (0.9123, float("nan"), "pct", "91.23 %"),
        (0.5, 0.0, "", "0.5"),  # exact by construction: never "± 0"
    ],
)
def test_a_measured_value_is_written_as_its_json_leaf(value, err, fmt, want):
    from hhscatter.analysis.stats.measured import Measured

    m = Measured(value, err, "MLE", 100)
    assert nb.format_leaf(m, fmt) == want
    leaf = m.to_dict() if err == err else {"value": value, "err": None}  # JSON writes a NaN error as null
    assert nb.format_leaf(leaf, fmt) == want


@pytest.mark.parametrize("err", [None, float("nan"), "n/a"])
def test_a_number_beside_a_missing_or_unmeasured_error_is_written_alone(err):
    doc = {"k": 0.0912, "k_err": err, "row": {"ours": -0.0912, "err": err}}
    assert nb.format_ref(doc, "k", "pm") == "0.0912"
    assert nb.format_ref(doc, "k", "pct") == "9.12 %"
    assert nb.format_ref(doc, "row") == "\u22120.0912"
