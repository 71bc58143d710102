"""Coverage of the error bars (issue 13, item 4): on synthetic ensembles with a known answer, about 68 % of the
1σ intervals must cover the truth, within the exact binomial band at 3σ over ≥ 200 replicates."""
from __future__ import annotations

import math

import numpy as np
from scipy import stats

from hhscatter.analysis.cmeasure import kappa_from_cmeasure

ONE_SIGMA = math.erf(1 / math.sqrt(2))  # 0.6827: the chance that a 1σ interval covers the truth
P_3SIGMA = 2 * stats.norm.sf(3.0)       # 0.0027


def _covers_as_1sigma(hits) -> bool:
    """Whether the number of covering intervals agrees with 68.27 % (exact binomial test at 3σ)."""
    hits = np.asarray(hits, bool)
    return stats.binomtest(int(hits.sum()), hits.size, ONE_SIGMA).pvalue > P_3SIGMA


def test_the_binomial_band_refuses_a_wrong_coverage():
    assert _covers_as_1sigma([True] * 137 + [False] * 63)        # 68.5 %
    assert not _covers_as_1sigma([True] * 100 + [False] * 100)   # 50 %
    assert not _covers_as_1sigma([True] * 180 + [False] * 20)    # 90 %


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
    truth = (1.0 - q ** (1.0 / k)) / theta  # the Lotka root (tests/test_analysis_survival.py checks the closed form)
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
