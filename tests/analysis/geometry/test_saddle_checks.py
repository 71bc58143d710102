"""The checks of a saddle measurement against the open baker map, whose λ̄ and d₁ are known in closed form
(tests/analysis/geometry/test_saddle.py states the map and its closed forms), and against exact lines."""

import math

import numpy as np
import pytest

from hhscatter.analysis.geometry.saddle import information_dimension_neighbours, mean_lyapunov, saddle_points
from hhscatter.analysis.geometry.saddle_checks import information_dimension_radius, interval_lyapunov, tmin_trend
from hhscatter.errors import ConfigError
from tests.analysis.geometry.test_saddle import TWO_SCALE, closed_forms, natural_measure, sprinkle


def _covered(a, seeds):
    truth = 2 * closed_forms(a, a)["d1u"]
    out = []
    for seed in seeds:
        P, orbits = natural_measure(a, 2000, 5, seed)
        d = information_dimension_radius(P, groups=orbits, n_boot=20, seed=seed)
        out.append((abs(d.value - truth) <= 2 * d.err, d.err / truth))
    return out


def test_radius_information_dimension_covers_the_uniform_baker_measure():
    """10⁴ points (2000 orbits of 5 iterates) of the area-preserving baker map, a = (0.45, 0.45): the plane's
    D₁ = 2d₁ᵘ inside the 2σ interval, to ≤ 2 %."""
    for covered, rel in _covered((0.45, 0.45), [0, 1]):
        assert covered and rel < 0.02


@pytest.mark.slow
@pytest.mark.parametrize(("a", "max_rel"), [((0.45, 0.45), 0.02), ((0.6, 0.25), 0.03), ((0.7, 0.1), 0.06)])
def test_radius_information_dimension_covers_the_closed_form_over_seeds(a, max_rel):
    """The 2σ interval covers the closed form in at least 9 of 10 seeds, near-uniform and strongly non-uniform
    measures (q = 0.875, 0.125) alike."""
    res = _covered(a, range(10))
    assert sum(c for c, _ in res) >= 9, res
    assert max(r for _, r in res) < max_rel, res


def test_radius_and_neighbour_estimators_agree_on_the_same_points():
    """The two estimators weigh a non-uniform measure differently at finite scales; on the baker's measure
    (a = (0.6, 0.25)) both read the closed form, so they agree within their errors on the same points."""
    a = (0.6, 0.25)
    P, orbits = natural_measure(a, 2000, 5, 4)
    r = information_dimension_radius(P, groups=orbits, n_boot=20)
    nb = information_dimension_neighbours(P, groups=orbits, n_boot=20)
    assert abs(r.value - nb.value) <= 2 * math.hypot(r.err, nb.err), (r, nb)
    assert r.method.startswith("fixed-radius") and r.eps_range[1] <= np.ptp(P, axis=0).max() / 8


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda P: information_dimension_radius(P, per_factor_two=0), "per_factor_two"),
        (lambda P: information_dimension_radius(P, min_count=0.0), "min_count"),
        (lambda P: information_dimension_radius(P, max_empty=1.0), "max_empty"),
        (lambda P: information_dimension_radius(P, eps_min=-1.0), "eps_min"),
        (lambda P: information_dimension_radius(P, eps_max=0.0), "eps_max"),
        (lambda P: information_dimension_radius(P, groups=np.zeros(3)), "groups"),
        (lambda P: information_dimension_radius(P, n_boot=-1), "n_boot"),
        (lambda P: information_dimension_radius(P[:1]), "at least 2"),
        (lambda P: information_dimension_radius(P, eps_min=0.1), "fewer than 4 radii"),
    ],
)
def test_radius_dimension_refuses_bad_input_naming_it(call, name):
    P = np.random.default_rng(0).random((1000, 2))
    with pytest.raises(ConfigError, match=name):
        call(P)


def test_tmin_trend_extrapolates_a_line_in_one_over_t_min():
    """Values on v = 0.8 − 3/t_min with 1 % noise: the extrapolation covers 0.8, the slope −3 is resolved."""
    rng = np.random.default_rng(5)
    t = np.array([10.0, 15.0, 20.0, 30.0, 40.0])
    err = np.full(t.size, 0.01)
    tr = tmin_trend(t, 0.8 - 3.0 / t + rng.normal(0, 0.01, t.size), err)
    assert abs(tr.extrapolated - 0.8) <= 2 * tr.extrapolated_err and not tr.converged
    assert abs(tr.slope + 3.0) <= 2 * tr.slope_err and tr.n == 5
    assert tr.bound >= abs(tr.extrapolated - tr.last)


