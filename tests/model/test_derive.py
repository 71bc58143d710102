"""Derived E_c, exits, Ω and R(E) against closed forms, and the pitfalls each a clear error (or a right answer)."""

import math

import numpy as np
import pytest

from hhscatter.errors import ConfigError
from hhscatter.model import HenonHeiles, make_system
from hhscatter.model.declared import DeclaredSystem
from hhscatter.model.derive import Landscape, no_return_radius
from hhscatter.model.parse import parse_potential


def _angles(exits):
    return [math.atan2(e.y, e.x) % (2 * math.pi) for e in exits]


@pytest.mark.parametrize("n", [3, 4, 5, 6])
def test_n_exit_closed_forms(n):
    s = make_system("n_exit", params={"n": n})
    assert s.critical_energy == pytest.approx((n - 2) / (2 * n), rel=1e-14)
    assert len(s.exits) == n
    for e in s.exits:
        assert e.distance == pytest.approx(1.0, rel=1e-14) and e.energy == pytest.approx(s.critical_energy, rel=1e-14)
    # saddles where sin(nθ) = −1: θ = (3π/2 + 2πk)/n, in ascending angle from 0
    want = sorted(((1.5 * math.pi + 2 * math.pi * k) / n) % (2 * math.pi) for k in range(n))
    assert np.allclose(_angles(s.exits), want, atol=1e-12)
    assert s.omega_radius == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("eps", [0.25, 0.1])
def test_contopoulos_closed_forms(eps):
    s = make_system("contopoulos", params={"eps": eps})
    assert s.critical_energy == pytest.approx(1 / (4 * eps), rel=1e-14)
    assert len(s.exits) == 4
    assert np.allclose(_angles(s.exits), [math.pi / 4, 3 * math.pi / 4, 5 * math.pi / 4, 7 * math.pi / 4], atol=1e-12)
    assert np.allclose([e.distance for e in s.exits], 1 / math.sqrt(eps), rtol=1e-13)
    assert s.omega_radius == pytest.approx(1 / math.sqrt(eps), rel=1e-13)


@pytest.mark.parametrize("eps", [0.5, 0.3])
def test_barbanis_closed_forms(eps):
    s = make_system("barbanis", params={"eps": eps})
    assert s.critical_energy == pytest.approx(1 / (8 * eps**2), rel=1e-14)
    got = sorted((e.x, e.y) for e in s.exits)
    want = sorted([(1 / (2 * eps), -1 / (math.sqrt(2) * eps)), (1 / (2 * eps), 1 / (math.sqrt(2) * eps))])
    assert np.allclose(got, want, rtol=1e-13)
    assert [e.energy for e in s.exits] == [pytest.approx(1 / (8 * eps**2), rel=1e-14)] * 2


def test_declared_hh_equals_the_builtin():
    hh, d = HenonHeiles(), make_system("n_exit", params={"n": 3})
    pts = np.random.default_rng(1).uniform(-2, 2, (2, 1000))
    assert np.allclose(d.potential(*pts), hh.potential(*pts), rtol=0, atol=1e-15 * 10)  # |V| ≤ ~10 here
    assert np.max(np.abs(d.potential(*pts) - hh.potential(*pts)) / np.maximum(1, np.abs(hh.potential(*pts)))) < 1e-15
    assert d.critical_energy == pytest.approx(hh.critical_energy, rel=1e-15)
    assert np.allclose(
        [(e.x, e.y, e.energy) for e in d.exits], [(e.x, e.y, e.energy) for e in hh.exits], rtol=0, atol=1e-15
    )
    assert d.saddle_radius == pytest.approx(hh.saddle_radius, rel=1e-15)
    assert d.omega_radius == pytest.approx(hh.omega_radius, rel=1e-15)
    for x, y in pts.T[:50]:  # channels: the same exit nearest in angle
        assert d.exit_channel(x, y) == hh.exit_channel(x, y)


@pytest.mark.parametrize("omega,lam", [(1.0, 1.0), (1.3, 0.7)])
def test_no_return_radius_reproduces_the_hh_closed_form(omega, lam):
    land = Landscape(parse_potential(f"0.5*{omega}**2*(x**2 + y**2) + {lam}*(x**2*y - y**3/3)"))
    hh = HenonHeiles(omega, lam)
    for f in (1.0, 1.5, 3.0, 10.0):
        E = f * hh.critical_energy
        want = math.sqrt(6 * E) / omega
        got = no_return_radius(land, E, hh.saddle_radius)
        assert got >= want and got == pytest.approx(want, rel=1e-8), (E, got, want)


