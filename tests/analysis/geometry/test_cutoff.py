"""Property tests (hypothesis) of each orbit's stretch Λ (orbit_stretch) and the share of orbits beyond ln(1/ε)
(stretch_tail): on valid arguments every answer is checked against a computation of its own (a count, a closed form,
the defining equation of the Wilson interval); a wrong argument is refused with a ConfigError that names it, without
a numpy warning on the way."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hhscatter.analysis.geometry.cutoff import orbit_stretch, stretch_tail
from hhscatter.errors import ConfigError

PROFILE = settings(max_examples=60)  # the rest from the suite's profile (conftest.py)
#: 1/ε overflows below this ε
TINY_EPS = 1.0 / np.finfo(float).max
#: absolute slack of the comparisons: a rate or a stretch among the subnormal floats has few digits
SUBNORMAL = 1e-300


def _strict(f, *args):
    """f(*args) with numpy's warnings (overflow, invalid value, division by zero) turned into errors."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return f(*args)


def _as(form, values):
    """``values`` (a list) in the container ``form``: list, tuple or numpy array."""
    return {"list": list, "tuple": tuple, "array": np.asarray}[form](values)


FORMS = st.sampled_from(["list", "tuple", "array"])
STRETCH = st.one_of(st.floats(-50.0, 1e3), st.integers(-5, 100))
EPS = st.floats(min_value=1e-300, max_value=1e3)


@st.composite
def stretches_and_eps(draw):
    """Orbits' stretches and scales ε, some stretches exactly at an ln(1/ε) (a tie is not beyond)."""
    eps = draw(st.lists(EPS, min_size=1, max_size=8))
    lam = draw(st.lists(STRETCH, min_size=1, max_size=40))
    ties = draw(st.lists(st.sampled_from(eps), max_size=3))
    lam = lam + [float(np.log(1.0 / e)) for e in ties]
    order = draw(st.permutations(range(len(lam))))
    return [lam[i] for i in order], eps


# -- stretch_tail on valid arguments -----------------------------------------------------------------------------
@PROFILE
@given(stretches_and_eps(), FORMS, FORMS)
def test_stretch_tail_share_is_the_plain_count_of_stretches_beyond_ln_one_over_eps(drawn, form_l, form_e):
    lam, eps = drawn
    r = _strict(stretch_tail, _as(form_l, lam), _as(form_e, eps))
    L = np.array(lam, dtype=float)
    for j, e in enumerate(eps):
        beyond = L > np.log(1.0 / e)  # strictly beyond: an orbit at exactly ln(1/ε) does not part the pair
        assert r.k[j] == np.count_nonzero(beyond)
        assert r.share[j] == beyond.mean()
    assert r.n == len(lam) and r.eps.tolist() == [float(e) for e in eps]
    assert r.share.shape == r.lo.shape == r.hi.shape == r.k.shape == (len(eps),)


@PROFILE
@given(stretches_and_eps())
def test_stretch_tail_share_never_rises_with_ln_one_over_eps_and_stays_in_zero_one(drawn):
    lam, eps = drawn
    eps = sorted(eps, reverse=True)  # ln(1/ε) increasing
    r = _strict(stretch_tail, lam, eps)
    assert np.all((r.share >= 0) & (r.share <= 1))
    assert np.all(np.diff(r.share) <= 0) and np.all(np.diff(r.k) <= 0)
    assert np.all((r.k >= 0) & (r.k <= r.n))


@PROFILE
@given(stretches_and_eps())
def test_stretch_tail_wilson_bounds_bracket_the_share_and_solve_the_score_equation(drawn):
    """The Wilson 1σ bounds q are the two roots of (p − q)² = q(1 − q)/n in [0, 1], below and above the share p."""
    lam, eps = drawn
    r = _strict(stretch_tail, lam, eps)
    tol = 1e-12
    assert np.all((r.lo >= -tol) & (r.hi <= 1 + tol))
    assert np.all((r.lo <= r.share + tol) & (r.share <= r.hi + tol))
    for q in (r.lo, r.hi):
        np.testing.assert_allclose((r.share - q) ** 2, q * (1 - q) / r.n, rtol=1e-9, atol=1e-15)
    assert np.all(r.hi - r.lo > 0)  # honest at k = 0 and k = n too


