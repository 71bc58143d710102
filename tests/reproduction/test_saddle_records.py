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
    assert r["d1_range_floor"] == "floor"  # the table has ε = 0.01 below eps_min = 0.015
    assert r["d1_rel_err"] == pytest.approx(0.05 / 1.25, rel=1e-12)
    # no ε below eps_min: the range ends at the nearest neighbours' distance; the bootstrap part the largest
    r = sr.d1_error_record(_dim(1.0, (0.01, 0.02, 0.0), (0.02, 0.2), [0.02, 0.2]), extent=1.0, eps_min=0.01)
    assert (r["d1_range_floor"], r["d1_err_largest"]) == ("points", "resample")
    assert math.isnan(sr.d1_error_record(_dim(0.0, (0.01, 0.0, 0.0), (0.1, 1), [0.1]), 1.0, 0.01)["d1_rel_err"])


def test_floor_scan_record_halves_the_section_dimension_and_keeps_the_refusals():
    """Two floors of a scan with a value (D₁ = 1.30 ± 0.04 and 1.24 ± 0.06: d₁ = D₁/2) and one the estimator refused
    (no value, its note kept); the points' extent, 2, from eps_min/floor: the range in units of the extent."""
    scan = pd.DataFrame({"factor": [0.5, 1.0, 2.0], "floor": [0.004, 0.008, 0.016], "eps_min": [0.008, 0.016, 0.032],
                         "value": [1.30, 1.24, math.nan], "err": [0.04, 0.06, math.nan],
                         "eps_lo": [0.0082, 0.0164, math.nan], "eps_hi": [0.1, 0.1, math.nan],
                         "note": ["", "", "points: fewer than 4 neighbour scales"]})  # fmt: skip
    r = sr.floor_scan_record(scan, 0.02)
    assert r["floor"] == 0.008 and r["scatter_extent"] == 0.02
    assert [x["factor"] for x in r["rows"]] == [0.5, 1.0, 2.0]
    assert r["rows"][0]["d1"] == {"value": 0.65, "err": 0.02} and r["rows"][1]["d1"]["value"] == pytest.approx(0.62)
    assert r["rows"][1]["eps_range_extent"] == pytest.approx([0.0082, 0.05])
    assert r["rows"][2]["d1"] is None and r["rows"][2]["note"].startswith("points: fewer")
    assert sr.floor_scan_record(scan.iloc[[0, 2]], 0.02)["floor"] is None  # no factor 1: no rule's floor


def test_d1_precision_counts_the_points_within_the_target():
    recs = [
        {"id": "a", "d1_rel_err": 0.03, "d1_err_largest": "fit", "d1_range_floor": "points",
         "d1_eps_range_extent": [0.001, 0.1]},
        {"id": "b", "d1_rel_err": 0.031, "d1_err_largest": "range", "d1_range_floor": "floor",
         "d1_eps_range_extent": [0.01, 0.1]},
        {"id": "c", "d1": None},
    ]  # fmt: skip
    p = sr.d1_precision(recs)
    assert (p["n_with_d1"], p["n_within"]) == (2, 1)  # 3 % is within, 3.1 % not
    assert p["largest_part"] == {"fit": 1, "resample": 0, "range": 1}
    assert p["range_floor"] == {"floor": 1, "points": 1}
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


def _gap_record(**extra):
    # κ = 0.1, λ̄ = 0.4 (exact): 1 − κ/λ̄ = 0.75; d₁ = 0.70 ± 0.01: the gap 0.05 ± 0.01, z = −5
    return {"id": "p", "system": "hh", "ratio": 1.5, "kappa": 0.1, "kappa_err": 0.0, "lyapunov": 0.4, "lyapunov_err": 0.0, "d1": 0.70,
            "d1_err": 0.01, "d1_implied": 0.75, "d1_implied_err": 0.0, "z": -5.0, **extra}  # fmt: skip


