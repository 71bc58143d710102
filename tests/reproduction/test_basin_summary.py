"""The records of a basin study (hhscatter.reproduction.basin_summary), S_b at fixed box sides
(hhscatter.analysis.geometry.basins.entropy_by_box) and the cut-off comparison
(hhscatter.analysis.geometry.cutoff.cutoff_comparison) on synthetic input with known answers."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.geometry.basins import commensurate_sides, entropy_by_box
from hhscatter.analysis.geometry.cutoff import cutoff_comparison
from hhscatter.reproduction import basin_summary as bs

ALPHA, C, N = 0.4, 0.5, 200_000


def _unc(eps, k_override=None):
    """An f(ε) table of the exact power law f = C ε^α with counts k = round(f n) (``k_override``: {index: k})."""
    eps = np.asarray(eps, dtype=float)
    k = np.round(C * eps**ALPHA * N).astype(int)
    for i, v in (k_override or {}).items():
        k[i] = v
    return pd.DataFrame({"eps": eps, "f": k / N, "k": k, "n": N})


def test_uncertainty_fits_choose_the_resolved_window():
    # ε decreasing, as in the study; the two smallest ε are unresolved (k < 10) and far off the power law:
    # the window must leave them out
    eps = np.geomspace(1e-2, 1e-9, 8)
    unc = _unc(eps, {6: 9, 7: 3})
    ok, fit, cut = bs.uncertainty_fits(unc, 10)
    np.testing.assert_array_equal(ok.to_numpy(), [True] * 6 + [False, False])
    assert fit.eps_range == (eps[5], eps[0])
    assert fit.n_points == 6
    assert fit.alpha == pytest.approx(ALPHA, abs=5e-3)  # rounding of the counts only
    assert cut is not None and not cut.detected  # a single power law: no cut-off


def test_uncertainty_fits_need_three_points_for_alpha_and_five_for_the_cutoff():
    eps = np.geomspace(1e-2, 1e-6, 6)
    for n_ok, has_fit, has_cut in [(2, False, False), (3, True, False), (4, True, False), (5, True, True)]:
        unc = _unc(eps, {i: 0 for i in range(n_ok, len(eps))})
        ok, fit, cut = bs.uncertainty_fits(unc, 10)
        assert int(ok.sum()) == n_ok
        assert (fit is not None, cut is not None) == (has_fit, has_cut), n_ok


def test_point_numbers_tau2_and_smallest_resolved_eps():
    """τ2 = ln(E0/E_c)/γ (Eq. (eq:tau2) with μ = 1; ∞ at γ = 0) and the smallest resolved ε's decision time."""
    eps = np.geomspace(1e-2, 1e-6, 6)  # decreasing, as in the study
    unc = _unc(eps, {5: 0}).assign(t_decide_median=np.arange(6.0) + 10)
    ok, fit, cut = bs.uncertainty_fits(unc, 10)

    class Frac:
        frac, lo, hi, n = [1.0, 0, 0, 0, 0], [0.9, 0, 0, 0, 0], [1.0, 0, 0, 0, 0], 100

    class Wada:
        wada, wada_fraction, r_wada, hausdorff_slope = False, np.array([0.1, 0.2]), 5, 1.0

    class Chans:
        p_value, frac = 0.5, [1 / 3] * 3

    ent = pd.DataFrame(
        {"box": [5], "S_b": [0.3], "S_b_err": [0.01], "S_bb": [0.8], "S_bb_err": [0.02], "log2_fractal": [True]}
    )
    loc = pd.DataFrame({"eps_mid": [1e-3, 1e-4], "d": [1.5, math.nan], "d_err": [0.1, math.nan]})
    m = {
        "fr": Frac,
        "present": [0],
        "wada": Wada,
        "chans": Chans,
        "exits": [0],
        "wada_x": None,
        "slim": None,
        "rate": None,
        "ok": ok,
        "fit": fit,
        "cut": cut,
    }
    ec = 1 / 6
    p = bs.point_record(0.3, 0.01, 5, ec, ent, unc, loc, m)
    assert p["tau2_mu1"] == pytest.approx(math.log(0.3 / ec) / 0.01, rel=1e-15)
    assert bs.point_record(0.3, 0.0, 5, ec, ent, unc, loc, m)["tau2_mu1"] == math.inf
    # the smallest resolved ε is the fifth row (the sixth has k = 0); its decision time comes along
    assert p["smallest_resolved_eps"] == eps[4] and p["t_decide_median_smallest_eps"] == 14.0
    assert p["S_bb"] == {"value": 0.8, "err": 0.02} and p["log2_fractal"] is True
    assert p["wada"]["W_at_r"] == 0.2  # r_wada beyond the table: its last entry
    assert p["local_d"] == [{"eps_mid": 1e-3, "d": 1.5, "d_err": 0.1}]  # NaN rows dropped
    # a headline box not in the table: no entropies
    assert bs.point_record(0.3, 0.01, 7, ec, ent, unc, loc, m)["S_b"] is None


