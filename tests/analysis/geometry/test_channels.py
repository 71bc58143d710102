"""Tests of the Lyapunov orbits of :mod:`hhscatter.analysis.geometry.channels` for any system.

References independent of the code under test: invariants (energy, rest at both brake ends, periodicity), the
linearisation at the saddle with the Hessian computed here symbolically (sympy) from the system's V as text,
the three-fold rotation symmetry of Hénon–Heiles, its mirror symmetry x → −x, and the numbers of the
symmetric shooting the Hénon–Heiles orbits were computed with before (brentq on p_y at the first x = 0
crossing from a brake point on the wall).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from hhscatter.analysis.geometry import channels
from hhscatter.analysis.geometry.channels import lyapunov_orbit
from hhscatter.model import Exit, HenonHeiles, make_system

# (system name, exit, energies above the exit's saddle energy E_s: 1/6, 1 and 1/2)
CASES = [
    ("henon_heiles", 0, (0.2, 0.3)),
    ("contopoulos", 2, (1.05, 1.3)),
    ("barbanis", 1, (0.55, 0.8)),
]


@pytest.fixture(scope="module")
def systems():
    return {name: make_system(name) for name, _, _ in CASES}


def _saddle_hessian(system, k):
    """V's Hessian at exit k's saddle, from V as text differentiated by sympy (energy/length²)."""
    x, y = sp.symbols("x y")
    V = sp.sympify(system.potential_text, locals={"x": x, "y": y}).subs(system.params)
    e = system.exits[k]
    H = sp.hessian(V, (x, y)).subs({x: e.x, y: e.y})
    return np.array(H.evalf(), dtype=float)


@pytest.mark.parametrize("name, k, energies", CASES)
def test_energy_is_conserved_along_the_orbit(systems, name, k, energies):
    s = systems[name]
    for E in energies:
        L = lyapunov_orbit(E, s, exit=k)
        x, y, px, py = L.states.T
        np.testing.assert_allclose(s.energy(x, y, px, py), E, rtol=0, atol=1e-10 * E)
        assert L.energy == E and L.exit == k


def _assert_brake_orbit(L, e):
    """Rest at both brake ends, moving in between, closed after one period, straddling the saddle of exit e."""
    E = L.energy
    p_scale = math.sqrt(2 * (E - e.energy))  # |p| where the orbit crosses the channel, roughly
    half = (len(L.t) - 1) // 2
    assert L.states[0].tolist() == [L.x_b, L.y_b, 0.0, 0.0]
    assert np.hypot(*L.states[half, 2:]) < 1e-8 * p_scale  # the other brake end, half a period later
    assert np.max(np.hypot(L.states[1:half, 2], L.states[1:half, 3])) > 0.5 * p_scale  # moving in between
    np.testing.assert_allclose(L.states[-1], L.states[0], rtol=0, atol=1e-8)
    assert L.t[-1] == L.period
    # it straddles the channel: the brake ends lie on both sides of the saddle, the orbit passes nearer
    ends = L.states[[0, half], :2] - [e.x, e.y]
    assert np.dot(ends[0], ends[1]) < 0
    assert math.hypot(L.x_axis - e.x, L.y_axis - e.y) < 0.5 * min(np.hypot(*ends.T))


@pytest.mark.parametrize("name, k, energies", CASES)
def test_rest_at_both_brake_ends_and_closed_after_one_period(systems, name, k, energies):
    s = systems[name]
    for E in energies:
        _assert_brake_orbit(lyapunov_orbit(E, s, exit=k, n_samples=400), s.exits[k])


def test_far_above_the_saddle_the_family_is_continued_from_the_saddle():
    # at E = 3 (18 E_c) Newton from the linear guess falls to the trivial root T = 0
    s = HenonHeiles()
    L = lyapunov_orbit(3.0, s, n_samples=200)
    _assert_brake_orbit(L, s.exits[0])
    x, y, px, py = L.states.T
    np.testing.assert_allclose(s.energy(x, y, px, py), 3.0, rtol=0, atol=1e-10 * 3.0)
    assert abs(L.x_axis) < 1e-10  # the mirror symmetry x → −x of exit 0 holds for the family member


@pytest.mark.parametrize("name, k, energies", CASES)
def test_period_tends_to_the_saddle_frequency_as_the_energy_falls_to_the_saddle(systems, name, k, energies):
    s = systems[name]
    e = s.exits[k]
    hess = _saddle_hessian(s, k)
    lam = np.linalg.eigvalsh(hess)
    assert lam[0] < 0 < lam[1]
    omega_v = math.sqrt(lam[1])
    p0 = 2 * math.pi / omega_v
    errs = []
    for dE in (1e-3 * e.energy, 1e-5 * e.energy):
        L = lyapunov_orbit(e.energy + dE, s, exit=k)
        errs.append(abs(L.period / p0 - 1))
        # the brake point: A = √(2 ΔE)/ω_v from the saddle along the stable eigenvector
        v = np.linalg.eigh(hess)[1][:, 1]
        d = np.array([L.x_b - e.x, L.y_b - e.y])
        assert abs(abs(d @ v) / (math.sqrt(2 * dE) / omega_v) - 1) < 0.02
    assert errs[1] < 1e-4
    assert 30 < errs[0] / errs[1] < 300  # the correction is O(ΔE)


def test_henon_heiles_exits_are_rotations_of_exit_0():
    m = HenonHeiles()
    L0 = lyapunov_orbit(0.25, m)  # the second argument positionally, as before
    for k in (1, 2):
        Lk = lyapunov_orbit(0.25, m, exit=k)
        a = 2 * math.pi * k / 3
        R = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
        np.testing.assert_allclose(Lk.states[:, :2], L0.states[:, :2] @ R.T, rtol=0, atol=1e-9)
        np.testing.assert_allclose(Lk.states[:, 2:], L0.states[:, 2:] @ R.T, rtol=0, atol=1e-9)
        assert Lk.period == pytest.approx(L0.period, rel=1e-11)
        assert (Lk.r_min, Lk.r_max) == (pytest.approx(L0.r_min, rel=1e-11), pytest.approx(L0.r_max, rel=1e-11))
    # exit 0 is symmetric under x → −x: its brake ends are (±x_b, y_b), it crosses x = 0 on the y axis
    x = L0.states[:, 0]
    assert np.max(np.abs(x)) == pytest.approx(L0.x_b, rel=1e-6)
    assert L0.states[200, :2] == pytest.approx([-L0.x_b, L0.y_b], abs=1e-10)
    assert abs(L0.x_axis) < 1e-12 and 1.0 < L0.y_axis < L0.y_b


def test_henon_heiles_orbits_scale_with_omega_and_lambda():
    # V(x; ω, λ) = (ω⁶/λ²) V(λx/ω²; 1, 1): lengths scale by ω²/λ, energies by ω⁶/λ², times by 1/ω
    omega, lam, E1 = 1.3, 0.7, 0.27
    ell, eps = omega**2 / lam, omega**6 / lam**2
    L1 = lyapunov_orbit(E1, HenonHeiles())
    L = lyapunov_orbit(E1 * eps, HenonHeiles(omega, lam), exit=2)
    assert L.period == pytest.approx(L1.period / omega, rel=1e-10)
    assert (L.r_min, L.r_max) == (pytest.approx(L1.r_min * ell, rel=1e-8), pytest.approx(L1.r_max * ell, rel=1e-8))


@pytest.mark.parametrize(
    "E, r_min, r_max, period",
    [
        (0.2, 1.010084652874157, 1.0226305834624203, 3.6139535733025596),
        (0.3, 1.0384919062588425, 1.0857872089168934, 3.576290487737233),
    ],
)
def test_henon_heiles_matches_the_symmetric_shooting(E, r_min, r_max, period):
    L = lyapunov_orbit(E, HenonHeiles())
    assert (L.r_min, L.r_max, L.period) == (
        pytest.approx(r_min, rel=1e-10),
        pytest.approx(r_max, rel=1e-10),
        pytest.approx(period, rel=1e-10),
    )


class _NoExit(HenonHeiles):
    """A system whose definition gives no exit."""

    @property
    def exits(self):
        return ()


class _MinimumAsExit(HenonHeiles):
    """A system whose only 'exit' is the well's minimum, not a saddle."""

    @property
    def exits(self):
        return (Exit(0.0, 0.0, -1.0),)