def test_with_gap_measures_what_each_candidate_leaves_of_the_gap():
    rec = sr.with_gap(_gap_record(
        d1_radius={"value": 0.745, "err": 0.01},  # leaves 0.005 ± 0.01: closes it
        lyapunov_mid={"value": 0.5, "err": 0.0},  # 1 − 0.1/0.5 = 0.8: leaves 0.10 ± 0.01, share −1
        d1_trend_by_t_min=[{"t_min_kappa": c, "d1_section": {"value": 2 * (0.8 - 1 / c), "err": 0.02}} for c in (5, 10, 20)],
        lyapunov_by_t_min=[{"t_min_kappa": c, "value": 0.4, "err": 0.001} for c in (5, 10, 20)],
    ))  # fmt: skip
    g = rec["gap"]
    assert g["gap"]["value"] == pytest.approx(0.05) and g["gap"]["err"] == pytest.approx(0.01)
    assert g["estimator"]["left"]["value"] == pytest.approx(0.005) and g["estimator"]["closes"]
    assert g["estimator"]["share"] == pytest.approx(0.9)
    assert g["mid_life"]["left"]["value"] == pytest.approx(0.1) and not g["mid_life"]["closes"]
    assert g["mid_life"]["share"] == pytest.approx(-1.0)
    # d₁ = 0.8 − 1/(t_min κ) exactly: extrapolated 0.8, λ̄ flat at 0.4: 0.75 − 0.8 = −0.05 left
    assert rec["d1_trend"]["extrapolated"]["value"] == pytest.approx(0.8)
    assert g["selection"]["left"]["value"] == pytest.approx(-0.05) and not rec["d1_trend"]["converged"]
    assert sr.gap_row(rec)["share_estimator"] == pytest.approx(0.9)
    s = sr.gap_summary([rec, sr.with_gap(_gap_record(id="q", z=1.0))])
    assert s["n_gap"] == 1 and s["candidates"]["estimator"]["closes_at"] == ["p"] and s["not_explained"] == []
    assert "closes it at 1 of 1 (p)" in s["statement"]


def test_a_candidate_consistent_only_by_its_larger_error_does_not_close_the_gap():
    """A candidate that moves the gap the wrong way (share < 0) but whose own error is large enough to leave |z| ≤ 2
    is not an explanation: counted apart, and the point stays unexplained."""
    rec = sr.with_gap(_gap_record(d1_radius={"value": 0.66, "err": 0.06}))  # leaves 0.09 ± 0.06: z 1.5, share −0.8
    g = rec["gap"]["estimator"]
    assert abs(g["z"]) <= 2 and g["share"] == pytest.approx(-0.8)
    assert not g["closes"] and g["within_by_error"]
    s = sr.gap_summary([rec])
    assert s["candidates"]["estimator"]["n_closes"] == 0 and s["candidates"]["estimator"]["within_by_error_at"] == ["p"]
    assert s["not_explained"] == ["p"] and "consistent only by its larger error at 1" in s["statement"]


def test_with_gap_without_a_check_or_enough_t_min_leaves_notes():
    rec = sr.with_gap({"id": "x", "z": None, "d1_trend_by_t_min": [{"t_min_kappa": 4.0, "d1_section": None}]})
    assert (
        "gap" not in rec and "at least 3" in rec["d1_trend"]["note"] and "at least 3" in rec["lyapunov_trend"]["note"]
    )
    s = sr.gap_summary([sr.with_gap(_gap_record())])
    assert s["not_explained"] == ["p"] and s["statement"].endswith("not explained by any at 1 (p)")