# ---------------------------------------------------------------------------
# S_b and S_bb at fixed physical box sides
# ---------------------------------------------------------------------------
def _straight(n, x_b=0.05):
    """An n × n map of [−1, 1]² with label 0 left of x = x_b and 1 right of it (cell centres)."""
    c = -1 + (np.arange(n) + 0.5) * 2.0 / n
    return np.broadcast_to((c >= x_b).astype(int), (n, n)).copy()


def test_entropy_by_box_of_a_straight_boundary_matches_the_closed_form():
    """x = 0.05 splits the box column [0, 0.1) in half (S = ln 2) and [0, 0.2) at 1/4 (S = h(1/4)); one column of
    boundary boxes out of 1/side columns."""
    t = entropy_by_box(_straight(40), (-1, 1, -1, 1), [0.1, 0.2])
    h = lambda p: -p * math.log(p) - (1 - p) * math.log(1 - p)
    assert t.box_cells.tolist() == [2, 4] and t.grid.tolist() == [40, 40]
    assert t.n_boundary.tolist() == [20, 10]
    assert t.S_bb.tolist() == pytest.approx([math.log(2), h(0.25)], rel=1e-12)
    assert t.S_b.tolist() == pytest.approx([math.log(2) / 20, h(0.25) / 10], rel=1e-12)


def test_entropy_by_box_compares_grids_like_for_like():
    """The same straight boundary on a 40² and an 80² map: at the same side (0.1: 2 and 4 cells) the same S_b;
    at the same number of cells (2: sides 0.1 and 0.05) not (x = 0.05 is a box edge at side 0.05)."""
    a = entropy_by_box(_straight(40), (-1, 1, -1, 1), [0.1]).iloc[0]
    b = entropy_by_box(_straight(80), (-1, 1, -1, 1), [0.1, 0.05])
    assert b.box_cells.tolist() == [4, 2]
    assert b.S_b.iloc[0] == pytest.approx(a.S_b, rel=1e-12)
    assert a.S_b == pytest.approx(math.log(2) / 20, rel=1e-12) and b.S_b.iloc[1] == 0.0


def test_entropy_by_box_refuses_sides_that_are_not_whole_cells():
    assert commensurate_sides([0.01, 0.025, 0.05, 0.1], (-1, 1, -1, 1), 200) == [0.05, 0.1]
    assert commensurate_sides([0.01, 0.025], (-1, 1, -1, 1), 2000) == [0.01, 0.025]
    with pytest.raises(ValueError, match="0.025"):
        entropy_by_box(_straight(200), (-1, 1, -1, 1), [0.025])
    with pytest.raises(ValueError, match="square"):
        entropy_by_box(_straight(40), (-1, 1, -1, 2), [0.1])


