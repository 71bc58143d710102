"""hhscatter.analysis.noise.survivors: the survivors' energy distribution against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hhscatter.analysis.noise import noise_energy_gain, survivor_energies


def test_two_energies_in_known_shares():
    """300 orbits at 0.1 and 100 at 0.3: mean 0.15, sd √(0.0075 · 400/399), a quarter at or above 0.2."""
    e = np.r_[np.full(300, 0.1), np.full(100, 0.3)]
    s = survivor_energies(e, 0.2)
    assert s.mean == pytest.approx(0.15, rel=1e-12)
    assert s.sd == pytest.approx(math.sqrt(0.0075 * 400 / 399), rel=1e-12)
    assert s.mean_err == pytest.approx(s.sd / 20, rel=1e-12)
    assert s.below == 0.75 and s.below_err == pytest.approx(math.sqrt(0.75 * 0.25 / 400), rel=1e-12)
    assert (s.quantiles[0.1], s.quantiles[0.5], s.quantiles[0.9]) == (0.1, 0.1, 0.3)
    assert s.measured("mean").n == 400


def test_all_below_is_a_lower_bound():
    s = survivor_energies(np.full(20, 0.1), 0.2)
    assert s.below == 1.0 and s.below_err is None and s.below_lower == pytest.approx(0.05 ** (1 / 20), rel=1e-12)


@pytest.mark.parametrize(
    "energies, threshold, match",
    [([0.1], 0.2, "at least 2"), ([0.1, math.nan], 0.2, "finite"), ([0.1, 0.2], math.inf, "threshold")],
)
def test_bad_input_is_refused(energies, threshold, match):
    with pytest.raises(ValueError, match=match):
        survivor_energies(energies, threshold)


def test_noise_energy_gain_is_sigma_squared_t():
    """dp = σ dW on two momenta: each ⟨p²⟩ grows by σ² t, ⟨(p_x² + p_y²)/2⟩ by σ² t (0.01² · 300 = 0.03)."""
    assert noise_energy_gain(0.01, 300.0) == pytest.approx(0.03, rel=1e-12)
    assert noise_energy_gain(np.array([0.0, 0.2]), 5.0) == pytest.approx([0.0, 0.2])
