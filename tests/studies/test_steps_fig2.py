"""Steps of study fig2's analysis (the Fig. 2a curves, the c-measure z-scores, the comparison of κ with the paper's
law) on synthetic input with a known answer."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hhscatter.studies import stage_module

mod = stage_module("fig2")


class _Recorder:
    """Stands in for a Study: records compare() calls."""

    def __init__(self):
        self.rows = []

    def compare(self, quantity, ours, err=None, paper=None, **kw):
        self.rows.append({"quantity": quantity, "ours": ours, "err": err, "paper": paper, **kw})


def _at(curve, t, col):
    """The step value of ``col`` at the last tabulated time ≤ t (no event lies between it and t below)."""
    return float(curve.loc[curve["t"] <= t, col].iloc[-1])


def test_pt_curves_kaplan_meier_of_all_orbits_and_of_the_escaping_ones():
    t_end = np.array([1.5, 2.5, 3.5, 4.5])
    obs = np.array([True, True, False, True])  # the orbit at 3.5 is censored (still inside at t_max)
    fit = SimpleNamespace(predict=lambda t: 0.8 * np.exp(-0.5 * t))
    r = SimpleNamespace(fits=[fit], t_stop=4.0)
    curve, line = mod._pt_curves(0.3, t_end, obs, r)
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


def test_cmeasure_table_z_scores_against_both_kappas_from_pt():
    rows = [{"kappa_cm": 1.0, "kappa_cm_err": 0.3, "kappa_pt_grid": 1.5, "kappa_pt_grid_err": 0.4,
             "kappa_pt_same_run": 0.0, "kappa_pt_same_run_err": 0.4},
            {"kappa_cm": 2.0, "kappa_cm_err": 0.05, "kappa_pt_grid": 2.0, "kappa_pt_grid_err": 0.12,
             "kappa_pt_same_run": 2.13, "kappa_pt_same_run_err": 0.12}]
    df = mod._cmeasure_table(rows)
    np.testing.assert_allclose(df["z_vs_grid"], [-1.0, 0.0])         # (1 − 1.5)/hypot(0.3, 0.4) = −0.5/0.5
    np.testing.assert_allclose(df["z_vs_same_run"], [2.0, -1.0])     # 1/0.5; −0.13/0.13
    assert len(df) == 2 and isinstance(df, pd.DataFrame)


def _fit_result(kappa=0.2, kappa_err=0.01):
    return SimpleNamespace(kappa=kappa, kappa_err=kappa_err)


def test_compare_pt_uses_the_paper_law_of_each_regime_and_no_tail_rows_without_a_tail():
    st = _Recorder()
    E_C = 1.0 / 6.0
    no_tail = SimpleNamespace(tail=None)
    mod._compare_pt(st, 0.25, _fit_result(), no_tail, E_C)   # below E_b = 0.27: a x² + b x
    mod._compare_pt(st, 0.30, _fit_result(), no_tail, E_C)   # above: c x
    x1, x2 = 0.25 - E_C, 0.30 - E_C
    assert [r["paper"] for r in st.rows] == pytest.approx([13.63 * x1 ** 2 + 0.03 * x1, 1.41 * x2])
    assert [r["quantity"] for r in st.rows] == ["kappa(E0=0.25) [Fig. 2a]", "kappa(E0=0.30) [Fig. 2a]"]


def test_compare_pt_tau_star_error_is_the_distance_of_its_two_definitions():
    st = _Recorder()
    tl = SimpleNamespace(window=(80.0, 500.0), z=2.1, z_err=0.1)
    mod._compare_pt(st, 0.25, _fit_result(), SimpleNamespace(tail=tl, tau_star=95.0), 1.0 / 6.0)
    mod._compare_pt(st, 0.25, _fit_result(), SimpleNamespace(tail=tl, tau_star=float("inf")), 1.0 / 6.0)
    tau = [r for r in st.rows if r["quantity"].startswith("tau*")]
    assert (tau[0]["ours"], tau[0]["err"], tau[0]["verdict"]) == (95.0, 15.0, None)
    # no crossing: τ* = τ_c = 80, within 20 % of the paper's 100
    assert (tau[1]["ours"], tau[1]["err"], tau[1]["verdict"]) == (80.0, None, "agrees within 20 %")
    assert [r["ours"] for r in st.rows if r["quantity"].startswith("z ")] == [2.1, 2.1]
