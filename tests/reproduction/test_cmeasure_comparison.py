"""Section points against the c-measure: sets, sample sizes and distances on point sets with a known answer."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hhscatter.reproduction.cmeasure_comparison import (
    ComparisonSettings,
    authors_record,
    cap_rows,
    common_sample_size,
    crossing_sets,
    difference_record,
    distance_tables,
    interval_record,
    paired_differences,
    paired_reference_distances,
    paired_scale_curves,
    reference_record,
    scale_of_curve,
    within_radius,
)

EXTENT = (-1.0, 1.0, -1.0, 1.0)


def _settings(**kw):
    base = dict(
        extent=EXTENT,
        boxes=(1.0, 0.5),
        box_headline=0.5,
        n_splits=2,
        n_boot=4,
        n_proj=8,
        z=2.0,
        delta=0.1,
        noise_max=0.5,
        n_cap=10**5,
        m_min=5,
        seed=3,
        verdict_offsets=1,
        verdict_boot=20,
        verdict_level=0.9,
    )
    return ComparisonSettings(**{**base, **kw})


def _uniform(rng, n, x=(-1.0, 1.0)):
    """n orbits' points uniform in x-range × [−1, 1] (one point per orbit, traj_id 0..n−1)."""
    return pd.DataFrame({"traj_id": np.arange(n), "x": rng.uniform(*x, n), "y": rng.uniform(-1.0, 1.0, n)})


def test_cap_rows_is_a_seeded_subsample_in_order():
    df = pd.DataFrame({"traj_id": np.arange(100)}, index=np.arange(100) + 7)
    a = cap_rows(df, 10, seed=5)
    assert len(a) == 10 and a["traj_id"].is_monotonic_increasing and a.index.tolist() == list(range(10))
    assert a.equals(cap_rows(df, 10, seed=5)) and not a.equals(cap_rows(df, 10, seed=6))
    assert cap_rows(df, 100, seed=5)["traj_id"].tolist() == list(range(100))


def test_within_radius_keeps_the_open_disk():
    df = pd.DataFrame({"x": [0.6, 0.8, 0.0], "y": [0.8, 0.8, -0.99]})  # r = 1, 1.13, 0.99
    assert within_radius(df, 1.0)["y"].tolist() == [-0.99]


def test_crossing_sets_first_crossing_after_t_star_and_the_band():
    sec = pd.DataFrame(
        {
            "traj_id": [0, 0, 0, 1, 1, 2, 3],
            "t": [4.0, 5.0, 9.0, 2.0, 6.0, 7.5, 3.0],
            "x": 0.1,
            "y": 0.2,
            "energy": [0.40, 0.305, 0.29, 0.35, 0.295, 0.31, 0.33],
        }
    )
    t_end = [10.0, 10.0, 8.0, 3.5, 4.0]
    a, b, n = crossing_sets(sec, t_end, 5.0, (0.295, 0.305), n_cap=100, seed=0)
    # orbit 0: its crossing at t = 5 (t ≥ t*, not the later one); 1 at 6; 2 at 7.5; 3 has none after t*
    assert a[["traj_id", "t"]].values.tolist() == [[0, 5.0], [1, 6.0], [2, 7.5]]
    assert b["traj_id"].tolist() == [0, 1]  # the band is closed; orbit 0's later crossing at 0.29 is not looked at
    assert (n["N"], n["n_alive_t_star"], n["n_a_all"], n["n_a"], n["n_b"]) == (5, 3, 3, 3, 2)
    assert n["mean_E_a"] == pytest.approx((0.305 + 0.295 + 0.31) / 3)
    assert n["mean_t_a"] == pytest.approx((5.0 + 6.0 + 7.5) / 3) and n["std_E_a"] == pytest.approx(
        np.std([0.305, 0.295, 0.31], ddof=1)
    )
    a2, _, n2 = crossing_sets(sec, t_end, 5.0, (0.295, 0.305), n_cap=2, seed=0)
    assert len(a2) == 2 and n2["n_a_all"] == 3 and n2["n_a"] == 2


def test_common_sample_size():
    assert common_sample_size({"a": range(40), "b": range(100)}, range(60), 10) == ({"a": 20, "b": 30}, 20)
    with pytest.raises(ValueError, match="m_min"):
        common_sample_size({"a": range(10)}, range(60), 10)


