"""The shared conventions (studies/conventions.toml): declared once, inherited by the figure studies, strictly checked."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from tests.scene.test_schema import _run_study, _study_root

ROOT = Path(__file__).resolve().parents[2]
STUDIES = ROOT / "studies"
FIGURES = ("fig1", "fig2", "fig3", "fig4", "fig5", "fig6")


def _doc(name):
    return tomllib.loads((STUDIES / name / "study.toml").read_text())


def test_the_figure_studies_and_only_they_take_the_paper_convention():
    figures = sorted(p.parent.name for p in STUDIES.glob("*/study.toml") if _doc(p.parent.name)["about"].get("paper"))
    assert figures == list(FIGURES)
    for name in FIGURES:
        assert _doc(name).get("convention") == "paper", name
    for name in ("resc", "basins"):  # about other choices (the escape radius; exits beyond every Lyapunov orbit)
        text = (STUDIES / name / "study.toml").read_text()
        assert "convention" not in _doc(name)
        assert 'does not take the shared convention "paper"' in text.replace("\n# ", " "), name


@pytest.mark.parametrize("scale", ["quick", "tiny", "paper"])
@pytest.mark.parametrize("name", FIGURES)
def test_a_study_of_the_convention_gets_the_authors_setup(name, scale):
    from hhscatter.studies import load_study

    study = load_study(name, scale)
    extra = {} if "energy" in study.config["scene"] else {"energy": 0.3}
    scene = study.scene("base", **extra)
    assert (scene.r_esc, scene.region, scene.radius) == (1.03, "disk", 0.5)


def test_the_convention_file_is_the_one_place_of_the_escape_radius_of_the_figure_studies():
    conv = (STUDIES / "conventions.toml").read_text()
    assert len(re.findall(r"(?m)^\s*r_esc\s*=\s*1\.03\b", conv)) == 1
    assert tomllib.loads(conv)["paper"] == {"region": "disk", "radius": 0.5, "r_esc": 1.03}
    for name in FIGURES:
        text = (STUDIES / name / "study.toml").read_text()
        assert not re.search(r"(?m)^\s*(r_esc|region|radius)\s*=", text), name
        assert not re.search(r"r_esc\s*=\s*1\.03", text), name


def test_a_study_file_with_a_convention_is_the_merged_scene():
    """A study made of the convention and a few keys of its own: the convention lies under its [scene]."""
    from hhscatter.scene.schema import apply_convention

    conv = {"paper": {"region": "disk", "radius": 0.5, "r_esc": 1.03}}
    doc = {"convention": "paper", "scene": {"n": 10, "energy": 0.3}}
    out = apply_convention(doc, conv, "s.toml", "c.toml")
    assert out["scene"] == {"region": "disk", "radius": 0.5, "r_esc": 1.03, "n": 10, "energy": 0.3}
    assert doc == {"convention": "paper", "scene": {"n": 10, "energy": 0.3}}  # the file's own dict is unchanged
    assert apply_convention({"scene": {"n": 1}}, conv, "s", "c") == {"scene": {"n": 1}}


REFUSED = [
    # (edit of fig3's study.toml, what the message must say)
    (
        lambda t: t.replace('convention = "paper"', 'convention = "papr"', 1),
        "studies/fig3/study.toml: unknown convention 'papr'; conventions in ",
    ),
    (
        lambda t: t.replace('convention = "paper"', 'conventon = "paper"', 1),
        "studies/fig3/study.toml: unknown key 'conventon' (did you mean 'convention'?) before the first table; allowed keys there: convention",
    ),
    (
        lambda t: t.replace('convention = "paper"', "convention = 1", 1),
        "studies/fig3/study.toml: convention must be a string (in quotes), got 1",
    ),
    (
        lambda t: t.replace("seed = 2026 ", "r_esc = 1.5\nseed = 2026 ", 1),
        "studies/fig3/study.toml: [scene] r_esc is set by convention 'paper' (",
    ),
    (
        lambda t: t.replace("[scale.tiny.scene]\n", "[scale.tiny.scene]\nradius = 0.4\n", 1),
        "studies/fig3/study.toml: [scale.tiny.scene] radius is set by convention 'paper' (",
    ),
]


@pytest.mark.parametrize("edit, message", REFUSED)
def test_a_bad_convention_exits_2_naming_it(edit, message, tmp_path, capsys, monkeypatch):
    root = _study_root(tmp_path, "fig3", edit)
    rc, err = _run_study(root, "fig3", capsys, monkeypatch, tmp_path)
    assert rc == 2
    assert err.startswith("hhscatter: error: " + message), err


@pytest.mark.parametrize(
    "text, message",
    [
        (
            '[paper]\nregion = "disk"\nradius = 0.5\nr_ecs = 1.03\n',
            "[paper] unknown key 'r_ecs' (did you mean 'r_esc'?); allowed keys: ",
        ),
        ('[paper]\nr_esc = "1.03"\n', "[paper] r_esc must be a number, got '1.03'"),
        ('[paper]\nregion = "disc"\n', "[paper] region must be one of "),
        ("paper = 1.03\n", "[paper] must be a table, got 1.03"),
    ],
)
def test_a_bad_conventions_file_exits_2_naming_the_key(text, message, tmp_path, capsys, monkeypatch):
    root = _study_root(tmp_path, "fig3", lambda t: t + "\n")
    (root / "conventions.toml").write_text(text)
    rc, err = _run_study(root, "fig3", capsys, monkeypatch, tmp_path)
    assert rc == 2
    assert err.startswith("hhscatter: error: studies/conventions.toml: " + message), err
