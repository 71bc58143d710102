"""hhscatter.analysis.noise: the Kramers–Langer rate against closed forms, the thermal-rate estimator and the
re-activation extension against synthetic samples drawn from their own assumptions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hhscatter.analysis.noise import (
    ThermalRate,
    exit_fractions,
    hessian,
    kramers_langer,
    reactivation_survival,
    thermal_rate,
    well_barrier,
    window_constancy,
)
from hhscatter.model import HenonHeiles


@pytest.mark.parametrize("omega, lam", [(1.0, 1.0), (1.3, 0.7)])
@pytest.mark.parametrize("gamma", [0.05, 1.0, 8.0])
def test_kramers_langer_of_henon_heiles_against_its_closed_form(omega, lam, gamma):
    """Hénon–Heiles(ω, λ): minimum Hessian ω² I, three saddles at distance ω²/λ with eigenvalues 3ω², −ω²
    (det −3ω⁴, ω_b = ω), barrier E_c = ω⁶/(6λ²): k = 3 (λ₊/2π)(1/√3) e^{−E_c/T}, λ₊ = −γ/2 + √(γ²/4 + ω²)."""
    T = 0.02 * omega**6 / lam**2
    kl = kramers_langer(HenonHeiles(omega, lam), gamma, T)
    lam_plus = -gamma / 2 + math.sqrt(gamma**2 / 4 + omega**2)
    e_c = omega**6 / (6 * lam**2)
    assert kl.rate == pytest.approx(3 * lam_plus / (2 * math.pi) / math.sqrt(3) * math.exp(-e_c / T), rel=1e-6)
    assert kl.barrier_over_T == pytest.approx(e_c / T, rel=1e-12)
    assert [t.omega_b for t in kl.terms] == pytest.approx([omega] * 3, rel=1e-6)


def test_kramers_langer_limits():
    """γ → 0: the transition-state rate (λ₊ → ω_b); γ → ∞: Smoluchowski, λ₊ → ω_b²/γ."""
    m = HenonHeiles()
    tst = 3 / (2 * math.pi) / math.sqrt(3) * math.exp(-5.0)
    assert kramers_langer(m, 1e-9, 1 / 30).rate == pytest.approx(tst, rel=1e-6)
    assert kramers_langer(m, 1e4, 1 / 30).rate * 1e4 == pytest.approx(tst, rel=1e-6)
    with pytest.raises(ValueError, match="gamma must be > 0"):
        kramers_langer(m, 0.0, 0.1)


def test_hessian_of_a_quadratic_form_is_exact():
    class Quadratic:
        def potential(self, x, y):
            return 0.5 * (2.0 * x * x + 2 * 0.3 * x * y - 0.5 * y * y)

    np.testing.assert_allclose(hessian(Quadratic(), 0.4, -0.2), [[2.0, 0.3], [0.3, -0.5]], rtol=1e-7)


def test_thermal_rate_recovers_a_constant_hazard_with_truncation_and_censoring():
    rng = np.random.default_rng(3)
    k, n = 0.004, 40000
    t = rng.exponential(1 / k, n)
    t_cens = rng.uniform(100.0, 600.0, n)  # each orbit censored at its own time
    t_end = np.minimum(t, t_cens)
    r = thermal_rate(t_end, t <= t_cens, 50.0, 500.0)
    assert abs(r.rate - k) < 3 * r.rate_err and r.rate_err / r.rate < 0.03
    (a, ea), (b, eb) = r.halves
    assert abs(a - k) < 3 * ea and abs(b - k) < 3 * eb
    # a hazard that doubles half way shows in the halves
    t2 = np.where(t < 275.0, t, 275.0 + (t - 275.0) / 2)
    (a, ea), (b, eb) = thermal_rate(np.minimum(t2, 500.0), t2 < 500.0, 50.0, 500.0).halves
    assert b - a > 5 * math.hypot(ea, eb)


def test_reactivation_survival_against_the_process_it_assumes():
    """Draw the assumed process: escapers leave at their drag-only time, settled orbits wait an exponential
    time of rate k after settling. Its empirical survival matches the formula."""
    rng = np.random.default_rng(5)
    n, k = 200000, 0.02
    settled = rng.random(n) < 0.7
    t0 = np.where(settled, rng.uniform(5.0, 30.0, n), rng.exponential(8.0, n))
    t_leave = np.where(settled, t0 + rng.exponential(1 / k, n), t0)
    grid = np.array([0.0, 3.0, 10.0, 25.0, 60.0, 150.0])
    empirical = (t_leave[None, :] > grid[:, None]).mean(axis=1)
    model = reactivation_survival(grid, t0, ~settled, settled, k)
    np.testing.assert_allclose(model, empirical, atol=4 * math.sqrt(0.25 / n))
    with pytest.raises(ValueError, match="beyond the earliest censoring"):
        reactivation_survival([50.0], [10.0, 40.0], [True, False], [False, False], k)


def test_a_window_without_escapes_is_an_upper_bound_not_a_rate_of_zero():
    """No escape in [50, 300] among 1000 orbits still inside: the rate is NaN, the bound −ln(0.05)/exposure."""
    t_end = np.concatenate([np.full(1000, 400.0), [10.0, 20.0]])
    escaped = np.concatenate([np.zeros(1000, bool), [True, True]])
    r = thermal_rate(t_end, escaped, 50.0, 300.0)
    assert r.is_bound and r.n_events == 0 and math.isnan(r.rate) and math.isnan(r.rate_err)
    assert r.exposure == 1000 * 250.0
    assert r.upper95 == pytest.approx(-math.log(0.05) / 250000.0, rel=1e-12)
    assert all(math.isnan(k) for k, _ in r.halves)
    with_escapes = thermal_rate(np.array([60.0, 400.0]), np.array([True, False]), 50.0, 300.0)
    assert not with_escapes.is_bound and math.isnan(with_escapes.upper95)
    assert with_escapes.rate == pytest.approx(1 / 260.0)


@pytest.mark.parametrize("lam", [1.0, 1e-4, 1e-5])
def test_kramers_langer_of_a_rescaled_henon_heiles_is_scale_invariant(lam):
    """λ rescales lengths by 1/λ and energies by 1/λ²; at ΔE/T = 6 the rate is the λ = 1 closed form
    3 (λ₊/2π)(1/√3) e^{−6} (a fixed difference step was 6 % high at λ = 1e-4, no saddle at λ = 1e-5)."""
    m = HenonHeiles(1.0, lam)
    kl = kramers_langer(m, 1.0, m.critical_energy / 6)
    assert kl.rate == pytest.approx(3 * (math.sqrt(5) - 1) / 2 / (2 * math.pi) / math.sqrt(3) * math.exp(-6), rel=1e-9)
    np.testing.assert_allclose(hessian(m, 0.0, 1 / lam), [[3.0, 0.0], [0.0, -1.0]], rtol=1e-12, atol=1e-12)
    c, s = math.cos(math.radians(210)), math.sin(math.radians(210))  # the saddle at angle 210°
    np.testing.assert_allclose(
        hessian(m, c / lam, s / lam), [[1 + 2 * s, 2 * c], [2 * c, 1 - 2 * s]], rtol=1e-12, atol=1e-12
    )


@pytest.mark.parametrize("eps", [0.5, 1e-4])
def test_kramers_langer_of_barbanis_against_its_closed_form(eps):
    """V = (x² + y²)/2 − εxy²: saddles (1/(2ε), ±1/(√2 ε)) with Hessian [[1, ∓√2], [∓√2, 0]] (eigenvalues 2, −1,
    det −2), minimum Hessian I, barrier 1/(8ε²): k = 2 (λ₊/2π) √(1/2) e^{−ΔE/T}, λ₊ = −γ/2 + √(γ²/4 + 1)."""
    from hhscatter.model.builtins import barbanis

    m = barbanis(eps)
    gamma, T = 0.3, 1 / (8 * eps**2) / 5
    kl = kramers_langer(m, gamma, T)
    lam_plus = -gamma / 2 + math.sqrt(gamma**2 / 4 + 1)
    assert kl.rate == pytest.approx(2 * lam_plus / (2 * math.pi) * math.sqrt(0.5) * math.exp(-5.0), rel=1e-9)
    np.testing.assert_allclose(
        hessian(m, 1 / (2 * eps), 1 / (math.sqrt(2) * eps)), [[1.0, -math.sqrt(2)], [-math.sqrt(2), 0.0]], atol=1e-9
    )


def test_difference_hessian_of_a_function_scales_its_step_with_the_point():
    """A potential given as a function only: the step follows the length scale (a quartic far out)."""

    class Quartic:
        def potential(self, x, y):
            return 1e-20 * x**4 + y * y

    # V_xx = 12e-20 x² = 12 at x = 1e10; a fixed step of 1e-4 there is lost in rounding
    np.testing.assert_allclose(hessian(Quartic(), 1e10, 0.0), [[12.0, 0.0], [0.0, 2.0]], rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("omega, lam", [(1.0, 1.0), (1.3, 0.7)])
def test_well_barrier_of_henon_heiles_is_its_closed_form(omega, lam):
    """Hénon–Heiles(ω, λ): E_c = ω⁶/(6λ²) above V(0, 0) = 0."""
    assert well_barrier(HenonHeiles(omega, lam)) == pytest.approx(omega**6 / (6 * lam**2), rel=1e-12)


def test_window_constancy_compares_the_halves_in_combined_sigma():
    """Halves 0.02 ± 0.003 and 0.028 ± 0.004: z = 0.008/0.005 = 1.6; constant within 2σ, not within 1.5σ; a half
    without an escape (NaN error) gives no z and is never constant."""
    r = ThermalRate(0.024, 0.0025, 80, 3300.0, 10.0, 110.0, ((0.02, 0.003), (0.028, 0.004)))
    c = window_constancy(r, 2.0)
    assert c.z == pytest.approx(1.6, rel=1e-12) and c.constant
    assert (c.first.value, c.first.err, c.second.value, c.second.err) == (0.02, 0.003, 0.028, 0.004)
    assert not window_constancy(r, 1.5).constant
    empty = ThermalRate(0.01, 0.005, 4, 400.0, 10.0, 110.0, ((0.02, 0.01), (math.nan, math.nan)))
    e = window_constancy(empty, 3.0)
    assert math.isnan(e.z) and not e.constant


def test_exit_fractions_count_the_escapes_inside_the_window_by_exit():
    """Escapes in (20, 80]: exits 0, 0, 1, 0 (the escape at t = 20 and the one at t = 90 lie outside, the censored
    orbit does not count): shares 3/4 ± √(3/4 · 1/4 / 4) and 1/4, none through exit 2 (bound 1 − 0.05^(1/4))."""
    t = np.array([20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 90.0])
    esc = np.array([True, True, True, True, True, False, True])
    ch = np.array([1, 0, 0, 1, 0, 2, 2])
    f = exit_fractions(t, esc, ch, 20.0, 80.0, 3)
    assert [x.value for x in f] == [0.75, 0.25, 0.0]
    assert f[0].err == pytest.approx(math.sqrt(0.75 * 0.25 / 4), rel=1e-12)
    assert f[2].err is None and f[2].upper == pytest.approx(1 - 0.05**0.25, rel=1e-12)
    none = exit_fractions(t, np.zeros(7, bool), ch, 20.0, 80.0, 2)
    assert [x.value for x in none] == [0.0, 0.0] and none[0].upper == pytest.approx(0.95, rel=1e-12)