@pytest.mark.parametrize(
    "name, params, closed",
    [
        # V = r²/2 + r^k g(θ) homogeneous: V_r = 0 and V = E meet at r² = 2kE/(k − 2) (k = 3: HH's √(6E))
        ("n_exit", {"n": 4}, lambda E: math.sqrt(8 * E / 2)),
        ("n_exit", {"n": 5}, lambda E: math.sqrt(10 * E / 3)),
        ("contopoulos", {"eps": 0.25}, lambda E: 2 * math.sqrt(E)),
        ("barbanis", {"eps": 0.5}, lambda E: math.sqrt(6 * E)),
    ],
)
def test_no_return_radius_closed_forms_of_the_builtins(name, params, closed):
    s = make_system(name, params=params)
    for f in (1.0, 1.5, 3.0):
        E = f * s.critical_energy
        got, want = s.no_return_radius(E), max(closed(E), s.saddle_radius)
        assert got >= want and got == pytest.approx(want, rel=1e-8), (E, got, want)


def test_no_return_radius_is_a_no_return_radius():
    """Beyond R(E), −∂V/∂r > 0 wherever V ≤ E (checked on a fine polar grid independent of the one used)."""
    for s in (make_system("contopoulos"), make_system("barbanis")):
        for E in (s.critical_energy, 1.5 * s.critical_energy):
            R = s.no_return_radius(E)
            assert R >= s.saddle_radius
            r = np.linspace(R, 20 * R, 500)
            th = np.linspace(0, 2 * np.pi, 1001)
            rr, tt = np.meshgrid(r, th)
            x, y = rr * np.cos(tt), rr * np.sin(tt)
            land = s._landscape
            bad = (s.potential(x, y) <= E) & (land.radial(x, y) >= 0)
            assert not bad.any(), (s.name, E)


def test_exits_opening_at_different_energies():
    # separable: saddles (1, 0) at 1/6 and (0, 1/8) at 1/384, a maximum at (1, 1/8) (not an exit)
    s = DeclaredSystem("0.5*(x**2 + y**2) - x**3/3 - 8*y**3/3")
    assert [(e.x, e.y) for e in s.exits] == [(1.0, 0.0), (0.0, 0.125)]
    assert [e.energy for e in s.exits] == [pytest.approx(1 / 6, rel=1e-15), pytest.approx(1 / 384, rel=1e-15)]
    assert s.critical_energy == pytest.approx(1 / 384, rel=1e-15)
    assert s.omega_radius == pytest.approx(0.125)
    kinds = sorted(p.kind for p in s.critical_points)
    assert kinds == ["maximum", "minimum", "saddle", "saddle"]


def test_saddle_that_does_not_lead_out():
    """A double well along y: V = x²/2 + f(y), f'(y) = y(1 − 2y)(1 − y)(1 − 2y/3).

    Minima at y = 0 (the well) and y = 1 (f = 1/90), saddles at y = 1/2 (f = 19/720, between the two wells: no
    exit) and y = 3/2 (f = 3/80, the exit): E_c = 3/80, Ω reaches out to 3/2 around both wells.
    """
    s = DeclaredSystem("x**2/2 + y**2/2 - 11*y**3/9 + y**4 - 4*y**5/15")
    assert [(e.x, e.y) for e in s.exits] == [(0.0, 1.5)]
    assert s.critical_energy == pytest.approx(3 / 80, rel=1e-14)
    saddles = sorted(p.y for p in s.critical_points if p.kind == "saddle")
    assert saddles == [pytest.approx(0.5, rel=1e-14), pytest.approx(1.5, rel=1e-14)]
    assert s.omega_radius == pytest.approx(1.5, rel=1e-14)
    assert bool(s.inside_well(0.0, 1.0))  # the second well is part of the well below E_c


@pytest.mark.parametrize(
    "text, match",
    [
        # a whole circle of maxima (the ring) at r = 1: the critical points form a curve
        ("0.5*(x**2 + y**2) - 0.25*(x**2 + y**2)**2", "form a curve.*`critical_energy` and `exits`"),
        # an inflection x(1−x)²: a degenerate critical point at (1, 0)
        ("x**2/2 - 2*x**3/3 + x**4/4 + y**2/2", r"degenerate critical point at \(1, 0\)"),
        ("0.5*(x**2 + y**2) + x**4", "no exit"),
        ("0.5*((x - 1)**2 + y**2)", r"minimum must be at the origin, found at \(1, 0\)"),
        ("0.5*(x**2 + y**2) + 1 - x**3", "V = 0, but V\\(0, 0\\) = 1"),
        ("x**2 - y**2 + x**3", "origin is a saddle"),
    ],
)
def test_pitfalls_are_clear_errors(text, match):
    with pytest.raises(ConfigError, match=match):
        DeclaredSystem(text)


