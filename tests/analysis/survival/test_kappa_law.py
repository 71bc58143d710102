"""hhscatter.analysis.survival.kappa_law: the piecewise law κ0(E) of Fig. 2b at energies with a hand-computed answer."""

import math

import numpy as np
import pytest

from hhscatter.analysis.survival.kappa_energy import fit_kappa_energy
from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
from hhscatter.model import HenonHeiles
from hhscatter.reproduction.fig2 import PAPER_KAPPA

E_C = HenonHeiles().critical_energy  # E_c comes from the system


def test_critical_energy_is_that_of_the_model():
    """E_c = ω⁶/(6λ²) = 1/6 for ω = λ = 1 (closed form, not the model's code), and the paper's law carries it."""
    assert E_C == pytest.approx(1.0 / 6.0, rel=1e-15)
    assert PAPER_KAPPA.E_c == E_C


def test_paper_law_at_known_energies():
    """κ0 = 13.63 ΔE² + 0.03 ΔE below E = 0.27, 1.41 ΔE from there on, 0 at and below E_c (ΔE = E − 1/6)."""
    E = np.array([0.0, 0.1, 1 / 6, 0.2, 0.25, 0.27, 0.3, 0.5])
    d = E - 1.0 / 6.0
    expected = [
        0.0,
        0.0,
        0.0,
        13.63 * (1 / 30) ** 2 + 0.03 / 30,  # E = 0.2: ΔE = 1/30
        13.63 * (1 / 12) ** 2 + 0.03 / 12,  # E = 0.25: ΔE = 1/12
        1.41 * d[5],  # E_switch belongs to the linear branch
        1.41 * (0.3 - 1 / 6),
        1.41 / 3,
    ]
    np.testing.assert_allclose(PAPER_KAPPA(E), expected, rtol=1e-12, atol=0)


def test_the_two_branches_do_not_join_at_the_switch():
    """The reference law's branches at E_switch = 0.27: 0.1486 (quadratic, just below) and 0.1457 (linear, at it)."""
    just_below = float(PAPER_KAPPA(0.27 - 1e-12))
    at = float(PAPER_KAPPA(0.27))
    assert just_below == pytest.approx(0.1486, abs=5e-5)
    assert at == pytest.approx(0.1457, abs=5e-5)


def test_other_coefficients_and_shapes():
    law = PiecewiseKappa(a2=2.0, a1=0.5, slope=3.0, E_switch=0.4, E_c=0.25)
    assert float(law(0.3)) == pytest.approx(2.0 * 0.05**2 + 0.5 * 0.05, rel=1e-12)
    assert float(law(0.5)) == pytest.approx(3.0 * 0.25, rel=1e-12)
    assert float(law(0.2)) == 0.0
    grid = np.linspace(0.2, 0.6, 12).reshape(3, 4)
    assert law(grid).shape == (3, 4) and np.ndim(law(0.3)) == 0
    assert np.all(np.diff(law(np.linspace(0.25, 0.39, 50))) > 0)  # increasing on the quadratic branch


def test_fitted_law_reproduces_a_continuous_piecewise_kappa():
    """κ(E) points of a PiecewiseKappa whose branches meet at E_switch: the fit's predict() is that law."""
    a2, a1, E_s = 9.0, 0.2, 0.3
    law = PiecewiseKappa(a2=a2, a1=a1, slope=a2 * (E_s - E_C) + a1, E_switch=E_s, E_c=E_C)
    E = np.linspace(0.18, 0.5, 25)
    fit = fit_kappa_energy(E, law(E), np.full(E.size, 1e-3), E_C, n_boot=0)
    assert (fit.a, fit.b, fit.E_b) == pytest.approx((a2, a1, E_s), rel=1e-6)
    probe = np.linspace(0.1, 0.6, 101)
    np.testing.assert_allclose(fit.predict(probe), law(probe), rtol=1e-6, atol=1e-12)
    assert math.isclose(fit.c, law.slope, rel_tol=1e-6)
