"""DeclaredSystem in heyoka: the same trajectories and cost as the built-in, energy conserved; immutable, picklable;
make_system's errors name the key."""

import math
import pickle

import numpy as np
import pytest

from hhscatter.errors import ConfigError
from hhscatter.model import BUILTINS, DeclaredSystem, HenonHeiles, make_system


@pytest.fixture(scope="module")
def hh3():
    return make_system("n_exit", params={"n": 3})


@pytest.fixture(scope="module")
def conto():
    return make_system("contopoulos", params={"eps": 0.25})


def _ta(system, state, gamma=None, tol=1e-15, events=()):
    import heyoka as hy

    g = None if gamma is None else hy.par[0]
    kw = {"pars": [gamma]} if gamma is not None else {}
    return hy.taylor_adaptive(system.equations(hy, g), state, tol=tol, t_events=list(events), **kw)


def test_declared_hh_costs_no_more_per_step_than_the_builtin(hh3):
    import heyoka as hy

    for gamma in (None, 0.01):
        sizes = [len(_ta(m, [0.1, 0.2, 0.3, 0.1], gamma).decomposition) for m in (HenonHeiles(), hh3)]
        assert sizes[1] <= sizes[0], sizes  # 15 vs 17 (conservative), 19 vs 21 (linear drag)
    quad = DeclaredSystem(HenonHeiles().potential_text, {"omega": 1.0, "lam": 1.0}, "quadratic")
    sizes = [
        len(hy.taylor_adaptive(m.equations(hy, hy.par[0]), [0.1, 0.2, 0.3, 0.1], pars=[0.01]).decomposition)
        for m in (HenonHeiles(dissipation="quadratic"), quad)
    ]
    assert sizes[1] <= sizes[0] + 2, sizes


def _escape_time(system, state, radius=3.0):
    import heyoka as hy

    x, y = hy.make_vars("x", "y")
    ev = hy.t_event(x**2 + y**2 - radius**2)
    ta = _ta(system, state, events=[ev])
    ta.propagate_until(500.0)
    assert ta.time < 500.0  # stopped by the event
    return ta.time


def test_n_exit_3_gives_henon_heiles_escape_times(hh3):
    """Escape times (r = 3) from the origin at E = 0.2 in 12 directions: to 1e-12 for direct escapes (t < 20).

    The two right-hand sides are the same polynomials summed in another order (ulp-level differences), which
    a chaotic transient amplifies like any rounding: for the long escapes the difference is compared with the
    built-in's own change under a 1-ulp change of the initial momentum (measured: within a factor 0.35-1 of it).
    """
    hh = HenonHeiles()
    p = math.sqrt(2 * 0.2)
    for a in np.linspace(0.1, 2 * np.pi, 12):
        state = [0.0, 0.0, p * math.cos(a), p * math.sin(a)]
        t_hh, t_d = _escape_time(hh, state), _escape_time(hh3, state)
        if t_hh < 20:
            assert abs(t_hh - t_d) <= 1e-12 * t_hh, (a, t_hh, t_d)
        else:
            nudged = [0.0, 0.0, np.nextafter(state[2], 1.0), state[3]]
            ulp = abs(_escape_time(hh, nudged) - t_hh)
            assert abs(t_hh - t_d) <= max(1e-12 * t_hh, 10 * ulp), (a, t_hh, t_d, ulp)


def test_n_exit_3_gives_henon_heiles_trajectory(hh3):
    grid = np.linspace(0, 200, 41)
    state = [0.1, -0.05, 0.3, 0.35]  # E ≈ 0.117 < E_c: a bounded orbit
    out = [_ta(m, state).propagate_grid(grid)[5] for m in (HenonHeiles(), hh3)]
    assert np.abs(out[0] - out[1]).max() < 1e-12


@pytest.mark.parametrize("tol", [1e-9, 1e-13])
def test_energy_conserved_without_drag(conto, tol):
    state = [0.3, -0.2, 0.9, 0.5]
    E0 = conto.energy(*state)
    assert E0 < conto.critical_energy  # bounded: inside the well
    res = _ta(conto, state, tol=tol).propagate_grid(np.linspace(0, 500, 501))[5]
    drift = np.abs(conto.energy(*res.T) - E0).max() / E0
    assert drift < 100 * tol, drift  # the Taylor scheme's local error is ~ tol per step


