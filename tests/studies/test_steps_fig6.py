"""Steps of study fig6's comparison with the paper (τ1/τ2 observed vs predicted, the mixture against the homogeneous
model) on synthetic tables with a known answer."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pandas as pd

from hhscatter.studies import stage_module

mod = stage_module("fig6")


class _Recorder:
    """Stands in for a Study: records compare() calls."""

    def __init__(self):
        self.rows = []

    def compare(self, quantity, ours, err=None, paper=None, **kw):
        self.rows.append({"quantity": quantity, "ours": ours, "err": err, "paper": paper, **kw})


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
    st = _Recorder()
    mod._compare_taus(st, taus, ["paper", "integrated"])
    got = [(r["quantity"], r["ours"], r["verdict"]) for r in st.rows]
    assert got == [
        ("τ2(γ=0.01) observed vs Eq. (eq:tau2)", 110.0, "+10% from predicted 100.0"),
        ("τ1(γ=0.01) observed vs model (paper)", 50.0, "model 60.0 (+20%)"),
        # no τ1 of the integrated hazard at γ = 0.01, no τ2 observed at γ = 0.02
        ("τ1(γ=0.02) observed vs model (paper)", 40.0, "model 30.0 (-25%)"),
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
    s = SimpleNamespace(
        hazards=["paper", "integrated"],
        mixtures=[{"name": "mixture_tau0", "by": "energy", "t_ref": "tau0", "fne_mode": "shared"}],
    )
    st = _Recorder()
    mod._compare_mixtures(st, s, cmps)
    assert [(r["ours"], r["verdict"]) for r in st.rows] == [("1 (1) of 2", "differs"), ("2 (1) of 2", "agrees")]
    assert "A: 0.200 → 0.100, B: 0.100 → 0.300" in st.rows[0]["note"]
    assert "one trapped fraction" in st.rows[0]["note"]
