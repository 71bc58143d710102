"""The declared plot stage: the figure function gets the tables, numbers, path and parameters it declares."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import pandas as pd
import pytest

from hhscatter.errors import StudyError
from hhscatter.studies.plot_stage import (
    NUMBERS,
    PATH,
    SCALE,
    Param,
    Sibling,
    Table,
    Upstream,
    figure_stage,
    figures,
)

FIGURE = """
import json
from pathlib import Path

def draw(*args, **kwargs):
    calls = Path(__file__).with_name("calls.jsonl")
    shown = lambda v: v.to_dict("list") if hasattr(v, "to_dict") else (str(v) if isinstance(v, Path) else v)
    row = {"args": [shown(a) for a in args], "kwargs": {k: shown(v) for k, v in kwargs.items()}}
    with calls.open("a") as f:
        f.write(json.dumps(row) + "\\n")
"""


def _study(tmp_path: Path, name: str) -> SimpleNamespace:
    folder = tmp_path / "studies" / name
    (folder / "out" / "tiny" / "derived").mkdir(parents=True)
    (folder / "study.py").write_text("")
    (folder / "figure.py").write_text(FIGURE)
    pd.DataFrame({"t": [0.0, 1.5], "P": [1.0, 0.25]}).to_parquet(folder / "out" / "tiny" / "derived" / "curve.parquet")
    return SimpleNamespace(
        name=name,
        root=folder,
        out=folder / "out" / "tiny",
        scale="tiny",
        params=SimpleNamespace(t_max=42.0, parts=["claims"]),
        figure_path=folder / "out" / "tiny" / f"{name}.png",
        read_numbers=lambda other=None: _numbers(folder, other),
        upstream=lambda role: "absent_upstream",
    )


def _numbers(folder: Path, other: str | None) -> dict:
    if other is not None:  # as Study.read_numbers for a study that has not run
        raise FileNotFoundError(f"{folder.parent / other} has no numbers")
    return {"kappa": {"value": 0.1, "err": 0.01}}


def _calls(study) -> list:
    path = study.root / "calls.jsonl"
    return [json.loads(line) for line in path.read_text().splitlines()] if path.exists() else []


def test_the_figure_function_gets_what_is_declared_in_order(tmp_path):
    study = _study(tmp_path, "declared_a")
    plot = figure_stage(
        "draw",
        "curve",
        Table("missing", optional=True),
        NUMBERS,
        PATH,
        t_max=Param("t_max"),
        scale=SCALE,
        other=Sibling("_residuals"),
    )
    plot(study)
    (call,) = _calls(study)
    out = study.root / "out" / "tiny"
    assert call["args"] == [
        {"t": [0.0, 1.5], "P": [1.0, 0.25]},
        None,
        {"kappa": {"value": 0.1, "err": 0.01}},
        str(out / "declared_a.png"),
    ]
    assert call["kwargs"] == {"t_max": 42.0, "scale": "tiny", "other": str(out / "declared_a_residuals.png")}


def test_a_missing_table_is_an_error_unless_declared_optional(tmp_path):
    study = _study(tmp_path, "declared_b")
    with pytest.raises(FileNotFoundError):
        figure_stage("draw", "missing", PATH)(study)
    assert _calls(study) == []


def test_skipped_figures_are_not_drawn(tmp_path):
    study = _study(tmp_path, "declared_c")
    plot = figures(
        figure_stage("draw", Table("missing", skip=True), PATH),  # absent table: not drawn
        figure_stage("draw", "curve", when=("parts", "evidence")),  # "evidence" not in [study] parts: not drawn
        figure_stage("draw", Sibling("_b"), when=("parts", "claims")),
    )
    plot(study)
    assert _calls(study) == [{"args": [str(study.out / "declared_c_b.png")], "kwargs": {}}]


def test_an_upstream_without_the_table_gives_none(tmp_path):
    study = _study(tmp_path, "declared_d")
    figure_stage("draw", Upstream("cmeasure", "cmeasure_points"))(study)
    assert _calls(study) == [{"args": [None], "kwargs": {}}]


def test_a_declaration_that_is_no_input_is_refused_when_declared():
    with pytest.raises(StudyError, match=r"figure_stage\('draw'\).*got 3"):
        figure_stage("draw", NUMBERS, width=3)


def test_every_study_declares_its_plot_stage():
    from hhscatter.studies import stage_module, study_names

    for name in study_names():
        doc = stage_module(name).plot.__doc__
        assert doc.startswith("plot(study) -> None: ") and "figure.plot_" in doc, name
