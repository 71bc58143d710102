"""Coverage of the error bars: on synthetic ensembles with a known answer, about 68 % of the
1σ intervals must cover the truth, within the exact binomial band at 3σ over ≥ 200 replicates."""

from __future__ import annotations

import math

import numpy as np
from scipy import optimize, stats

from hhscatter.analysis.survival.cmeasure import kappa_from_cmeasure

ONE_SIGMA = math.erf(1 / math.sqrt(2))  # 0.6827: the chance that a 1σ interval covers the truth
P_3SIGMA = 2 * stats.norm.sf(3.0)  # 0.0027


def _covers_as_1sigma(hits) -> bool:
    """Whether the number of covering intervals agrees with 68.27 % (exact binomial test at 3σ)."""
    hits = np.asarray(hits, bool)
    return stats.binomtest(int(hits.sum()), hits.size, ONE_SIGMA).pvalue > P_3SIGMA


def test_the_binomial_band_refuses_a_wrong_coverage():
    assert _covers_as_1sigma([True] * 137 + [False] * 63)  # 68.5 %
    assert not _covers_as_1sigma([True] * 100 + [False] * 100)  # 50 %
    assert not _covers_as_1sigma([True] * 180 + [False] * 20)  # 90 %


# -- κ from the c-measure: bootstrap over orbits ------------------------------------------------------------
def _orbit_ensemble(rng, n_orbits, q, k, theta, per_orbit):
    """Each orbit gives ``per_orbit`` sample points that share its fate (return with probability q, else exit) and
    its return time T_o ~ Gamma(k, θ): the extreme of correlated crossings. Truth: q E[e^{κT}] = 1."""
    T_o = rng.gamma(k, theta, n_orbits)
    orbit = np.repeat(np.arange(n_orbits), per_orbit)
    ret = (rng.random(n_orbits) < q)[orbit]
    return T_o[orbit[ret]], orbit[ret], orbit[~ret]


def test_kappa_from_the_cmeasure_bootstrap_over_orbits_covers_the_truth():
    q, k, theta, per_orbit = 0.8, 3.0, 2.0, 4
    truth = (
        1.0 - q ** (1.0 / k)
    ) / theta  # the Lotka root (tests/analysis/survival/test_survival.py checks the closed form)
    rng = np.random.default_rng(1313)
    by_orbit, by_point = [], []
    for _ in range(200):
        T, orb, exit_orb = _orbit_ensemble(rng, 200, q, k, theta, per_orbit)
        seed = int(rng.integers(2**31))
        r = kappa_from_cmeasure(T, exit_orb.size, orbits=orb, exit_orbits=exit_orb, n_boot=60, rng=seed)
        by_orbit.append(abs(r.kappa - truth) <= r.kappa_err)
        p = kappa_from_cmeasure(T, exit_orb.size, n_boot=60, rng=seed)  # the old bootstrap over crossings
        by_point.append(abs(p.kappa - truth) <= p.kappa_err)
        assert p.kappa == r.kappa
    print(f"κ_cm 1σ coverage: over orbits {np.mean(by_orbit):.3f}, over crossings {np.mean(by_point):.3f}")
    assert _covers_as_1sigma(by_orbit)
    assert not _covers_as_1sigma(by_point) and np.mean(by_point) < ONE_SIGMA  # too small: it undercovers


def test_the_orbit_bootstrap_needs_the_orbit_of_every_point():
    import pytest

    with pytest.raises(ValueError, match="orbit of each"):
        kappa_from_cmeasure(np.ones(3), 2, orbits=[0, 1], exit_orbits=[2, 3], n_boot=5)


# -- τ2 observed: order-statistic interval of a low quantile of the settling time ----------------------------
def _settling_ensemble(rng, n, f_settle, tau):
    """N orbits; a share f_settle settles at t ~ Exp(τ), the others escape. F(t) = f(1 − e^{−t/τ})."""
    t = rng.exponential(tau, n)
    return t, np.where(rng.random(n) < f_settle, "settled", "escaped")


def _truth_quantile(p, f_settle, tau):
    return -tau * math.log1p(-p / f_settle)


import pytest  # noqa: E402


