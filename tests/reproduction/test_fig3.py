"""Fig. 3's tables (hhscatter.reproduction.fig3: the window chooser, the paper's fit, the bootstrap
errors, the histogram rows, the ribbons, μ in the authors' conventions) on synthetic input with a known answer."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hhscatter.reproduction import fig3 as mod


def test_fit_windows_paper_later_sliding_alt_in_order():
    windows, kinds = mod.fit_windows((0.0, 200.0), [(200.0, 400.0), (400.0, 600.0)], [100.0, 50.0], (0.0, 100.0), 260.0)
    # sliding windows start at 0, 50, 100, 150 (the last one, [150, 250], still ends by t_last = 260)
    assert windows == [
        (0.0, 200.0),
        (200.0, 400.0),
        (400.0, 600.0),
        (0.0, 100.0),
        (50.0, 150.0),
        (100.0, 200.0),
        (150.0, 250.0),
        (0.0, 100.0),
    ]
    assert kinds == ["paper", "later", "later"] + ["sliding"] * 4 + ["alt"]


def test_fit_windows_last_sliding_window_may_end_exactly_at_t_last():
    windows, kinds = mod.fit_windows((0.0, 200.0), [], [100.0, 50.0], (0.0, 100.0), 250.0)
    assert windows[-2] == (150.0, 250.0)
    assert kinds.count("sliding") == 4


def _exponential_me(mu, gamma, E0=0.3, t_max=400.0):
    t = np.arange(0.0, t_max + 1e-9, 2.0)
    return pd.DataFrame({"t": t, "mean_E": E0 * np.exp(-mu * gamma * t)})


def test_paper_fit_recovers_the_exponent_of_an_exact_exponential():
    me = _exponential_me(0.87, 0.01)
    fit = mod.paper_fit(me, 0.3, 0.01, (0.0, 200.0))
    assert fit.mu == pytest.approx(0.87, rel=1e-10)
    np.testing.assert_allclose(me["fit_E"], me["mean_E"], rtol=1e-10)


def test_mu_table_every_window_recovers_the_exponent():
    me = _exponential_me(0.6, 0.02)
    windows, kinds = [(0.0, 200.0), (100.0, 300.0), (0.0, 100.0)], ["paper", "sliding", "alt"]
    tab = mod.mu_table(me, 0.3, 0.02, windows, kinds)
    assert list(tab["kind"]) == kinds
    np.testing.assert_allclose(tab["mu"], 0.6, rtol=1e-10)
    np.testing.assert_allclose(tab["mu_free"], 0.6, rtol=1e-10)
    assert {"mu_fit_err", "mu_free_fit_err"} <= set(tab.columns) and "mu_err" not in tab


def test_bootstrap_errors_are_the_replicates_std_times_scale_per_window():
    n_boot, n_w = 4, 2
    # replicate-major rows: (b0 w0, b0 w1, b1 w0, ...); window 0 takes μ 1, 2, 3, 4 (std 1.29...), window 1 constant
    mu = np.array([1.0, 5.0, 2.0, 5.0, 3.0, 5.0, 4.0, 5.0])
    boot = pd.DataFrame({"mu": mu, "mu_free": 2 * mu})
    tab = pd.DataFrame({"t_lo": [0.0, 100.0], "t_hi": [200.0, 300.0]})
    me = pd.DataFrame({"t": [0.0, 400.0], "mean_E": [0.4, 0.0]})
    mod.add_bootstrap_errors(tab, me, boot, 0.5, n_w, n_boot)
    sd = np.std([1.0, 2.0, 3.0, 4.0], ddof=1)
    np.testing.assert_allclose(tab["mu_err"], [0.5 * sd, 0.0])
    np.testing.assert_allclose(tab["mu_free_err"], [sd, 0.0])
    np.testing.assert_allclose(tab["t_mid"], [100.0, 200.0])
    np.testing.assert_allclose(tab["mean_E_mid"], [0.3, 0.2])  # linear interpolation of ⟨E⟩ at the centres


def test_histogram_rows_density_integrates_to_one_in_log10_E():
    edges = np.array([0.01, 0.1, 1.0, 100.0])  # Δlog10 E = 1, 1, 2
    counts = np.array([[2, 6, 2], [0, 0, 0]])
    h = SimpleNamespace(
        t_requested=np.array([10.0, 20.0]),
        t=np.array([10.5, 19.5]),
        counts=counts,
        n_alive=np.array([10, 0]),
        mean_E=np.array([0.5, np.nan]),
    )
    rows = mod.histogram_rows(h, edges)
    assert len(rows) == 6
    first = rows[rows["t"] == 10.5]
    np.testing.assert_allclose(first["density_log10E"], [0.2, 0.6, 0.1])
    assert float((first["density_log10E"] * np.diff(np.log10(edges))).sum()) == pytest.approx(1.0)
    assert list(first["e_lo"]) == [0.01, 0.1, 1.0] and list(first["e_hi"]) == [0.1, 1.0, 100.0]
    assert rows[rows["t"] == 19.5]["density_log10E"].isna().all()  # nobody inside: no density
    assert list(rows["count"]) == [2, 6, 2, 0, 0, 0]


def test_nearest_times_pick_the_grid_time_closest_to_each_request():
    grid = np.array([0.0, 10.0, 20.0, 30.0])
    np.testing.assert_array_equal(mod.nearest_times(grid, [4.0, 6.0, 25.0, 99.0, -3.0]), [0.0, 10.0, 20.0, 30.0, 0.0])


def test_ribbons_three_sd_is_sqrt_n_times_three_sem_and_the_maximum_is_taken_on_the_axis():
    n = np.array([400, 100, 25])
    sd = np.array([0.02, 0.02, 0.02])
    me = pd.DataFrame(
        {"t": [0.0, 50.0, 100.0], "n": n, "mean_E": [0.3, 0.2, 0.1], "std_E": sd, "sem_E": sd / np.sqrt(n)}
    )
    r = mod.ribbons(me, 40.0, t_max=60.0)
    assert (r["t"], r["n"]) == (50.0, 100)
    assert r["half_width_3sd"] == pytest.approx(0.06) and r["half_width_3sem"] == pytest.approx(0.006)
    assert r["max_rel_half_width_3sd"] == pytest.approx(0.06 / 0.2)  # t = 100 is beyond the axis
    assert [row["authors"] for row in r["rows"]] == [True, False]


def _authors(me, boot_err, selection="inside", authors_window=(0.0, 200.0)):
    return mod.authors_convention(
        me,
        boot_err,
        (0.0, 200.0),
        (0.0, 100.0),
        0.3,
        0.01,
        1000,
        paper_mu=0.91,
        half_unit=0.005,
        selection=selection,
        authors_window=authors_window,
        setup="disk",
    )


def test_authors_convention_judges_each_selection_and_window_and_names_the_agreeing_authors_row():
    t = np.arange(0.0, 201.0, 5.0)
    # every orbit inside: μ = 0.95 (differs from 0.91 by 8σ at err 0.005); above E_c only: μ = 0.91, ends at t = 150
    above = np.where(t <= 150.0, 0.3 * np.exp(-0.91 * 0.01 * t), np.nan)
    me = pd.DataFrame(
        {
            "t": t,
            "mean_E": 0.3 * np.exp(-0.95 * 0.01 * t),
            "mean_E_above": above,
            "n_above": np.where(t <= 150.0, 10, 0),
        }
    )
    err = {(s, w): 0.005 for s in ("inside", "above") for w in ((0.0, 200.0), (0.0, 100.0))}
    rows = {(r["selection"], tuple(r["window"])): r for r in _authors(me, err, "above")["mu"]}
    ours = rows["inside", (0.0, 200.0)]
    assert ours["value"] == pytest.approx(0.95) and ours["ours"] and not ours["authors"]
    assert ours["verdict"] == "differs in our convention only; agrees under the authors' (above, fit [0, 200])"
    theirs = rows["above", (0.0, 200.0)]
    assert theirs["value"] == pytest.approx(0.91) and theirs["authors"] and theirs["t_last"] == 150.0
    assert "its points end at t = 150" in theirs["convention"] and theirs["convention"].endswith("; disk")
    # the authors' reading being ours, the difference stands
    assert _authors(me, err)["mu"][0]["verdict"] == "differs"
    with pytest.raises(ValueError, match="authors_window"):
        _authors(me, err, authors_window=(0.0, 50.0))
    with pytest.raises(ValueError, match="authors_selection"):
        _authors(me, err, selection="below")


def test_fit_overshoot_is_the_mean_log_ratio_over_the_last_quarter_of_the_window():
    t = np.arange(0.0, 301.0, 10.0)
    me = pd.DataFrame({"t": t, "mean_E": 0.3 * np.exp(-0.01 * t)})
    me["fit_E"] = me["mean_E"] * np.exp(np.where(t >= 150.0, 0.02 * (t - 140.0), 0.0))
    # window [0, 200]: t = 150 … 200, log ratios 0.2, 0.4, …, 1.2; t > 200 left out
    assert mod.fit_overshoot(me, (0.0, 200.0)) == pytest.approx(np.mean([0.2, 0.4, 0.6, 0.8, 1.0, 1.2]))


def test_decay_results_predict_tau2_count_settled_orbits_and_take_the_above_errors_per_window():
    t = np.arange(0.0, 201.0, 10.0)
    mean_E = 0.3 * np.exp(-0.9 * 0.01 * t)
    me = pd.DataFrame(
        {
            "t": t,
            "n": 100,
            "mean_E": mean_E,
            "std_E": 0.01,
            "sem_E": 0.001,
            "fit_E": mean_E,
            "mean_E_above": mean_E,
            "n_above": 100,
        }
    )
    tab = pd.DataFrame(
        {"kind": ["paper", "later", "later", "alt"], "mu": [0.9, 0.95, 0.97, 0.9], "mu_err": [0.02, 0.1, 0.2, 0.03]}
    )
    # replicates: window, alt, window, alt, window, alt
    boot_up = pd.DataFrame({"mu": [0.90, 0.80, 0.92, 0.84, 0.94, 0.88]})
    r = mod.decay_results(
        me,
        tab,
        ["settled", "escaped", "settled", "censored"],
        boot_up,
        0.5,
        (0.0, 200.0),
        (0.0, 100.0),
        0.3,
        0.01,
        1 / 6,
        4,
        n_boot=3,
        paper_mu=0.91,
        half_unit=0.005,
        selection="inside",
        authors_window=(0.0, 200.0),
        setup="disk",
        ribbon_t=100.0,
    )
    tau2 = np.log(0.3 * 6) / (0.9 * 0.01)
    assert r.tau2_pred == pytest.approx(tau2) and r.tau2_pred_err == pytest.approx(tau2 * 0.02 / 0.9)
    assert r.n_settled == 2 and r.over == pytest.approx(0.0, abs=1e-12)
    assert list(r.later_tab["mu"]) == [0.95, 0.97] and r.last["mu"] == 0.97 and r.p["kind"] == "paper"
    errs = {(row["selection"], tuple(row["window"])): row["err"] for row in r.authors["mu"]}
    assert errs["inside", (0.0, 200.0)] == 0.02 and errs["inside", (0.0, 100.0)] == 0.03
    assert errs["above", (0.0, 200.0)] == pytest.approx(0.02 * 0.5)  # std of 0.90, 0.92, 0.94 times the scale
    assert errs["above", (0.0, 100.0)] == pytest.approx(0.04 * 0.5)  # std of 0.80, 0.84, 0.88
    assert r.ribbon["t"] == 100.0


def test_mean_energy_table_band_and_the_orbits_above_the_critical_energy_per_time():
    from hhscatter.analysis.dissipative.decay import inside_mean_energy

    # three orbits at t = 0, 10, 20: one settles below E_c = 0.1 by t = 20, none is above E_c at t = 30
    snaps = pd.DataFrame(
        {
            "t": [0.0] * 3 + [10.0] * 3 + [20.0] * 3 + [30.0] * 2,
            "energy": [0.3, 0.3, 0.3, 0.2, 0.24, 0.16, 0.15, 0.13, 0.05, 0.08, 0.04],
        }
    )
    ime = inside_mean_energy([snaps], 0.1)
    me = mod.mean_energy_table(ime.inside, ime.above)
    assert me["t"].tolist() == [0.0, 10.0, 20.0, 30.0]
    assert me["n_above"].tolist() == [3, 3, 2, 0] and me["n_above"].dtype == np.int64
    assert me["mean_E_above"].iloc[:3].tolist() == pytest.approx([0.3, 0.2, 0.14]) and np.isnan(
        me["mean_E_above"].iloc[3]
    )
    sem_10 = np.std([0.2, 0.24, 0.16], ddof=1) / np.sqrt(3)
    assert me["lo_3sem"].iloc[1] == pytest.approx(0.2 - 3 * sem_10) and me["hi_3sem"].iloc[1] == pytest.approx(
        0.2 + 3 * sem_10
    )
    assert me["mean_E"].iloc[2] == pytest.approx(0.11)  # the settled orbit still counts inside Ω


def test_histogram_edges_are_geometric_from_below_the_lowest_energy_to_above_e0():
    edges = mod.histogram_edges(np.array([0.02, 0.2, 0.1]), 0.3, 4)
    assert len(edges) == 5 and edges[0] == pytest.approx(0.0196) and edges[-1] == pytest.approx(0.3003)
    assert np.diff(np.log(edges)) == pytest.approx(np.full(4, np.log(0.3003 / 0.0196) / 4))
    assert mod.histogram_edges([0.0, 0.1], 0.3, 2)[0] == pytest.approx(0.98e-12)  # a zero energy: the floor
