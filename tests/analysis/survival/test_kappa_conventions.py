"""κ(E) under several conventions (hhscatter.analysis.survival.kappa_conventions), on synthetic lifetimes with a known κ."""

import math

import numpy as np
import pytest

from hhscatter.analysis.survival.escape_rate import escape_rate
from hhscatter.analysis.survival.kappa_conventions import (
    censored_fraction,
    escape_rate_p_levels,
    p_level_windows,
    plateau_check,
    plateau_rate,
)
from hhscatter.errors import ConfigError


def _lifetimes(kappa, n, f_censored=0.0, t_max=400.0, seed=0):
    """Exponential lifetimes (rate κ) and a fraction f_censored that never escapes (censored at t_max)."""
    rng = np.random.default_rng(seed)
    t = rng.exponential(1 / kappa, n)
    censored = rng.random(n) < f_censored
    t[censored] = t_max
    obs = ~censored & (t < t_max)
    return np.minimum(t, t_max), obs


def test_the_censored_fraction_counts_the_orbits_still_inside_and_refuses_a_mask_of_another_size():
    assert censored_fraction([1.0, 3.0, 9.0], [True, False, False]) == pytest.approx(2 / 3)
    with pytest.raises(ConfigError, match="t_end must hold at least 1 value"):  # a share of no orbit is none
        censored_fraction([], [])
    with pytest.raises(ConfigError, match="observed must have one value per orbit: 2 != 3"):
        censored_fraction([1.0, 3.0, 9.0], [True, False])
    with pytest.raises(ConfigError, match="t_end must be an array of numbers"):
        censored_fraction("t", [True])


def test_p_level_windows_of_an_exponential_are_at_its_levels():
    kappa = 0.2
    t = np.linspace(0, 60, 60001)
    w = p_level_windows(t, np.exp(-kappa * t), 0.5, 0.01)
    assert w[0][0] == pytest.approx(math.log(2) / kappa, abs=2e-3)
    assert w[0][1] == pytest.approx(math.log(100) / kappa, abs=2e-3)
    L = w[0][1] - w[0][0]
    assert w[1] == pytest.approx((w[0][0], w[0][0] + L / 2)) and w[3] == pytest.approx(
        (w[0][0] + L / 4, w[0][0] + 3 * L / 4)
    )
    assert p_level_windows(t, 0.05 + 0.95 * np.exp(-kappa * t), 0.5, 0.01) is None  # a plateau above p_lo
    with pytest.raises(ValueError, match="p_lo"):
        p_level_windows(t, np.exp(-t), 0.01, 0.5)


def test_p_level_rate_covers_the_true_kappa():
    """1σ intervals of 40 independent ensembles cover the true κ about 68 % of the time (binomial ±3σ)."""
    kappa, hits, n_rep = 0.15, 0, 40
    for seed in range(n_rep):
        t, obs = _lifetimes(kappa, 4000, seed=seed)
        r = escape_rate_p_levels(t, obs, p_hi=0.5, p_lo=0.01)
        assert r.defined
        hits += abs(r.kappa - kappa) <= r.kappa_err
    p = 0.683
    assert abs(hits - p * n_rep) <= 3 * math.sqrt(n_rep * p * (1 - p)) + 1


def test_a_censored_plateau_makes_kappa_ill_defined_instead_of_small():
    """With 6.5 % never escaping (square ICs at E = 0.18) P never reaches 1 %: no κ; our window rule's κ is
    flagged when its window ends on the plateau; without censored orbits both are defined."""
    kappa = 0.1
    t, obs = _lifetimes(kappa, 20000, f_censored=0.065, seed=3)
    assert censored_fraction(t, obs) == pytest.approx(0.065, abs=0.005)
    r = escape_rate_p_levels(t, obs)
    assert not r.defined and "never falls" in r.reason and math.isnan(r.kappa)
    res = escape_rate(t, obs, detect_tail=False)
    pr = plateau_rate(res, t, obs)
    P_end = float(np.interp(res.t_stop, res.curve.t, res.curve.P))
    assert pr.defined == (0.065 / P_end <= 0.1)
    assert pr.bias_at_end == pytest.approx(censored_fraction(t, obs) / P_end)
    # the fraction is the censored one, under its name and under the name before (callers of that name still read it)
    assert pr.censored_fraction == pr.trapped_fraction == censored_fraction(t, obs) == r.censored_fraction
    t0, obs0 = _lifetimes(kappa, 20000, seed=3)
    assert (
        escape_rate_p_levels(t0, obs0).defined
        and plateau_rate(escape_rate(t0, obs0, detect_tail=False), t0, obs0).defined
    )


