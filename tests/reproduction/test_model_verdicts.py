"""The survival model's paper-comparison rows (τ1/τ2 observed vs predicted, the mixture against the homogeneous
model, the paper's constants beside ours) on synthetic tables with a known answer."""

from __future__ import annotations

import math

import pandas as pd

from hhscatter.reproduction.model_verdicts import (
    constants_comparisons,
    mixture_comparisons,
    tau_comparisons,
)


def test_compare_taus_relative_differences_and_skips_what_was_not_observed():
    taus = pd.DataFrame(
        {
            "gamma": [0.01, 0.02],
            "tau2_observed": [110.0, math.nan],
            "tau2_predicted": [100.0, 50.0],
            "tau1_observed": [50.0, 40.0],
            "tau1_pred_paper": [60.0, 30.0],
            "tau1_pred_integrated": [math.nan, 42.0],
        }
    )
    got = [(r["quantity"], r["ours"], r["verdict"]) for r in tau_comparisons(taus, ["paper", "integrated"])]
    assert got == [
        ("τ2(γ=0.01) observed vs Eq. (eq:tau2)", 110.0, "+10% from predicted 100.0"),
        ("τ1(γ=0.01) observed vs model (paper)", 50.0, "model 60.0 (+20%)"),
        # no τ1 of the integrated hazard at γ = 0.01, no τ2 observed at γ = 0.02
        ("τ1(γ=0.02) observed vs model (paper)", 40.0, "model 30.0 (−25%)"),
        ("τ1(γ=0.02) observed vs model (integrated)", 40.0, "model 42.0 (+5%)"),
    ]


def _cmps(rms, aic, hazard):
    """compare_fits rows: {pair: (homogeneous, mixture)} of rms log residuals and AICs."""
    rows = []
    for pair in rms:
        for k, model in enumerate(("homogeneous", "mixture_tau0")):
            rows.append(
                {"pair": pair, "model": model, "hazard": hazard, "rms_log_residual": rms[pair][k], "aic": aic[pair][k]}
            )
    return rows


def test_compare_mixtures_counts_pairs_where_the_mixture_fits_better():
    cmps = pd.DataFrame(
        _cmps({"A": (0.2, 0.1), "B": (0.1, 0.3)}, {"A": (5.0, 7.0), "B": (5.0, 4.0)}, "paper")
        + _cmps({"A": (0.2, 0.1), "B": (0.3, 0.25)}, {"A": (5.0, 4.0), "B": (5.0, 6.0)}, "integrated")
    )
    mixtures = [{"name": "mixture_tau0", "by": "energy", "t_ref": "tau0", "fne_mode": "shared"}]
    rows = mixture_comparisons(cmps, ["paper", "integrated"], mixtures)
    assert [(r["ours"], r["verdict"]) for r in rows] == [("1 (1) of 2", "differs"), ("2 (1) of 2", "agrees")]
    assert "A: 0.200 → 0.100, B: 0.100 → 0.300" in rows[0]["note"]
    assert "one never-escaping share φ" in rows[0]["note"]
    free = mixture_comparisons(cmps, ["paper"], [{**mixtures[0], "fne_mode": "free"}])
    assert "K − 1 more parameters" in free[0]["note"]


PC = {"a": 13.63, "b": 0.03, "c": 1.41, "E_b": 0.27, "mu": 0.91}


def test_constants_comparisons_count_the_pairs_and_say_which_constants_predict_closer():
    pcf = pd.DataFrame(
        [
            {"pair": p, "hazard": "paper", "rms_log_residual": rp, "rms_log_residual_ours": ro, "better": b}
            | {"n_points": 30, "chi2_red": 1.0, "chi2_red_ours": 1.0}
            for p, rp, ro, b in (("A", 0.1, 0.2, "paper_constants"), ("B", 0.3, 0.2, "ours"), ("C", 0.2, 0.2, "tie"))
        ]
    )
    pct = pd.DataFrame(
        {
            "gamma": [0.01],
            "tau1_observed": [50.0],
            "tau2_observed": [100.0],
            "tau2_predicted": [90.0],
            "tau2_predicted_ours": [120.0],
            "tau1_pred_paper": [40.0],
            "tau1_pred_paper_ours": [55.0],
            "rms_paper": [0.1],
            "rms_paper_ours": [0.2],
        }
    )
    rows = constants_comparisons(PC, 5.0, pcf, pct, ["paper"], "paper setup: disk r < 0.5")
    assert all(r["authors"] for r in rows)
    verdicts = [r["verdict"] for r in rows]
    assert verdicts[:3] == [
        "paper's constants fit better: rms 0.100 vs 0.200 with ours",
        "our constants fit better: rms 0.200 vs 0.300 with the paper's",
        "equal fit: rms 0.200 with both",
    ]
    # one pair each: neither set of constants fits better on more pairs
    assert verdicts[3] == "neither: the paper's constants fit better on 1, ours on 1 of 3 pairs"
    # τ2: |100 − 90| < |100 − 120| (the paper's μ closer); τ1: |40 − 50| = 10 > |55 − 50| = 5 (ours closer)
    assert verdicts[4] == "observed 100.0 is +11% from it (−17% from 120.0 with our μ): paper's μ closer"
    assert verdicts[5] == "−20% from observed 50.0; our constants 55.0 (+10%): our constants closer"
    assert rows[4]["convention"] == "paper's μ = 0.91; paper setup: disk r < 0.5"