def test_bad_input_is_refused_before_any_integration(systems, monkeypatch):
    def no_work(*args, **kwargs):
        raise AssertionError("integrated before checking the input")

    monkeypatch.setattr(channels.integrate, "solve_ivp", no_work)
    hh, barb = HenonHeiles(), systems["barbanis"]
    with pytest.raises(ValueError, match=r"E_s = 0\.166667.*got 0\.1"):
        lyapunov_orbit(0.1, hh)
    with pytest.raises(ValueError, match=r"got 0\.16666666666666666"):
        lyapunov_orbit(1 / 6, hh)
    with pytest.raises(ValueError, match=r"E_s = 0\.5 of exit 1.*got 0\.5"):
        lyapunov_orbit(0.5, barb, exit=1)
    with pytest.raises(ValueError, match="got nan"):
        lyapunov_orbit(math.nan, hh)
    with pytest.raises(ValueError, match="system must be a System"):  # no default system: the caller names it
        lyapunov_orbit(0.3, None)
    for bad in (3, -1, True, 1.0):
        with pytest.raises(ValueError, match=rf"exit must be a channel index from 0 to 2, got {bad!r}"):
            lyapunov_orbit(0.3, hh, exit=bad)
    with pytest.raises(ValueError, match="exit must be a channel index from 0 to 1, got 2"):
        lyapunov_orbit(0.6, barb, exit=2)
    with pytest.raises(ValueError, match="has no exit"):
        lyapunov_orbit(0.3, _NoExit())
    with pytest.raises(ValueError, match=r"exit 0 at \(0, 0\) is not a saddle"):
        lyapunov_orbit(0.3, _MinimumAsExit())
