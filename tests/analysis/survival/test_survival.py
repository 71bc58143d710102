"""Tests of hhscatter.analysis.survival.fits / escape_rate on synthetic data with known answers.

Every statistical test uses a fixed seed and compares with an independent
closed-form truth (the survival function the sample was drawn from, the
Lotka root of a renewal process, the parameters of a synthetic κ(E) law).
"""

import math
import warnings

import numpy as np
import pandas as pd
import pytest
from scipy import integrate, optimize, stats

from hhscatter.analysis.survival.escape_rate import (
    choose_windows,
    cmeasure_sample_from_sections,
    escape_rate,
    escape_rate_from_lifetimes,
    escape_rate_mle,
    fit_kappa_energy,
    kappa_from_cmeasure,
    power_law_exponent_mle,
)
from hhscatter.analysis.survival.fits import (
    crossover_time,
    detect_power_law_tail,
    fit_exponential,
    fit_power_law_tail,
    lifetimes_to_arrays,
    survival_curve,
    survival_from_lifetimes,
)
from hhscatter.errors import ConfigError

E_C = 1.0 / 6.0


# ---------------------------------------------------------------------------
# synthetic samples
# ---------------------------------------------------------------------------
def sample_fast_plus_exponential(rng, n, kappa=0.15, fast_rate=1.5, fast_weight=0.3):
    """Lifetimes with P(t) = w e^{−a t} + (1−w) e^{−κ t}: an irregular start, then e^{−κt}."""
    fast = rng.random(n) < fast_weight
    return np.where(fast, rng.exponential(1 / fast_rate, n), rng.exponential(1 / kappa, n))


class PiecewiseSurvival:
    """P(t) = A e^{−a t} + B e^{−κ t} for t ≤ τ*, P(τ*)(τ*/t)^z after (continuous at τ*)."""

    def __init__(self, A=0.4, a=1.0, kappa=0.06, tau_star=100.0, z=1.8):
        self.A, self.a, self.B, self.kappa, self.tau_star, self.z = A, a, 1 - A, kappa, tau_star, z
        self.P_star = float(self.A * math.exp(-a * tau_star) + self.B * math.exp(-kappa * tau_star))

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        early = self.A * np.exp(-self.a * t) + self.B * np.exp(-self.kappa * t)
        late = self.P_star * (self.tau_star / np.maximum(t, self.tau_star)) ** self.z
        return np.where(t <= self.tau_star, early, late)

    def sample(self, rng, n):
        """Inverse-CDF sampling: T = P^{-1}(U)."""
        u = rng.random(n)
        tg = np.linspace(0.0, self.tau_star, 400_001)
        Pg = self(tg)
        early = np.interp(u, Pg[::-1], tg[::-1])
        late = self.tau_star * (self.P_star / u) ** (1.0 / self.z)
        return np.where(u <= self.P_star, late, early)


