"""hhscatter.analysis.survival.windows: the steps of choose_windows on survival curves with a known rate."""

import math

import numpy as np
import pytest

from hhscatter.analysis.survival.kaplan_meier import survival_curve
from hhscatter.analysis.survival.windows import (
    _fitting_windows,
    _iterate_plateau,
    _overlapping_run,
    _pilot_rate,
    _plateau_level,
    _smoothing_width,
    choose_windows,
)

KAPPA, N = 0.15, 1_000_000
T = np.round(np.arange(0.0, 120.0, 0.01), 10)


def exact(t, fast_weight=0.0, fast_rate=1.5):
    """P(t) = w e^{−a t} + (1 − w) e^{−κ t}: an irregular start (w > 0), then the exponential regime e^{−κt}."""
    return fast_weight * np.exp(-fast_rate * t) + (1 - fast_weight) * np.exp(-KAPPA * t)


def t_floor_of(P, n=N, min_survivors=100.0):
    return float(T[np.flatnonzero(n * P >= min_survivors)[-1]])


def test_smoothing_width():
    """w = max(2π, 1/κ), capped; 2π when κ ≤ 0."""
    assert _smoothing_width(0.1, 2 * math.pi, 100.0) == 10.0
    assert _smoothing_width(1.0, 2 * math.pi, 100.0) == 2 * math.pi
    assert _smoothing_width(0.0, 2 * math.pi, 100.0) == 2 * math.pi
    assert _smoothing_width(0.01, 2 * math.pi, 30.0) == 30.0


def test_pilot_rate_of_an_exact_exponential():
    """Between P = 0.1 and P = 10^{−3} the log-slope of e^{−κt} is κ (to rounding)."""
    P = exact(T)
    t_a, t_b, k = _pilot_rate(T, P, N, t_floor_of(P), 100.0, 0.1, 2.0)
    assert k == pytest.approx(KAPPA, rel=1e-10)
    assert t_a == pytest.approx(math.log(10) / KAPPA, abs=0.011)  # first grid time with P ≤ 0.1
    assert t_b == pytest.approx(math.log(1000) / KAPPA, abs=0.011)  # first with P ≤ max(floor, 10^{−3})


def test_plateau_level_skips_the_fast_start():
    """With a fast component (30 %, rate 1.5) the plateau's band (level ± 10 %) holds κ, and its run starts after
    the fast decay; the level itself is only a start, refined by the iteration."""
    P = exact(T, fast_weight=0.3)
    w = _smoothing_width(KAPPA, 2 * math.pi, 1e9)
    kappa_ref, (start, end) = _plateau_level(T, P, N, w, t_floor_of(P), 0.5, 0.1, 3.0, 200)
    assert abs(kappa_ref - KAPPA) <= 0.1 * kappa_ref
    assert start > 2.0 and end > 50.0


def test_overlapping_run_prefers_overlap_then_length_then_earlier():
    c = np.arange(20.0)
    runs = [(0, 3), (5, 9), (12, 14), (16, 18)]
    assert _overlapping_run(c, runs, (6.0, 8.0)) == (5, 9)
    assert _overlapping_run(c, runs, (8.5, 13.0)) == (12, 14)  # overlap 1.0 vs 0.5
    assert _overlapping_run(c, runs, (30.0, 40.0)) == (5, 9)  # no overlap: the longest
    assert _overlapping_run(c, [(0, 2), (4, 6)], (30.0, 40.0)) == (0, 2)  # equal length: the earlier


def test_fitting_windows():
    assert _fitting_windows(2.0, 10.0) == ((2.0, 10.0), (2.0, 6.0), (6.0, 10.0), (4.0, 8.0))
    with pytest.raises(ValueError, match="degenerate"):
        _fitting_windows(5.0, 5.0)


def test_iteration_converges_to_the_rate_from_a_nearby_level():
    """Started 7 % off (inside the 10 % band), the iteration settles on κ and the whole range."""
    P = exact(T)
    tf = t_floor_of(P)
    w = _smoothing_width(0.16, 2 * math.pi, 1e9)
    tau0, t_stop, k, w_end, (c, s, se), converged = _iterate_plateau(
        T, P, N, tf, w, 0.16, (0.0, tf), (0.0, tf), 0.1, 3.0, 2 * math.pi, 1e9, 20
    )
    assert converged and tau0 == 0.0 and t_stop == tf
    assert k == pytest.approx(KAPPA, rel=2e-3) and w_end == pytest.approx(1 / k)
    assert c.shape == s.shape == se.shape


def test_exact_exponential_window_is_the_whole_range():
    P = exact(T)
    wc = choose_windows(T, P, n_total=N)
    assert wc.converged and wc.tau0 == 0.0 and wc.t_stop == t_floor_of(P)
    assert wc.kappa_ref == pytest.approx(KAPPA, rel=2e-3)


def test_sampled_curve_window_has_the_local_rate_kappa():
    """Lifetimes drawn from P(t) = 0.3 e^{−1.5t} + 0.7 e^{−κt}: on the chosen window the log-slope of the
    Kaplan–Meier curve is κ (within 3 %), and τ0 lies after the fast component has died out
    (0.3 e^{−1.5t} < 1 % of 0.7 e^{−κt} from t ≈ 2.8) but well before the floor."""
    rng = np.random.default_rng(5)
    n = 200_000
    fast = rng.random(n) < 0.3
    life = np.where(fast, rng.exponential(1 / 1.5, n), rng.exponential(1 / KAPPA, n))
    c = survival_curve(life, np.ones(n, bool), np.linspace(0, 80, 4001))
    wc = choose_windows(c.t, c.P, c.P_err)
    assert 2.0 < wc.tau0 < 15.0 and wc.t_stop > 40.0
    P_at = np.interp([wc.tau0, wc.t_stop], c.t, c.P)
    local_rate = math.log(P_at[0] / P_at[1]) / (wc.t_stop - wc.tau0)
    assert local_rate == pytest.approx(KAPPA, rel=0.03)
    assert wc.kappa_ref == pytest.approx(KAPPA, rel=0.03)
    # a pure exponential has no irregular regime: the window starts at t = 0
    pure = survival_curve(rng.exponential(1 / KAPPA, n), np.ones(n, bool), np.linspace(0, 80, 4001))
    assert choose_windows(pure.t, pure.P, pure.P_err).tau0 == 0.0


def test_no_plateau_warns_and_returns_the_pilot_range():
    """A curve whose local rate never stays within a 1 % band: the warning, and the pilot range as the window."""
    t = np.linspace(0, 100, 1001)
    P = np.minimum.accumulate(np.exp(-0.05 * t - 0.3 * np.sin(0.2 * t) ** 2))
    with pytest.warns(UserWarning, match="no exponential plateau"):
        wc = choose_windows(t, P, n_total=50_000, rel_tol=0.01, n_sigma=0.5)
    t_floor = float(t[np.flatnonzero(50_000 * P >= 100)[-1]])
    t_a, t_b, _ = _pilot_rate(t, P, 50_000, t_floor, 100.0, 0.1, 2.0)
    assert (wc.tau0, wc.t_stop) == (t_a, t_b) and not wc.converged