@PROFILE
@given(
    st.floats(min_value=5e-324, max_value=TINY_EPS),
    st.lists(st.floats(-50.0, 50.0).filter(lambda d: abs(d) > 1e-6), min_size=1, max_size=20),
)
def test_stretch_tail_counts_beyond_ln_one_over_eps_where_one_over_eps_overflows(eps, offsets):
    """ε below 1/(largest float) is a valid scale, ln(1/ε) = −ln ε ≈ 709–744: stretches around it are counted."""
    x = -math.log(eps)
    r = _strict(stretch_tail, [x + d for d in offsets], [eps, 1.0])
    assert r.k.tolist() == [sum(d > 0 for d in offsets), sum(x + d > 0 for d in offsets)]


# -- orbit_stretch on valid arguments ----------------------------------------------------------------------------
ENERGY = st.floats(0.01, 2.0)
ORBIT_ENERGY = st.one_of(ENERGY, st.floats(min_value=5e-324, max_value=1e300))
T_END = st.floats(0.0, 1e6)


@st.composite
def rates(draw, low=0.0, high=20.0):
    """λ(E) at 1–6 distinct increasing energies."""
    E = sorted(draw(st.lists(ENERGY, min_size=1, max_size=6, unique=True)))
    return E, draw(st.lists(st.floats(low, high), min_size=len(E), max_size=len(E)))


@st.composite
def orbits(draw, max_size=8):
    n = draw(st.integers(1, max_size))
    e0 = draw(st.lists(ORBIT_ENERGY, min_size=n, max_size=n))
    e_end = draw(st.lists(ORBIT_ENERGY, min_size=n, max_size=n))
    return e0, e_end, draw(st.lists(T_END, min_size=n, max_size=n))


def _rate_at(E, lam, e):
    """λ(e) by hand: linear between the finite nodes (E, λ), held at the end values beyond them."""
    nodes = sorted((a, b) for a, b in zip(E, lam) if math.isfinite(a) and math.isfinite(b))
    if e <= nodes[0][0]:
        return nodes[0][1]
    for (a0, b0), (a1, b1) in zip(nodes, nodes[1:]):
        if e <= a1:
            return b0 + (b1 - b0) * (e - a0) / (a1 - a0)
    return nodes[-1][1]


@PROFILE
@given(orbits(), rates(), st.floats(-5.0, 20.0), FORMS)
def test_orbit_stretch_of_a_constant_rate_is_rate_times_lifetime(orb, rate, c, form):
    e0, e_end, t_end = orb
    got = _strict(orbit_stretch, _as(form, e0), _as(form, e_end), _as(form, t_end), rate[0], [c] * len(rate[0]))
    np.testing.assert_allclose(got, c * np.array(t_end), rtol=1e-12, atol=SUBNORMAL)


@PROFILE
@given(orbits(), rates())
def test_orbit_stretch_lies_between_the_smallest_and_largest_rate_times_lifetime(orb, rate):
    """Λ/t_end is a mean of λ(E) over ln E, and the interpolation stays within the nodes' values: so λ ≥ 0 gives
    Λ ≥ 0."""
    e0, e_end, t_end = orb
    E, lam = rate
    got = _strict(orbit_stretch, e0, e_end, t_end, E, lam)
    t = np.array(t_end)
    tol = 1e-12 * max(lam) * t + SUBNORMAL
    assert got.shape == (len(e0),) and np.all(got >= 0)
    assert np.all(got >= min(lam) * t - tol) and np.all(got <= max(lam) * t + tol)


@PROFILE
@given(orbits(), rates(low=-5.0), st.floats(0.0, 1e3))
def test_orbit_stretch_is_linear_in_the_lifetime_and_the_same_both_ways_along_the_history(orb, rate, c):
    """Λ = t_end·⟨λ⟩ with ⟨λ⟩ the mean over ln E between the two end energies: scaling t_end scales Λ, and an
    orbit from e_end to e0 gathers what one from e0 to e_end does."""
    e0, e_end, t_end = orb
    E, lam = rate
    got = _strict(orbit_stretch, e0, e_end, t_end, E, lam)
    scale = max(abs(v) for v in lam) * max(t_end)
    np.testing.assert_allclose(_strict(orbit_stretch, e0, e_end, [c * t for t in t_end], E, lam), c * got,
                               rtol=1e-12, atol=1e-12 * c * scale + SUBNORMAL)  # fmt: skip
    np.testing.assert_allclose(_strict(orbit_stretch, e_end, e0, t_end, E, lam), got, rtol=0,
                               atol=1e-9 * scale + SUBNORMAL)  # fmt: skip


