"""hhscatter.analysis.noise.energy_diffusion: the energy-diffusion eigenvalue against the zero of a confluent
hypergeometric function (the one-dimensional harmonic well), its flux closure against the harmonic transition-state
rate, the well's shells of Hénon–Heiles against the exact integral over its triangle, the shells kept per
temperature, separability against potentials built as sums of one-dimensional ones, and argument checks."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from scipy import optimize, special

from hhscatter.analysis.noise import (
    energy_diffusion_rate,
    is_separable,
    thermal_well_shells,
    well_energy_diffusion,
    well_shells,
)
from hhscatter.errors import ConfigError
from hhscatter.model import HenonHeiles, make_system


def _harmonic_zero(x_b: float) -> float:
    """The smallest a with ₁F₁(−a; 1; x_b) = 0: for a 1-D harmonic well (Ω = 2πE/ω) absorbing at E_b = x_b T, the
    energy-diffusion equation x f'' + (1 − x) f' + (λ/γ) f = 0 (x = E/T) is Laguerre's; λ = γ a."""
    return optimize.brentq(lambda a: special.hyp1f1(-a, 1.0, x_b), 1e-12, 0.5, xtol=1e-15, rtol=1e-13)


@pytest.mark.parametrize("x_b", [3.0, 5.0, 8.0])
@pytest.mark.parametrize("omega", [1.0, 2.5])
def test_the_absorbing_rate_of_a_harmonic_well_is_the_hypergeometric_zero(x_b, omega):
    gamma, T = 0.01, 0.2
    E = np.linspace(0.0, x_b * T, 4001)
    k = energy_diffusion_rate(E, 2 * math.pi * E / omega, gamma, T, dof=1)
    assert k == pytest.approx(gamma * _harmonic_zero(x_b), rel=1e-5)


def test_the_absorbing_rate_tends_to_kramers_energy_diffusion_rate():
    """(γS/T)(ω/2π) e^{−ΔE/T}, S = 2πΔE/ω: the ratio tends to 1 as ΔE/T grows (≈ 1 − 1/x at large x)."""
    ratios = []
    for x_b in (5.0, 10.0, 20.0):
        E = np.linspace(0.0, x_b, 8001)
        ratios.append(energy_diffusion_rate(E, 2 * math.pi * E, 1e-3, 1.0, dof=1) / (1e-3 * x_b * math.exp(-x_b)))
    assert ratios[0] < ratios[1] < ratios[2] < 1
    assert ratios[2] == pytest.approx(1.0, abs=0.08)


def test_the_flux_closure_reaches_the_transition_state_rate_at_large_drag_and_the_absorbing_one_at_small():
    """1-D harmonic well (ω = 1) with the flux F = 1 above E_b (each orbit above crosses once a period) and a
    reflecting top: at large γ the rate is k_TST = (1/Z) ∫_{E_b}^{top} e^{−E/T} dE, Z = ∫_0^{top} 2π e^{−E/T} dE."""
    T, e_b, top = 1.0, 4.0, 12.0
    E = np.linspace(0.0, top, 12001)
    om, flux = 2 * math.pi * E, (E >= e_b).astype(float)
    k_tst = (math.exp(-e_b / T) - math.exp(-top / T)) / (2 * math.pi * (1 - math.exp(-top / T)))
    assert energy_diffusion_rate(E, om, 200.0, T, dof=1, flux=flux) == pytest.approx(k_tst, rel=1e-3)
    gamma = 1e-7
    e_abs = E[E <= e_b]
    absorbing = energy_diffusion_rate(e_abs, 2 * math.pi * e_abs, gamma, T, dof=1)
    assert energy_diffusion_rate(E, om, gamma, T, dof=1, flux=flux) == pytest.approx(absorbing, rel=2e-3)


def test_henon_heiles_shells_against_the_exact_triangle():
    """Ω(E_b) = 2π ∫ (1/6 − V) over the triangle of the saddles (exact, sympy); along y = 1, V = 1/6 + 3x²/2:
    A(E) = 2π (E − 1/6)/√3 per saddle; near the minimum Ω = 2π² E² (two unit oscillators)."""
    x, y = sp.symbols("x y")
    v = (x**2 + y**2) / 2 + x**2 * y - y**3 / 3
    inner = sp.integrate(sp.Rational(1, 6) - v, (x, -(1 - y) / sp.sqrt(3), (1 - y) / sp.sqrt(3)))
    exact = float(2 * sp.pi * sp.integrate(inner, (y, -sp.Rational(1, 2), 1)))
    sh = well_shells(HenonHeiles(), 0.3, n_energies=3001)
    assert sh.barrier == pytest.approx(1 / 6, rel=1e-12) and sh.top == 0.3
    assert float(np.interp(1 / 6, sh.energies, sh.phase_volume)) == pytest.approx(exact, rel=2e-5)
    above = sh.energies > 1 / 6 + 0.01
    for a in sh.flux_by_exit:
        assert a[above] == pytest.approx(2 * math.pi * (sh.energies[above] - 1 / 6) / math.sqrt(3), rel=1e-3)
    assert np.all(sh.flux[sh.energies < 1 / 6] == 0)
    low = (sh.energies > 0.002) & (sh.energies < 0.004)
    assert sh.phase_volume[low] == pytest.approx(2 * math.pi**2 * sh.energies[low] ** 2, rel=1e-2)


def test_the_top_stops_where_a_dividing_line_spills():
    """(x² + y²)/2 − x³/3 − 5y³/18: along the dividing line y = 6/5 of the saddle (0, 6/5), V = 0.24 + x²/2 − x³/3
    peaks at x = 1 at 0.24 + 1/6: the shells stop there."""
    m = make_system(potential="(x**2 + y**2)/2 - x**3/3 - 5*y**3/18")
    sh = well_shells(m, 1.0, n_energies=501)
    assert sh.top == pytest.approx(0.24 + 1 / 6, rel=1e-6)
    assert sh.barrier == pytest.approx(1 / 6, rel=1e-12)


def test_the_shell_delta_of_henon_heiles_is_twice_the_shell_phase_volume_over_the_flux_integral():
    """δ = 2γ Ω(E_b) e^{−E_b/T} / ∫F e^{−E/T} dE; with F = 3 · 2π(E − E_b)/√3 above E_b (exact for Hénon–Heiles up
    to where the lines spill, beyond the top here): ∫ = 2√3 π T² e^{−E_b/T} (1 − (1 + u) e^{−u}), u = (top − E_b)/T."""
    T, gamma = 1 / 18, 0.01
    sh = well_shells(HenonHeiles(), 1 / 6 + 12 * T, n_energies=4001)
    ed = well_energy_diffusion(HenonHeiles(), gamma, T, shells=sh)
    u = 12.0
    flux_integral = 2 * math.sqrt(3) * math.pi * T**2 * (1 - (1 + u) * math.exp(-u))
    assert ed.delta == pytest.approx(2 * gamma * ed.phase_volume_barrier / flux_integral, rel=1e-4)
    assert ed.rate < ed.rate_absorbing < ed.absorbing_limit * 1.2


@pytest.mark.parametrize(
    "kwargs, word",
    [
        ({"energies": [0.0, 1.0, 3.0]}, "energies"),
        ({"phase_volume": [0.0, 1.0]}, "phase_volume"),
        ({"gamma": 0.0}, "gamma"),
        ({"temperature": -1.0}, "temperature"),
        ({"dof": 0}, "dof"),
        ({"flux": [0.0, 1.0]}, "flux"),
        ({"phase_volume": [0.0, 0.0, 0.0]}, "phase_volume"),
    ],
)
def test_bad_arguments_are_refused_by_name(kwargs, word):
    args = {"energies": [0.0, 1.0, 2.0], "phase_volume": [0.0, 1.0, 2.0], "gamma": 0.1, "temperature": 1.0}
    args.update(kwargs)
    with pytest.raises(ConfigError, match=word):
        energy_diffusion_rate(**args)


def test_shells_refuse_a_top_below_the_barrier():
    with pytest.raises(ConfigError, match="top"):
        well_shells(HenonHeiles(), 0.1)


def test_thermal_shells_reach_the_barrier_plus_widths_of_t_and_are_kept_per_temperature():
    m, T = HenonHeiles(), 0.04
    sh = thermal_well_shells(m, T, top_widths=2.5, grid=201, n_energies=101)
    # Hénon–Heiles: V(min) = 0, E_b = 1/6 (closed form)
    assert sh.top == pytest.approx(1 / 6 + 2.5 * T, abs=1e-15)
    assert sh.barrier == pytest.approx(1 / 6, abs=1e-15)
    direct = well_shells(m, 1 / 6 + 2.5 * T, grid=201, n_energies=101)
    np.testing.assert_array_equal(sh.phase_volume, direct.phase_volume)
    np.testing.assert_array_equal(sh.flux, direct.flux)
    assert thermal_well_shells(HenonHeiles(), T, top_widths=2.5, grid=201, n_energies=101) is sh
    other = thermal_well_shells(m, 0.05, top_widths=2.5, grid=201, n_energies=101)
    assert other is not sh and other.top == pytest.approx(1 / 6 + 2.5 * 0.05, abs=1e-15)
    # another system with the same settings is another entry
    wide = thermal_well_shells(HenonHeiles(lam=0.5), T, top_widths=2.5, grid=201, n_energies=101)
    assert wide.barrier == pytest.approx(1 / 6 / 0.25, abs=1e-12)  # E_c = ω⁶/(6λ²)


@pytest.mark.parametrize(
    ("kwargs", "word"),
    [
        ({"temperature": 0.0}, "temperature"),
        ({"temperature": math.nan}, "temperature"),
        ({"top_widths": -1.0}, "top_widths"),
        ({"grid": 10}, "grid"),
        ({"n_energies": 2.5}, "n_energies"),
        ({"model": "hh"}, "model"),
    ],
)
def test_thermal_shells_refuse_bad_arguments_by_name(kwargs, word):
    args = {"model": HenonHeiles(), "temperature": 0.05, **kwargs}
    with pytest.raises(ConfigError, match=word):
        thermal_well_shells(args.pop("model"), args.pop("temperature"), **args)


@pytest.mark.parametrize(
    ("potential", "separable"),
    [
        # sums of a function of x and a function of y (by construction)
        ("(x**2 + y**2)/2 - x**3/3 - 5*y**3/18", True),
        ("x**2/2 - x**4/4 + y**2 - y**3", True),
        # couplings: V_xy = 2x (Hénon–Heiles), y/5 and 1/10 (bilinear)
        ("(x**2 + y**2)/2 + x**2*y - y**3/3", False),
        ("(x**2 + y**2)/2 - x**3/3 - 5*y**3/18 + x*y**2/10", False),
        ("(x**2 + y**2)/2 - x**3/3 - 5*y**3/18 + x*y/10", False),
    ],
)
def test_separability_against_potentials_built_as_sums(potential, separable):
    assert is_separable(make_system(potential=potential)) is separable


def test_hénon_heiles_is_not_separable_and_a_coupling_below_the_tolerance_counts_as_none():
    assert is_separable(HenonHeiles()) is False
    weak = make_system(potential="(x**2 + y**2)/2 - x**3/3 - 5*y**3/18 + 1e-15*x*y")
    assert is_separable(weak) is True  # V_xy = 1e-15 ≤ 1e-12 × max(|V_xx|, |V_yy|, 1)
    assert is_separable(weak, rtol=1e-16) is False


@pytest.mark.parametrize(
    ("kwargs", "word"),
    [({"span": 0.0}, "span"), ({"nodes": 1}, "nodes"), ({"rtol": -1.0}, "rtol"), ({"rtol": math.inf}, "rtol")],
)
def test_separability_refuses_bad_arguments_by_name(kwargs, word):
    with pytest.raises(ConfigError, match=word):
        is_separable(HenonHeiles(), **kwargs)
    with pytest.raises(ConfigError, match="model"):
        is_separable(None)
