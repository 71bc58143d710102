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
