"""Docs that tell the truth: equation labels become numbers, symbol stars and field lists survive Markdown,
MathJax is served from the site (offline), and the concept pages agree with the code's defaults."""

from __future__ import annotations

import re

import pytest
from test_docs import DOCS, ROOT, _load  # the docs tests' module loader and paths


@pytest.fixture(scope="module")
def site():
    return _load(DOCS / "_hooks" / "site.py", "hh_docs_site")


def test_every_cited_equation_label_has_a_number(site):
    numbers = site.equation_numbers(DOCS)
    assert numbers["eqn:kappa_hyperbolic"] == "2" and numbers["eq:tau2"] == "12"
    assert numbers["eqn:surv_prob_model"] == "18" and len(set(numbers.values())) == len(numbers)
    cited = set()
    code = [*ROOT.joinpath("hhscatter").rglob("*.py"), *ROOT.joinpath("studies").glob("*/*.py")]
    for path in [*code, *DOCS.rglob("*.md"), *ROOT.joinpath("studies").glob("*/page.md")]:
        cited |= set(re.findall(r"\((eqn?:[\w-]+)\)", path.read_text()))
    assert cited and cited <= set(numbers), sorted(cited - set(numbers))
    figures = set()
    for path in code:
        figures |= set(re.findall(r"\bfig:([\w-]+)", path.read_text()))
    assert figures <= set(site.FIGURES), sorted(figures - set(site.FIGURES))


def test_labels_become_linked_numbers_outside_code(site):
    html = (
        "<p>P of Eqs. (eqn:kappa_hyperbolic) and (eq:tau2); paper Fig. 4 (fig:survprob), "
        "Fig. 3 = fig:energy_decay, (paper fig:um_comparison)</p>"
        "<pre><code>see (eqn:kappa_hyperbolic)</code></pre><code>(eq:tau2)</code>"
    )
    out = site.link_labels(html, {"eqn:kappa_hyperbolic": "2", "eq:tau2": "12"}, "../../")
    assert 'Eqs. (<a href="../../equations.html#eqn-kappa_hyperbolic" title="eqn:kappa_hyperbolic">2</a>)' in out
    assert '(<a href="../../equations.html#eq-tau2" title="eq:tau2">12</a>)' in out
    assert "paper Fig. 4, Fig. 3, (paper Fig. 5)</p>" in out
    assert out.endswith("<pre><code>see (eqn:kappa_hyperbolic)</code></pre><code>(eq:tau2)</code>")


def test_mathjax_comes_from_an_installed_wheel_not_a_cdn(site):
    pytest.importorskip("mathjax", reason="the docs extra (django-static-mathjax) is not installed")
    es5 = site.mathjax_dir()
    assert (es5 / "tex-chtml.js").stat().st_size > 500_000
    assert any((es5 / "output/chtml/fonts/woff-v2").glob("*.woff"))
    cfg = (ROOT / "mkdocs.yml").read_text()
    assert "javascripts/mathjax/tex-chtml.js" in cfg and "arithmatex" in cfg
    assert not re.search(r"https?://[^\s]*(mathjax|katex|polyfill)", cfg, re.I)


def test_docstrings_keep_symbol_stars_and_field_lists():
    pytest.importorskip("griffe")
    roles = _load(DOCS / "_hooks" / "griffe_roles.py", "hh_docs_roles2")
    out = roles.clean_docstring("τ* is where f* t^{−z} meets; the *last* one; `a*b`; 2 * x")
    assert out == "τ\\* is where f\\* t<sup>−z</sup> meets; the *last* one; `a*b`; 2 \\* x"
    text = (
        "Result:\n\nkappa, kappa_err      escape rate and\n                      its error\n"
        "tau0        end of the irregular regime\n\nAfter."
    )
    assert roles.field_lists(text) == (
        "Result:\n\n- `kappa`, `kappa_err`: escape rate and its error\n"
        "- `tau0`: end of the irregular regime\n\n\nAfter."
    )
    code = "Example:\n\n    a  = 1\n    bb = 2\n"
    assert roles.escape_literal_stars(code + "    x * y\n") == code + "    x * y\n"  # code blocks untouched
    doc = "Twice τ* of x.\n\nExamples\n--------\n>>> 4 * 2\n8\n>>> [0] * 2\n[0, 0]\n\nThen 2 * x."
    assert roles.clean_docstring(doc) == doc.replace("τ*", "τ\\*").replace("2 * x", "2 \\* x")  # doctests kept


def test_concept_pages_state_the_code_defaults():
    from hhscatter.scene.scene import Scene

    r_esc = Scene(energy=0.3, n=1).r_esc
    assert r_esc == 1.5
    assert (
        f"| `r_esc` | escape radius | the system's: {r_esc:g} for Hénon–Heiles "
        in (DOCS / "concepts" / "scenes.md").read_text()
    )
    assert f"| {r_esc:g} (default" in (DOCS / "concepts" / "index.md").read_text()
    assert f"default r_esc = {r_esc:g}" in (DOCS / "concepts" / "events.md").read_text()
    pages = [p.read_text() for p in (*DOCS.rglob("*.md"), ROOT / "README.md")]
    assert not any("about 11 s" in t for t in pages)  # the demo takes ~15 s (measured)
    assert not any(
        re.search(r"chunk size or the\s+batch size \(2, 4,? (and )?8 lanes; tested\s+bitwise\)", t) for t in pages
    )  # not true for γ > 0 yet
