"""The heat-bath check against synthetic ensembles drawn from the re-activation process itself: settling at
τ ~ U(0, 10) in the drag-only ensemble, then leaving at a known thermal rate in the bath."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hhscatter.analysis.noise import reactivation_check


def _ensembles(k=0.05, n=20000, t_max=200.0, seed=4):
    rng = np.random.default_rng(seed)
    tau = rng.uniform(0.0, 10.0, n)
    esc_t = rng.uniform(0.0, 5.0, n)
    escapes = rng.random(n) < 0.3  # 30 % escape during the transient, the rest settle at tau
    t0 = np.where(escapes, esc_t, tau)
    t_bath = np.where(escapes, esc_t, tau + rng.exponential(1 / k, n))
    return t0, escapes, ~escapes, np.minimum(t_bath, t_max), t_bath < t_max


def test_the_extension_holds_when_the_bath_only_reactivates():
    t0, esc0, set0, tT, escT = _ensembles()
    c = reactivation_check(t0, esc0, set0, tT, escT, 0.05, 200.0, 20.0)
    assert c.settled_fraction == pytest.approx(set0.mean()) and c.escaped_fraction == pytest.approx(esc0.mean())
    assert c.max_deviation_sigma < 5.0
    # P_T at the grid's end: 0.7 e^{-k (200 - τ)} averaged over τ ~ U(0, 10), by hand
    expected = 0.7 * (math.exp(-0.05 * 190.0) - math.exp(-0.05 * 200.0)) / (0.05 * 10.0)
    assert c.table["model"].iloc[-1] == pytest.approx(expected, rel=0.03)
    assert abs(c.tail.rate - 0.05) < 3 * c.tail.rate_err
    assert c.t_settled_99 == pytest.approx(9.9, abs=0.05)  # 99 % quantile of U(0, 10)
    assert list(c.table.columns) == ["t", "P_T", "P_T_err", "P_0", "P_0_settled_inside", "model"]


def test_a_wrong_thermal_rate_shows_as_a_deviation():
    t0, esc0, set0, tT, escT = _ensembles()
    assert reactivation_check(t0, esc0, set0, tT, escT, 0.025, 200.0, 20.0).max_deviation_sigma > 10.0


def test_a_tail_window_before_settling_is_refused():
    t0, esc0, set0, tT, escT = _ensembles(n=200)
    with pytest.raises(ValueError, match="tail_start = 5 is before"):
        reactivation_check(t0, esc0, set0, tT, escT, 0.05, 200.0, 5.0)