def test_distance_tables_separated_and_equal_sets():
    rng = np.random.default_rng(1)
    left, right = _uniform(rng, 400, (-1.0, 0.0)), _uniform(rng, 400, (0.0, 1.0))
    refs = {"E1": left[["x", "y"]].to_numpy(), "E2": right[["x", "y"]].to_numpy()}
    sets = {(0.01, "a"): left.copy(), (0.01, "b"): left.iloc[:3]}  # b: too few points, left out
    dtab, stab = distance_tables(sets, refs, {(0.01, "a"): 200}, 150, _settings())
    assert stab[["set", "ref"]].values.tolist() == [["a", "E1"], ["a", "E2"], ["cm_E2", "E1"]]
    s = stab.set_index(["set", "ref"])
    # the same points: distance 0; points on the two sides of x = 0 (a box edge at ε = 1 and 0.5): Hellinger 1
    assert s.loc[("a", "E1"), "hellinger"] == 0.0 and s.loc[("a", "E1"), "sw1"] == pytest.approx(0.0, abs=1e-12)
    assert s.loc[("a", "E2"), "hellinger"] == pytest.approx(1.0) and s.loc[("a", "E2"), "tv"] == pytest.approx(1.0)
    # against E1 at the common m, against E2 at the largest m = min(|P|, |Q|) // 2
    assert s.loc[("a", "E1"), "m"] == 150 and bool(s.loc[("a", "E1"), "common_m"])
    assert s.loc[("a", "E2"), "m"] == 200 and not s.loc[("a", "E2"), "common_m"]
    assert (s["box_headline"] == 0.5).all() and set(dtab["box"]) == {1.0, 0.5}
    # uniform halves 1 wide: SW1 of a shift by 1 along x, averaged over directions, is 2/π (E|cos θ| · 1)
    assert s.loc[("cm_E2", "E1"), "sw1"] == pytest.approx(2 / math.pi, abs=0.08)


def test_interval_record_is_mean_and_percentiles():
    v = np.arange(1.0, 12.0)
    rec = interval_record(v, 0.8)
    assert rec == {"value": 6.0, "interval": [pytest.approx(np.quantile(v, 0.1)), pytest.approx(np.quantile(v, 0.9))]}


def test_scale_of_curve_skips_uninformative_sides():
    boxes = [1.0, 0.5, 0.25, 0.125]
    assert scale_of_curve(boxes, [0.05, 0.5, 0.08, 0.2], [True, False, True, True], 0.1) == 0.25
    assert scale_of_curve(boxes, [0.05] * 4, [False] * 4, 0.1) == math.inf
    assert scale_of_curve(boxes, [0.05] * 4, [True] * 4, 0.1) == 0.125


def test_paired_differences_find_the_set_farther_from_the_reference():
    rng = np.random.default_rng(2)
    ref, near, far = _uniform(rng, 600), _uniform(rng, 600), _uniform(rng, 600, (0.0, 1.0))
    rows = paired_differences(
        [("x", "far − near", None, (near, far, ref)), ("y", "tiny", 2, (near[:3], far, ref))], _settings()
    )
    r = rows[0]
    assert (r["construction"], r["offsets"], r["n_5a"], r["n_5b"], r["box"]) == ("x", 1, 600, 600, 0.5)
    # the far set lies on half of the reference's support: H² = 1 − Σ √(p q) = 1 − √(1/2), far above the near set
    assert r["delta_interval"][0] > 0.3 and r["d_5a"] < 0.1
    assert set(rows[1]) == {"construction", "label", "note"}


def test_paired_reference_distances_closer_to_the_right_reference():
    rng = np.random.default_rng(4)
    E1, E2 = _uniform(rng, 500), _uniform(rng, 500, (0.0, 1.0))
    runs = {"5a": _uniform(rng, 500), "5b": _uniform(rng, 500, (0.0, 1.0))}
    rows, curves, box = paired_reference_distances([("ours", "test", runs, {"E1": E1, "E2": E2})], _settings())
    assert box == 0.5 and [c["set"] for c in curves["ours"]] == ["5a", "5a", "5b", "5b", "E2"]
    by = {r["set"]: r for r in rows}
    assert by["5a"]["delta"]["interval"][0] > 0  # 5a drawn like E1: closer to E1
    assert by["5b"]["delta"]["interval"][1] < 0  # 5b drawn like E2: closer to E2
    assert by["5a"]["d_E2"]["value"] == pytest.approx(by["5a"]["d_E1"]["value"] + by["5a"]["delta"]["value"])


def test_paired_scale_curves_order_by_relaxation_time():
    rng = np.random.default_rng(5)
    ref = _uniform(rng, 500)
    sets_a = {0.01: _uniform(rng, 500), 0.02: _uniform(rng, 500, (0.0, 1.0)), 0.03: _uniform(rng, 3)}
    t_star = {0.01: 17.0, 0.02: 8.5, 0.03: 5.6}
    dtab = pd.DataFrame(
        {"gamma": [0.01, 0.01, 0.02, 0.02], "set": "a", "ref": "E1", "box": [1.0, 0.5] * 2, "hellinger_noise": 0.1}
    )
    rec = paired_scale_curves(sets_a, t_star, dtab, ref, _settings())
    # γ = 0.03 has too few points; the others by t*: 0.02 (8.5) then 0.01 (17)
    assert [c["gamma"] for c in rec["curves"]] == [0.02, 0.01]
    far, near = rec["curves"]
    assert near["eps_delta"] == 0.5 and far["eps_delta"] is None  # the far set never within δ
    assert rec["eps_shrink_share"] == 1.0 and rec["steps"][0]["interval"][1] < 0
    assert paired_scale_curves({0.01: ref}, {0.01: 1.0}, dtab, ref, _settings()) is None
    # a reference of 3 orbits cannot be half-sampled
    assert "note" in paired_scale_curves({0.01: ref[:5], 0.02: ref[:5]}, t_star, dtab, ref[:3], _settings())


