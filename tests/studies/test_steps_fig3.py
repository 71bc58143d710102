"""Steps of study fig3's analysis (the window chooser, the paper's fit, the bootstrap errors, the histogram rows)
on synthetic input with a known answer."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hhscatter.studies import stage_module

mod = stage_module("fig3")


def test_fit_windows_paper_later_sliding_alt_in_order():
    windows, kinds = mod._fit_windows(
        (0.0, 200.0), [(200.0, 400.0), (400.0, 600.0)], [100.0, 50.0], (0.0, 100.0), 260.0
    )
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
    windows, kinds = mod._fit_windows((0.0, 200.0), [], [100.0, 50.0], (0.0, 100.0), 250.0)
    assert windows[-2] == (150.0, 250.0)
    assert kinds.count("sliding") == 4


def _exponential_me(mu, gamma, E0=0.3, t_max=400.0):
    t = np.arange(0.0, t_max + 1e-9, 2.0)
    return pd.DataFrame({"t": t, "mean_E": E0 * np.exp(-mu * gamma * t)})


def test_paper_fit_recovers_the_exponent_of_an_exact_exponential():
    me = _exponential_me(0.87, 0.01)
    fit = mod._paper_fit(me, 0.3, 0.01, (0.0, 200.0))
    assert fit.mu == pytest.approx(0.87, rel=1e-10)
    np.testing.assert_allclose(me["fit_E"], me["mean_E"], rtol=1e-10)


def test_mu_table_every_window_recovers_the_exponent():
    me = _exponential_me(0.6, 0.02)
    windows, kinds = [(0.0, 200.0), (100.0, 300.0), (0.0, 100.0)], ["paper", "sliding", "alt"]
    tab = mod._mu_table(me, 0.3, 0.02, windows, kinds)
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
    mod._add_bootstrap_errors(tab, me, boot, 0.5, n_w, n_boot)
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
    rows = mod._histogram_rows(h, edges)
    assert len(rows) == 6
    first = rows[rows["t"] == 10.5]
    np.testing.assert_allclose(first["density_log10E"], [0.2, 0.6, 0.1])
    assert float((first["density_log10E"] * np.diff(np.log10(edges))).sum()) == pytest.approx(1.0)
    assert list(first["e_lo"]) == [0.01, 0.1, 1.0] and list(first["e_hi"]) == [0.1, 1.0, 100.0]
    assert rows[rows["t"] == 19.5]["density_log10E"].isna().all()  # nobody inside: no density
    assert list(rows["count"]) == [2, 6, 2, 0, 0, 0]