def test_maxima_near_the_threshold_are_not_exits():
    # saddles on the axes at E = 1/4, maxima on the diagonals at 1/(2(1 − 2k)) = 0.2778 (k = −0.4)
    s = DeclaredSystem("0.5*(x**2 + y**2) - 0.25*(x**4 + y**4) - 0.4*x**2*y**2")
    assert s.critical_energy == pytest.approx(0.25, rel=1e-15)
    assert np.allclose(_angles(s.exits), [0, math.pi / 2, math.pi, 1.5 * math.pi], atol=1e-12)
    assert sum(p.kind == "maximum" for p in s.critical_points) == 4


def test_a_non_polynomial_potential_is_derived_numerically():
    # atan is monotone: the critical points and exits of atan(V_HH) are Hénon–Heiles', E_c = atan(1/6)
    s = DeclaredSystem("atan(0.5*(x**2 + y**2) + x**2*y - y**3/3)")
    assert s.derivation.method == "numeric"
    assert s.critical_energy == pytest.approx(math.atan(1 / 6), rel=1e-14)
    assert np.allclose([(e.x, e.y) for e in s.exits], [(e.x, e.y) for e in HenonHeiles().exits], atol=1e-12)
    assert s.no_return_radius(math.atan(0.25)) == pytest.approx(math.sqrt(6 * 0.25), rel=1e-8)


@pytest.mark.parametrize("lam_text, lam", [("sqrt(2)", math.sqrt(2)), ("pi/3", math.pi / 3)])
def test_irrational_coefficients_go_the_numeric_way(lam_text, lam):
    s = DeclaredSystem(f"0.5*(x**2 + y**2) + {lam_text}*(x**2*y - y**3/3)")
    assert s.derivation.method == "numeric"
    hh = HenonHeiles(1.0, lam)
    assert s.critical_energy == pytest.approx(hh.critical_energy, rel=1e-14)
    assert np.allclose([(e.x, e.y) for e in s.exits], [(e.x, e.y) for e in hh.exits], atol=1e-13)


def test_overrides_replace_the_derivation():
    # the ring: nothing derivable, everything given
    s = DeclaredSystem(
        "0.5*(x**2 + y**2) - 0.25*(x**2 + y**2)**2",
        critical_energy=0.25,
        exits=[[1, 0], [0, 1], [-1, 0], [0, -1]],
        omega_radius=1.0,
    )
    assert s.critical_energy == 0.25 and s.omega_radius == 1.0 and s.derivation.method == "given"
    assert [e.energy for e in s.exits] == [0.25] * 4
    assert s.provenance()["critical_energy"] == 0.25
    with pytest.raises(ConfigError, match=r"exits\[1\] must be \[x, y\]"):
        DeclaredSystem("0.5*(x**2 + y**2) - x**3", exits=[[1, 0], "a"])
    with pytest.raises(ConfigError, match="omega_radius must be"):
        DeclaredSystem("0.5*(x**2 + y**2) + x**2*y - y**3/3", omega_radius=-1)


def test_a_critical_energy_the_derived_exits_contradict_is_refused():
    # exits at 1/384 (r = 1/8) and at 1/6 (r = 1): E_c is the lower one; forcing it up to the far exit's energy
    # contradicts the derivation and is refused, naming both values
    with pytest.raises(
        ConfigError,
        match=r"critical_energy = 0.16666666666666666 contradicts the exits: E_c is the "
        r"lowest exit's energy, 0.0026041666666666\d* \(exits derived\)",
    ):
        DeclaredSystem("0.5*(x**2 + y**2) - x**3/3 - 8*y**3/3", critical_energy=1 / 6)


def test_a_descent_that_crawls_is_given_up_with_a_clear_error():
    # cosh(y) walls close the y-channel exponentially: the path from the saddle crawls out to R(E) ~ 1300
    with pytest.raises(ConfigError, match=r"saddle at \(0, 0.707107\).*neither a minimum nor infinity.*`exits`"):
        DeclaredSystem("0.5*(x**2 + y**2) + sqrt(2)*(x**2*y - y**3/3) + 0.01*erf(x**2)*cosh(y)")
