"""[system] overrides checked against the derivation, expressions bounded, potentials that are not finite named.

Each case a hostile input that used to pass silently (wrong numbers with exit 0) or end in a traceback; each now
ends in a ConfigError naming the key and the reason.
"""

import pytest

from hhscatter.errors import ConfigError
from hhscatter.model.declared import DeclaredSystem
from hhscatter.model.parse import parse_potential
from hhscatter.scene.scene import Scene

HH = "x**2/2 + y**2/2 + x**2*y - y**3/3"  # Hénon–Heiles: E_c = 1/6, saddles (0, 1), (±√3/2, −1/2), Ω radius 1


def test_a_critical_energy_that_contradicts_the_derivation_is_refused_naming_both():
    with pytest.raises(
        ConfigError,
        match=r"critical_energy = 0.1 contradicts the exits: E_c is the lowest exit's "
        r"energy, 0.1666666666666666\d* \(exits derived\)",
    ):
        DeclaredSystem(HH, critical_energy=0.1)
    assert DeclaredSystem(HH, critical_energy=1 / 6).critical_energy == 1 / 6  # the same value is accepted


def test_an_omega_radius_that_is_not_a_radius_of_omega_is_refused():
    with pytest.raises(
        ConfigError,
        match=r"omega_radius = 0.3 is not a radius of Ω, which must hold the well's part "
        r"of \{V < E_c\} and meet no other part: .*; the derivation finds 1",
    ):
        DeclaredSystem(HH, omega_radius=0.3)
    with pytest.raises(ConfigError, match=r"omega_radius = 3.0 is not a radius of Ω.*meets another part of V < E_c"):
        DeclaredSystem(HH, omega_radius=3.0)


def test_exits_that_are_not_critical_points_are_refused():
    ec = 1 / 6
    with pytest.raises(
        ConfigError,
        match=r"exits\[0\] = \[1, 0, 0.1666\d*\] is not a critical point of V "
        r"\(\|∇V\| = 1.41, V = 0.5 there\)",
    ):
        DeclaredSystem(HH, exits=[[1, 0, ec], [-1, 0, ec], [0, -1, ec]])
    with pytest.raises(ConfigError, match=r"exits\[0\] = \[0, 1, 0.2\]: its energy 0.2 is not V there"):
        DeclaredSystem(HH, exits=[[0, 1, 0.2]])


def test_exits_the_derivation_contradicts_are_refused_naming_both():
    # one true saddle of the three: a critical point at its energy, but not the derived set of exits
    with pytest.raises(
        ConfigError,
        match=r"exits \[\[0, 1, 0.166667\]\] contradict the derivation, which finds the "
        r"exits \[\[0, 1, 0.166667\], \[-0.866025, -0.5, 0.166667\], "
        r"\[0.866025, -0.5, 0.166667\]\]",
    ):
        DeclaredSystem(HH, exits=[[0, 1]])


@pytest.mark.parametrize(
    "text,message",
    [
        (HH + " + 0*((((9**64)**64)**64)**64)**64", r"the constant '\(9 \*\* 64\) \*\* 64' is out of range"),
        (HH + " + 1e300*1e300*x**2", r"the constant \d+ is out of range"),
        ("-" * 9000 + "x**2 + y**2", "nested more than 200 levels deep"),
        ("+".join("(" + "+".join(["x"] * 20) + ")" for _ in range(60)), "more than 2000 terms and operations"),
        ("x**2/2 + y**2/2 + (x + y)**20", "its degree is up to 20, more than 16"),
    ],
)
def test_expressions_are_bounded_in_size_and_cost(text, message):
    with pytest.raises(ConfigError, match=message):
        parse_potential(text)


def test_a_potential_not_finite_on_a_descent_path_is_named():
    # sqrt(1.2 − x) is not real beyond x = 1.2, between the well and the right-hand saddles' far side
    with pytest.raises(
        ConfigError,
        match=r"the potential or its gradient is not finite at \(1.2\d*, .*\) on the "
        r"steepest descent from the saddle",
    ):
        DeclaredSystem(HH + " + 0.01*sqrt(1.2 - x) - 0.01*sqrt(1.2) + 0.01*x/(2*sqrt(1.2))")


def test_a_potential_not_finite_where_orbits_move_is_refused_by_the_scene():
    # log(4 + x) is finite within the conservative r_esc = 1.5 (accepted), not within the dissipative r_far ≈ 10
    spec = {"potential": HH + " + 0.01*log(4 + x) - 0.01*log(4) - 0.0025*x"}
    assert Scene(energy=0.3, n=10, system=spec).r_esc < 4  # (accepted: orbits stop at r_esc)
    with pytest.raises(
        ConfigError,
        match=r"system.potential: V or its gradient is not finite at \(-4.0\d*, [-0-9.]+\), "
        r"inside r ≤ 9.99\d* \(r_far\) where orbits move",
    ):
        Scene(energy=0.3, n=10, gamma=0.01, system=spec)
    with pytest.raises(ConfigError, match=r"not finite at \(-1.8\d*, .*inside r ≤ 3 \(r_esc\)"):
        Scene(energy=0.3, n=10, r_esc=3.0, system={"potential": HH + " + 0.01*log(1.8 + x) - 0.01*log(1.8) - x/180"})
