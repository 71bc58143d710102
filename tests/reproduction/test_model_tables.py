"""Tables of the survival model against simulations, against values worked out by hand."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hhscatter.reproduction.model_tables import (
    PAPER_CONSTANTS,
    ModelInputs,
    TauReference,
    constants_row,
    constants_taus,
    fit_row,
    kappa_from_constants,
    model_rows,
    pair_fits,
    survival_grid_curve,
    tau2_curve,
    tau2_reference,
    tau_predictions,
    tau_reference,
    tau_vs_gamma,
    value_and_err,
)

E_C = 1 / 6


def _fit(rms, t_fit=(1.0, 2.0), level=1.0, **values):
    vals = {"f_ne": 0.1, "f_e": 0.5, "L": 1.0, "b": 2.0, **values}
    return SimpleNamespace(
        t_fit=list(t_fit),
        rms_log_residual=rms,
        n_points=len(t_fit),
        free=["f_ne", "L", "b"],
        chi2=1.0,
        dof=len(t_fit) - 3,
        chi2_red=1.0,
        aic=7.0,
        success=True,
        values=vals,
        errors={"f_ne": 0.01, "L": 0.1},
        predict=lambda t: np.full_like(np.asarray(t, float), level),
    )


def test_kappa_from_constants_is_the_piecewise_law():
    k = kappa_from_constants({"a": 2.0, "b": 0.5, "c": 3.0, "E_b": 0.25}, E_C)
    x = np.array([0.2, 0.3]) - E_C
    np.testing.assert_allclose(k([0.1, 0.2, 0.3]), [0.0, 2 * x[0] ** 2 + 0.5 * x[0], 3 * x[1]], rtol=1e-14)


def test_survival_grid_curve_counts_the_survivors():
    lt = pd.DataFrame({"t_end": [0.5, 1.5, 1.5, 3.0], "outcome": ["escaped", "escaped", "settled", "censored"]})
    t, P, P_err = survival_grid_curve(lt, 1.0)
    assert t.tolist() == [0.0, 1.0, 2.0, 3.0]
    # one of four leaves by t = 1, two more by t = 2; the censored orbit is not an event
    np.testing.assert_allclose(P, [1.0, 0.75, 0.25, 0.25])
    assert P_err[0] == 0.0 and P_err[1] == pytest.approx(math.sqrt(0.75 * 0.25 / 4))  # Greenwood, one step


def test_fit_row_keeps_scalar_parameters_only():
    r = fit_row("p", "mixture", "paper", _fit(0.1, f_ne=np.array([0.1, 0.2])), {"E0": 0.3})
    assert (r["pair"], r["model"], r["hazard"], r["E0"], r["n_free"]) == ("p", "mixture", "paper", 0.3, 3)
    assert "f_ne" not in r and r["L_err"] == 0.1 and math.isnan(r["b_err"])


def test_constants_row_names_the_better_fit_and_refuses_other_points():
    row = constants_row(_fit(0.2), _fit(0.1), pair="p", E0=0.3, gamma=0.01, hazard="paper", tau2_ours=1, tau2_pc=2)
    assert row["better"] == PAPER_CONSTANTS and row["rms_log_residual_ours"] == 0.2 and row["L"] == 1.0
    assert constants_row(_fit(0.2), _fit(0.2), pair="p", E0=0, gamma=0, hazard="h", tau2_ours=1, tau2_pc=1)[
        "better"
    ] == ("tie")
    with pytest.raises(ValueError, match="other points"):
        constants_row(
            _fit(0.2), _fit(0.1, t_fit=(1.0, 3.0)), pair="p", E0=0, gamma=0, hazard="h", tau2_ours=1, tau2_pc=1
        )


def test_model_rows_add_every_model_curve_and_one_constants_row_per_hazard():
    t = np.array([0.0, 1.0, 2.0])
    cur = pd.DataFrame({"t": t})
    homog = {"paper": _fit(0.2, level=0.5), "integrated": _fit(0.3, level=0.6)}
    homog_pc = {"paper": _fit(0.1, level=0.7), "integrated": _fit(0.4, level=0.8)}
    mixes = {"mixture_a": {"paper": _fit(0.15, level=0.9), "integrated": _fit(0.35, level=1.0)}}
    fits, cmps, pcs = model_rows(
        t, cur, "p", homog, homog_pc, mixes, {"E0": 0.3, "gamma": 0.01}, E_c=E_C, mu=0.9, mu_pc=0.91
    )
    assert [(f["model"], f["hazard"]) for f in fits] == [
        ("homogeneous", "paper"),
        ("mixture_a", "paper"),
        ("homogeneous", "integrated"),
        ("mixture_a", "integrated"),
    ]
    assert cur["mixture_a_integrated"].tolist() == [1.0] * 3 and cur["paper_constants_paper"].tolist() == [0.7] * 3
    assert [c["model"].tolist() for c in cmps] == [["homogeneous", "mixture_a"]] * 2
    assert [p["better"] for p in pcs] == [PAPER_CONSTANTS, "ours"]
    assert pcs[0]["tau2_predicted"] == pytest.approx(math.log(0.3 / E_C) / (0.91 * 0.01), rel=1e-12)
    assert pcs[0]["tau2_predicted_ours"] == pytest.approx(math.log(0.3 / E_C) / (0.9 * 0.01), rel=1e-12)


def test_value_and_err_reads_both_forms():
    assert value_and_err({"value": "1.5", "err": None}) == (1.5, None)
    assert value_and_err(float("inf")) == (None, None)


def test_tau_vs_gamma_without_lifetimes_predicts_tau2_only():
    obs = pd.DataFrame(
        {
            "gamma": [0.02, 0.0, 0.01],
            "tau1_observed": [30.0, None, 50.0],
            "tau1_err": [1.0, None, {}],
            "tau2_observed": [40.0, None, float("nan")],
            "tau2_err": [None] * 3,
        }
    )
    tab, fits = tau_vs_gamma(
        TauReference(obs, {}, None, 0.3),
        kappa=None,
        mu=0.9,
        mu_err=float("nan"),
        tau0=5.0,
        E_c=E_C,
        hazards=["paper", "integrated"],
        dt=0.5,
        fit_dt=2.0,
        min_count=20,
        alpha=2.0,
    )
    assert fits == {} and tab["gamma"].tolist() == [0.01, 0.02]  # γ > 0, sorted
    np.testing.assert_allclose(tab["tau2_predicted"], [math.log(0.3 / E_C) / (0.9 * g) for g in (0.01, 0.02)])
    assert tab["tau2_predicted_err"].isna().all()
    # no finite number: missing (a {} error, a NaN τ2)
    assert np.isnan(tab["tau2_observed"].iloc[0]) and np.isnan(tab["tau1_observed_err"].iloc[0])
    assert tab["tau1_observed_err"].iloc[1] == 1.0
    assert tab["tau1_pred_paper"].isna().all() and tab["f_ne_integrated"].isna().all()


def test_constants_taus_need_the_same_gammas():
    t = pd.DataFrame({"gamma": [0.01], "tau1_observed": [1.0], "tau2_observed": [2.0], "tau2_predicted": [3.0]})
    with pytest.raises(RuntimeError, match="different γ"):
        constants_taus(t, t.assign(gamma=0.02), {}, {}, [])
    fits = {0.01: {"paper": _fit(0.1)}}
    row = constants_taus(t.assign(tau1_pred_paper=4.0), t.assign(tau1_pred_paper=5.0), fits, fits, ["paper"]).iloc[0]
    assert (row["tau1_pred_paper"], row["tau1_pred_paper_ours"], row["better_paper"]) == (5.0, 4.0, "tie")


def test_tau2_curve_band_and_range():
    c = tau2_curve(pd.DataFrame({"gamma": [0.005, 0.05]}), 0.3, E_C, 0.9, 0.09, 0.91)
    assert c["gamma"].iloc[0] == pytest.approx(0.8e-3) and c["gamma"].iloc[-1] == pytest.approx(0.0625)
    t2 = math.log(0.3 / E_C) / (0.9 * c["gamma"].iloc[0])
    assert c["tau2_predicted"].iloc[0] == pytest.approx(t2, rel=1e-12)
    assert (c["tau2_lo"].iloc[0], c["tau2_hi"].iloc[0]) == pytest.approx((t2 / 1.1, t2 / 0.9), rel=1e-12)
    assert c["tau2_predicted_paper_constants"].iloc[0] == pytest.approx(t2 * 0.9 / 0.91, rel=1e-12)


PAPER = {"a": 13.63, "b": 0.03, "c": 1.41, "E_b": 0.27, "mu": 0.91}


def _inputs(mixtures=(), mu=0.9, mu_err=0.05):
    k = kappa_from_constants(PAPER, E_C)
    return ModelInputs({}, k, mu, mu_err, 5.0, E_C, PAPER, k, ["paper", "integrated"], list(mixtures))


def test_pair_fits_read_the_snapshots_once_and_split_them_into_sub_ensembles():
    """Every orbit's energy decays as E_i(0) e^(−μγt) with μ = 0.9: each sub-ensemble's μ_k is 0.9."""
    rng = np.random.default_rng(3)
    n, E0, g = 600, 0.3, 0.01
    t_end = 5.0 + np.concatenate([rng.exponential(8.0, n // 2), rng.uniform(20.0, 120.0, n - n // 2)])
    lt = pd.DataFrame({"t_end": t_end, "outcome": ["escaped"] * (n // 2) + ["settled"] * (n - n // 2)})
    ts = np.arange(5.0, 60.0, 5.0)
    E_i = rng.uniform(0.25, 0.35, n)
    snaps = pd.DataFrame(
        {
            "traj_id": np.repeat(np.arange(n), ts.size),
            "t": np.tile(ts, n),
            "energy": (E_i[:, None] * np.exp(-0.9 * g * ts[None, :])).ravel(),
        }
    )
    calls = []

    def read():
        calls.append(1)
        return snaps

    mix = {"name": "mixture_e", "by": "energy", "t_ref": "tau0", "fne_mode": "shared"}
    cur, (fits, comps, cmps, pcs) = pair_fits(
        lt, read, _inputs([mix]), label="p", E0=E0, gamma=g, dt=1.0, fit_dt=2.0, min_count=5, fit_tau2=False,
        n_components=3, fit_end=60.0,
    )  # fmt: skip
    assert calls == [1]
    assert cur["P"].iloc[0] == 1.0 and (cur["N"] == n).all() and set(cur["pair"]) == {"p"}
    assert [(f["model"], f["hazard"]) for f in fits] == [
        ("homogeneous", "paper"),
        ("mixture_e", "paper"),
        ("homogeneous", "integrated"),
        ("mixture_e", "integrated"),
    ]
    assert fits[0]["tau2_eq"] == pytest.approx(math.log(E0 / E_C) / (0.9 * g), rel=1e-12)
    assert fits[0]["tau2_observed"] is None or math.isfinite(fits[0]["tau2_observed"])
    (c,) = comps
    assert len(c) == 3 and c["weight"].sum() == pytest.approx(1.0) and (c["model"] == "mixture_e").all()
    np.testing.assert_allclose(c["mu"], 0.9, rtol=1e-9)
    assert len(cmps) == 2 and [p["hazard"] for p in pcs] == ["paper", "integrated"]


def test_tau_predictions_give_tau2_with_both_exponents():
    obs = pd.DataFrame(
        {"gamma": [0.01, 0.02], "tau1_observed": [None] * 2, "tau1_err": [None] * 2, "tau2_observed": [80.0, 40.0]}
    ).assign(tau2_err=None)
    taus, curve, pct = tau_predictions(
        TauReference(obs, {}, None, 0.3), _inputs(), dt=0.5, fit_dt=2.0, min_count=20, alpha=2.0
    )
    gs = np.array([0.01, 0.02])
    np.testing.assert_allclose(taus["tau2_predicted"], np.log(0.3 / E_C) / (0.9 * gs))
    np.testing.assert_allclose(taus["tau2_predicted_err"], np.log(0.3 / E_C) / (0.9 * gs) * 0.05 / 0.9)
    np.testing.assert_allclose(pct["tau2_predicted"], np.log(0.3 / E_C) / (0.91 * gs))
    assert len(curve) > 0


def test_tau_reference_reads_the_tau_table_and_keeps_the_runs_of_its_gammas():
    rows = pd.DataFrame(
        {
            "g": [0.005, 0.01],
            "t1": [{"value": 80.0, "err": 2.0}, None],  # τ1 not resolved at γ = 0.01
            "t2": [{"value": 400.0, "err": 10.0}, 200.0],  # a plain number: no error
        }
    )
    conservative = pd.DataFrame({"t_end": [1.0, 2.0, 3.0, 4.0], "outcome": ["escaped"] * 3 + ["censored"]})
    dissipative = pd.DataFrame({"t_end": [1.0], "outcome": ["settled"]})
    runs = {0.0: conservative, 0.005: dissipative, 0.02: dissipative}  # γ = 0.02 is not in the table
    ref = tau_reference(rows, runs, E0=0.3, dt=1.0, fields=("g", "t1", "t2"))
    assert ref.E0 == 0.3 and list(ref.lifetimes) == [0.005] and ref.lifetimes[0.005] is dissipative
    obs = ref.obs.to_dict(orient="list")  # a missing time or error is NaN in its float column
    assert list(obs) == ["gamma", "tau1_observed", "tau1_err", "tau2_observed", "tau2_err"]
    assert obs["gamma"] == [0.005, 0.01] and obs["tau2_observed"] == [400.0, 200.0]
    assert obs["tau1_observed"][0] == 80.0 and obs["tau1_err"][0] == 2.0 and obs["tau2_err"][0] == 10.0
    assert all(math.isnan(obs[k][1]) for k in ("tau1_observed", "tau1_err", "tau2_err"))
    t, P = ref.P_0
    # Kaplan–Meier of three escapes at 1, 2, 3 among four orbits, the fourth censored at 4
    assert t.tolist() == [0.0, 1.0, 2.0, 3.0, 4.0] and P.tolist() == pytest.approx([1.0, 0.75, 0.5, 0.25, 0.25])
    with pytest.raises(KeyError):
        tau_reference(rows, {0.005: dissipative}, E0=0.3, dt=1.0, fields=("g", "t1", "t2"))


def test_tau2_reference_has_the_first_settling_time_and_no_tau1():
    lt = {
        0.02: pd.DataFrame({"t_end": [7.0, 2.0, 5.0], "outcome": ["settled", "escaped", "settled"]}),
        0.01: pd.DataFrame({"t_end": [9.0, 4.0], "outcome": ["censored", "settled"]}),
    }
    ref = tau2_reference(lt, 0.3)
    assert ref.P_0 is None and ref.lifetimes is lt and ref.E0 == 0.3
    assert ref.obs["gamma"].tolist() == [0.01, 0.02] and ref.obs["tau2_observed"].tolist() == [4.0, 5.0]
    assert ref.obs[["tau1_observed", "tau1_err", "tau2_err"]].isna().all().all()