def test_entropy_exponents_recover_a_power_law_and_skip_short_groups():
    recs = [
        {
            "E0": 0.25,
            "gamma": 0.0,
            "map": "map",
            "grid": 400,
            "box_side": s,
            "box_cells": int(round(s * 200)),
            "S_b": 0.7 * s**0.24,
            "S_b_err": 1e-4,
        }
        for s in (0.01, 0.025, 0.05, 0.1, 0.2)
    ]
    recs[0]["S_b"] = 0.01  # a 2-cell box: below min_cells, left out
    recs += [
        {
            "E0": 0.25,
            "gamma": 0.0,
            "map": "scan",
            "grid": 200,
            "box_side": s,
            "box_cells": int(round(s * 100)),
            "S_b": s,
            "S_b_err": 1e-4,
        }
        for s in (0.02, 0.05, 0.1)
    ]  # 2, 5, 10 cells: two sides left
    out = bs.entropy_exponents(recs)
    assert len(out) == 1 and out[0]["grid"] == 400
    assert out[0]["alpha"] == pytest.approx(0.24, abs=1e-12)


# ---------------------------------------------------------------------------
# the cut-off: measured against predicted
# ---------------------------------------------------------------------------
def test_cutoff_comparison_against_the_closed_form():
    """λ constant on [E_c, E0]: ln(1/ε_c) = λ ln(E0/E_c)/(μγ); the predicted interval is the envelope of λ ± σ,
    μ ± σ and the second estimator (λ_alt) of λ."""
    E0, g, ec, mu, smu, lam, sl, alt = 0.3, 0.01, 0.15, 1.0, 0.005, 0.5, 0.002, 0.4
    L = lambda l, m: math.exp(-l * math.log(E0 / ec) / (m * g))
    pred = L(lam, mu)
    meas = pred * 10**-0.5
    c = cutoff_comparison(
        E0,
        g,
        ec,
        mu,
        smu,
        [0.2, 0.3],
        [lam] * 2,
        [sl] * 2,
        lam_alt=[alt] * 2,
        measured=meas,
        measured_lo=meas * 0.9,
        measured_hi=meas * 1.1,
    )
    assert c.predicted == pytest.approx(pred, rel=1e-6)
    assert c.predicted_alt == pytest.approx(L(alt, mu), rel=1e-6)
    assert c.predicted_lo == pytest.approx(L(lam + sl, mu - smu), rel=1e-6)
    assert c.predicted_hi == pytest.approx(L(alt, mu + smu), rel=1e-6)
    assert c.log10_ratio == pytest.approx(-0.5, abs=1e-6) and c.factor == pytest.approx(10**0.5, rel=1e-6)
    # measured below: the gap is from the measured interval's top to the predicted interval's bottom
    gap = math.log10(c.predicted_lo) - math.log10(meas * 1.1)
    assert gap > 0 and c.gap_decades == pytest.approx(gap, rel=1e-6) and not c.overlap
    assert "factor 3.2 below" in c.statement


def test_cutoff_comparison_without_a_detected_cutoff_checks_the_bound():
    args = (0.3, 0.01, 0.15, 1.0, 0.0, [0.2, 0.3], [0.5, 0.5], [0.0, 0.0])
    pred = math.exp(-0.5 * math.log(2) / 0.01)
    ok = cutoff_comparison(*args, measured=None, measured_hi=pred * 10)
    assert math.isnan(ok.log10_ratio) and ok.overlap and "consistent" in ok.statement
    far = cutoff_comparison(*args, measured=None, measured_hi=pred / 100)
    assert far.gap_decades == pytest.approx(2.0, abs=1e-6) and not far.overlap
    with pytest.raises(ValueError, match="γ"):
        cutoff_comparison(0.3, 0.0, *args[2:])


