"""μ predicted from the mean kinetic energy (hhscatter.analysis.dissipative.kinetic): closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from hhscatter.analysis.dissipative.kinetic import (
    decay_path,
    kinetic_fraction_from_energies,
    microcanonical_kinetic_fraction,
)


@pytest.mark.parametrize("k", [2, 4, 6])
def test_microcanonical_fraction_is_the_virial_value_for_homogeneous_wells(k):
    """V = r^k/k: 2⟨K⟩ = k⟨V⟩ (virial) so 2⟨K⟩/E = 2k/(k + 2): 1 for the harmonic well, 4/3 for r⁴."""
    f = microcanonical_kinetic_fraction(lambda x, y: (x * x + y * y) ** (k / 2) / k, 0.3, 1.5, n_grid=1201)
    assert f == pytest.approx(2 * k / (k + 2), abs=2e-3)


def test_microcanonical_fraction_refuses_a_region_beyond_the_grid():
    with pytest.raises(ValueError, match="edge"):
        microcanonical_kinetic_fraction(lambda x, y: 0.5 * (x * x + y * y), 0.3, 0.5)


def test_kinetic_fraction_recovers_known_kinetic_energies_and_weights_by_time():
    """Orbits with constant K_i lose E at 2γK_i: the estimate is the time-weighted mean of 2K_i/E0."""
    rng = np.random.default_rng(1)
    g, E0 = 1e-6, 0.3
    ids, ts, es, num, den = [], [], [], 0.0, 0.0
    for i in range(200):
        K = rng.uniform(0.05, 0.25)
        life = rng.uniform(3, 40)
        t = np.arange(0.0, np.floor(life) + 1)
        ids.append(np.full(t.size, i))
        ts.append(t)
        es.append(E0 - 2 * g * K * t)
        span = min(t[-1], 30.0) - 5.0
        if span > 0:
            num += 2 * K / E0 * span
            den += span
    r = kinetic_fraction_from_energies(
        np.concatenate(ids), np.concatenate(ts), np.concatenate(es), g, 5.0, 30.0, n_boot=100, rng=2
    )
    assert r.value == pytest.approx(num / den, rel=2e-4)  # E_k vs E0 in the denominator: O(γ K t/E)
    assert 0 < r.err < 0.05


def test_kinetic_fraction_bootstrap_error_matches_the_scatter_of_independent_ensembles():
    g, E0 = 1e-6, 0.3
    vals, errs = [], []
    for s in range(30):
        rng = np.random.default_rng(100 + s)
        K = rng.uniform(0.05, 0.25, 100)
        t = np.arange(0.0, 11.0)
        ids = np.repeat(np.arange(100), t.size)
        E = E0 - 2 * g * K[ids] * np.tile(t, 100)
        r = kinetic_fraction_from_energies(ids, np.tile(t, 100), E, g, 0.0, 10.0, n_boot=200, rng=s)
        vals.append(r.value)
        errs.append(r.err)
    assert 0.7 < np.mean(errs) / np.std(vals, ddof=1) < 1.4


def test_decay_path_is_the_exponential_law_for_constant_mu_and_slower_for_smaller_mu_at_low_energy():
    t = np.linspace(0, 200, 101)
    np.testing.assert_allclose(decay_path(t, 0.3, 0.01, lambda E: 0.93 + 0 * E), 0.3 * np.exp(-0.0093 * t), rtol=1e-8)
    slow = decay_path(t, 0.3, 0.01, lambda E: np.where(E < 0.2, 0.5, 0.93))
    assert np.all(slow >= 0.3 * np.exp(-0.0093 * t) * (1 - 1e-9)) and slow[-1] > 1.2 * 0.3 * np.exp(-1.86)


def test_kinetic_fraction_by_time_is_the_decay_rate_of_a_fixed_set_of_orbits():
    """Orbits E_i = E0_i e^{−μ_i γ t}: μ_K = Σ μ_i E_i/Σ E_i (exactly, by the closed form of ΔE/Ē), and it ignores
    orbits that leave: here half of them stop at t = 10."""
    from hhscatter.analysis.dissipative.kinetic import kinetic_fraction_by_time

    g, grid = 0.01, np.arange(0.0, 21.0, 1.0)
    rng = np.random.default_rng(4)
    e0, mus = rng.uniform(0.2, 0.4, 50), rng.uniform(0.8, 1.2, 50)
    ids, ts, es = [], [], []
    for i in range(50):
        tt = grid if i % 2 else grid[grid <= 10]
        ids.append(np.full(tt.size, i))
        ts.append(tt)
        es.append(e0[i] * np.exp(-mus[i] * g * tt))
    d = kinetic_fraction_by_time(np.concatenate(ids), np.concatenate(ts), np.concatenate(es), g)
    for row in d.itertuples():
        alive = [i for i in range(50) if i % 2 or row.t_hi <= 10]
        E_lo = e0[alive] * np.exp(-mus[alive] * g * row.t_lo)
        E_hi = e0[alive] * np.exp(-mus[alive] * g * row.t_hi)
        want = np.sum(E_lo - E_hi) / (g * (row.t_hi - row.t_lo)) / np.sum(0.5 * (E_lo + E_hi))
        assert row.n == len(alive)
        assert row.mu_K == pytest.approx(want, rel=1e-12)
        assert row.mu_K == pytest.approx(np.sum(mus[alive] * E_lo) / np.sum(E_lo), rel=2e-3)


def test_binned_hazard_recovers_a_known_exponential_rate_and_observed_over_expected_covers_one():
    """Exponential escapes at rate 0.2 with competing settling at rate 0.1: the escape hazard is 0.2 in every bin
    (the competing exit only removes exposure); O/E against the true rate is 1 within its Poisson error in ≥ 90 %
    of independent ensembles (nominal 95 %)."""
    from hhscatter.analysis.survival.effective_rate import (
        binned_hazard,
        observed_over_expected,
    )

    hits = 0
    for s in range(40):
        rng = np.random.default_rng(s)
        te, ts = rng.exponential(1 / 0.2, 4000), rng.exponential(1 / 0.1, 4000)
        t_end, esc = np.minimum(te, ts), te < ts
        b = binned_hazard(t_end, esc, np.arange(0.0, 12.0, 2.0))
        r, e, _ = observed_over_expected(b, np.full(len(b), 0.2))
        hits += abs(r - 1) <= 2 * e
        if s == 0:
            np.testing.assert_allclose(b["hazard"], 0.2, rtol=0.15)
            # exposure = ∫ N(t > s) ds over the bin, counted directly
            lo, hi = 2.0, 4.0
            assert b["exposure"].iloc[1] == pytest.approx(np.clip(t_end - lo, 0, hi - lo).sum(), rel=1e-12)
    assert hits >= 36
