"""The checks of a saddle measurement against the open baker map, whose λ̄ and d₁ are known in closed form
(tests/analysis/geometry/test_saddle.py states the map and its closed forms), and against exact lines."""

import math

import numpy as np
import pytest

from hhscatter.analysis.geometry.saddle import information_dimension_neighbours, mean_lyapunov, saddle_points
from hhscatter.analysis.geometry.saddle_checks import (
    ftle_dimension,
    information_dimension_radius,
    interval_lyapunov,
    low_ftle_share,
    tmin_trend,
)
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
        (lambda P: information_dimension_radius(P, eps_min=0.2, eps_max=0.1), r"below eps_max .*\[0.2, 0.1\]"),
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


def _gaussian_stretches(lam, diff, n, seed):
    """Log-stretches of n orbits with lifetimes uniform in [50, 150]: Λ = λ̄T + √(DT)·N(0, 1) (Gaussian, so the
    cumulant form of the Lyapunov partition function is exact)."""
    rng = np.random.default_rng(seed)
    T = rng.uniform(50.0, 150.0, n)
    return lam * T + np.sqrt(diff * T) * rng.normal(size=n), T


@pytest.mark.parametrize(("q", "form"), [(2.0, "partition"), (2.0, "cumulant"), (0.0, "partition")])
def test_ftle_dimension_covers_the_closed_form_of_gaussian_stretches(q, form):
    """λ̄ = 0.5, D = 0.2, κ = 0.15: d_q = 1 − 2κ/(λ̄ + √(λ̄² − 2(q − 1)Dκ)) (d₂ = 0.6811, d₀ = 0.7175) inside the
    2σ interval in at least 9 of 10 seeds, D inside its own 2σ, and d₂ < 1 − κ/λ̄ < d₀."""
    truth = 1 - 2 * 0.15 / (0.5 + math.sqrt(0.25 - 2 * (q - 1) * 0.2 * 0.15))
    hits = 0
    for seed in range(10):
        L, T = _gaussian_stretches(0.5, 0.2, 3000, seed)
        r = ftle_dimension(L, T, 0.15, q=q, form=form, n_boot=50, seed=seed)
        hits += abs(r.value - truth) <= 2 * r.err
        assert abs(r.diffusion - 0.2) <= 3 * r.diffusion_err, r
        assert (r.value < r.d1) if q > 1 else (r.value > r.d1)
    assert hits >= 9


def _baker_d2(a):
    """d₂ᵘ of the open baker map's natural measure (strips a, weights a_i/Σa): Σ (a_i/Σa)² a_i^(−d₂) = 1."""
    from scipy.optimize import brentq

    a = np.asarray(a)
    w = a / a.sum()
    return brentq(lambda d: float((w**2 * a ** (-d)).sum()) - 1.0, 1e-6, 1.0)


def test_ftle_dimension_reads_the_baker_correlation_dimension():
    """The two-scale baker map (a = (0.7, 0.1)): on its natural measure a step stretches by ln(1/a_i) with
    probability a_i/Σa, so Λ over T steps is a binomial sum; with κ = −ln Σa the partition form's 2σ interval
    covers d₂ᵘ = 0.5779 (closed form) in at least 4 of 5 seeds, while the Gaussian (cumulant) form misses it by
    more than 5σ (the stretches are far from Gaussian); d₂ lies below d₁ᵘ."""
    ref = closed_forms(**TWO_SCALE)
    a, truth = np.asarray(TWO_SCALE["a"]), _baker_d2(TWO_SCALE["a"])
    hits = 0
    for seed in range(5):
        rng = np.random.default_rng(seed)
        T = rng.integers(20, 60, 4000)
        k = rng.binomial(T, a[0] / a.sum())
        L = -k * math.log(a[0]) - (T - k) * math.log(a[1])
        r = ftle_dimension(L, T.astype(float), ref["kappa"], n_boot=50, seed=seed)
        hits += abs(r.value - truth) <= 2 * r.err
        assert r.value < ref["d1u"] and abs(r.d1 - ref["d1u"]) < 0.01
        c = ftle_dimension(L, T.astype(float), ref["kappa"], form="cumulant", n_boot=50, seed=seed)
        assert abs(c.value - truth) > 5 * c.err
    assert hits >= 4