def test_mid_life_and_t_min_lyapunov_use_only_the_orbits_they_may():
    lo = pd.DataFrame(
        {"traj_id": [0, 1, 2], "outcome": ["censored", "censored", "censored"], "log_stretch": [1.0, 2.0, 3.0]}
    )
    hi = pd.DataFrame(
        {"traj_id": [2, 1, 0], "outcome": ["escaped", "censored", "censored"], "log_stretch": [9.0, 6.0, 3.0]}
    )
    r = sr.mid_lyapunov_record(lo, hi, 10.0, 20.0, n_boot=5)["lyapunov_mid"]
    assert r["value"] == pytest.approx((2.0 + 4.0) / 20.0) and (r["n_orbits"], r["n_left"]) == (
        2,
        1,
    )  # matched by traj_id
    assert "fewer than 2" in sr.mid_lyapunov_record(lo, hi.assign(outcome="escaped"), 10.0, 20.0)["lyapunov_mid_note"]
    tg = pd.DataFrame({"t_end": [10.0, 20.0, 40.0], "log_stretch": [2.0, 6.0, 10.0]})
    rows = sr.lyapunov_by_t_min(tg, [10.0, 20.0, 40.0], 0.1, n_boot=5)
    assert [(r["t_min_kappa"], r["n_orbits"]) for r in rows] == [(1.0, 3), (2.0, 2)]
    assert rows[1]["value"] == pytest.approx(16.0 / 60.0)


def test_the_fluctuation_and_hyperbolic_candidates_replace_the_implied_d1_and_both_inputs():
    """κ = 0.1, λ̄ = 0.4, d₁ = 0.70 ± 0.01: the fluctuations move 1 − κ/λ̄ by −0.04 ± 0.01 (leaves 0.01, share 0.8:
    closes it); the hyperbolic part has λ̄ higher by 0.1 (1 − 0.1/0.5 = 0.8) and d₁ = 0.72 ± 0.01: leaves 0.08."""
    rec = sr.with_gap(_gap_record(
        ftle_fluctuation={"shift": {"value": -0.04, "err": 0.01}},
        hyperbolic={"lyapunov_shift": {"value": 0.1, "err": 0.0}, "d1": {"value": 0.72, "err": 0.01}},
    ))  # fmt: skip
    g = rec["gap"]
    assert g["fluctuation"]["d1_implied"]["value"] == pytest.approx(0.71)
    assert g["fluctuation"]["left"]["value"] == pytest.approx(0.01) and g["fluctuation"]["share"] == pytest.approx(0.8)
    assert g["fluctuation"]["left"]["err"] == pytest.approx(math.hypot(0.01, 0.01)) and g["fluctuation"]["closes"]
    assert g["hyperbolic"]["d1_implied"]["value"] == pytest.approx(0.8) and g["hyperbolic"]["d1"]["value"] == 0.72
    assert g["hyperbolic"]["left"]["value"] == pytest.approx(0.08) and not g["hyperbolic"]["closes"]
    row = sr.gap_row(rec)
    assert row["left_fluctuation"]["value"] == pytest.approx(0.01) and row["share_hyperbolic"] == pytest.approx(-0.6)
    s = sr.gap_summary([rec])
    assert s["candidates"]["fluctuation"]["closes_at"] == ["p"] and s["candidates"]["hyperbolic"]["n_closes"] == 0


def test_fluctuation_record_reads_the_stretches_of_the_selected_orbits():
    """Gaussian stretches, λ̄ = 0.5, D = 0.2, κ = 0.15: the shift d₂ − (1 − κ/λ̄) is −0.0206 in closed form; its 2σ
    interval covers it in at least 6 of 8 seeds (an exponential average: its bootstrap error is itself noisy)."""
    import numpy as np

    shift = 1 - 2 * 0.15 / (0.5 + math.sqrt(0.25 - 2 * 0.2 * 0.15)) - 0.7
    hits = 0
    for seed in range(8):
        rng = np.random.default_rng(seed)
        T = rng.uniform(50.0, 150.0, 4000)
        tg = pd.DataFrame({"t_end": T, "log_stretch": 0.5 * T + np.sqrt(0.2 * T) * rng.normal(size=T.size)})
        r = sr.fluctuation_record(tg, 0.15, 0.0, n_boot=50)["ftle_fluctuation"]
        hits += abs(r["shift"]["value"] - shift) <= 2 * r["shift"]["err"]
        assert r["shift"]["err"] < 0.002 and r["n_orbits"] == 4000 and r["q"] == 2.0
    assert hits >= 6
    bad = sr.fluctuation_record(tg.assign(log_stretch=-tg["log_stretch"]), 0.15, 0.0, n_boot=5)
    assert "not > 0" in bad["ftle_fluctuation_note"]