def test_quadratic_drag_only_lowers_the_energy(conto):
    s = DeclaredSystem(conto.potential_text, conto.params, "quadratic")
    res = _ta(s, [0.3, -0.2, 0.9, 0.5], gamma=0.05, tol=1e-14).propagate_grid(np.linspace(0, 50, 201))[5]
    E = s.energy(*res.T)
    assert (np.diff(E) <= 1e-13).all() and E[-1] < E[0] - 0.05
    # dE/dt = −γ |p|³: the energy lost over the run equals ∫ γ |p|³ dt (trapezoid on the grid, to its accuracy)
    speed3 = np.hypot(res[:, 2], res[:, 3]) ** 3
    lost = np.trapezoid(0.05 * speed3, dx=50 / 200)
    assert E[0] - E[-1] == pytest.approx(lost, rel=2e-3)


def test_scalar_energy_and_potential_agree(conto):
    f = conto.scalar_energy()
    pts = np.random.default_rng(2).uniform(-2, 2, (4, 100))
    assert np.allclose([f(*p) for p in pts.T], conto.energy(*pts), rtol=1e-15, atol=1e-15)
    assert isinstance(f(0.1, 0.2, 0.3, 0.4), float)


def test_immutable_equal_hashable_and_picklable(conto):
    with pytest.raises(AttributeError, match="immutable"):
        conto.dissipation = "quadratic"
    again = make_system("contopoulos", params={"eps": 0.25})
    assert again == conto and hash(again) == hash(conto)
    assert make_system("contopoulos", params={"eps": 0.3}) != conto
    back = pickle.loads(pickle.dumps(conto))
    assert back == conto and back.exits == conto.exits and back.critical_energy == conto.critical_energy
    assert back.omega_radius == conto.omega_radius and back.derivation.method == "given"  # not derived again
    assert np.array_equal(back.potential([0.1, 1.0], [0.2, -1.0]), conto.potential([0.1, 1.0], [0.2, -1.0]))


def test_provenance_records_the_system(hh3, conto):
    assert conto.provenance() == {
        "system": "contopoulos",
        "potential": "0.5*(x**2 + y**2) - eps*x**2*y**2",
        "params": {"eps": 0.25},
        "dissipation": "linear",
    }
    assert conto.hash_items() == conto.provenance()
    assert hh3.provenance()["builtin_params"] == {"n": 3} and hh3.provenance()["params"] == {}
    d = DeclaredSystem("0.5*(x**2 + y**2) + x**2*y - y**3/3")
    assert d.name == "declared" and d.provenance()["potential"] == "0.5*(x**2 + y**2) + x**2*y - y**3/3"


def test_a_sympy_or_heyoka_potential_builds_the_same_system():
    import heyoka as hy
    import sympy as sp

    x, y = sp.symbols("x y")
    a = DeclaredSystem(x**2 / 2 + y**2 / 2 + x**2 * y - y**3 / 3)
    hx, hy_ = hy.make_vars("x", "y")
    b = DeclaredSystem(0.5 * (hx**2 + hy_**2) + hx**2 * hy_ - hy_**3 / 3.0)
    for s in (a, b):
        assert s.critical_energy == pytest.approx(1 / 6, rel=1e-14) and len(s.exits) == 3


def test_make_system_builtins_and_defaults():
    assert make_system() == HenonHeiles()
    assert make_system("henon_heiles", params={"omega": 1.3, "lam": 0.7}) == HenonHeiles(1.3, 0.7)
    assert make_system("henon_heiles", dissipation="quadratic").dissipation == "quadratic"
    assert {"henon_heiles", "contopoulos", "barbanis"} <= set(BUILTINS)  # the built-ins the studies name
    s = make_system("n_exit", params={"n": 4.0})  # a TOML float that is an integer
    assert s.name == "n_exit" and len(s.exits) == 4


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"name": "henon_heils"}, "unknown built-in 'henon_heils' .*" + ", ".join(BUILTINS)),
        ({"name": "contopoulos", "params": {"epsilon": 0.2}}, r"unknown parameter\(s\) \['epsilon'\] of 'contopoulos'"),
        ({"name": "contopoulos", "params": {"eps": -1}}, "eps must be a finite number > 0"),
        ({"name": "n_exit", "params": {"n": 2}}, "n must be an integer from 3 to 8"),
        ({"name": "n_exit", "params": {"n": 3.5}}, "'n' must be an integer"),
        ({"name": "henon_heiles", "params": {"omega": 0}}, "henon_heiles: omega must be a finite number > 0"),
        ({"name": "contopoulos", "potential": "x**2 + y**2"}, "either `name`.*or `potential`"),
        ({"potential": "x**2/2 + y**2/2 - x**3", "dissipation": "cubic"}, "dissipation must be one of"),
        ({"name": "contopoulos", "critical_energy": 1.0}, "cannot be given for the built-in"),
        ({"potential": "x**2/2 + y**2/2 - x**3", "omega": 1.0}, r"unknown key\(s\) \['omega'\]"),
        ({"potential": "x**2/2 + y**2/2 - a*x**3"}, r"unknown symbol 'a'.*declare a parameter in \[system.params\]"),
        ({"potential": "x**2/2 + y**2/2 - a*x**3", "params": {"b": 1}}, r"\['a'\] have no value"),
    ],
)
def test_make_system_errors_name_the_key(kwargs, match):
    with pytest.raises(ConfigError, match=match):
        make_system(**kwargs)


