"""Escape-rate results as numbers and plot tables (hhscatter.reproduction.escape_summaries) on synthetic input with a
known answer."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hhscatter.reproduction.escape_summaries import (
    cmeasure_windows,
    kappa_cmeasure_z,
    kappa_law_curves,
    recording_time,
    survival_tables,
    tau_star_estimate,
)


def _at(curve, t, col):
    """The step value of ``col`` at the last tabulated time ≤ t (no event lies between it and t below)."""
    return float(curve.loc[curve["t"] <= t, col].iloc[-1])


def test_survival_tables_kaplan_meier_of_all_orbits_and_of_the_escaping_ones():
    t_end = np.array([1.5, 2.5, 3.5, 4.5])
    obs = np.array([True, True, False, True])  # the orbit at 3.5 is censored (still inside at t_max)
    fit = SimpleNamespace(predict=lambda t: 0.8 * np.exp(-0.5 * t))
    r = SimpleNamespace(fits=[fit], t_stop=4.0)
    curve, line = survival_tables(0.3, t_end, obs, r)
    assert (curve["energy"] == 0.3).all() and curve["t"].iloc[0] == 0.0 and curve["t"].iloc[-1] == 4.5
    # all orbits: 3/4 after the first escape, 2/4 after the second, the censored orbit changes nothing, 0 at the end
    for t, P in ((1.0, 1.0), (2.0, 0.75), (3.0, 0.5), (4.0, 0.5), (4.5, 0.0)):
        assert _at(curve, t, "P") == pytest.approx(P), t
    # the escaping orbits only (1.5, 2.5, 4.5): 2/3, 1/3, 1/3, 0
    for t, P in ((1.0, 1.0), (2.0, 2 / 3), (3.0, 1 / 3), (4.0, 1 / 3), (4.5, 0.0)):
        assert _at(curve, t, "P_esc") == pytest.approx(P), t
    assert _at(curve, 2.0, "P_err") == pytest.approx(np.sqrt(0.75 * 0.25 / 4))  # binomial before any censoring
    # the fitted exponential, drawn on [0, 1.25 t_stop]
    assert list(line["kind"].unique()) == ["exponential"] and len(line) == 300
    assert line["t"].iloc[-1] == pytest.approx(5.0)
    np.testing.assert_allclose(line["P"], 0.8 * np.exp(-0.5 * line["t"]))


def test_kappa_cmeasure_z_scores_against_both_kappas_from_pt():
    rows = [
        {
            "kappa_cm": 1.0,
            "kappa_cm_err": 0.3,
            "kappa_pt_grid": 1.5,
            "kappa_pt_grid_err": 0.4,
            "kappa_pt_same_run": 0.0,
            "kappa_pt_same_run_err": 0.4,
        },
        {
            "kappa_cm": 2.0,
            "kappa_cm_err": 0.05,
            "kappa_pt_grid": 2.0,
            "kappa_pt_grid_err": 0.12,
            "kappa_pt_same_run": 2.13,
            "kappa_pt_same_run_err": 0.12,
        },
    ]
    df = kappa_cmeasure_z(pd.DataFrame(rows))
    np.testing.assert_allclose(df["z_vs_grid"], [-1.0, 0.0])  # (1 − 1.5)/hypot(0.3, 0.4) = −0.5/0.5
    np.testing.assert_allclose(df["z_vs_same_run"], [2.0, -1.0])  # 1/0.5; −0.13/0.13
    assert len(df) == 2 and isinstance(df, pd.DataFrame)


def test_tau_star_is_the_crossing_with_its_distance_to_the_change_point_else_the_change_point():
    tl = SimpleNamespace(window=(80.0, 500.0))
    assert tau_star_estimate(SimpleNamespace(tail=tl, tau_star=95.0))[:2] == (95.0, 15.0)
    assert tau_star_estimate(SimpleNamespace(tail=tl, tau_star=float("inf")))[:2] == (80.0, None)


def test_cmeasure_windows_by_hand():
    # t_rec = ceil(3.2 + 2/0.25) = 12, sample 4/0.25 = 16 → 28, recording + 1/0.25 + 40 → 72
    assert cmeasure_windows(0.25, 3.2, 2.0, 4.0, 40.0, 1.0) == (12.0, 28.0, 72.0)
    with pytest.raises(ValueError, match="kappa must be finite"):
        cmeasure_windows(0.0, 3.2, 2.0, 4.0, 40.0)


def test_recording_time_is_the_ceiling_of_tau0_plus_n_efolds():
    assert recording_time(0.2, 3.4, 4.0) == 24.0  # ceil(3.4 + 20)
    assert recording_time(0.25, 3.0, 2.0) == 11.0  # ceil(11.0): an integer stays
    assert cmeasure_windows(0.2, 3.4, 4.0, 1.0, 0.0)[0] == recording_time(0.2, 3.4, 4.0)  # one rule for both
    for bad in (0.0, -0.1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="kappa must be finite"):
            recording_time(bad, 1.0, 4.0)


def test_kappa_law_curves_follow_each_law_on_its_side_of_the_break():
    law = SimpleNamespace(a=10.0, b=0.1, c=1.5, E_b=0.3)
    t = kappa_law_curves({"L": law}, x_max=0.4, E_c=0.1)
    nl, li = t[t.regime == "nonlinear"], t[t.regime == "linear"]
    assert nl.x.max() <= 0.2 * 1.15 and li.x.min() >= 0.2 * 0.85
    np.testing.assert_allclose(nl.kappa, 10.0 * nl.x**2 + 0.1 * nl.x)
    np.testing.assert_allclose(li.kappa, 1.5 * li.x)
