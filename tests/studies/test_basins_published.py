"""The basin estimators against maps with published or closed-form values.

* Newton's method for z³ = 1 on [−1, 1]²: three Wada basins (the Julia set is
  the common boundary of all three), boundary dimension ≈ 1.42 (box-counting
  and uncertainty dimension; e.g. Daza et al., Sci. Rep. 6, 31416 (2016)
  and references there), S_bb > ln 2 (ibid.).
* Newton's method for z² = 1: a straight boundary (the imaginary axis), two
  basins: d = 1 (α = 1), S_bb ≤ ln 2 (the log 2 criterion cannot fire).
* The open triadic map x → 3x mod 1 with the hole [1/3, 2/3) split into two
  exits at 1/2: boundary = the middle-thirds Cantor set, dimension
  D = ln 2/ln 3, so α = 1 − ln 2/ln 3 = 0.369, and nearby points separate at
  the rate λ = ln 3 per step (the decision time grows as ln(1/ε)/ln 3).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.geometry import basins as B
from hhscatter.analysis.geometry import cutoff as C
from hhscatter.analysis.geometry import uncertainty as U

ROOTS3 = np.exp(2j * np.pi * np.arange(3) / 3)


def newton3(z, iterations=40):
    """Index of the root of z³ = 1 that Newton's method reaches from z."""
    z = np.asarray(z, dtype=complex)
    for _ in range(iterations):
        z = z - (z**3 - 1) / (3 * z**2)
    return np.argmin(np.abs(z[..., None] - ROOTS3), axis=-1)


def newton2(z, iterations=40):
    z = np.asarray(z, dtype=complex)
    for _ in range(iterations):
        z = z - (z**2 - 1) / (2 * z)
    return (z.real > 0).astype(int)


def grid(n):
    x = -1 + (np.arange(n) + 0.5) * 2 / n
    return x[None, :] + 1j * x[:, None]


@pytest.fixture(scope="module")
def newton_map():
    return newton3(grid(512))


def uncertainty_counts(outcome, eps, n, seed):
    """Uncertain counts of ``outcome`` on fresh uniform points of [−1, 1]² (complex) shifted by ε along x."""
    rng = np.random.default_rng(seed)
    k = []
    for e in eps:
        x = rng.uniform(-1, 1, n) + 1j * rng.uniform(-1, 1, n)
        k.append(int(np.count_nonzero(outcome(x) != outcome(x + e))))
    return np.array(k)


def test_newton_z3_box_counting_dimension_is_published_value(newton_map):
    bc = B.box_counting_dimension(newton_map, (8, 16, 32, 64))
    assert abs(bc.D - 1.42) < 0.06, bc  # measured 1.39 ± 0.03 on 512²
    # the straight boundary of z² = 1 has dimension 1
    assert abs(B.box_counting_dimension(newton2(grid(128) + 2 / 128), (2, 4, 8, 16)).D - 1.0) < 0.02


def test_newton_z3_uncertainty_dimension_and_local_exponent():
    eps = np.logspace(-1, -7, 7)
    n = 20000
    k = uncertainty_counts(newton3, eps, n, seed=1)
    fit = U.uncertainty_exponent(eps, k / n, n)
    assert abs(fit.d - 1.42) < 3 * fit.d_err + 0.01, fit  # measured d = 1.435 ± 0.008
    loc = U.local_exponent(eps, k, n)
    ok = np.isfinite(loc.d)
    # one power law: every local dimension within 3σ of the published value, no slim fractal
    assert np.all(np.abs(loc.d[ok] - 1.42) < 3 * loc.d_err[ok] + 0.01), loc
    assert not U.slim_fractal(loc)["slim"]


def test_newton_z2_smooth_boundary_has_alpha_one():
    eps = np.logspace(-1, -5, 5)
    n = 20000
    fit = U.uncertainty_exponent(eps, uncertainty_counts(newton2, eps, n, seed=2) / n, n)
    assert abs(fit.alpha - 1.0) < 3 * fit.alpha_err, fit
    assert B.basin_entropy(newton2(grid(200) + 0.02), 5).S_bb <= math.log(2) + 1e-12