def test_ftle_dimension_at_q_one_is_the_kantz_grassberger_dimension():
    """At q = 1 the fluctuations drop out: d₁ = 1 − κ/λ̄ exactly, whatever the spread; κ's error enters as κ_err/λ̄."""
    L, T = _gaussian_stretches(0.4, 0.5, 500, 3)
    r = ftle_dimension(L, T, 0.1, 0.002, q=1.0, n_boot=0)
    assert r.value == pytest.approx(1 - 0.1 / r.lyapunov, rel=1e-12) == pytest.approx(r.d1, rel=1e-12)
    assert math.isnan(r.err) and r.diffusion > 0.3


def test_ftle_dimension_without_spread_is_one_minus_kappa_over_lambda():
    """The uniform baker map stretches every orbit by ln(1/a) per step: D = 0 and d₂ = d₁ = 1 − κ/λ̄ (closed form)."""
    ref = closed_forms((0.45, 0.45), (0.45, 0.45))
    T = np.arange(10.0, 60.0)
    r = ftle_dimension(T * ref["lam"], T, ref["kappa"], n_boot=20)
    assert r.diffusion == pytest.approx(0.0, abs=1e-20) and r.value == pytest.approx(ref["d1u"], rel=1e-9)
    assert r.shift == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"kappa": 0.0}, "kappa"),
        ({"kappa_err": -1.0}, "kappa_err"),
        ({"q": float("nan")}, "q"),
        ({"n_boot": -1}, "n_boot"),
        ({"form": "exact"}, "form"),
        ({"kappa": 5.0, "form": "cumulant"}, "no root"),
    ],
)
def test_ftle_dimension_refuses_bad_input_naming_it(kwargs, name):
    L, T = _gaussian_stretches(0.5, 0.2, 50, 0)
    with pytest.raises(ConfigError, match=name):
        ftle_dimension(L, T, **{"kappa": 0.15, **kwargs})


def test_ftle_dimension_refuses_a_sample_without_unstable_direction():
    with pytest.raises(ConfigError, match="not > 0"):
        ftle_dimension([-1.0, -2.0], [10.0, 10.0], 0.1)


def test_low_ftle_share_finds_the_sticky_orbits_and_their_threshold_systematic():
    """A sample with 5 % sticky orbits (exponent 0.02) among hyperbolic ones (0.4 ± 0.03): the share is 5 % at
    thresholds 0.25–0.75 of λ̄ (the gap between the two groups), λ̄ of the rest is 0.4, and the mask picks them."""
    rng = np.random.default_rng(5)
    n = 4000
    sticky = np.arange(n) < n // 20
    T = rng.uniform(100.0, 200.0, n)
    ftle = np.where(sticky, 0.02, 0.4) + rng.normal(0, 0.03, n) * ~sticky
    for th in (0.25, 0.5, 0.75):
        s = low_ftle_share(ftle * T, T, threshold=th, n_boot=50)
        assert s.n_low == n // 20 and np.array_equal(s.hyperbolic, ~sticky)
        assert abs(s.rest.value - 0.4) <= 3 * s.rest.err and s.lyapunov < 0.39
        assert s.share_err == pytest.approx(math.sqrt(0.05 * 0.95 / n))


def test_low_ftle_share_of_a_hyperbolic_sample_is_zero():
    T = np.full(100, 80.0)
    s = low_ftle_share(0.3 * T + np.linspace(-2, 2, 100), T, n_boot=0)
    assert s.share == 0.0 and s.share_err == 0.0 and s.hyperbolic.all() and s.rest.n_orbits == 100


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [({"threshold": 0.0}, "threshold"), ({"threshold": 1.0}, "threshold"), ({"threshold": True}, "threshold"),
     ({"n_boot": 1.5}, "n_boot")],
)  # fmt: skip
def test_low_ftle_share_refuses_bad_input_naming_it(kwargs, name):
    with pytest.raises(ConfigError, match=name):
        low_ftle_share([3.0, 4.0, 5.0], [10.0, 10.0, 10.0], **kwargs)
