"""decay_exponent: μ of ⟨E⟩(t) with its bootstrap error, against closed forms."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.dissipative.decay import decay_exponent


def _orbits(mus, gamma=0.01, E0=0.3, t_max=200.0, dt=5.0) -> pd.DataFrame:
    t = np.arange(0.0, t_max + dt / 2, dt)
    return pd.DataFrame(
        {
            "traj_id": np.repeat(np.arange(len(mus)), len(t)),
            "t": np.tile(t, len(mus)),
            "energy": np.concatenate([E0 * np.exp(-mu * gamma * t) for mu in mus]),
        }
    )


def test_identical_orbits_give_their_exponent_and_no_spread():
    rows = _orbits([0.85] * 4)
    d = decay_exponent([rows[rows.traj_id < 2], rows[rows.traj_id >= 2]], rows, 4, 4, 0.3, 0.01, 1 / 6, (0, 200))
    assert d.mu == pytest.approx(0.85, rel=1e-12)
    assert d.mu_err == pytest.approx(0.0, abs=1e-12)
    # E ≤ 1/6 from t ≥ ln(1.8)/(0.85·0.01) = 69.15: the grid times 70 … 200, 27 of them, per orbit
    assert d.rows_below_ec == 4 * 27
    assert d.window == (0, 200)


def test_the_exponent_is_the_fixed_intercept_log_fit_of_the_mean_energy():
    gamma, E0, window = 0.01, 0.3, (0.0, 100.0)
    rows = _orbits([0.6, 1.0, 0.8, 1.2], gamma=gamma, E0=E0)
    d = decay_exponent([rows], rows, 4, 4, E0, gamma, 1 / 6, window, n_boot=50, seed=3)
    # the least-squares slope through the origin of ln(⟨E⟩/E0) against −γt on the window, written out
    t = np.arange(0.0, 100.1, 5.0)
    mean = np.mean([E0 * np.exp(-mu * gamma * t) for mu in (0.6, 1.0, 0.8, 1.2)], axis=0)
    x, y = -gamma * t, np.log(mean / E0)
    assert d.mu == pytest.approx(np.sum(x * y) / np.sum(x * x), rel=1e-10)
    assert d.mu_err > 0  # four different orbits: replicates differ


def test_errors_of_the_first_k_orbits_are_scaled_to_all_of_them():
    rows = _orbits([0.6, 1.0, 0.8, 1.2])
    a = decay_exponent([rows], rows, 4, 4, 0.3, 0.01, 1 / 6, (0, 100), n_boot=40, seed=5)
    b = decay_exponent([rows], rows, 16, 4, 0.3, 0.01, 1 / 6, (0, 100), n_boot=40, seed=5)
    assert b.mu_err == pytest.approx(a.mu_err * np.sqrt(4 / 16), rel=1e-12)
    with pytest.raises(ValueError, match="k must be in"):
        decay_exponent([rows], rows, 4, 5, 0.3, 0.01, 1 / 6, (0, 100))


def test_orbit_decay_exponent_is_the_time_weighted_mean_of_the_orbits_own_exponents():
    """Two orbits with their own μ (0.6 over t = 10, 1.2 over t = 30): the time-weighted mean (0.6·10 + 1.2·30)/40
    = 1.05, not the plain mean 0.9; the bootstrap error is the spread of that ratio over resampled orbits."""
    from hhscatter.analysis.dissipative.decay import orbit_decay_exponent

    g, t = 0.02, np.array([10.0, 30.0])
    e_end = 0.25 * np.exp(-np.array([0.6, 1.2]) * g * t)
    r = orbit_decay_exponent([0.25, 0.25], e_end, t, g, n_boot=400, seed=3)
    assert r.mu == pytest.approx(1.05, rel=1e-12) and r.n_orbits == 2
    # resamples: both orbit 0 (0.6), both orbit 1 (1.2), or one of each (1.05): an error between 0.1 and 0.4
    assert 0.1 < r.mu_err < 0.4
    assert r.measured("mu").value == r.mu


@pytest.mark.parametrize(
    ("args", "name"),
    [
        (([0.3], [0.0], [1.0], 0.01), "e_end"),
        (([0.3], [0.2], [1.0, 2.0], 0.01), "one value per orbit"),
        (([0.3], [0.2], [1.0], 0.0), "gamma"),
        (([], [], [], 0.01), "e0"),
        ((["a"], [0.2], [1.0], 0.01), "e0"),
    ],
)
def test_orbit_decay_exponent_refuses_bad_input(args, name):
    from hhscatter.analysis.dissipative.decay import orbit_decay_exponent
    from hhscatter.errors import ConfigError

    with pytest.raises(ConfigError, match=name):
        orbit_decay_exponent(*args)