def test_newton_z3_is_wada_with_sbb_above_log2(newton_map):
    assert B.wada_merging(newton_map).wada
    ent = B.basin_entropy(newton_map, 5)
    assert ent.log2_fractal and ent.S_bb > math.log(2), ent  # measured 0.715 ± 0.009 (box 5, 512²)


def triadic(x, iterations=45):
    """Outcome (0: exit [1/3, 1/2), 1: exit [1/2, 2/3), −1: none) and exit step of x → 3x mod 1."""
    x = np.array(x, dtype=float)
    out = np.full(x.shape, -1)
    t = np.full(x.shape, np.nan)
    for i in range(iterations):
        live = out < 0
        a = live & (x >= 1 / 3) & (x < 0.5)
        b = live & (x >= 0.5) & (x < 2 / 3)
        out[a], out[b] = 0, 1
        t[a | b] = i
        x = np.where(x < 1 / 3, 3 * x, 3 * x - 2)
    return out, t


def test_open_triadic_map_cantor_exponent_and_lyapunov_rate():
    eps = np.logspace(-3, -9, 7)
    n = 40000
    rng = np.random.default_rng(3)
    k, times = [], []
    for e in eps:
        x = rng.uniform(0, 1 - e, n)
        (a, ta), (b, tb) = triadic(x), triadic(x + e)
        ch = a != b
        k.append(int(ch.sum()))
        times.append(np.fmin(ta, tb)[ch])
    fit = U.uncertainty_exponent(eps, np.array(k) / n, n)
    assert abs(fit.alpha - (1 - math.log(2) / math.log(3))) < 0.04, fit  # Cantor set: log-periodic wiggles
    rate = C.decision_rate(eps, times)
    assert abs(rate.lam / math.log(3) - 1) < 0.1, rate


def test_local_exponent_errors_cover_on_synthetic_binomial_data():
    """1σ intervals of α(ε) cover the true local exponent in ≈ 68 % of replicates."""
    rng = np.random.default_rng(4)
    eps = np.array([1e-2, 1e-3, 1e-4, 1e-5])
    f_true = np.array([0.05, 0.02, 0.004, 0.0005])  # a bending law: α(ε) 0.40, 0.70, 0.90
    a_true = np.log(f_true[1:] / f_true[:-1]) / np.log(eps[1:] / eps[:-1])
    hits = []
    for _ in range(400):
        k = rng.binomial(200000, f_true)
        loc = U.local_exponent(eps, k, 200000)
        hits.append(np.abs(loc.alpha.to_numpy() - a_true) <= loc.alpha_err.to_numpy())
    cover = np.mean(hits)
    assert 0.62 < cover < 0.74, cover


def test_slim_fractal_detects_a_falling_dimension():
    t = pd.DataFrame({"eps_mid": np.logspace(-1, -8, 8), "d": np.linspace(1.8, 1.1, 8), "d_err": 0.02})
    s = U.slim_fractal(t)
    assert s["slim"] and s["slope"] > 0
    assert not U.slim_fractal(t.assign(d=1.8))["slim"]


def test_predicted_cutoff_closed_form():
    # constant λ: ln(1/ε_c) = λ τ2 = λ ln(E0/E_c)/(μγ)
    lam, E0, ec, mu, g = 0.4, 0.3, 0.2, 0.9, 0.01
    pred = C.predicted_cutoff(E0, g, mu, [0.25], [lam], ec)
    assert math.log(1 / pred) == pytest.approx(lam * math.log(E0 / ec) / (mu * g), rel=1e-6)
    # λ ∝ E: ∫ λ/E dE = c (E0 − E_c)
    pred = C.predicted_cutoff(E0, g, mu, [ec, E0], [2 * ec, 2 * E0], ec)
    assert math.log(1 / pred) == pytest.approx(2 * (E0 - ec) / (mu * g), rel=1e-6)
    assert C.predicted_cutoff(E0, 0.0, mu, [0.25], [lam], ec) == 0.0
    with pytest.raises(ValueError):
        C.predicted_cutoff(0.1, g, mu, [0.25], [lam], ec)
