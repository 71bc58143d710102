"""hhscatter.analysis.noise.turnover: the Mel'nikov–Meshkov factor against an independent quadrature and its
closed-form limits, the turnover rate against the Kramers limits written out for Hénon–Heiles."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest

from hhscatter.analysis.noise import (
    barrier_action,
    depopulation_factor,
    energy_loss_parameter,
    kramers_langer,
    turnover_rate,
)
from hhscatter.model import HenonHeiles


def _upsilon_mpmath(delta: float) -> float:
    """Υ(δ) in the form (1/π) ∫ ln(1 − e^{−δ(1 + y²)/4}) dy/(1 + y²), by mpmath's tanh-sinh quadrature."""
    d = mpmath.mpf(delta)
    f = lambda y: mpmath.log(-mpmath.expm1(-d * (1 + y * y) / 4)) / (1 + y * y)
    return float(mpmath.exp(mpmath.quad(f, [-mpmath.inf, -1, 0, 1, mpmath.inf]) / mpmath.pi))


@pytest.mark.parametrize("delta", [1e-3, 0.05, 0.3, 1.0, 3.0, 12.0])
def test_depopulation_factor_against_an_independent_quadrature(delta):
    assert float(depopulation_factor(delta)) == pytest.approx(_upsilon_mpmath(delta), rel=1e-9)


def test_depopulation_factor_limits():
    """δ → 0: Υ = δ (1 + ζ(1/2) √(δ/π) + O(δ)); δ → ∞: Υ → 1; increasing in between."""
    for d in (1e-8, 1e-6):
        u = float(depopulation_factor(d))
        assert u / d == pytest.approx(1.0, abs=2 * math.sqrt(d))
        assert (u / d - 1) / math.sqrt(d) == pytest.approx(float(mpmath.zeta(0.5)) / math.sqrt(math.pi), abs=1e-2)
    assert float(depopulation_factor(100.0)) == pytest.approx(1.0, abs=1e-10)
    grid = np.geomspace(1e-4, 30.0, 25)
    ups = depopulation_factor(grid)
    assert ups.shape == grid.shape and np.all(np.diff(ups) > 0) and np.all((ups > 0) & (ups < 1))


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf, [1.0, 0.0]])
def test_depopulation_factor_refuses_a_nonpositive_delta(bad):
    with pytest.raises(ValueError, match="delta must be finite and > 0"):
        depopulation_factor(bad)


def test_energy_loss_parameter_refuses_bad_arguments():
    assert energy_loss_parameter(0.2, 1.5, 0.5) == pytest.approx(0.6, rel=1e-12)
    for args, name in (((0.0, 1.0, 1.0), "gamma"), ((1.0, -1.0, 1.0), "action"), ((1.0, 1.0, math.nan), "temperature")):
        with pytest.raises(ValueError, match=name):
            energy_loss_parameter(*args)


@pytest.mark.parametrize("gamma", [1e-3, 0.03, 1.0])
def test_turnover_rate_of_henon_heiles_written_out(gamma):
    """Three saddles, ω_b = 1, det ratio 1/3, ΔE = 1/6: k_TST = 3 (1/2π)(1/√3) e^{−ΔE/T}, k_KL = λ₊ k_TST,
    δ = γ S/T, k_MM = Υ(δ) k_KL, k_ED = δ k_TST."""
    T, S = 1 / 18, 0.7
    tst = 3 / (2 * math.pi) / math.sqrt(3) * math.exp(-3.0)
    lam = -gamma / 2 + math.sqrt(gamma**2 / 4 + 1)
    d = gamma * S / T
    tr = turnover_rate(kramers_langer(HenonHeiles(), gamma, T), S)
    assert tr.transition_state == pytest.approx(tst, rel=1e-6)
    assert tr.spatial_diffusion == pytest.approx(lam * tst, rel=1e-6)
    assert tr.energy_diffusion == pytest.approx(d * tst, rel=1e-6)
    assert tr.rate == pytest.approx(_upsilon_mpmath(d) * lam * tst, rel=1e-6)
    assert tr.delta == pytest.approx((d,) * 3, rel=1e-12) and tr.gamma_over_omega_b == pytest.approx(gamma, rel=1e-6)
    # the rate lies below both Kramers limits
    assert tr.rate < min(tr.energy_diffusion, tr.spatial_diffusion)


def test_turnover_rate_takes_one_action_per_saddle():
    kl = kramers_langer(HenonHeiles(), 0.1, 1 / 18)
    one = turnover_rate(kl, [0.7, 0.7, 0.7])
    assert one.rate == pytest.approx(turnover_rate(kl, 0.7).rate, rel=1e-12)
    mixed = turnover_rate(kl, [0.7, 0.7, 7.0])
    assert mixed.upsilon[2] > mixed.upsilon[0] and mixed.rate > one.rate
    with pytest.raises(ValueError):
        turnover_rate(kl, [0.7, 0.7])


@pytest.mark.parametrize("omega, lam", [(1.0, 1.0), (1.3, 0.7)])
def test_barrier_action_of_henon_heiles_against_its_closed_form(omega, lam):
    """Along x = 0, V = ω² y²/2 − λ y³/3: with y = (ω²/λ) z, E_s − V = (ω⁶/λ²)(1 − z)²(z + 1/2)/3 and
    S = 2 ∫ √(2(E_s − V)) dy = (ω⁵/λ²) · 2√(2/3) ∫_{−1/2}^{1} (1 − z)√(z + 1/2) dz = (6/5) ω⁵/λ²."""
    m = HenonHeiles(omega, lam)
    for k in range(3):  # the three saddles are images of each other under the 120° rotation
        assert barrier_action(m, k) == pytest.approx(1.2 * omega**5 / lam**2, rel=1e-9)
    with pytest.raises(ValueError, match="exit must be a channel index"):
        barrier_action(m, 3)
