"""Direct tests of the steps of fit_energy_decay: the window chooser and the two fits (synthetic, known answers)."""

import math

import numpy as np
import pytest

from hhscatter.analysis.dissipative import decay

E0, GAMMA = 0.3, 0.01


def test_window_keeps_only_usable_points_inside_the_inclusive_window():
    t = np.arange(0.0, 10.0)
    m = np.exp(-t)
    m[2], m[3], m[4] = np.nan, 0.0, -1.0
    w = np.ones(10)
    w[5], w[6] = 0.0, np.inf
    tw, y, ww, win = decay._decay_window(t, m, E0, GAMMA, (1, 8), w)
    np.testing.assert_array_equal(tw, [1.0, 7.0, 8.0])  # 0 and 9 outside; 2–4 bad ⟨E⟩; 5–6 bad weights
    np.testing.assert_array_equal(y, -tw)  # log⟨E⟩ exactly
    np.testing.assert_array_equal(ww, [1.0, 1.0, 1.0])
    assert win == (1.0, 8.0) and isinstance(win[0], float)
    # weights None: unit weights
    _, _, w1, _ = decay._decay_window(t, np.ones(10), E0, GAMMA, (0, 9), None)
    np.testing.assert_array_equal(w1, np.ones(10))


@pytest.mark.parametrize("args, key", [((0.3, 0.0), "gamma"), ((-0.1, 0.01), "E0")])
def test_window_rejects_bad_constants(args, key):
    with pytest.raises(ValueError, match=key):
        decay._decay_window(np.arange(3.0), np.ones(3), *args, (0, 2), None)


def test_window_rejects_mismatched_lengths():
    with pytest.raises(ValueError, match="weights must have one value per time t"):
        decay._decay_window(np.arange(3.0), np.ones(3), E0, GAMMA, (0, 2), np.ones(2))


def test_fixed_intercept_recovers_exact_slope_and_nan_without_points():
    t = np.arange(0.0, 51.0)
    y = np.log(E0) - 0.8 * GAMMA * t
    mu, err, rms = decay._fit_fixed_intercept(t, y, np.ones_like(t), E0, GAMMA, "scaled")
    assert mu == pytest.approx(0.8, rel=1e-12) and err < 1e-10 and rms < 1e-12
    # only t = 0: the slope is not determined
    assert all(
        math.isnan(v) for v in decay._fit_fixed_intercept(np.zeros(1), np.zeros(1), np.ones(1), E0, GAMMA, "scaled")
    )


def test_free_intercept_recovers_slope_and_intercept_and_nan_with_one_time():
    t = np.arange(10.0, 61.0)
    y = -1.7 - 1.2 * GAMMA * t  # anchored elsewhere than E0: only the free fit sees it
    mu, mu_err, a, a_err, rms = decay._fit_free_intercept(t, y, np.ones_like(t), GAMMA, "scaled")
    assert mu == pytest.approx(1.2, rel=1e-10) and a == pytest.approx(-1.7, rel=1e-10)
    assert mu_err < 1e-8 and a_err < 1e-8 and rms < 1e-10
    out = decay._fit_free_intercept(np.full(3, 5.0), np.zeros(3), np.ones(3), GAMMA, "scaled")
    assert all(math.isnan(v) for v in out)


def test_absolute_errors_use_the_weights_as_variances():
    """With absolute errors the slope's σ is 1/sqrt(Σ w t²)/γ whatever the residuals (exact identity)."""
    t = np.arange(1.0, 21.0)
    rng = np.random.default_rng(5)
    y = np.log(E0) - GAMMA * t + 0.05 * rng.standard_normal(t.size)
    w = np.full(t.size, 4.0)
    _, err, _ = decay._fit_fixed_intercept(t, y, w, E0, GAMMA, "absolute")
    assert err == pytest.approx(1 / np.sqrt(np.sum(w * t * t)) / GAMMA, rel=1e-12)