def _in_disk(df):
    return int(((df["x"] ** 2 + df["y"] ** 2) < 1.0).sum())


def test_difference_record_cuts_the_reference_for_the_authors_constructions_only():
    rng = np.random.default_rng(6)
    ref = _uniform(rng, 800)
    ours = (_uniform(rng, 500), _uniform(rng, 500, (0.0, 1.0)))
    authors = (_uniform(rng, 300), _uniform(rng, 310))
    random = (_uniform(rng, 320), _uniform(rng, 330))
    rec = difference_record(ref, ours, authors, random, _settings(verdict_offsets=2), E1=0.3, momentum="random")
    by = {r["construction"]: r for r in rec["rows"]}
    assert list(by) == ["old", "cut", "cut_offsets", "cut_offsets_random", "ours"]
    assert [by[k]["offsets"] for k in by] == [1, 1, 4, 4, 4]  # one placement, or verdict_offsets² of them
    assert by["old"]["n_ref"] == by["ours"]["n_ref"] == 800
    assert by["cut"]["n_ref"] == by["cut_offsets_random"]["n_ref"] == _in_disk(ref) < 800
    assert (by["cut_offsets_random"]["n_5a"], by["cut_offsets_random"]["n_5b"]) == (320, 330)
    assert (by["cut"]["n_5a"], by["ours"]["n_5b"]) == (300, 500)
    assert by["ours"]["delta_interval"][0] > 0.3  # 5b on half of the reference's support: far farther than 5a
    assert "momentum = 'random'" in rec["sensitivity_momentum"] and rec["level"] == 0.9 and rec["n_boot"] == 20


def test_reference_record_pairs_both_constructions():
    rng = np.random.default_rng(7)
    refs = {"E1": _uniform(rng, 600), "E2": _uniform(rng, 600, (0.0, 1.0))}
    ours = (_uniform(rng, 500), _uniform(rng, 500, (0.0, 1.0)))
    rec = reference_record(refs, ours, (_uniform(rng, 400), _uniform(rng, 400)), _settings(), E1=0.3, E2=0.35)
    by = {(r["construction"], r["set"]): r for r in rec["rows"]}
    assert list(by) == [("ours", "5a"), ("ours", "5b"), ("authors", "5a"), ("authors", "5b")]
    assert by[("ours", "5a")]["n_E1"] == 600 and by[("authors", "5a")]["n_E1"] == _in_disk(refs["E1"])
    assert by[("ours", "5a")]["delta"]["interval"][0] > 0  # 5a drawn like E1: closer to E1
    assert by[("ours", "5b")]["delta"]["interval"][1] < 0  # 5b drawn like E2: closer to E2
    assert (rec["box"], rec["boxes"], rec["E1"], rec["E2"], rec["offsets"]) == (0.5, [1.0, 0.5], 0.3, 0.35, 1)
    assert set(rec["curves"]) == {"ours", "authors"}


def test_authors_record_rows_of_their_sets_at_one_common_size_without_the_reference_row():
    rng = np.random.default_rng(2)
    left, right = _uniform(rng, 300, (-1.0, 0.0)), _uniform(rng, 300, (0.0, 1.0))
    refs = {"E1": left[["x", "y"]].to_numpy(), "E2": right[["x", "y"]].to_numpy()}
    sets = {("authors", "5a_authors"): left.iloc[:100], ("authors", "5b_authors"): right.iloc[:40]}
    rec = authors_record(sets, refs, "their square ICs", _settings())
    assert rec["convention"] == "their square ICs" and rec["n_points"] == {"5a_authors": 100, "5b_authors": 40}
    rows = {(r["set"], r["ref"]): r for r in rec["rows"]}
    assert list(rows) == [("5a_authors", "E1"), ("5a_authors", "E2"), ("5b_authors", "E1"), ("5b_authors", "E2")]
    # against E1 both at the smaller set's half, 40 // 2; against E2 each at its own half
    assert [rows[k]["m"] for k in rows] == [20, 50, 20, 20]
    # 5a: points on E1's side of x = 0 (a box edge), 5b: on E2's side: disjoint from the other reference
    assert rows[("5a_authors", "E2")]["hellinger"] == pytest.approx(1.0)
    assert rows[("5b_authors", "E1")]["hellinger"] == pytest.approx(1.0)
    assert rows[("5a_authors", "E1")]["hellinger"] < 0.3 and rows[("5b_authors", "E2")]["hellinger"] < 0.3


def test_authors_record_without_rows_when_no_set_is_large_enough():
    rng = np.random.default_rng(3)
    pts = _uniform(rng, 9)
    refs = {"E1": pts[["x", "y"]].to_numpy(), "E2": pts[["x", "y"]].to_numpy()}
    rec = authors_record({("authors", "5a_authors"): pts}, refs, "c", _settings(m_min=5))  # 9 // 2 = 4 < 5
    assert rec == {"convention": "c", "n_points": {"5a_authors": 9}, "rows": None}