def test_cutoff_records_and_summary():
    per = [
        {"energy": 0.3, "gamma": 0.0, "cutoff": None, "smallest_resolved_eps": 1e-10},
        {
            "energy": 0.3,
            "gamma": 0.01,
            "smallest_resolved_eps": 1e-10,
            "cutoff": {"detected": True, "eps_c": 1e-3, "eps_c_lo": 0.9e-3, "eps_c_hi": 1.1e-3},
        },
        {
            "energy": 0.3,
            "gamma": 0.02,
            "smallest_resolved_eps": 1e-10,
            "cutoff": {"detected": False, "eps_c": math.nan, "eps_c_lo": 0.0, "eps_c_hi": 1e-9},
        },
    ]
    scan = pd.DataFrame(
        {"energy": [0.2, 0.3], "lam": [0.5, 0.5], "lam_err": [0.0, 0.0], "lam_kg": [math.nan, math.nan]}
    )
    recs = bs.cutoff_records(per, scan, 1.0, 0.0, 0.15)
    assert [(r["E0"], r["gamma"], r["detected"]) for r in recs] == [(0.3, 0.01, True), (0.3, 0.02, False)]
    pred = math.exp(-0.5 * math.log(2) / 0.01)
    assert recs[0]["log10_ratio"] == pytest.approx(math.log10(1e-3 / pred), rel=1e-6)
    assert recs[1]["log10_ratio"] is None and recs[1]["eps_c_predicted_kantz_grassberger"] is None
    summ = bs.cutoff_summary(recs)
    assert summ["n_resolved"] == 1 and summ["n_below"] == 0 and summ["n_overlap"] == 0
    assert summ["factor_min"] == pytest.approx(1e-3 / pred, rel=1e-6)


def test_entropy_by_box_at_keeps_the_asked_sides_of_every_grid():
    """The same physical box on both grids, and nothing else: sides matched to 1e-9, not to the cell count."""
    from hhscatter.reproduction.basin_summary import entropy_by_box_at

    recs = [
        {"E0": E, "gamma": 0.0, "map": m, "grid": n, "box_side": s, "box_cells": round(s * n / 2), "S_b": 0.1}
        for E in (0.30, 0.25)
        for m, n in (("map", 2000), ("scan", 400))
        for s in (0.01, 0.025, 0.05 + 1e-12, 0.1)
    ]
    got = entropy_by_box_at(recs)
    assert [(r["E0"], r["grid"], r["box_cells"]) for r in got[:4]] == [
        (0.25, 400, 5),
        (0.25, 2000, 25),
        (0.25, 400, 10),
        (0.25, 2000, 50),
    ]
    assert len(got) == 8 and entropy_by_box_at(recs, sides=(0.2,)) == []


def _stripes():
    """Four vertical stripes: exits 0, 1, 2 two cells wide each, settled one cell, and a forbidden column."""
    return np.repeat(np.array([[0, 0, 1, 1, 2, 2, bs.SETTLED_CODE, bs.OUTSIDE]]), 8, axis=0)


def _measures(img, g, times=None, **kw):
    eps = np.geomspace(1e-2, 1e-6, 6)
    args = {"wada_min_share": 0.1, "wada_r": 1, "symmetry_radius": 1.0, "fit_min_count": 10, **kw}
    return bs.map_measures(img, np.zeros(img.shape), _unc(eps), eps, times, 0.3, g, [2, 4], **args)


def test_map_measures_of_straight_stripes():
    ent, loc, m = _measures(_stripes(), 0.01)
    # 56 allowed cells: 16 per exit, 8 settled, no trapped cell
    np.testing.assert_allclose(m["fr"].frac, [16 / 56, 16 / 56, 16 / 56, 8 / 56, 0.0])
    assert m["present"] == [0, 1, 2, bs.SETTLED_CODE] and m["exits"] == [0, 1, 2]
    assert not m["wada"].wada and not m["wada_x"].wada  # straight boundaries: no point touches three basins
    np.testing.assert_allclose(m["chans"].frac, [1 / 3, 1 / 3, 1 / 3])
    assert m["fit"].alpha == pytest.approx(ALPHA, abs=5e-3) and m["rate"] is None  # λ at γ = 0 only
    assert list(ent["box"]) == [2, 4] and set(ent["energy"]) == {0.3} and set(ent["gamma"]) == {0.01}
    assert set(loc["gamma"]) == {0.01}


def test_map_measures_keep_the_exits_wada_test_for_three_exits_and_the_symmetry_disk():
    img = _stripes()
    img[:, 4:6] = bs.SETTLED_CODE  # exit 2 gone: two exits left
    _, _, m = _measures(img, 0.01)
    assert m["exits"] == [0, 1] and m["wada_x"] is None
    r = np.tile(
        np.arange(8.0), (8, 1)
    )  # the distance grows to the right: the disk r < 3 holds exit 0 and one exit-1 column
    _, _, m = bs.map_measures(
        _stripes(), r, _unc(np.geomspace(1e-2, 1e-6, 6)), np.geomspace(1e-2, 1e-6, 6), None, 0.3, 0.01, [2],
        wada_min_share=0.1, wada_r=1, symmetry_radius=3.0, fit_min_count=10,
    )  # fmt: skip
    assert list(m["chans"].counts) == [16, 8, 0]