@pytest.mark.parametrize("rank", [1, 20])  # the first settling time (the paper's τ2,obs), and the 20th
def test_the_order_statistic_interval_of_tau2_covers_the_quantile(rank):
    from hhscatter.analysis.dissipative.transitions import settle_quantile_interval

    n, f, tau = 2000, 0.3, 100.0
    p = rank / n
    truth = _truth_quantile(p, f, tau)
    rng = np.random.default_rng(4242 + rank)
    hits, stated = [], set()
    for _ in range(300):
        t, oc = _settling_ensemble(rng, n, f, tau)
        iv = settle_quantile_interval(t, oc, p)
        stated.add(round(iv.coverage, 12))
        hits.append(iv.lo <= truth < iv.hi)
        assert iv.lo <= iv.value <= iv.hi
    (cov,) = stated  # the ranks depend on N and p only: one exact coverage
    print(f"τ2 order-statistic interval, rank {rank}: stated {cov:.3f}, measured {np.mean(hits):.3f}")
    assert ONE_SIGMA <= cov < ONE_SIGMA + 0.08
    assert stats.binomtest(int(np.sum(hits)), len(hits), cov).pvalue > P_3SIGMA  # its exact coverage
    assert _covers_as_1sigma(hits)  # and about 68 %


def test_the_first_settling_time_and_its_interval_on_a_tiny_ensemble():
    import pandas as pd

    from hhscatter.analysis.dissipative.transitions import tau2_observed, tau2_observed_interval

    lt = pd.DataFrame(
        {"t_end": [5.0, 3.0, 9.0, 1.0, 7.0], "outcome": ["settled", "settled", "escaped", "escaped", "censored"]}
    )
    iv = tau2_observed_interval(lt)
    assert iv.value == tau2_observed(lt) == 3.0 and (iv.r, iv.s) == (0, 2) and (iv.lo, iv.hi) == (0.0, 5.0)
    assert iv.n_settled == 2 and iv.coverage == pytest.approx(0.8**5 + 5 * 0.2 * 0.8**4)


# -- τ2 from the survival model: the Δχ² = 1 ends of its profile by root-finding ---------------------------------
def test_the_profile_interval_by_root_finding_covers_the_truth():
    """y = A e^{−t/τ} + N(0, σ²), A profiled out (linear): the Δχ² = 1 interval of τ must cover τ_true ≈ 68 %."""
    from hhscatter.analysis.dissipative.survival_model import profile_interval

    t = np.linspace(0.0, 10.0, 40)
    A, tau, sigma = 1.0, 3.0, 0.05
    rng = np.random.default_rng(2626)
    hits, widths = [], []
    for _ in range(300):
        y = A * np.exp(-t / tau) + rng.normal(0, sigma, t.size)

        def chi2(x, y=y):
            f = np.exp(-t / x)
            a = (f @ y) / (f @ f)
            return float(np.sum((y - a * f) ** 2)) / sigma**2

        grid = np.linspace(0.5, 20.0, 25)  # a coarse scan, as fit_tau2 does; then the ends by root-finding
        best = float(optimize.minimize_scalar(chi2, bounds=(0.5, 20.0), method="bounded", options={"xatol": 1e-10}).x)
        lo, hi = profile_interval(chi2, best, chi2(best), 0.5, 20.0, step=grid[1] - grid[0])
        assert chi2(lo) == pytest.approx(chi2(best) + 1, abs=1e-6) and chi2(hi) == pytest.approx(
            chi2(best) + 1, abs=1e-6
        )
        hits.append(lo <= tau <= hi)
        widths.append((hi - lo) / 2)
    print(
        f"τ profile interval 1σ coverage: {np.mean(hits):.3f} (mean half-width {np.mean(widths):.3f}, "
        f"grid step {grid[1] - grid[0]:.3f})"
    )
    assert _covers_as_1sigma(hits)
    # the interval is not bounded by the scan's step: the old cap would have been ±1 grid step
    assert np.mean(widths) < grid[1] - grid[0]


def test_an_unbounded_side_of_the_profile_ends_at_its_edge():
    from hhscatter.analysis.dissipative.survival_model import profile_interval

    lo, hi = profile_interval(lambda x: (x - 2.0) ** 2 if x < 2.0 else 0.0, 2.0, 0.0, 0.0, 10.0)
    assert lo == pytest.approx(1.0) and hi == 10.0
