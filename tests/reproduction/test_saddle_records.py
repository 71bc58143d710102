"""The records of a chaotic-saddle study (hhscatter.reproduction.saddle_records): d₁'s error parts and range on
hand-made dimension results, and the rows and summaries against the committed quick-scale numbers of study saddle
(made from the same point records before these functions existed)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd
import pytest

from hhscatter.analysis.geometry.saddle import SaddleDimension
from hhscatter.reproduction import saddle_records as sr

QUICK = Path(__file__).resolve().parents[2] / "docs" / "studies" / "assets" / "saddle.json"


def _dim(value, parts, eps_range, eps):
    fit, res, rng = parts
    err = math.sqrt(sum(e * e for e in parts if math.isfinite(e)))
    return SaddleDimension(value=value, err=err, err_fit=fit, err_resample=res, err_range=rng, method="test",
                           eps_range=eps_range, n_points=100, n_groups=10, table=pd.DataFrame({"eps": eps}))  # fmt: skip


def test_d1_error_record_names_the_largest_finite_part_and_what_ends_the_range():
    # fit 0.03, resample NaN (no bootstrap), range 0.04: the largest is the range part, err = 0.05
    d = _dim(1.25, (0.03, math.nan, 0.04), (0.02, 0.2), [0.01, 0.02, 0.2])
    r = sr.d1_error_record(d, extent=2.0, eps_min=0.015)
    assert r["d1_err_largest"] == "range"
    assert r["d1_section_err_parts"]["fit"] == 0.03 and math.isnan(r["d1_section_err_parts"]["resample"])
    assert r["d1_eps_range_extent"] == [0.01, 0.1] and r["d1_eps_min_extent"] == 0.0075
    assert r["d1_range_floor"] == "resolution"  # the table has ε = 0.01 below eps_min = 0.015
    assert r["d1_rel_err"] == pytest.approx(0.05 / 1.25, rel=1e-12)
    # no ε below eps_min: the range ends at the nearest neighbours' distance; the bootstrap part the largest
    r = sr.d1_error_record(_dim(1.0, (0.01, 0.02, 0.0), (0.02, 0.2), [0.02, 0.2]), extent=1.0, eps_min=0.01)
    assert (r["d1_range_floor"], r["d1_err_largest"]) == ("points", "resample")
    assert math.isnan(sr.d1_error_record(_dim(0.0, (0.01, 0.0, 0.0), (0.1, 1), [0.1]), 1.0, 0.01)["d1_rel_err"])


def test_d1_precision_counts_the_points_within_the_target():
    recs = [
        {"id": "a", "d1_rel_err": 0.03, "d1_err_largest": "fit", "d1_range_floor": "points",
         "d1_eps_range_extent": [0.001, 0.1]},
        {"id": "b", "d1_rel_err": 0.031, "d1_err_largest": "range", "d1_range_floor": "resolution",
         "d1_eps_range_extent": [0.01, 0.1]},
        {"id": "c", "d1": None},
    ]  # fmt: skip
    p = sr.d1_precision(recs)
    assert (p["n_with_d1"], p["n_within"]) == (2, 1)  # 3 % is within, 3.1 % not
    assert p["largest_part"] == {"fit": 1, "resample": 0, "range": 1}
    assert p["range_floor"] == {"resolution": 1, "points": 1}
    assert "at 1 of the 2 points with d₁ (a)" in p["statement"] and "span 1.0–2.0 decades" in p["statement"]
    assert sr.d1_precision(recs, target=0.05)["n_within"] == 2


def test_with_d0_keeps_the_note_and_checks_the_order_only_with_both_dimensions():
    rec = sr.with_d0({"notes": [], "d1": 0.70, "d1_err": 0.03}, {"d0": 0.60, "d0_err": 0.01})
    # d₀ − d₁ = −0.10, σ = √(0.03² + 0.01²) = 0.0316: z = −3.2, d₀ ≥ d₁ − 2σ fails
    assert rec["d0_ge_d1"]["holds"] is False and rec["d0_ge_d1"]["z"] == pytest.approx(-0.1 / math.sqrt(0.001))
    d0 = {"note": "d0: fewer than 3 values of ε"}
    rec = sr.with_d0({"notes": ["x"], "d1": 0.5, "d1_err": 0.1}, d0)
    assert rec["notes"] == ["x", "d0: fewer than 3 values of ε"] and "d0_ge_d1" not in rec and "note" not in rec


@pytest.fixture(scope="module")
def quick():
    return json.loads(QUICK.read_text())


def test_the_rows_and_summaries_are_the_committed_quick_numbers(quick):
    """The quick-scale JSON was written by the study's record builder before these functions; from its point
    records they give the same relation and dimension rows, summaries and d₁ precision statement."""
    recs = quick["saddle"]
    assert [sr.relation_row(r) for r in recs] == quick["relation"]
    assert sr.relation_summary(recs) == quick["summary"]
    assert [sr.dimension_row(r) for r in recs] == quick["dimensions"]
    assert sr.dimension_summary(recs) == quick["dimensions_summary"]
    assert sr.d1_precision(recs) == quick["d1_precision"]