def test_hyperbolic_record_leaves_out_the_sticky_orbits_points_and_reuses_d1_when_none():
    tg = pd.DataFrame({"traj_id": [7, 8, 9, 10], "t_end": [100.0] * 4, "log_stretch": [1.0, 40.0, 41.0, 39.0]})
    pts = pd.DataFrame({"traj_id": [7, 7, 8, 9, 10], "x": [0.0, 0.1, 0.2, 0.3, 0.4]})
    d = _dim(1.4, (0.01, 0.01, 0.01), (0.01, 0.1), [0.01])
    seen = []
    h = sr.hyperbolic_record(tg, pts, lambda p: seen.append(sorted(set(p["traj_id"]))) or d, d, n_boot=5)["hyperbolic"]
    assert seen == [[8, 9, 10]] and h["n_low"] == 1 and h["threshold"] == 0.5 and h["d1"]["value"] == 0.7
    assert [s["threshold"] for s in h["shares"]] == [0.25, 0.5, 0.75]
    assert h["shares"][1]["share"]["value"] == 0.25
    seen.clear()
    h = sr.hyperbolic_record(tg.iloc[1:], pts, lambda p: seen.append(1) or d, d, n_boot=5)["hyperbolic"]
    assert seen == [] and h["n_low"] == 0 and h["lyapunov_shift"]["value"] == 0.0


def test_fluctuation_record_takes_the_mid_life_stretch_of_the_orbits_inside_at_both_times():
    """Mid-life stretches Λ(t_to) − Λ(t_from) with λ̄ = 0.5 and D = 0.2 over t_to − t_from = 40 (two orbits of
    2002 leave before t_to and are left out, matched by traj_id); the whole lives carry an offset scattered per
    orbit (the way in and out): their shift is larger, the bound."""
    import numpy as np

    rng = np.random.default_rng(1)
    n = 2002
    ids = rng.permutation(n) + 100
    la = 0.5 * 20 + rng.normal(0, 1.0, n)
    lb = la + 0.5 * 40 + np.sqrt(0.2 * 40) * rng.normal(size=n)
    lo = pd.DataFrame({"traj_id": ids, "outcome": "censored", "log_stretch": la})
    hi = pd.DataFrame(
        {"traj_id": ids[::-1], "outcome": ["escaped"] * 2 + ["censored"] * (n - 2), "log_stretch": lb[::-1]}
    )
    T = rng.uniform(80.0, 120.0, n)
    tg = pd.DataFrame(
        {"t_end": T, "log_stretch": 0.5 * T + np.sqrt(0.2 * T) * rng.normal(size=n) + rng.normal(0, 4.0, n)}
    )
    r = sr.fluctuation_record(tg, 0.15, 0.0, (lo, hi, 20.0, 60.0), n_boot=50)["ftle_fluctuation"]
    truth = 1 - 2 * 0.15 / (0.5 + math.sqrt(0.25 - 2 * 0.2 * 0.15)) - 0.7
    assert r["n_orbits"] == n - 2 and r["stretch"] == "mid-life, t = 20 to 60"
    assert abs(r["shift"]["value"] - truth) <= 3 * r["shift"]["err"] and abs(r["diffusion"]["value"] - 0.2) < 0.03
    assert r["shift_whole_life"]["value"] < r["shift"]["value"] - 5 * r["shift"]["err"]
    gone = sr.fluctuation_record(tg, 0.15, 0.0, (lo, hi.assign(outcome="escaped"), 20.0, 60.0), n_boot=5)
    assert "fewer than 2" in gone["ftle_fluctuation_note"]