def test_tmin_trend_of_a_constant_is_converged():
    tr = tmin_trend([7.0, 8.0, 9.0, 10.0], [0.70, 0.71, 0.69, 0.70], [0.01, 0.012, 0.02, 0.02])
    assert (
        tr.converged and abs(tr.slope) <= 2 * tr.slope_err and tr.step_z == pytest.approx(0.01 / math.hypot(0.02, 0.02))
    )


@pytest.mark.parametrize(
    ("args", "name"),
    [
        (([1.0, 2.0], [0.5, 0.5], [0.1, 0.1]), "at least 3"),
        (([1.0, 3.0, 2.0], [0.5] * 3, [0.1] * 3), "increasing"),
        (([1.0, 2.0, 3.0], [0.5] * 3, [0.1, 0.0, 0.1]), "err"),
        (([1.0, 2.0, 3.0], [0.5] * 2, [0.1] * 3), "one entry per selection"),
        (([1.0, 2.0, float("nan")], [0.5] * 3, [0.1] * 3), "t_min"),
    ],
)
def test_tmin_trend_refuses_bad_input_naming_it(args, name):
    with pytest.raises(ConfigError, match=name):
        tmin_trend(*args)


def test_interval_lyapunov_reads_the_baker_exponent_without_the_way_in_and_out():
    """Sprinkler orbits of the two-scale baker map: Λ summed from the step log-stretches up to t_a = 12 and
    t_b = 18 (all orbits live ≥ 30 steps) gives the closed-form λ̄ within 3σ."""
    ref = closed_forms(**TWO_SCALE)
    life, states = sprinkle(**TWO_SCALE, n0=400_000, t_min=30, seed=7)
    sp = saddle_points(life, states, t_min=30, window=(0.0, 1.0), columns=["lam"])
    pts = sp.points
    la = pts[pts["t"] <= 12].groupby("traj_id")["lam"].sum()
    lb = pts[pts["t"] <= 18].groupby("traj_id")["lam"].sum()
    lam = interval_lyapunov(la.to_numpy(), lb.reindex(la.index).to_numpy(), 12.0, 18.0, n_boot=200)
    assert abs(lam.value - ref["lam"]) <= 3 * lam.err, (lam.value, lam.err, ref["lam"])
    assert lam.n_orbits == sp.n_orbits > 100


def test_interval_lyapunov_removes_an_offset_that_biases_the_whole_life_mean():
    """Λ(t) = Λ₀ + λ t on every orbit (a way in that stretches by Λ₀ = −3): over the whole life ΣΛ/ΣT is biased by
    Λ₀/T; between two times the offset cancels and λ is exact."""
    T = np.linspace(30.0, 60.0, 50)
    whole = mean_lyapunov(-3.0 + 0.25 * T, T, n_boot=0)
    mid = interval_lyapunov(-3.0 + 0.25 * 10.0 + 0 * T, -3.0 + 0.25 * 25.0 + 0 * T, 10.0, 25.0, n_boot=0)
    assert whole.value < 0.25 - 0.05 and mid.value == pytest.approx(0.25, rel=1e-12)


@pytest.mark.parametrize(
    ("args", "name"),
    [
        (([1.0, 2.0], [3.0], 1.0, 2.0), "one value per orbit"),
        (([1.0, 2.0], [3.0, 4.0], 2.0, 2.0), "t_a < t_b"),
        (([1.0, 2.0], [3.0, 4.0], -1.0, 2.0), "t_a < t_b"),
        (([1.0, 2.0], [3.0, 4.0], [1.0, 1.0, 1.0], 2.0), "one time per orbit"),
        (([1.0, float("inf")], [3.0, 4.0], 1.0, 2.0), "log_stretch_a"),
    ],
)
def test_interval_lyapunov_refuses_bad_input_naming_it(args, name):
    with pytest.raises(ConfigError, match=name):
        interval_lyapunov(*args)
