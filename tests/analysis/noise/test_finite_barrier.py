"""hhscatter.analysis.noise.finite_barrier: the weighted fit against the closed-form least-squares solution, and the
transition-state correction against hand-derived Laplace coefficients and a direct quadrature of the well."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from hhscatter.analysis.noise import finite_barrier_fit, laplace_coefficient, transition_state_correction
from hhscatter.model import HenonHeiles, make_system

QUARTIC = "x**2/2 + y**2/2 - x**4/4 - y**4/4"


def test_the_fit_is_the_closed_form_weighted_line():
    """Unequal weights: slope = (S Sxy − Sx Sy)/Δ with Δ = S Sxx − Sx², σ_c² = S/Δ; the intercept-1 slope is
    Σw x (y − 1)/Σw x² with σ² = 1/Σw x²."""
    b = np.array([3.0, 4.0, 5.0, 6.0, 8.0])
    y = np.array([0.93, 0.95, 0.94, 0.97, 0.96])
    e = np.array([0.010, 0.012, 0.015, 0.011, 0.02])
    x, w = 1 / b, 1 / e**2
    S, Sx, Sy, Sxx, Sxy = w.sum(), (w * x).sum(), (w * y).sum(), (w * x * x).sum(), (w * x * y).sum()
    delta = S * Sxx - Sx**2
    f = finite_barrier_fit(b, y, e)
    assert f.slope == pytest.approx((S * Sxy - Sx * Sy) / delta, rel=1e-12)
    assert f.intercept == pytest.approx((Sxx * Sy - Sx * Sxy) / delta, rel=1e-12)
    assert f.slope_err == pytest.approx(math.sqrt(S / delta), rel=1e-12)
    assert f.intercept_err == pytest.approx(math.sqrt(Sxx / delta), rel=1e-12)
    assert f.slope_unit == pytest.approx((w * x * (y - 1)).sum() / (w * x * x).sum(), rel=1e-12)
    assert f.slope_unit_err == pytest.approx(1 / math.sqrt((w * x * x).sum()), rel=1e-12)
    resid = y - f.intercept - f.slope * x
    assert f.chi2 == pytest.approx((w * resid**2).sum(), rel=1e-12) and (f.dof, f.n) == (3, 5)
    assert f.measured("slope").value == f.slope


@pytest.mark.parametrize(
    "args, match",
    [(([3, 4], [0.9, 0.9], [0.01, 0.01]), "at least 3"), (([3, 4, 5], [0.9] * 3, [0.01, 0.0, 0.01]), "> 0")],
)
def test_the_fit_refuses_too_few_points_or_a_zero_error(args, match):
    with pytest.raises(ValueError, match=match):
        finite_barrier_fit(*args)


def test_henon_heiles_transition_state_slope_is_minus_two_ninths():
    """A_well = (1/12) Σ V_ijk² = (1/12)(3·2² + (−2)²) = 4/3 (Σ_i V_iik = 0); V(x, 1) = 3x²/2 + 1/6: A_s = 0."""
    c = transition_state_correction(HenonHeiles())
    assert c.well == pytest.approx(4 / 3, rel=1e-12)
    assert max(abs(a) for a in c.saddles) < 1e-12
    assert c.slope == pytest.approx(-2 / 9, rel=1e-12) and c.barrier == pytest.approx(1 / 6, rel=1e-12)


def test_a_quartic_well_and_its_anharmonic_dividing_lines():
    """V = (x² + y²)/2 − (x⁴ + y⁴)/4: each direction ∫ e^{−(q²/2 − q⁴/4)/T} = √(2πT)(1 + 3T/4 + …), so A_well = 3/2;
    along y through the saddle (1, 0) the same one-dimensional form: A_s = 3/4; c = (1/4)(3/4 − 3/2) = −3/16."""
    m = make_system(potential=QUARTIC)
    c = transition_state_correction(m)
    assert c.well == pytest.approx(1.5, rel=1e-12) and c.saddles == pytest.approx((0.75,) * 4, rel=1e-12)
    assert c.slope == pytest.approx(-3 / 16, rel=1e-12) and c.lowest == (0, 1, 2, 3)


def test_the_well_coefficient_against_a_quadrature_of_the_well():
    """(Z(T)/Z_harmonic − 1)/T → A as T → 0, with Z = ∫ e^{−V/T} over the disk r < 0.6 (the rest is below e^{−40});
    Richardson's extrapolation of T = 0.004 and 0.002 leaves O(T²)."""
    m = HenonHeiles()

    def a_of(T):
        f = lambda r, th: r * math.exp(-float(m.potential(r * math.cos(th), r * math.sin(th))) / T)
        z = integrate.dblquad(f, 0.0, 2 * math.pi, 0.0, 0.6, epsabs=0, epsrel=1e-12)[0]
        return (z / (2 * math.pi * T) - 1) / T

    a = 2 * a_of(0.002) - a_of(0.004)
    assert a == pytest.approx(laplace_coefficient(m), rel=2e-3)


def test_the_line_coefficient_against_a_quadrature_of_the_line():
    """Along y through the quartic system's saddle (1, 0): ∫ e^{−(V − V_s)/T} dy against √(2πT)(1 + A_s T)."""
    m = make_system(potential=QUARTIC)

    def a_of(T):
        f = lambda y: math.exp(-(float(m.potential(1.0, y)) - 0.25) / T)
        z = integrate.quad(f, -0.6, 0.6, epsabs=0, epsrel=1e-13)[0]
        return (z / math.sqrt(2 * math.pi * T) - 1) / T

    a = 2 * a_of(0.002) - a_of(0.004)
    assert a == pytest.approx(laplace_coefficient(m, 1.0, 0.0, (0.0, 1.0)), rel=2e-3)


def test_laplace_coefficient_refuses_a_point_that_is_not_a_minimum():
    with pytest.raises(ValueError, match="not a minimum"):
        laplace_coefficient(HenonHeiles(), 0.0, 1.0)
    with pytest.raises(ValueError, match="unit vector"):
        laplace_coefficient(HenonHeiles(), 0.0, 1.0, (1.0, 1.0))
