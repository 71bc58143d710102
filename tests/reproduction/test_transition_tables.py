"""Tables of the transition times of paired ensembles against values worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hhscatter.reproduction.transition_tables import (
    log_time_grid,
    survival_ratio_tables,
    transition_comparisons,
    transition_table,
)

E_C = 1 / 6
KEY = "g{:g}".format


def _ensembles():
    """Four orbits per γ: γ = 0 all escape at 1, 2, 3, 4; γ = 0.1 one settles at 3.5 and one at 6."""
    return {
        0.0: pd.DataFrame({"t_end": [1.0, 2.0, 3.0, 4.0], "outcome": ["escaped"] * 4}),
        0.1: pd.DataFrame({"t_end": [1.0, 3.5, 5.0, 6.0], "outcome": ["escaped", "settled", "escaped", "settled"]}),
    }


def _grid_P():
    grid = np.arange(0.0, 6.5, 0.5)
    # survival counted by hand on the grid (right-continuous: an orbit leaving at t is gone at t)
    P0 = np.array([4, 4, 3, 3, 2, 2, 1, 1, 0, 0, 0, 0, 0]) / 4
    P1 = np.array([4, 4, 3, 3, 3, 3, 3, 2, 2, 2, 1, 1, 0]) / 4
    return grid, {0.0: P0, 0.1: P1}


def _boot():
    return pd.DataFrame(
        {
            "label": [0.1, 0.1, 0.1],
            "tau0": [0.0, 1.0, 2.0],
            "tau1": [2.0, 3.0, np.nan],
            "t_settle_q0.01": [3.0, 4.0, 5.0],
            "t_settle_q0.5": [6.0, 6.0, 6.0],
        }
    )


def test_transition_table_against_hand_values():
    grid, P = _grid_P()
    tab = transition_table(
        _ensembles(),
        grid,
        P,
        0.0,
        _boot(),
        0.5,
        E0=0.3,
        E_c=E_C,
        mu=0.9,
        mu_err=0.09,
        paper_mu=0.91,
        alpha=2.0,
        min_ref_orbits=2,
        key=KEY,
    ).set_index("gamma")
    r = tab.loc[0.1]
    assert r["key"] == "g0.1" and r["n"] == 4
    assert (r["f_escaped"], r["f_settled"], r["f_censored"]) == (0.5, 0.5, 0.0)
    # P_γ/P_0 first reaches 2 at t = 3 (3/4 over 1/4 = 3 ≥ 2; at 2.5: (3/4)/(2/4) = 1.5), interpolated in log ratio
    lr = lambda i: math.log(P[0.1][i] / P[0.0][i])  # noqa: E731
    t1 = 2.5 + 0.5 * (math.log(2) - lr(5)) / (lr(6) - lr(5))
    assert r["tau1"] == pytest.approx(t1, rel=1e-12)
    assert r["n0_at_tau1"] == pytest.approx(4 * np.interp(t1, grid, P[0.0]), rel=1e-12)
    assert 1 < r["n0_at_tau1"] < 2 and not r["tau1_resolved"]  # fewer than min_ref_orbits = 2 reference orbits
    assert r["tau2_obs"] == 3.5  # the first settling time
    assert r["tau2_pred"] == pytest.approx(math.log(0.3 / E_C) / (0.9 * 0.1), rel=1e-12)
    assert r["tau2_pred_err"] == pytest.approx(r["tau2_pred"] * 0.1, rel=1e-12)
    assert r["tau2_pred_paper_mu"] == pytest.approx(math.log(0.3 / E_C) / (0.91 * 0.1), rel=1e-12)
    # bootstrap σ of the finite replicates times the scale; the share of replicates with a τ1
    assert r["tau1_err"] == pytest.approx(0.5 * np.std([2.0, 3.0], ddof=1), rel=1e-12)
    assert r["tau0_err"] == pytest.approx(0.5 * 1.0, rel=1e-12)
    assert r["tau1_boot_defined"] == pytest.approx(2 / 3)
    assert r["t_settle_q50_err"] == 0.0
    ref = tab.loc[0.0]
    assert math.isnan(ref["tau1"]) and math.isinf(ref["tau2_pred"]) and math.isnan(ref["tau2_obs"])
    assert ref["tau0_err"] == pytest.approx(0.5 * 1.0)  # the σ of every replicate's τ0


def test_survival_ratio_tables_stop_where_the_reference_is_empty():
    grid, P = _grid_P()
    surv, ratio = survival_ratio_tables(_ensembles(), grid, P, 0.5, 6.0, key=KEY)
    np.testing.assert_array_equal(surv[surv["gamma"] == 0.0]["t"], log_time_grid(6.0))
    at = surv[(surv["gamma"] == 0.1)].set_index("t")["P"]
    # two of the four orbits left after 3.5: the Kaplan–Meier product (3/4)(2/3), exact to rounding
    assert at.iloc[np.searchsorted(at.index, 4.0)] == pytest.approx(0.5, rel=1e-15)
    # the reference is empty from t = 4 on: the ratio stops there
    assert ratio["t"].max() == 3.5
    row = ratio.set_index("t").loc[3.0]
    assert (row["ratio"], row["n0"]) == (3.0, 1.0)


def _taus(gammas, tau1, tau2):
    n = len(gammas)
    return pd.DataFrame(
        {
            "gamma": gammas,
            "tau1": tau1,
            "tau1_err": np.full(n, 1.0),
            "tau1_resolved": np.isfinite(tau1),
            "tau2_obs": tau2,
            "tau2_obs_err": np.full(n, 1.0),
            "tau2_obs_lo": tau2,
            "tau2_obs_hi": tau2,
            "f_settled": np.full(n, 0.1),
            "tau2_pred": np.full(n, 50.0),
            "tau2_pred_err": np.full(n, 1.0),
            "t_settle_q50": 2 * np.asarray(tau2),
            "t_settle_q50_err": np.full(n, 1.0),
        }
    )


def _comparisons(taus, mu_other=None):
    return transition_comparisons(
        taus,
        N=1000,
        E0=0.3,
        E_c=E_C,
        mu_gamma=0.01,
        mu_window=(0.0, 200.0),
        mu=0.9,
        mu_err=0.01,
        mu_other=mu_other,
        tau0=5.0,
        tau0_err=0.5,
        paper_mu=0.91,
    )


def test_transition_comparisons_exponents_and_statements():
    g = np.array([0.0, 0.005, 0.01, 0.02])
    rows, p = _comparisons(_taus(g, [np.nan, 80.0, 40.0, 20.0], 3.0 / np.maximum(g, 1e-9) ** 0.5))
    assert p["tau2"][0] == pytest.approx(0.5, rel=1e-9) and p["settle_median"][0] == pytest.approx(0.5, rel=1e-9)
    assert p["tau1"][0] == pytest.approx(1.0, rel=1e-9)
    q = {r["quantity"]: r for r in rows}
    assert q["τ1 increases as γ decreases"]["verdict"] == "agrees"
    # the paper's τ2 at γ = 0.01 from its μ, Eq. (eq:tau2)
    assert q["τ2 predicted at γ = 0.01"]["paper"] == pytest.approx(math.log(0.3 / E_C) / (0.91 * 0.01), rel=1e-12)
    assert "μ: fig4's own vs fig3" not in q
    rows, _ = _comparisons(_taus(g, [np.nan, 30.0, 40.0, 20.0], [np.nan, 3.0, 2.0, 1.0]), {"value": 0.88})
    q = {r["quantity"]: r for r in rows}
    assert q["τ1 increases as γ decreases"]["verdict"] == "differs"
    assert q["μ: fig4's own vs fig3"]["paper"] == 0.88
    assert [r["quantity"] for r in rows][0].startswith("μ used for τ2 (own γ=0.01 run, [0, 200])")


def test_transition_comparisons_without_enough_gammas_give_no_exponent():
    rows, p = _comparisons(_taus(np.array([0.0, 0.02]), [np.nan, np.nan], [np.nan, 5.0]))
    assert p == {"tau2": (None, None), "settle_median": (None, None), "tau1": (None, None)}
    assert not any(r["quantity"].startswith("p") for r in rows)
    assert next(r for r in rows if r["quantity"].startswith("τ1 increases"))["verdict"] is None
