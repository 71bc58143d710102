"""The tiny scale is a smoke test of a few hundred orbits: its outputs state values and no verdict."""

from __future__ import annotations

import json
import re

from hhscatter.reproduction.verdicts import NO_VERDICT

#: what a verdict reads like, wherever it would sit in a JSON (a row's verdict, a claim's, a note)
VERDICT_WORDS = re.compile(r"^(agrees|differs|consistent with|closer to|same as|not shown|comparable|Wada)\b")


def _verdicts(obj, path=""):
    """(path, value) of every "verdict" key and every string that reads as a verdict, outside the configuration."""
    if isinstance(obj, dict):
        for k, v in obj.items():
            if k in ("config", "provenance", "made_from"):
                continue
            if k == "verdict":
                yield f"{path}.{k}", v
            else:
                yield from _verdicts(v, f"{path}.{k}")
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            yield from _verdicts(v, f"{path}[{i}]")
    elif isinstance(obj, str) and VERDICT_WORDS.match(obj):
        yield path, obj


def test_every_tiny_json_states_no_verdict(tiny_studies):
    docs = sorted(tiny_studies.glob("*/out/tiny/*.json"))
    docs = [p for p in docs if p.name == f"{p.parent.parent.parent.name}.json"]  # each study's numbers
    assert len(docs) >= 10
    found = {p.name: list(_verdicts(json.loads(p.read_text()))) for p in docs}
    assert sum(len(v) for v in found.values()) > 50  # the rows are there, each with its verdict cell
    wrong = [(name, path, v) for name, got in found.items() for path, v in got if v != NO_VERDICT]
    assert not wrong, wrong[:10]


def test_every_tiny_json_records_its_library_warnings(tiny_studies):
    """Each study's analyze stage writes the numpy/scipy warnings it counted (a list, possibly empty) into its JSON."""
    docs = [
        p for p in sorted(tiny_studies.glob("*/out/tiny/*.json")) if p.name == f"{p.parent.parent.parent.name}.json"
    ]
    assert len(docs) >= 10
    for p in docs:
        recs = json.loads(p.read_text())["library_warnings"]
        assert isinstance(recs, list), p.name
        for r in recs:
            assert set(r) == {"where", "category", "message", "count"} and r["count"] >= 1, (p.name, r)


#: the multi-panel figures the pages show, each written panel by panel too (hhscatter.publish.figures.save_panels)
MULTI_PANEL = {
    "fig1": "fig1",
    "fig4": "fig4",
    "fig5": "fig5",
    "fig6": "fig6",
    "resc": "resc",
    "noise": "noise",
    "operator": "operator",
    "generality": "generality",
    "generality_decay": "generality",
    "generality_sections": "generality",
    "basins_measures": "basins",
    "basins_scale": "basins",
}


def test_every_multi_panel_figure_is_written_panel_by_panel(tiny_studies):
    """Each multi-panel figure of the tiny build has ≥ 2 panels beside it, each between 600 and 1400 px wide: shown
    at a page's full content width (≈ 1000 px) its labels print at about their drawn size, not at a third of it."""
    from matplotlib.image import imread

    for fig, study in MULTI_PANEL.items():
        out = tiny_studies / study / "out" / "tiny"
        assert (out / f"{fig}.png").exists(), fig
        panels = sorted(out.glob(f"{fig}_panel_*.png"))
        assert len(panels) >= 2, fig
        for p in panels:
            w = imread(p).shape[1]
            assert 600 <= w <= 1400, (p.name, w)