def _sheet_points(n=6000, seed=0):
    """Positions filling a square beside the origin, tangential speeds 0 … 4, a harmonic force: r̈ = (v² − r²)/r."""
    import numpy as np

    rng = np.random.default_rng(seed)
    x, y, v = 2 + rng.random(n), rng.random(n) - 0.5, 4 * rng.random(n)
    phi = np.arctan2(y, x)
    return pd.DataFrame({"traj_id": np.arange(n), "x": x, "y": y, "px": -v * np.sin(phi), "py": v * np.cos(phi)})


def test_sheets_record_splits_by_the_sign_of_the_radial_acceleration_and_feeds_two_gap_candidates():
    import numpy as np

    pts = _sheet_points()
    v, r = np.hypot(pts["px"], pts["py"]), np.hypot(pts["x"], pts["y"])
    rec = sr.sheets_record(pts, lambda x, y: (-x, -y), floor=1 / 128, k_max=8, n_boot=10)
    assert rec["sheets"]["r_max"]["n_points"] == int((v < r).sum())
    assert rec["sheets"]["r_min"]["n_points"] == int((v > r).sum())
    for s in ("r_max", "r_min"):  # each sheet fills an area in both charts: d₁ = 1 up to the square's edges
        for chart in ("xy", "canonical"):
            assert abs(rec["sheets"][s][chart]["value"] - 1) < 0.06, (s, chart, rec["sheets"][s][chart])
    mean = (rec["sheets"]["r_max"]["xy"]["value"] + rec["sheets"]["r_min"]["xy"]["value"]) / 2
    assert rec["d1_sheets"]["value"] == pytest.approx(mean, rel=1e-12)
    # a force that pulls harder empties the r-minimum sheet: its refusal is kept, no mean is formed
    few = sr.sheets_record(pts, lambda x, y: (-100 * x, -100 * y), floor=1 / 128, k_max=8, n_boot=10)
    assert few["sheets"]["r_min"]["n_points"] == 0 and "xy_note" in few["sheets"]["r_min"]
    assert "d1_sheets" not in few and "d1_chart" not in few
    # the gap's candidates take the mean in place of d₁
    base = {"kappa": 0.1, "kappa_err": 0.0, "lyapunov": 0.4, "lyapunov_err": 0.0, "d1": 0.70, "d1_err": 0.01,
            "d1_implied": 0.75, "d1_implied_err": 0.0, "z": -5.0}  # fmt: skip
    g = sr.with_gap({**base, "d1_sheets": {"value": 0.70, "err": 0.01}, "d1_chart": {"value": 0.745, "err": 0.01}})
    assert g["gap"]["sheets"]["closes"] is False and g["gap"]["chart"]["closes"] is True


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"points": [[0.0, 1.0]]}, "points"),
        ({"points": _sheet_points(100).drop(columns="py")}, "py"),
        ({"force": 3.0}, "force"),
        ({"floor": 0.0}, "floor"),
        ({"k_max": 2.5}, "k_max"),
        ({"n_boot": -1}, "n_boot"),
        ({"min_boxes": float("nan")}, "min_boxes"),
    ],
)
def test_sheets_record_refuses_bad_input_naming_it(kwargs, name):
    from hhscatter.errors import ConfigError

    args = {"points": _sheet_points(100), "force": lambda x, y: (-x, -y), "floor": 0.01, "k_max": 4, "n_boot": 0,
            **kwargs}  # fmt: skip
    with pytest.raises(ConfigError, match=name):
        sr.sheets_record(args.pop("points"), args.pop("force"), **args)


def test_long_lived_keeps_the_orbits_that_left_late_and_refuses_a_table_without_its_columns():
    from hhscatter.errors import ConfigError

    lt = pd.DataFrame({"traj_id": [0, 1, 2], "outcome": ["escaped", "censored", "settled"], "t_end": [5.0, 50.0, 20.0]})
    assert sr.long_lived(lt, 5.0)["traj_id"].tolist() == [0, 2]
    assert sr.long_lived(lt.iloc[:0], 1.0).empty
    with pytest.raises(ConfigError, match="outcome"):
        sr.long_lived(lt.drop(columns="outcome"), 1.0)
    with pytest.raises(ConfigError, match="t_min"):
        sr.long_lived(lt, float("inf"))