def test_plateau_check_threshold():
    assert plateau_check(0.1, 0.005)[0] and not plateau_check(0.1, 0.02)[0]
    assert plateau_check(0.1, 0.02)[1] == pytest.approx(0.2)
    assert not plateau_check(0.0, 0.0)[0]


def test_quoted_verdict_uses_the_papers_printed_precision():
    from hhscatter.analysis.stats.verdicts import half_unit
    from hhscatter.reproduction.verdicts import quoted_verdict

    assert half_unit(0.27) == pytest.approx(0.005) and half_unit(13.63) == pytest.approx(0.005)
    assert half_unit(100.0) == 0.5 and half_unit(1.0) == 0.5
    assert quoted_verdict(0.2705, 0.001, 0.27, 0.005) == "agrees within 2σ"
    assert quoted_verdict(0.2750, 0.0021, 0.27, 0.005) == "agrees to the paper's quoted digits"
    assert quoted_verdict(0.2800, 0.0021, 0.27, 0.005) == "differs"


def test_the_reasons_name_the_orbits_still_inside_at_t_max_censored():
    """The reasons go into the studies' numbers and onto the pages: the glossary's "censored", never "trapped" or
    "KAM" (a censored orbit may be regular, sticky or chaotic but confined)."""
    ok, _, reason = plateau_check(0.1, 0.02)
    assert not ok and reason.startswith("plateau: censored orbits (still inside at t_max) are 2.00%, 20% of P")
    assert "trapped" not in reason and "KAM" not in reason


def test_a_window_holding_the_dead_time_before_the_first_escape_is_no_exponential_regime():
    """κ·(t_first − τ0) > 0.5: half an e-fold of the window passes before anyone leaves."""
    from hhscatter.analysis.survival.kappa_conventions import dead_time_check

    assert not dead_time_check(0.0, 1.56, 1.257)[0]  # 1.96 e-folds without an escape
    assert dead_time_check(0.0, 0.4, 1.0)[0]  # 0.4 e-fold: a flight time inside the regime
    assert dead_time_check(8.3, 1.56, 0.263) == (True, "")  # the window starts after the first escape


def test_a_window_shorter_than_an_e_fold_of_its_kappa_is_the_bursts_hand_over_not_a_regime():
    """κ·(t_hi − τ0) < 1 within one period 2π: the window's slope is a local slope, whatever its start."""
    from hhscatter.analysis.survival.kappa_conventions import dead_time_check

    ok, why = dead_time_check(2.78, 0.8, 0.661, t_hi=3.26)  # 0.32 e-folds, after the first escape
    assert not ok and why.startswith("window spans 0.32 e-folds of κ (< 1)")
    assert dead_time_check(8.3, 1.56, 0.263, t_hi=14.6) == (True, "")  # 1.7 e-folds
    assert dead_time_check(8.3, 1.56, 0.263, t_hi=14.6, min_efolds=2.0, min_span=10.0)[0] is False
    # less than an e-fold but over many periods (near the threshold, κ small): not the burst's hand-over
    assert dead_time_check(169.0, 5.17, 0.00398, t_hi=369.0) == (True, "")
    assert dead_time_check(2.78, 0.8, 0.661) == (True, "")  # without the window's end only the start is judged