@PROFILE
@given(st.lists(st.tuples(ORBIT_ENERGY, T_END), min_size=1, max_size=8), rates(low=-5.0), st.booleans())
def test_orbit_stretch_of_an_orbit_that_keeps_its_energy_is_the_rate_there_times_lifetime(orb, rate, unmeasured):
    """e0 = e_end: Λ = λ(e0)·t_end, λ interpolated linearly between the finite nodes (NaN nodes: not measured)."""
    e, t = (list(v) for v in zip(*orb))
    E, lam = rate
    if unmeasured:
        E, lam = [*E, 0.5, math.nan], [*lam, math.nan, 3.0]
    got = _strict(orbit_stretch, e, e, t, E, lam)
    want = np.array([_rate_at(E, lam, v) * tv for v, tv in zip(e, t)])
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * max(1.0, float(np.max(np.abs(want)))))


@PROFILE
@given(
    st.lists(st.tuples(ENERGY, ENERGY, T_END), min_size=1, max_size=8),
    st.floats(0.0, 5.0),
    st.floats(-5.0, 5.0),
    st.lists(ENERGY, min_size=0, max_size=4),
)
def test_orbit_stretch_of_a_linear_rate_is_its_closed_form_within_the_trapezoid_error(orb, a, b, inner):
    """λ = a + bE on nodes spanning every orbit: ⟨λ⟩ = a + b⟨E⟩ over ln E with ⟨E⟩ = e0·(e^L − 1)/L, L = ln(e_end/e0);
    the trapezoid rule on 513 points in ln E errs by at most h²/12·max|d²λ/du²| = h²/12·|b|·max(e0, e_end)·L²."""
    E = sorted({0.01, 2.0, *inner})  # extra nodes on the same line change nothing
    e0, e_end, t = (np.array(v) for v in zip(*orb))
    got = _strict(orbit_stretch, e0, e_end, t, E, [a + b * v for v in E])
    L = np.log(e_end / e0)
    mean_E = e0 * np.where(L == 0, 1.0, np.expm1(L) / np.where(L == 0, 1.0, L))
    bound = (1 / 512) ** 2 / 12 * abs(b) * np.maximum(e0, e_end) * L**2
    assert np.all(np.abs(got - t * (a + b * mean_E)) <= t * (bound + 1e-12 * (a + abs(b) * 2.0)) + SUBNORMAL)


@PROFILE
@given(
    st.floats(1.0, 300.0),
    st.floats(1.0, 300.0),
    st.floats(0.0, 5.0),
    st.floats(0.0, 5.0),
    st.booleans(),
    st.floats(1e-3, 1e3),
)
def test_orbit_stretch_of_far_apart_end_energies_weighs_each_rate_by_its_share_of_ln_e(A, B, p, q, down, t):
    """λ(E) = p below E = 1, q above E = 2, linear between: an orbit between e_lo = 10^−A and e_hi = 10^B spends the
    share ln(1/e_lo)/ln(e_hi/e_lo) of its ln E at p, ln(e_hi/2)/ln(e_hi/e_lo) at q, and gathers
    p ln 2 + (q − p)(1 − ln 2) over ln E in [1, 2]; the end energies' ratio may exceed the largest float."""
    e_lo, e_hi = 10.0**-A, 10.0**B
    span = math.log(e_hi) - math.log(e_lo)
    mean = (p * -math.log(e_lo) + p * math.log(2) + (q - p) * (1 - math.log(2)) + q * math.log(e_hi / 2)) / span
    ends = (e_hi, e_lo) if down else (e_lo, e_hi)
    got = _strict(orbit_stretch, [ends[0]], [ends[1]], [t], [1.0, 2.0], [p, q])[0]
    # λ(E(u)) is monotone in u: the trapezoid rule on 513 points errs by at most the step 1/512 times its rise |q − p|
    assert got == pytest.approx(t * mean, rel=0, abs=t * abs(q - p) / 512 + 1e-9)


