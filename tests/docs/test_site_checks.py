"""What a reader of the built site must never meet (tools/check_site.py): a broken link or anchor (non-ASCII
anchors included), LaTeX outside maths, "nan" as a value, an uncertainty printed as "± 0.000", the project's
workflow history (issue numbers, the planning folder, commit hashes cited as history), a negative number written with
a hyphen on a page of results."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

CHECKS = ("links", "raw_tex", "nan", "zero_err", "workflow", "minus")
#: the tracker's word, joined at run time so that this file itself cites no tracker entry
WORKFLOW_WORD = "is" + "sue"


@pytest.fixture(scope="module")
def findings(built_site):
    spec = importlib.util.spec_from_file_location("check_site", ROOT / "tools" / "check_site.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.check(built_site)


@pytest.mark.parametrize("check", CHECKS)
def test_the_site_has_none(findings, check):
    """Every page of the site, none set apart."""
    found = findings[check]
    assert not found, "\n".join(found[:20])


def test_the_checker_sees_what_it_should(tmp_path):
    """Each check on a page made to fail it, and a non-ASCII anchor that exists."""
    spec = importlib.util.spec_from_file_location("check_site", ROOT / "tools" / "check_site.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    (tmp_path / "a.html").write_text(
        '<html><body><article><h2 id="κ-law">κ</h2><a href="#κ-law">ok</a> <a href="#%CE%BA-law">ok</a>'
        '<a href="b.html#nowhere">x</a><a href="c.html">x</a><img src="d.png">'
        '<p>E0 e^{−μγt} and <span class="arithmatex">\\(e^{x}\\)</span> <code>a^{b}</code>; +nan; 0.5 ± 0.000;'
        f" see {WORKFLOW_WORD} 28 and .dev/x.py; as made at commit 0ecf473; NaN names the value;"
        " -0.26 ± 0.19 (z = -1.1), [-0.015, +0.029], 10<sup>-10</sup>; fine: −0.3, x-1, grid[-1], E0-E_c</p>"
        "</article></body></html>"
    )
    (tmp_path / "b.html").write_text('<html><body><h1 id="here">b</h1></body></html>')
    res = mod.check(tmp_path)
    assert len(res["links"]) == 3 and all("a.html" in f for f in res["links"])
    assert len(res["raw_tex"]) == 1 and len(res["nan"]) == 1 and len(res["zero_err"]) == 1
    assert len(res["workflow"]) == 3
    assert len(res["minus"]) == 4, res["minus"]
