"""The censoring-aware plateau-plus-exponential fit against samples drawn from known laws."""

import math

import numpy as np
import pytest

from hhscatter.analysis.survival.long_time import fit_plateau_exponential, hazard_profile, rate_status, survival_at


def _sample(n, q, kappa, t_max, seed):
    rng = np.random.default_rng(seed)
    t = np.where(rng.random(n) < q, np.inf, rng.exponential(1 / kappa, n))
    return np.minimum(t, t_max), t < t_max


@pytest.mark.parametrize("q, kappa", [(0.3, 0.01), (0.75, 0.001), (0.05, 0.003)])
def test_plateau_and_rate_recovered_within_errors(q, kappa):
    t, obs = _sample(40000, q, kappa, 2000.0, 5)
    f = fit_plateau_exponential(t, obs, 0.0)
    assert abs(f.q - q) < 4 * f.q_err and abs(f.kappa - kappa) < 4 * f.kappa_err
    assert f.chi2 / f.dof < 3


def test_errors_match_the_spread_over_samples():
    fits = [fit_plateau_exponential(*_sample(5000, 0.4, 0.004, 1000.0, s), 0.0) for s in range(30)]
    k = np.array([f.kappa for f in fits])
    err = np.median([f.kappa_err for f in fits])
    assert 0.6 < k.std(ddof=1) / err < 1.6


def test_a_single_exponential_on_a_plateau_is_rejected_by_its_chi2():
    t, obs = _sample(20000, 0.3, 0.01, 800.0, 1)
    single = fit_plateau_exponential(t, obs, 0.0, plateau=False)
    both = fit_plateau_exponential(t, obs, 0.0)
    assert single.chi2 / single.dof > 20 > both.chi2 / both.dof


def test_rate_is_not_conditioned_on_escape_before_t_max():
    # the escaping orbits alone look faster; the censoring-aware rate of the whole population does not
    t, obs = _sample(40000, 0.0, 0.002, 400.0, 2)
    f = fit_plateau_exponential(t, obs, 0.0, plateau=False)
    assert abs(f.kappa - 0.002) < 4 * f.kappa_err
    only_escaping = 1 / t[obs].mean()
    assert only_escaping > 2.5 * 0.002


def test_plateau_fraction_of_all_orbits_uses_survival_at_t0():
    t, obs = _sample(20000, 0.5, 0.01, 1000.0, 4)
    f = fit_plateau_exponential(t, obs, 100.0)
    P100 = survival_at(t, obs, [100.0])[0][0]
    assert f.p_t0 == pytest.approx(P100) and abs(f.p_inf - 0.5) < 4 * f.p_inf_err


def test_hazard_profile_is_flat_for_an_exponential():
    t, obs = _sample(50000, 0.0, 0.01, 300.0, 6)
    h = hazard_profile(t, obs, [0.0, 100.0, 200.0, 300.0])
    assert np.all(np.abs(h["hazard"] - 0.01) < 4 * h["hazard_err"])


def test_too_few_orbits_refused():
    with pytest.raises(ValueError, match="too few"):
        fit_plateau_exponential([1.0, 2.0], [True, True], 0.0)


def test_rate_status_flags_a_plateau_with_its_p_inf():
    from hhscatter.analysis.survival.long_time import rate_status

    t, obs = _sample(20000, 0.4, 0.005, 800.0, 8)
    s = rate_status(t, obs, 50.0, 700.0)
    assert s.status == "trapped" and "P∞" in s.note and abs(s.p_inf - 0.4) < 4 * s.p_inf_err


def test_rate_status_flags_a_falling_hazard_as_non_exponential():
    from hhscatter.analysis.survival.long_time import rate_status

    rng = np.random.default_rng(9)
    t = np.concatenate([rng.exponential(10.0, 10000), rng.exponential(100.0, 10000)])  # two rates: not one
    s = rate_status(np.minimum(t, 3000.0), t < 3000.0, 5.0, 400.0)
    assert s.status == "non-exponential" and s.note


def test_rate_status_passes_one_exponential():
    from hhscatter.analysis.survival.long_time import rate_status

    t, obs = _sample(20000, 0.0, 0.05, 400.0, 10)
    assert rate_status(t, obs, 5.0, 150.0).status == "exponential"


def test_nothing_censored_gives_the_single_exponential_without_overflow():
    """With every orbit escaped the likelihood falls with q: the MLE is q = 0, κ = escapes / exposure. This
    sample once sent the simplex to a logit beyond exp's range (OverflowError)."""
    t = np.random.default_rng(17).exponential(5.0, 100)
    f = fit_plateau_exponential(t, np.ones(t.size, bool), 10.0)
    s = t[t > 10.0] - 10.0
    assert f.q == 0.0 and f.p_inf == 0.0 and math.isnan(f.q_err)
    assert f.kappa == pytest.approx(s.size / s.sum(), rel=1e-12)


@pytest.mark.parametrize("seed", range(20))
def test_rate_status_of_uncensored_exponentials_is_exponential(seed):
    t = np.random.default_rng(seed).exponential(5.0, 600)
    st = rate_status(t, np.ones(t.size, bool), 1.0, 15.0)
    assert st.status == "exponential" and st.censored_fraction == 0.0 and st.note == ""
    assert st.p_inf == 0.0 and math.isfinite(st.kappa_inf)


