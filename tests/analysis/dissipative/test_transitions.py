"""The subsample bootstrap of the transition times (hhscatter.analysis.dissipative.transitions): its scale to the
whole ensemble, against the 1/√N law of a standard error."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.dissipative.transitions import SubsampleBootstrap, subsample_bootstrap_transition_times


def test_subsample_error_is_scaled_by_the_square_root_of_the_orbit_fraction():
    reps = pd.DataFrame({"tau0": [1.0, 2.0, 3.0, 4.0]})  # sample standard deviation √(5/3)
    b = SubsampleBootstrap(reps, 250, 1000)
    assert b.scale == 0.5 and b.err("tau0") == pytest.approx(0.5 * np.sqrt(5 / 3), rel=1e-12)


def test_subsample_bootstrap_uses_the_first_orbits_only():
    """Orbits beyond the first K settle at once: were they used, τ2,obs would be 0.5 in every replicate, not > 1."""
    rng = np.random.default_rng(4)
    n, k = 3000, 1000
    t = rng.exponential(10.0, n)
    outcome = np.where(np.arange(n) < k, "escaped", "settled")
    t_g = np.where(np.arange(n) < k, 0.8 * t, 0.5)
    outcome_g = outcome.copy()
    outcome_g[:k:10] = "settled"  # some settle among the first K, all later than 1
    t_g[:k:10] += 1.0
    lts = {
        0.0: pd.DataFrame({"t_end": t, "outcome": outcome}),
        0.01: pd.DataFrame({"t_end": t_g, "outcome": outcome_g}),
    }
    b = subsample_bootstrap_transition_times(
        lts, 0.0, np.arange(0.0, 60.0, 0.5), n_orbits=k, tau0=1.0, n_boot=30, seed=2
    )
    assert (b.n_orbits, b.n_total) == (k, n) and b.scale == pytest.approx(np.sqrt(1 / 3), rel=1e-12)
    assert len(b.replicates) == 30 and (b.replicates["tau2_obs"] > 1.0).all()
    big = subsample_bootstrap_transition_times(lts, 0.0, [0.0, 1.0], n_orbits=10**6, tau0=1.0, n_boot=2, seed=2)
    assert (big.n_orbits, big.scale) == (n, 1.0)
