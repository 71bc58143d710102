"""The one Kaplan–Meier estimator (hhscatter.analysis.survival.kaplan_meier) against library implementations,
with weights and streamed, and the other reference checks of the analysis (Wilson intervals)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from hhscatter.analysis.survival.kaplan_meier import KaplanMeierGrid, km_steps, survival_curve, survival_on_grid


def _sample(rng, n=3000):
    """Exponential lifetimes rounded to 0.05 (ties), right-censored at random times and at t_max = 40."""
    t = np.round(rng.exponential(8.0, n), 2)
    c = np.round(rng.uniform(0.0, 60.0, n), 2)
    t_end = np.minimum(np.minimum(t, c), 40.0)
    observed = (t <= c) & (t <= 40.0)
    return t_end, observed


def test_survival_curve_and_greenwood_match_scipy_ecdf_with_censored_data():
    rng = np.random.default_rng(1)
    t_end, observed = _sample(rng)
    res = stats.ecdf(stats.CensoredData(uncensored=t_end[observed], right=t_end[~observed]))
    grid = np.linspace(0.0, 39.0, 157)
    ours = survival_curve(t_end, observed, grid)
    np.testing.assert_allclose(ours.P, res.sf.evaluate(grid), rtol=1e-12, atol=1e-15)
    # Greenwood: scipy's 'linear' confidence interval is P ± z·P·√(Σ d/(n(n−d)))
    z = stats.norm.ppf(0.975)
    ci = res.sf.confidence_interval(0.95, method="linear")
    lo, hi = ci.low.evaluate(grid), ci.high.evaluate(grid)
    inside = (lo > 0) & (hi < 1)  # scipy clips the band to [0, 1]
    assert inside.sum() > 100
    np.testing.assert_allclose(ours.P_err[inside], ((hi - lo) / (2 * z))[inside], rtol=1e-9)


def test_weights_are_multiplicities():
    rng = np.random.default_rng(2)
    t_end, observed = _sample(rng, 800)
    w = rng.integers(0, 4, t_end.size)
    grid = np.linspace(0.0, 39.0, 80)
    weighted = survival_curve(t_end, observed, grid, weights=w)
    repeated = survival_curve(np.repeat(t_end, w), np.repeat(observed, w), grid)
    np.testing.assert_allclose(weighted.P, repeated.P, rtol=1e-12)
    np.testing.assert_allclose(weighted.P_err, repeated.P_err, rtol=1e-9)
    assert km_steps(t_end, observed, w).n_total == w.sum()
    with pytest.raises(ValueError, match="weights"):
        survival_curve(t_end, observed, grid, weights=-w)


def test_streamed_grid_equals_the_exact_estimator_when_censoring_is_at_t_max():
    rng = np.random.default_rng(3)
    t = np.round(rng.exponential(10.0, 5000), 2)
    t_end, observed = np.minimum(t, 50.0), t < 50.0
    grid = np.linspace(0.0, 50.0, 201)
    km = KaplanMeierGrid(grid)
    for part in np.array_split(np.arange(t_end.size), 7):  # batch by batch, as from part files
        km.add(t_end[part], observed[part])
    streamed, exact = km.curve(), survival_curve(t_end, observed, grid)
    assert km.first_censoring == 50.0
    np.testing.assert_allclose(streamed.P, exact.P, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(streamed.P_err, exact.P_err, rtol=1e-9, atol=1e-15)
    # ... and, before t_max, the plain (weighted) fraction of survivors, Σ w·1(t_end > g) / Σ w
    w = rng.poisson(1.0, t_end.size).astype(float)
    g = grid[:-1]
    frac = np.array([(w * (t_end > x)).sum() for x in g]) / w.sum()
    np.testing.assert_allclose(survival_on_grid(t_end, observed, g, w), frac, rtol=1e-12, atol=1e-15)


def test_grid_with_censoring_inside_bins_stays_close_to_the_exact_estimator():
    rng = np.random.default_rng(4)
    t_end, observed = _sample(rng, 20000)
    grid = np.linspace(0.0, 39.0, 391)
    km = KaplanMeierGrid(grid).add(t_end, observed)
    assert km.first_censoring < grid[-1]
    binned, exact = km.curve(), survival_curve(t_end, observed, grid)
    assert np.max(np.abs(binned.P - exact.P)) < 0.5 * np.max(exact.P_err)


def test_wilson_interval_matches_scipy_binomtest():
    from hhscatter.analysis.stats.intervals import wilson_interval

    for k, n in ((0, 50), (3, 50), (17, 40), (40, 40), (1234, 100000)):
        ci = stats.binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
        p, lo, hi = wilson_interval(k, n, stats.norm.ppf(0.975))
        assert p == k / n
        assert lo == pytest.approx(ci.low, rel=1e-9, abs=1e-12) and hi == pytest.approx(ci.high, rel=1e-9, abs=1e-12)


def test_weighted_least_squares_matches_scipy_curve_fit():
    from scipy.optimize import curve_fit

    from hhscatter.analysis.stats.least_squares import least_squares_operator, weighted_least_squares

    rng = np.random.default_rng(5)
    x = np.linspace(0.0, 10.0, 40)
    sigma = 0.05 + 0.02 * x
    y = 1.5 - 0.3 * x + 0.01 * x**2 + sigma * rng.standard_normal(x.size)
    X = np.column_stack([np.ones_like(x), x, x**2])

    def model(xx, a, b, c):
        return a + b * xx + c * xx**2

    for absolute in (True, False):
        popt, pcov = curve_fit(model, x, y, sigma=sigma, absolute_sigma=absolute)
        fit = weighted_least_squares(X, y, 1.0 / sigma**2, errors="absolute" if absolute else "scaled")
        np.testing.assert_allclose(fit.coef, popt, rtol=1e-7, atol=1e-10)
        np.testing.assert_allclose(fit.cov, pcov, rtol=1e-6)
    # unweighted: ordinary least squares with residual-scaled errors
    popt, pcov = curve_fit(model, x, y)
    ols = weighted_least_squares(X, y, errors="scaled")
    np.testing.assert_allclose(ols.coef, popt, rtol=1e-7, atol=1e-10)
    np.testing.assert_allclose(ols.cov, pcov, rtol=1e-6)
    assert ols.dof == x.size - 3 and ols.chi2 == pytest.approx(np.sum(ols.resid**2))
    # the operator maps any data to its fit; 'inflated' never shrinks the absolute errors
    A, F = least_squares_operator(X, 1.0 / sigma**2)
    np.testing.assert_allclose(A @ y, weighted_least_squares(X, y, 1.0 / sigma**2).coef, rtol=1e-12)
    tight = weighted_least_squares(X, y, 1.0 / (10 * sigma) ** 2, errors="inflated")
    np.testing.assert_allclose(tight.cov, np.linalg.inv(X.T @ (X / (10 * sigma[:, None]) ** 2)), rtol=1e-12)


def test_power_law_exponent_recovers_one_over_gamma():
    from hhscatter.analysis.dissipative.transitions import power_law_exponent, tau2_predicted

    g = np.array([0.001, 0.002, 0.005, 0.01, 0.02])
    tau = tau2_predicted(0.3, 1 / 6, 0.9, g)
    p, err = power_law_exponent(g, tau, 0.01 * tau)
    assert p == pytest.approx(1.0, rel=1e-12) and err > 0
    assert power_law_exponent(g[:1], tau[:1], tau[:1]) == (None, None)


def test_power_law_exponent_without_errors_takes_its_error_from_the_scatter():
    """No usable τ errors (e.g. τ2 observed, whose order-statistic interval is not a Gaussian σ): the fit is
    unweighted and σ_p is the residual-scatter error of a straight line in log–log, checked against curve_fit."""
    from scipy.optimize import curve_fit

    from hhscatter.analysis.dissipative.transitions import power_law_exponent

    g = np.array([0.005, 0.01, 0.02, 0.04])
    tau = 0.5 / g**1.05 * np.array([1.01, 0.98, 1.02, 0.99])
    p, err = power_law_exponent(g, tau, np.full(g.size, np.nan))
    (c, slope), cov = curve_fit(lambda x, c, s: c + s * x, np.log(g), np.log(tau))  # unweighted, scaled
    assert p == pytest.approx(-slope, rel=1e-8)  # curve_fit iterates to its xtol = 1.5e-8
    assert err == pytest.approx(np.sqrt(cov[1, 1]), rel=1e-6)  # curve_fit: finite-difference Jacobian
    assert 0 < err < 0.1  # not the σ = 1 of a made-up weight