def _stretches(lam_of_T, offset=0.0, n=60, seed=0):
    """n orbits in each of 5 lifetimes 200 … 400, Λ = λ(T)·T + offset with a small scatter (a tangent run's table)."""
    import numpy as np

    rng = np.random.default_rng(seed)
    T = np.repeat([200.0, 250.0, 300.0, 350.0, 400.0], n)
    L = lam_of_T(T) * T + offset + rng.normal(0.0, 0.05, T.size)
    return pd.DataFrame({"log_stretch": L, "t_end": T})


def test_lyapunov_record_takes_a_positive_intercept_and_gives_none_where_the_exponents_fall_to_zero():
    """An offset of 4 e-folds per orbit on λ∞ = 0.3: λ̄(T) = 0.3 + 4/T, λ∞ extrapolated to within 2σ of 0.3. Λ/T that
    falls linearly from 0.10 at T = 200 to 0.04 at T = 400 (the longer-lived stretching less, as orbits that stick
    to islands): the 1/T fit meets 0 or below, no λ̄, its bins and ΣΛ/ΣT kept, and the note says so. No drift at all:
    ΣΛ/ΣT, the rule "mean"."""
    lam, _ = sr.lyapunov_record(_stretches(lambda T: 0.3 + 0 * T, offset=4.0), n_bins=5, n_boot=50)
    assert lam["rule"].startswith("extrapolated") and abs(lam["value"] - 0.3) <= 2 * lam["err"]
    assert [round(r["T"]) for r in lam["by_T"]] == [200, 250, 300, 350, 400]
    assert lam["by_T"][0]["value"] == pytest.approx(0.3 + 4.0 / 200.0, abs=1e-3)
    falling, _ = sr.lyapunov_record(_stretches(lambda T: 0.10 - 0.06 * (T - 200.0) / 200.0), n_bins=5, n_boot=50)
    assert falling["value"] is None and falling["err"] is None and falling["rule"].startswith("none")
    assert not falling["converged"] and falling["extrapolated"] <= 2 * falling["extrapolated_err"]
    T = _stretches(lambda T: 0.1 + 0 * T)["t_end"]
    assert falling["mean"] == pytest.approx(float((0.10 - 0.06 * (T - 200.0) / 200.0).mul(T).sum() / T.sum()), abs=1e-3)
    note = sr.no_lyapunov_words(falling)
    assert note.startswith("λ̄: none; λ̄(T) = λ∞ + Λ₀/T extrapolates to λ∞ = −") and "at T = 200 to" in note
    assert note.endswith("over 300 orbits); the relation is not checked")
    flat, _ = sr.lyapunov_record(_stretches(lambda T: 0.3 + 0 * T), n_bins=5, n_boot=50)
    assert flat["rule"] == "mean" and flat["converged"] and flat["value"] == pytest.approx(0.3, abs=1e-3)


@pytest.mark.parametrize(
    "lam, name",
    [
        ({"extrapolated": 0.1, "extrapolated_err": 0.1, "mean": 0.1, "mean_err": 0.01, "n_orbits": 5}, "by_T"),
        ({"extrapolated": 0.1, "extrapolated_err": 0.1, "mean": 0.1, "mean_err": 0.01, "n_orbits": 5,
          "by_T": [{"T": 1.0, "value": 0.1, "err": 0.01}]}, "by_T"),
        ({"extrapolated_err": 0.1, "mean": 0.1, "mean_err": 0.01, "n_orbits": 5, "by_T": []}, "extrapolated"),
    ],
)  # fmt: skip
def test_no_lyapunov_words_refuses_a_record_without_its_fit_naming_the_key(lam, name):
    with pytest.raises(sr.ConfigError, match=name):
        sr.no_lyapunov_words(lam)