def test_rate_status_of_a_population_gone_before_tau0_is_empty_not_trapped():
    t = np.random.default_rng(0).exponential(1.0, 500)
    st = rate_status(t, np.ones(t.size, bool), 100.0, 200.0)
    assert st.status == "empty" and "inf" not in st.note and "no orbit is inside after τ0" in st.note


def test_rate_status_with_every_orbit_gone_before_the_window_end_has_no_plateau():
    """All escaped between τ0 and t_stop: P(t_stop) = 0 and nothing trapped is no bias (was 'trapped', inf %)."""
    t = np.random.default_rng(4).exponential(5.0, 2000)
    st = rate_status(t, np.ones(t.size, bool), 1.0, 10 * t.max())
    assert st.status == "exponential" and "inf" not in st.note


def test_one_orbit_left_in_a_tail_cell_expecting_1e_5_does_not_decide_the_fit():
    # an exponential sample with one orbit still inside at t_max, where one exponential expects ~1e-5 of them
    rng = np.random.default_rng(21)
    kappa, t_max, n = 0.024, 800.0, 2000
    t = np.append(rng.exponential(1 / kappa, n - 1), np.inf)
    obs = t < t_max
    f = fit_plateau_exponential(np.minimum(t, t_max), obs, 0.0, plateau=False)
    expected_inside = n * math.exp(-f.kappa * t_max)
    assert 1e-7 < expected_inside < 1e-3 and (~obs).sum() == 1  # unpooled, that cell alone adds ~1/expected
    assert not f.too_few and f.chi2 < 30 and f.p_value > 1e-3


def test_p_values_of_one_exponential_are_uniform_over_seeds():
    # 200 exponential samples whose tail cell expects < 5 orbits: rejections at 5 % within binomial bounds
    p = []
    for seed in range(200):
        t, obs = _sample(300, 0.0, 0.06, 100.0, 1000 + seed)
        f = fit_plateau_exponential(t, obs, 0.0, plateau=False)
        assert not f.too_few and f.dof >= 5
        p.append(f.p_value)
    p = np.array(p)
    assert 2 <= int((p < 0.05).sum()) <= 20  # 10 expected, binomial 1σ 3.1
    assert 0.38 < float((p < 0.5).mean()) < 0.62


def test_a_handful_of_orbits_gives_too_few_not_a_verdict():
    t, obs = _sample(12, 0.0, 0.05, 400.0, 3)
    f = fit_plateau_exponential(t, obs, 0.0, plateau=False)
    assert f.too_few and math.isnan(f.p_value) and f.dof < 1


def test_p_inf_error_carries_the_binomial_error_of_p_t0():
    # 8 % of 2000 orbits never leave, the others leave fast (κ = 0.05) so P∞ is close to a binomial count:
    # σ ≈ √(0.08 · 0.92 / 2000) = 0.0061, where q's error alone times P(t0) gives ≈ 0.0017
    binom = math.sqrt(0.08 * 0.92 / 2000)
    fits = [fit_plateau_exponential(*_sample(2000, 0.08, 0.05, 1000.0, 300 + s), 100.0) for s in range(100)]
    p_inf = np.array([f.p_inf for f in fits])
    err = float(np.median([f.p_inf_err for f in fits]))
    assert err == pytest.approx(binom, rel=0.1)
    assert 0.8 < p_inf.std(ddof=1) / err < 1.25  # the Monte Carlo spread over 100 samples


def test_a_hazard_bin_without_escape_gives_its_poisson_upper_bound_not_zero_plus_minus_zero():
    # orbits end at 10, 20 (escapes) and 100 (censored): [50, 100) has one orbit at risk for 50 time units, no escape
    h = hazard_profile([10.0, 20.0, 100.0], [True, True, False], [0.0, 50.0, 100.0])
    empty = h.iloc[1]
    assert empty["events"] == 0 and empty["exposure"] == 50.0 and empty["hazard"] == 0.0
    assert math.isnan(empty["hazard_err"])  # no "± 0"
    assert empty["hazard_upper"] == pytest.approx(2.995732 / 50.0, rel=1e-6)  # P(0 events | κ·50) = 0.05
    assert math.isnan(h.iloc[0]["hazard_upper"]) and h.iloc[0]["hazard_err"] > 0


@pytest.mark.parametrize("n", [6, 12])
def test_rate_status_with_too_few_orbits_says_so_by_the_pooled_chi2_rule(n):
    """A handful of exponential lifetimes: one exponential is neither accepted nor rejected (was 'exponential')."""
    from hhscatter.analysis.stats.goodness import TOO_FEW

    t = np.random.default_rng(n).exponential(10.0, n)
    obs = np.ones(n, bool)
    if n >= 10:  # fitted: the pooled χ²'s rule, with n orbits in cells of ≥ 5 expected no degree of freedom left
        assert fit_plateau_exponential(t, obs, 0.0, plateau=False).too_few
    else:  # too few to fit one exponential at all
        with pytest.raises(ValueError, match="too few"):
            fit_plateau_exponential(t, obs, 0.0, plateau=False)
    st = rate_status(t, obs, 0.0, 20.0)
    assert st.status == TOO_FEW == "too few orbits" and math.isnan(st.p_value) and TOO_FEW in st.note


def test_rate_status_gives_a_verdict_once_the_pooled_chi2_has_a_degree_of_freedom():
    t = np.random.default_rng(5).exponential(10.0, 200)
    obs = np.ones(t.size, bool)
    assert not fit_plateau_exponential(t, obs, 0.0, plateau=False).too_few
    assert rate_status(t, obs, 0.0, 20.0).status == "exponential"