def test_escape_radius_lies_beyond_every_bounded_orbit(conto):
    assert conto.default_escape_radius(1.5) == pytest.approx(max(2 * math.sqrt(1.5), 1.5 * 2.0))
    big = conto.default_escape_radius(10.0)
    assert big == pytest.approx(2 * math.sqrt(10.0), rel=1e-8) and big >= 2 * math.sqrt(10.0)
    # the argument (base.System.default_escape_radius): a bounded orbit of energy E never goes beyond R(E) (here R
    # without the saddle-distance floor, which alone would bound these orbits)
    from hhscatter.model.derive import no_return_radius

    for state in ([0.3, -0.2, 0.9, 0.5], [1.2, 0.0, 0.0, 0.6], [0.0, 0.5, 1.1, 0.1]):
        E = conto.energy(*state)
        R = no_return_radius(conto._landscape, E, 2.0)
        assert E < conto.critical_energy and R < conto.saddle_radius
        res = _ta(conto, state, tol=1e-12).propagate_grid(np.linspace(0, 300, 30001))[5]
        r_max = np.hypot(res[:, 0], res[:, 1]).max()
        assert 0.5 * R < r_max <= R, (E, r_max, R)


@pytest.mark.parametrize(
    "text",
    [
        "0.5*(x**2 + y**2) - 0.25*x**2*y**2",
        "atan(0.5*(x**2 + y**2) + x**2*y - y**3/3)",
        "0.5*(x**2 + y**2) + sqrt(2)*(x**2*y - y**3/3) + 0.01*erf(x**2)*cos(y)",
    ],
)
def test_heyoka_expressions_match_numpy_and_differentiation(text):
    import heyoka as hy

    s = DeclaredSystem(text)
    x, y = hy.make_vars("x", "y")
    V = s.potential_expression(x, y, hy)
    fx, fy = s.force_expressions(x, y, hy)
    pts = np.random.default_rng(3).uniform(-1.2, 1.2, (2, 300))
    v = hy.cfunc([V], vars=[x, y])(pts)[0]
    assert np.allclose(v, s.potential(*pts), rtol=1e-14, atol=1e-15)
    # the simplified force against heyoka's own derivative of V (an independent differentiation)
    got = hy.cfunc([fx, fy], vars=[x, y])(pts)
    want = hy.cfunc([-hy.diff(V, x), -hy.diff(V, y)], vars=[x, y])(pts)
    assert np.allclose(got, want, rtol=1e-13, atol=1e-14)


def test_spec_rebuilds_the_system_and_force_frequency_are_exact(hh3, conto):
    from hhscatter.model.spec import system_from_spec

    n4 = make_system("n_exit", params={"n": 4})
    assert n4.spec() == {"name": "n_exit", "params": {"n": 4}, "dissipation": "linear"}
    assert conto.spec() == {"name": "contopoulos", "params": {"eps": 0.25}, "dissipation": "linear"}
    for s in (n4, conto, DeclaredSystem("0.5*(x**2 + y**2) - eps*x*y**2", {"eps": 0.5}, "quadratic")):
        assert system_from_spec(s.spec()) == s
    fx, fy = hh3.force([0.3, -0.2], [0.1, 0.4])
    want = HenonHeiles().force([0.3, -0.2], [0.1, 0.4])
    assert np.allclose(fx, want[0], rtol=1e-9) and np.allclose(fy, want[1], rtol=1e-9)
    assert fx[0] == -(0.3 + 2 * 0.3 * 0.1)  # exact: −V_x = −(x + 2xy)
    assert conto.frequency == 1.0 and DeclaredSystem("0.5*x**2 + 2*y**2 - x**2*y**2").frequency == 2.0