def test_orbit_stretch_treats_every_orbit_alike_across_the_blocks_of_4096():
    rng = np.random.default_rng(3)
    e = rng.uniform(0.01, 2.0, 9000)
    t = rng.uniform(0.0, 100.0, e.size)
    E, lam = [0.1, 0.5, 1.5], [0.2, 1.0, 0.4]
    want = np.array([_rate_at(E, lam, v) for v in e]) * t
    np.testing.assert_allclose(orbit_stretch(e, e, t, E, lam), want, rtol=1e-9, atol=1e-12)


def test_orbit_stretch_of_no_orbit_is_empty():
    assert orbit_stretch([], [], [], [0.1, 0.4], [0.5, 1.0]).shape == (0,)


# -- wrong arguments ---------------------------------------------------------------------------------------------
NOT_AN_ARRAY = st.one_of(
    st.sampled_from(["", "x", "0.1", b"0.1"]),
    st.none(),
    st.booleans(),
    st.dictionaries(st.sampled_from("ab"), st.floats(), max_size=2),
    st.lists(st.booleans(), min_size=1, max_size=4),
    st.lists(st.sampled_from(["x", "0.1"]), min_size=1, max_size=3),
    st.lists(st.complex_numbers(allow_nan=False, allow_infinity=False), min_size=1, max_size=3),
    st.just([[1.0], [2.0, 3.0]]),  # ragged
    st.just([1.0, None]),
    st.builds(object),
)
NOT_FINITE = st.sampled_from([math.nan, math.inf, -math.inf])


def _with_one(values, bad):
    """``values`` (a list) with one entry replaced by ``bad``."""
    return st.integers(0, len(values) - 1).map(lambda i: [*values[:i], bad, *values[i + 1 :]])


def _refused_naming(f, kwargs, name):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numpy warning on the way is not a clean refusal
        with pytest.raises(ConfigError) as err:
            f(**kwargs)
    assert re.search(rf"\b{name}\b", str(err.value)), str(err.value)


@st.composite
def wrong_stretch_tail_call(draw):
    """A valid call of stretch_tail with one argument made wrong; (arguments, name of the wrong one)."""
    kw = {"stretch": draw(st.lists(st.floats(0.0, 50.0), min_size=1, max_size=6)),
          "eps": draw(st.lists(EPS, min_size=1, max_size=4))}  # fmt: skip
    name = draw(st.sampled_from(sorted(kw)))
    choices = [NOT_AN_ARRAY, st.just([]), NOT_FINITE.flatmap(lambda v: _with_one(kw[name], v))]
    if name == "eps":
        choices.append(st.floats(max_value=0.0).flatmap(lambda v: _with_one(kw[name], v)))
    kw[name] = draw(draw(st.sampled_from(choices)))  # each kind of wrong value as often as the others
    return kw, name


@PROFILE
@given(wrong_stretch_tail_call())
def test_stretch_tail_refuses_a_wrong_argument_with_a_config_error_naming_it(call):
    _refused_naming(stretch_tail, *call)


@st.composite
def wrong_orbit_stretch_call(draw):
    """A valid call of orbit_stretch with one argument made wrong; (arguments, name of the wrong one)."""
    e0, e_end, t_end = draw(orbits(max_size=5))
    E, lam = draw(rates())
    kw = {"e0": e0, "e_end": e_end, "t_end": t_end, "energies": E, "lam": lam}
    name = draw(st.sampled_from(sorted(kw)))
    choices = [NOT_AN_ARRAY]
    if name in ("e0", "e_end", "t_end"):
        choices.append(NOT_FINITE.flatmap(lambda v: _with_one(kw[name], v)))
        low = st.floats(max_value=0.0) if name != "t_end" else st.floats(max_value=-1e-300)
        choices.append(low.flatmap(lambda v: _with_one(kw[name], v)))
    if name in ("e_end", "t_end", "lam"):  # one value per orbit, or per energy
        n = len(kw[name])
        choices.append(st.lists(st.floats(0.1, 1.0), max_size=8).filter(lambda v: len(v) != n))
    if name == "energies":
        choices.append(st.just([]))
    if name in ("energies", "lam"):  # no node with both E and λ(E) finite
        choices.append(st.lists(NOT_FINITE, min_size=len(E), max_size=len(E)))
    kw[name] = draw(draw(st.sampled_from(choices)))  # each kind of wrong value as often as the others
    return kw, name


@PROFILE
@given(wrong_orbit_stretch_call())
def test_orbit_stretch_refuses_a_wrong_argument_with_a_config_error_naming_it(call):
    _refused_naming(orbit_stretch, *call)