def test_scan_row_reads_the_headline_box_and_the_trapped_share():
    img = _stripes()
    img[:, 6] = bs.TRAPPED_CODE
    eps = np.geomspace(1e-2, 1e-6, 6)
    kw = {"wada_min_share": 0.1, "wada_r": 1, "fit_min_count": 10}
    row = bs.scan_row(img, _unc(eps), eps, [np.array([1.0, 2.0])] * 6, 0.2, 0.19, [2, 4], 2, **kw)
    assert list(row) == bs.SCAN_COLUMNS
    assert row["above_E_b"] and row["trapped"] == pytest.approx(8 / 56) and not row["wada_exits"]
    assert row["alpha"] == pytest.approx(ALPHA, abs=5e-3)
    # 2 × 2 boxes on stripes two cells wide: one basin per box, no boundary box (S_bb undefined)
    assert row["S_b"] == 0.0 and math.isnan(row["S_bb"])
    # a headline box that is not on the list: the largest (4 × 4 boxes straddle two stripes: S_b > 0)
    wide = bs.scan_row(img, _unc(eps), eps, [np.array([1.0])] * 6, 0.2, 0.3, [2, 4], 3, **kw)
    assert not wide["above_E_b"] and wide["S_b"] > 0


def test_comparison_rows_alpha_and_s_bb_of_every_record_and_the_cut_off_only_with_drag():
    conservative = {
        "energy": 0.25, "gamma": 0.0, "alpha": {"value": 0.2, "err": 0.01}, "alpha_fit_range": [1e-7, 1e-4],
        "d": {"value": 1.8}, "S_bb": {"value": 0.8, "err": 0.02}, "log2_fractal": True,
        "cutoff": {"detected": True, "eps_c": 1e-5, "eps_c_lo": 5e-6, "eps_c_hi": 2e-5},
    }  # fmt: skip
    detected = {
        **conservative,
        "gamma": 0.02,
        "alpha": None,
        "S_bb": {"value": 0.6, "err": 0.03},
        "log2_fractal": False,
    }
    unseen = {**detected, "gamma": 0.05, "S_bb": None, "cutoff": {"detected": False, "eps_c_hi": 3e-6}}
    no_cutoff = {**unseen, "cutoff": None}
    rows = bs.comparison_rows([conservative, detected, unseen, no_cutoff], 16)
    assert [(r["quantity"], r["ours"], r["err"]) for r in rows] == [
        ("uncertainty exponent α (E0=0.25, γ=0)", 0.2, 0.01),
        ("boundary basin entropy S_bb (E0=0.25, γ=0, box 16)", 0.8, 0.02),  # γ = 0: no cut-off row
        ("boundary basin entropy S_bb (E0=0.25, γ=0.02, box 16)", 0.6, 0.03),
        ("cut-off ε_c of the power law f(ε) (E0=0.25, γ=0.02)", 1e-5, None),
        ("cut-off ε_c of the power law f(ε) (E0=0.25, γ=0.05)", None, None),
    ]
    notes = [r["note"] for r in rows]
    assert notes[0] == "f(ε) ∝ ε^α on ε ∈ [1e-07, 1e-04]; d = 2 − α = 1.800"
    assert notes[1].endswith(": yes") and notes[2].endswith(": not shown")
    assert notes[3] == "detected, 1σ [5e-06, 2e-05] (paper: expected for γ > 0)"
    assert notes[4] == "none seen: ε_c < 3e-06 (paper: expected for γ > 0)"