# ---------------------------------------------------------------------------
# survival_curve
# ---------------------------------------------------------------------------
def test_survival_curve_equals_plain_fraction_with_common_censoring():
    rng = np.random.default_rng(11)
    n, t_max = 50_000, 20.0
    life = np.ceil(rng.exponential(1 / 0.12, n) * 100) / 100  # ties, as with a fixed output step
    t_end = np.minimum(life, t_max)
    observed = life < t_max
    g = np.linspace(0, t_max - 1e-9, 801)
    c = survival_curve(t_end, observed, g)
    plain = (t_end[None, :] > g[:, None]).mean(axis=1)
    np.testing.assert_allclose(c.P, plain, rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(c.P_err, np.sqrt(plain * (1 - plain) / n), rtol=1e-6, atol=1e-13)
    assert c.P[0] == 1.0 and c.P_err[0] == 0.0
    assert np.all(np.diff(c.P) <= 0)
    # KM is defined up to t_max (censored orbits are at risk there), unknown beyond
    beyond = survival_curve(t_end, observed, [t_max, t_max + 1.0])
    assert beyond.P[0] == pytest.approx(np.mean(~observed), rel=1e-9)
    assert np.isnan(beyond.P[1])
    # the step representation (no grid)
    t, P, E = survival_curve(t_end, observed)
    assert t[0] == 0.0 and P[0] == 1.0
    assert np.all(np.diff(t) > 0) and np.all(np.diff(P) <= 0)
    assert t[-1] == t_max and P[-1] == pytest.approx(np.mean(~observed), rel=1e-10)
    # right-continuity: at an event time the orbits leaving there are already gone
    k = len(t) // 2
    assert P[k] == pytest.approx(np.mean(t_end > t[k]), rel=1e-10)


def test_survival_curve_all_leave_reaches_zero():
    t_end = np.array([1.0, 2.0, 2.0, 3.0])
    c = survival_curve(t_end, np.ones(4, bool), [0, 1, 1.5, 2, 2.5, 3, 10])
    np.testing.assert_allclose(c.P, [1, 0.75, 0.75, 0.25, 0.25, 0, 0])
    with pytest.raises(ConfigError, match="observed must be a boolean mask"):
        survival_curve(t_end, np.ones(4))


def test_kaplan_meier_handles_censoring_naive_does_not():
    rng = np.random.default_rng(5)
    n, kappa, t_max = 100_000, 0.2, 15.0
    life = rng.exponential(1 / kappa, n)
    cens = rng.uniform(0, 30, n)  # random censoring before t_max as well
    t_end = np.minimum.reduce([life, cens, np.full(n, t_max)])
    observed = life <= np.minimum(cens, t_max)
    g = np.linspace(0.1, t_max - 0.1, 100)
    km = survival_curve(t_end, observed, g)
    truth = np.exp(-kappa * g)
    zscore = (km.P - truth) / km.P_err
    assert np.max(np.abs(zscore)) < 4.0
    # treating censored orbits as leaving is badly wrong
    naive = survival_curve(t_end, np.ones(n, bool), g)
    i = np.searchsorted(g, 10.0)
    assert (truth[i] - naive.P[i]) / km.P_err[i] > 20
    # MLE: correct with censoring, biased if censored orbits are counted as events
    mle = escape_rate_mle(t_end, observed, 0.0, t_max)
    assert abs(mle.kappa - kappa) < 3 * mle.kappa_err
    bad = escape_rate_mle(t_end, np.ones(n, bool), 0.0, t_max)
    assert (bad.kappa - kappa) > 10 * mle.kappa_err


# ---------------------------------------------------------------------------
# exponential fits, windows, escape rate
# ---------------------------------------------------------------------------
def test_fits_exact_on_noiseless_laws():
    t = np.linspace(1, 200, 500)
    f = fit_exponential(t, 0.7 * np.exp(-0.08 * t), (10, 150))
    assert f.kappa == pytest.approx(0.08, rel=1e-12) and f.f0 == pytest.approx(0.7, rel=1e-10)
    p = fit_power_law_tail(t, 3.0 * t**-1.7, (10, 150))
    assert p.z == pytest.approx(1.7, rel=1e-12) and p.f_star == pytest.approx(3.0, rel=1e-10)
    # P = 0 points are excluded, not fatal
    P = 0.7 * np.exp(-0.08 * t)
    P[-50:] = 0.0
    assert fit_exponential(t, P, (10, 200)).kappa == pytest.approx(0.08, rel=1e-12)
    # crossover of two exact laws: f0 e^{-κτ} = f τ^{-z} at a known τ (the later root)
    tau = 100.0
    f_star = 0.7 * math.exp(-0.08 * tau) * tau**1.7
    p2 = fit_power_law_tail(t, f_star * t**-1.7, (10, 150))
    assert crossover_time(t, P, f, p2) == pytest.approx(tau, rel=1e-8)
    assert 1.7 / 0.08 < tau  # the root returned lies beyond the maximum of g at z/κ


def test_escape_rate_exponential_with_irregular_start():
    rng = np.random.default_rng(2024)
    n, kappa = 200_000, 0.15
    t_end = sample_fast_plus_exponential(rng, n, kappa=kappa)
    observed = np.ones(n, bool)
    r = escape_rate(t_end, observed)
    assert abs(r.kappa - kappa) < 3 * r.kappa_err
    assert abs(r.kappa - kappa) < 0.02 * kappa  # teeth: κ to 2 %, statistical error < 1 %
    assert r.kappa_stat < 0.01 * kappa and r.kappa_err < 0.04 * kappa
    assert abs(r.mle.kappa - kappa) < 3 * r.mle.kappa_err
    assert len(r.fits) == 4 and all(abs(f.kappa - kappa) < 4 * f.kappa_err for f in r.fits)
    # τ0 excludes the fast component (its weight in log P at τ0 is < 1 %) but not much more
    excess = 0.3 / 0.7 * math.exp(-(1.5 - kappa) * r.tau0)
    assert excess < 0.01 and r.tau0 < 10
    # the exponential regime extends to the counting floor (100 survivors)
    t_floor = -math.log(100 / (0.7 * n)) / kappa
    assert r.t_stop == pytest.approx(t_floor, abs=2.0)
    (lo, hi), (a1, b1), (a2, b2), (a3, b3) = r.windows
    assert (a1, b2) == (lo, hi) and b1 == a2 and lo < a3 < b3 < hi
    assert r.tail is None and math.isnan(r.tau_star)
    # without τ0 (fit from t = 0) the fast component biases κ by many σ
    naive = fit_exponential(r.curve.t, r.curve.P, (0.0, r.t_stop), r.curve.P_err)
    assert abs(naive.kappa - kappa) > max(10 * r.kappa_stat, 0.1 * kappa)
    # the correlation-aware error is realistic, the diagonal one is far too small
    f = r.fits[0]
    assert f.kappa_err_naive < 0.2 * f.kappa_err
    assert 0.5 < f.kappa_err / r.mle.kappa_err < 3


def test_choose_windows_pure_exponential_starts_at_zero():
    rng = np.random.default_rng(3)
    n = 100_000
    t_end = rng.exponential(1 / 0.2, n)
    g = np.linspace(0, 60, 6001)
    c = survival_curve(t_end, np.ones(n, bool), g)
    wc = choose_windows(c.t, c.P, c.P_err)  # N estimated from the binomial errors
    assert wc.converged
    assert wc.tau0 == 0.0
    assert wc.t_stop == pytest.approx(math.log(n / 100) / 0.2, abs=1.5)
    assert wc.kappa_ref == pytest.approx(0.2, rel=0.03)
    assert detect_power_law_tail(c.t, c.P, wc.tau0, c.P_err, n_total=n) is None


def test_choose_windows_picks_the_regime_that_carries_the_decay():
    """P = 0.99 e^{−0.2t} + 0.01 e^{−0.05t}: a slower component takes over at t ≈ 31, inside
    P ∈ [10^−4, 10^−1]; a median slope over a fixed P range would land in the crossover."""
    rng = np.random.default_rng(21)
    n = 500_000
    slow = rng.random(n) < 0.01
    t_end = np.where(slow, rng.exponential(1 / 0.05, n), rng.exponential(1 / 0.2, n))
    r = escape_rate(t_end, np.ones(n, bool), detect_tail=False)
    assert r.tau0 == 0.0 and 15 < r.t_stop < 28
    assert abs(r.kappa - 0.2) < 3 * r.kappa_err and abs(r.kappa - 0.2) < 0.01


def test_bursty_exponential_is_not_a_power_law():
    """Hazard h = κ (1 + 0.8 sin t) (escape in bursts at the orbital period): P = exp(−κt − 0.8κ(1 − cos t))."""
    kappa = 0.1
    tg = np.linspace(0, 300, 600_001)
    H = kappa * tg + 0.8 * kappa * (1 - np.cos(tg))
    rng = np.random.default_rng(13)
    n = 500_000
    t_end = np.interp(-np.log(rng.random(n)), H, tg)
    r = escape_rate(t_end, np.ones(n, bool))
    assert r.tail is None
    assert abs(r.kappa - kappa) < 3 * r.kappa_err and abs(r.kappa - kappa) < 0.005


def test_power_law_tail_and_crossover_time():
    law = PiecewiseSurvival(A=0.4, a=1.0, kappa=0.06, tau_star=100.0, z=1.8)
    rng = np.random.default_rng(7)
    n, t_max = 1_000_000, 5000.0
    life = law.sample(rng, n)
    # the sampler reproduces the law it was built from
    for tq in (5.0, 50.0, 300.0):
        p = float(law(tq))
        assert abs(np.mean(life > tq) - p) < 4 * math.sqrt(p * (1 - p) / n)
    t_end = np.minimum(life, t_max)
    r = escape_rate(t_end, life < t_max)
    assert abs(r.kappa - law.kappa) < 3 * r.kappa_err
    assert r.t_stop < law.tau_star < r.t_stop + 20
    assert r.tail is not None
    assert abs(r.tail.z - law.z) < 3 * r.tail.z_err and abs(r.tail.z - law.z) < 0.15
    assert abs(r.tail.z_mle - law.z) < 3 * r.tail.z_mle_err
    assert r.tail.hazard_exponent > 0.5
    assert r.tau_star == pytest.approx(law.tau_star, rel=0.05)
    # crossover from the two fits directly
    tau = crossover_time(r.curve.t, r.curve.P, r.fits[0], r.tail)
    assert tau == r.tau_star


# ---------------------------------------------------------------------------
# κ(E)
# ---------------------------------------------------------------------------
def test_fit_kappa_energy_recovers_continuous_piecewise_law():
    a, b, E_b = 13.63, 0.03, 0.27
    c = a * (E_b - E_C) + b
    E = np.linspace(0.18, 0.50, 33)
    x = E - E_C
    truth = np.where(E < E_b, a * x**2 + b * x, c * x)
    rng = np.random.default_rng(1)
    err = 0.01 * truth + 2e-4
    kap = truth + err * rng.standard_normal(E.size)
    fit = fit_kappa_energy(E, kap, err, E_C, n_boot=100, rng=0)
    for name, true in (("a", a), ("b", b), ("c", c), ("E_b", E_b)):
        est, sd = getattr(fit, name), getattr(fit, name + "_err")
        assert abs(est - true) < 3 * sd, (name, est, true, sd)
    assert abs(fit.E_b - E_b) < 0.02
    assert fit.c == pytest.approx(fit.a * (fit.E_b - E_C) + fit.b, rel=1e-9)
    assert fit.chi2 / fit.dof < 2.0
    # bootstrap and covariance errors agree roughly
    assert 0.3 < fit.boot_err[3] / fit.E_b_err < 3
    np.testing.assert_allclose(fit.predict(E), truth, rtol=0.03, atol=1e-3)
    assert fit.predict(0.1) == 0.0


def test_fit_kappa_energy_discontinuous_break():
    a, b, c, E_b = 13.63, 0.03, 1.60, 0.27  # a visible jump at the break
    E = np.linspace(0.18, 0.50, 33)
    x = E - E_C
    truth = np.where(E < E_b, a * x**2 + b * x, c * x)
    rng = np.random.default_rng(4)
    err = 0.005 * truth
    kap = truth + err * rng.standard_normal(E.size)
    fit = fit_kappa_energy(E, kap, err, E_C, continuous=False, n_boot=50, rng=1)
    assert abs(fit.E_b - E_b) <= 0.01  # the gap between the two bracketing energies
    assert abs(fit.c - c) < 4 * fit.c_err and abs(fit.a - a) < 4 * fit.a_err


# ---------------------------------------------------------------------------
# κ from the c-measure of a true-time map
# ---------------------------------------------------------------------------
def _lotka_kappa(q, k, theta):
    """Root of q E[e^{κT}] = 1, T ~ Gamma(k, θ): closed form and brentq on the numerical MGF."""
    closed = (1.0 - q ** (1.0 / k)) / theta
    mgf = lambda s: integrate.quad(lambda t: np.exp(s * t + stats.gamma.logpdf(t, k, scale=theta)), 0, np.inf)[0]  # noqa: E731
    root = optimize.brentq(lambda s: q * mgf(s) - 1.0, 0.0, 0.9 / theta)
    assert root == pytest.approx(closed, rel=1e-7)
    return closed


def test_kappa_from_cmeasure_renewal_process():
    q, k, theta = 0.8, 3.0, 2.0  # return with probability q after T ~ Gamma(3, 2)
    kappa_true = _lotka_kappa(q, k, theta)
    rng = np.random.default_rng(99)
    M = 20_000
    n_ret = rng.binomial(M, q)
    T = rng.gamma(k, theta, n_ret)
    res = kappa_from_cmeasure(T, M - n_ret, n_boot=200, rng=0)
    assert abs(res.kappa - kappa_true) < 3 * res.kappa_err
    assert res.kappa_err < 0.1 * kappa_true
    assert res.kappa_err_delta == pytest.approx(res.kappa_err, rel=0.3)
    assert res.mu_exit == pytest.approx((M - n_ret) / M)


def test_renewal_survival_decays_at_the_cmeasure_rate():
    """End-to-end check of the derivation: the flow's P(t) decays at the Lotka κ,
    whatever the (bounded) exit delays, and the exit times must not enter the estimator."""
    q, k, theta = 0.8, 3.0, 2.0
    kappa_true = _lotka_kappa(q, k, theta)
    rng = np.random.default_rng(123)
    n = 400_000
    returns = rng.geometric(1 - q, n) - 1  # number of returns before the exit
    exit_delay = rng.uniform(0, 10.0, n)
    life = rng.gamma(k * np.maximum(returns, 1), theta) * (returns > 0) + exit_delay
    observed = np.ones(n, bool)
    mle = escape_rate_mle(life, observed, 60.0, 200.0)
    assert abs(mle.kappa - kappa_true) < 3 * mle.kappa_err
    r = escape_rate(life, observed)
    assert abs(r.kappa - kappa_true) < 3 * r.kappa_err
    # c-measure sample from the same process (every crossing is iid here)
    M = 50_000
    n_ret = rng.binomial(M, q)
    T = rng.gamma(k, theta, n_ret)
    res = kappa_from_cmeasure(T, M - n_ret, n_boot=100, rng=1)
    assert abs(res.kappa - mle.kappa) < 3 * math.hypot(res.kappa_err, mle.kappa_err)
    # the other reading of Eq. (eqn:kappa_cmeasure_truetime), with exit times as T for exits, is wrong
    Te = rng.uniform(0, 10.0, M - n_ret)
    g = lambda s: (np.exp(s * T).sum() + np.exp(s * Te).sum()) / M - 1 - (M - n_ret) / M  # noqa: E731
    wrong = optimize.brentq(g, 1e-9, 1.0)
    assert abs(wrong - kappa_true) > 5 * res.kappa_err


def test_kappa_from_cmeasure_reduces_to_discrete_map():
    """T ≡ 1: Eq. (eqn:kappa_cmeasure_truetime) → κ = −log(1 − μ_c(𝓔)), Eq. (eqn:kappa_cmeasure_discrete)."""
    res = kappa_from_cmeasure(np.ones(900), 100, n_boot=20, rng=0)
    assert res.kappa == pytest.approx(-math.log(0.9), rel=1e-10)
    assert kappa_from_cmeasure(np.ones(10), 0, n_boot=2).kappa == 0.0


def test_cmeasure_sample_from_sections():
    sections = pd.DataFrame(
        {
            "traj_id": [1, 1, 1, 2, 2, 3, 4],
            "t": [10.0, 16.0, 23.0, 12.0, 30.0, 20.0, 5.0],
        }
    )
    lifetimes = pd.DataFrame(
        {
            "traj_id": [1, 2, 3, 4],
            "outcome": pd.Categorical(["escaped", "censored", "censored", "escaped"]),
            "t_end": [25.0, 100.0, 100.0, 6.0],
        }
    )
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        T, n_exit, n_und = cmeasure_sample_from_sections(sections, lifetimes, 10.0, 25.0, t_record_end=40.0)
    np.testing.assert_allclose(np.sort(T), [6.0, 7.0, 18.0])
    assert (n_exit, n_und) == (1, 1) and len(w) == 1


# ---------------------------------------------------------------------------
# DataFrame wrappers
# ---------------------------------------------------------------------------
def test_lifetimes_wrappers():
    rng = np.random.default_rng(8)
    n, t_max = 20_000, 30.0
    life = rng.exponential(1 / 0.2, n)
    outcome = np.where(life >= t_max, "censored", np.where(rng.random(n) < 0.9, "escaped", "settled"))
    df = pd.DataFrame(
        {
            "traj_id": np.arange(n, dtype="int64"),
            "e0": 0.3,
            "gamma": 0.0,
            "outcome": pd.Categorical(outcome),
            "t_end": np.minimum(life, t_max),
            "exit_channel": pd.array([pd.NA] * n, dtype="Int8"),
        }
    )
    t_end, observed = lifetimes_to_arrays(df)
    assert observed.sum() == np.sum(life < t_max)
    c = survival_from_lifetimes(df, [0.0, 10.0])
    assert c.P[1] == pytest.approx(np.mean(life > 10.0))
    r = escape_rate_from_lifetimes(df)
    assert abs(r.kappa - 0.2) < 3 * r.kappa_err
    with pytest.raises(ValueError):
        lifetimes_to_arrays(df.assign(outcome=np.where(np.arange(n) == 0, "lost", outcome)))
    with pytest.raises(ValueError):
        lifetimes_to_arrays(df.assign(e0=np.where(np.arange(n) == 0, 0.25, 0.3)))


def test_observed_from_outcome_on_a_categorical_is_the_label_test():
    """The categorical route (1e7 orbits: codes, no Python object per orbit) gives the same mask and errors."""
    import numpy as np
    import pandas as pd
    import pytest

    from hhscatter.analysis.survival.fits import observed_from_outcome

    labels = ["escaped", "censored", "settled", "stopped"] * 3
    cat = pd.Series(labels).astype("category")
    np.testing.assert_array_equal(observed_from_outcome(cat), observed_from_outcome(np.array(labels, dtype=object)))
    np.testing.assert_array_equal(observed_from_outcome(cat.array), [True, False, True, False] * 3)
    with pytest.raises(ValueError, match="bogus"):
        observed_from_outcome(pd.Series(["escaped", "bogus"]).astype("category"))
    with pytest.raises(ValueError, match="nan"):
        observed_from_outcome(pd.Categorical(["escaped", None]))


def test_power_law_exponent_mle_reports_its_window_in_time_units():
    # the MLE works in log t, but the result's window is the one asked for (time units), as escape_rate_mle's
    t = np.array([2.0, 5.0, 20.0, 50.0])
    r = power_law_exponent_mle(t, np.array([True, True, True, False]), 1.0, 40.0)
    assert (r.t_start, r.t_stop) == (1.0, 40.0)
    # and the exponent is D / Σ log(min(t, t_stop)/t_start), with a value worked out by hand
    assert r.n_events == 3 and r.kappa == pytest.approx(
        3 / (math.log(2.0) + math.log(5.0) + math.log(20.0) + math.log(40.0))
    )