def test_saddle_cutoff_records_against_the_closed_form():
    """λ̄ = 0.5 at every energy: ln(1/ε_c) = λ̄ ln(E0/E_c)/(μγ); with the ensemble's μ = 1 and the deciding orbits'
    μ = 0.5 (slower decay: a longer stay on the saddle, a smaller ε_c)."""
    g, E0, ec = 0.05, 0.3, 0.15
    pred = math.exp(-0.5 * math.log(2) / g)
    pred_own = math.exp(-0.5 * math.log(2) / (0.5 * g))
    per = [
        {"energy": E0, "gamma": 0.0, "cutoff": None},
        {"energy": E0, "gamma": g, "mu_own": {"value": 0.5, "err": 0.0},
         "cutoff": {"detected": True, "eps_c": 1.2 * pred, "eps_c_lo": 1.1 * pred, "eps_c_hi": 1.3 * pred}},
        {"energy": E0, "gamma": 2 * g, "mu_own": None,
         "cutoff": {"detected": True, "eps_c": 1e-3, "eps_c_lo": 0.9e-3, "eps_c_hi": 1.1e-3}},
    ]  # fmt: skip
    tangent = pd.DataFrame({"energy": [0.2, 0.3], "lam": [0.5, 0.5], "lam_err": [0.0, 0.0]})
    recs = bs.saddle_cutoff_records(per, tangent, 1.0, 0.0, ec)
    assert [(r["E0"], r["gamma"]) for r in recs] == [(E0, g), (E0, 2 * g)]
    a, b = recs
    assert a["eps_c_tangent"] == pytest.approx(pred, rel=1e-6)
    assert a["eps_c_tangent_own"] == pytest.approx(pred_own, rel=1e-6)
    assert a["factor_tangent"] == pytest.approx(1.2, rel=1e-6) and a["within_1p5_tangent"]
    assert a["factor_tangent_own"] == pytest.approx(1.2 * pred / pred_own, rel=1e-6) and not a["within_1p5_tangent_own"]
    pred2 = math.exp(-0.5 * math.log(2) / (2 * g))  # 0.0313: measured 1e-3 is a factor 31 below
    assert b["eps_c_tangent"] == pytest.approx(pred2, rel=1e-6) and "eps_c_tangent_own" not in b
    assert not b["within_1p5_tangent"] and b["verdict_tangent"].startswith("differs")
    rates = [{"decision_over_tangent": 0.8}, {"decision_over_tangent": 0.9}]
    s = bs.saddle_cutoff_summary(recs, rates, 1.0)
    assert s["n_resolved"] == 2 and s["tangent"]["n_within"] == 1 and s["tangent"]["n_below"] == 1
    assert s["tangent_own"] == {"n": 1, "n_within": 0, "n_overlap": 0, "factor_min": pytest.approx(a["factor_tangent_own"]),
                                "factor_max": pytest.approx(a["factor_tangent_own"]), "n_below": 0}  # fmt: skip
    assert "within a factor 1.5 in 1 of 2" in s["statement"] and "0.8–0.9 times λ̄" in s["statement"]
    assert "μ = 0.5–0.5 against the ensemble's μ = 1" in s["statement"]


def test_rate_table_keeps_the_energies_both_have():
    scan = pd.DataFrame({"energy": [0.2, 0.25, 0.3], "lam": [0.3, 0.35, 0.4], "lam_err": [0.01] * 3,
                         "lam_kg": [0.5, 0.55, 0.6], "lam_kg_err": [0.05] * 3})  # fmt: skip
    tangent = pd.DataFrame({"energy": [0.25, 0.5], "lam": [0.35, 0.7], "lam_err": [0.02, 0.02]})
    rows = bs.rate_table(scan, tangent)
    assert [r["E0"] for r in rows] == [0.25]
    r = rows[0]
    assert r["decision_over_tangent"] == pytest.approx(1.0) and r["decision_vs_tangent"] == "agrees (z = +0.0)"
    z = (0.55 - 0.35) / math.hypot(0.05, 0.02)
    assert r["kappa_over_alpha_vs_tangent"] == f"differs (z = +{z:.1f})"
    assert r["decision_over_tangent_err"] == pytest.approx(math.hypot(0.01 / 0.35, 0.02 / 0.35), rel=1e-9)
