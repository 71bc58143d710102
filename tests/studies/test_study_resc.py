"""Tests of the escape-criterion study ``resc`` and of hhscatter.analysis.geometry.channels.

References are independent of the code under test: closed forms (Wilson
interval), 1-D quadratures of motion along a symmetry axis of the potential,
synthetic samples with known rates, and the engine's own escape times. The
Lyapunov orbits are tested in tests/analysis/geometry/test_channels.py.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, optimize

from hhscatter.analysis.geometry.channels import channel_fractions, return_statistics
from hhscatter.analysis.stats.intervals import wilson_interval
from hhscatter.analysis.survival.paired import paired_mle_shift, survival_ratio_slope
from hhscatter.errors import ConfigError
from hhscatter.integrate.events import CENSORED, ESCAPED
from hhscatter.scene.scene import SceneError


# ---------------------------------------------------------------------------
# binomial fractions
# ---------------------------------------------------------------------------
def test_wilson_interval_closed_forms():
    # k = 0: lower bound 0, upper bound z²/(n + z²)
    p, lo, hi = wilson_interval(0, 10, 1.96)
    assert p == 0 and lo == pytest.approx(0, abs=1e-15)
    assert hi == pytest.approx(1.96**2 / (10 + 1.96**2), rel=1e-12)
    # k = n/2, z = 1: centre 1/2, half-width √(1/(4n) + 1/(4n²))/(1 + 1/n)
    p, lo, hi = wilson_interval(5, 10, 1.0)
    half = math.sqrt(0.025 + 1 / 400) / 1.1
    assert (lo, hi) == (pytest.approx(0.5 - half, rel=1e-12), pytest.approx(0.5 + half, rel=1e-12))
    with pytest.raises(ValueError, match="k ≤ n"):
        wilson_interval(3, 2)


def test_wilson_interval_coverage():
    # ±1σ Wilson intervals cover the true p in ≈ 68 % of binomial samples
    rng = np.random.default_rng(1)
    k = rng.binomial(400, 0.02, 20000)
    _, lo, hi = wilson_interval(k, 400, 1.0)
    cover = np.mean((lo <= 0.02) & (0.02 <= hi))
    assert 0.62 < cover < 0.76


def test_channel_fractions_symmetric_and_biased():
    rng = np.random.default_rng(2)
    sym = channel_fractions(np.concatenate([rng.integers(0, 3, 60000), [-1, -1]]))
    assert sym.n == 60000 and sym.counts.sum() == 60000
    assert np.all(np.abs(sym.frac - 1 / 3) < 4 * np.sqrt(2 / 9 / 60000))
    assert sym.p_value > 1e-4
    biased = channel_fractions(rng.choice(3, 60000, p=[0.4, 0.3, 0.3]))
    assert biased.p_value < 1e-20
    assert biased.lo[0] < 0.4 < biased.hi[0] + 3 * (biased.hi[0] - biased.frac[0])


# ---------------------------------------------------------------------------
# return statistics on hand-made crossing records
# ---------------------------------------------------------------------------
def test_return_statistics_known_sequences():
    # orbit 0: straight out; orbit 1: out past 1.03, back inside r < 1, out again;
    # orbit 2: no crossing at all; orbit 3: dips to r > 1 and back before escaping (not a return)
    rows = [
        (0, 1.0, 1.0, +1),
        (0, 2.0, 1.03, +1),
        (0, 3.0, 2.0, +1),
        (1, 1.0, 1.03, +1),
        (1, 2.0, 1.03, -1),
        (1, 2.5, 1.0, -1),
        (1, 5.0, 1.0, +1),
        (1, 6.0, 1.03, +1),
        (1, 7.0, 2.0, +1),
        (3, 1.0, 1.0, +1),
        (3, 1.5, 1.0, -1),
        (3, 4.0, 1.0, +1),
        (3, 4.5, 1.03, +1),
    ]
    o, t, r, d = (np.array(c) for c in zip(*rows))
    s = return_statistics(o, t, r, d, 4, 1.03)
    np.testing.assert_array_equal(s["returned"], [False, True, False, False])
    np.testing.assert_allclose(s["t_esc"], [2.0, 1.0, np.nan, 4.5])
    np.testing.assert_allclose(s["t_return"], [np.nan, 2.5, np.nan, np.nan])
    np.testing.assert_allclose(s["t_reesc"], [np.nan, 6.0, np.nan, np.nan])
    s2 = return_statistics(o, t, r, d, 4, 2.0)  # nobody returns after crossing r = 2
    np.testing.assert_array_equal(s2["returned"], [False] * 4)
    np.testing.assert_allclose(s2["t_esc"], [3.0, 7.0, np.nan, np.nan])
    with pytest.raises(ValueError, match="sorted"):
        return_statistics(o[::-1], t[::-1], r[::-1], d[::-1], 4, 1.03)


# ---------------------------------------------------------------------------
# follow_orbits against 1-D quadratures along the symmetry axis x = 0
# ---------------------------------------------------------------------------
def _v_axis(y):
    """V(0, y) = y²/2 − y³/3 (ω = λ = 1); on x = 0 the motion stays on the axis."""
    return 0.5 * y * y - y**3 / 3.0


def _time_between(E, a, b):
    """Time to move monotonically from y = a to y = b on the axis at energy E (no turning point inside)."""
    return integrate.quad(
        lambda y: 1.0 / math.sqrt(2.0 * (E - _v_axis(y))), min(a, b), max(a, b), epsabs=1e-14, epsrel=1e-13, limit=200
    )[0]


def _time_to_turning(E, a, yt):
    """Time from y = a down to the turning point yt < a (V(yt) = E) on the −y axis.

    In s = −y the integrand 1/√(2(E − V)) has a 1/√(s_t − s) end singularity: quad's 'alg' weight
    takes it, with g(s) = √(s_t − s)/√(2(E − V(−s))) → 1/√(2 V'(s_t)) at the end.
    """
    st = -yt

    def g(s):
        if st - s < 1e-13:
            return 1.0 / math.sqrt(2.0 * (st + st * st))  # dV(−s)/ds = s + s² at s_t
        return math.sqrt(st - s) / math.sqrt(2.0 * (E - _v_axis(-s)))

    return integrate.quad(g, -a, st, weight="alg", wvar=(0.0, -0.5), epsabs=1e-14, epsrel=1e-13)[0]


def _follow(ics, radii, r_far=10.0, t_max=100.0, r_esc=1.03):
    """The engine's follow mode (batch driver) on these initial conditions: (lifetimes, crossings)."""
    from hhscatter.integrate.engine import run_chunk
    from hhscatter.scene.scene import Follow, Scene

    ics = np.atleast_2d(np.asarray(ics, dtype=float))
    sc = Scene(energy=0.3, n=len(ics), r_esc=r_esc, r_far=r_far, t_max=t_max, follow=Follow(tuple(radii)))
    res = run_chunk(sc, ics, np.arange(len(ics)))
    return res.lifetimes, res.crossings


def test_follow_straight_out_never_returns():
    # along the channel-0 axis beyond the saddle, moving outward: it only goes out
    E = 0.3
    y0 = 1.01
    ic = [0.0, y0, 0.0, math.sqrt(2 * (E - _v_axis(y0)))]
    lt, cr = _follow([ic], [1.0, 1.03, 1.5, 2.0])
    assert lt["outcome"][0] == ESCAPED
    assert np.all(cr["direction"] == 1)
    np.testing.assert_allclose(cr["radius"], [1.03, 1.5, 2.0])
    expect = [_time_between(E, y0, R) for R in (1.03, 1.5, 2.0)]
    np.testing.assert_allclose(cr["t"], expect, rtol=1e-10, atol=1e-12)
    assert lt["t_end"][0] == cr["t"][0]  # the escape time is the first outward r_esc crossing
    assert abs(lt["e_end"][0] - E) < 1e-12
    s = return_statistics(cr["traj_id"], cr["t"], cr["radius"], cr["direction"], 1, 1.03)
    assert not s["returned"][0]


def test_follow_known_return_through_the_wall():
    # from the origin straight down the −y axis (towards the wall between channels 1 and 2):
    # out past r = 1.03 to the turning point yt, back through the origin and out along channel 0
    E = 1.2
    yt = optimize.brentq(lambda y: _v_axis(y) - E, -3.0, -0.5, xtol=1e-15)
    assert yt < -1.03
    ic = [0.0, 0.0, 0.0, -math.sqrt(2 * E)]
    lt, cr = _follow([ic], [1.0, 1.03])
    s = return_statistics(cr["traj_id"], cr["t"], cr["radius"], cr["direction"], 1, 1.03)
    t_out_1, t_out_103 = _time_between(E, 0.0, -1.0), _time_between(E, 0.0, -1.03)
    t_turn = _time_between(E, 0.0, -1.03) + _time_to_turning(E, -1.03, yt)
    t_back_1 = 2 * t_turn - t_out_1
    t_origin = 2 * t_turn
    t_up_103 = t_origin + _time_between(E, 0.0, 1.03)
    assert s["returned"][0]
    assert lt["t_end"][0] == pytest.approx(t_out_103, rel=1e-10)
    assert s["t_esc"][0] == pytest.approx(t_out_103, rel=1e-10)
    assert s["t_return"][0] == pytest.approx(t_back_1, rel=1e-9)
    assert s["t_reesc"][0] == pytest.approx(t_up_103, rel=1e-9)
    # the crossing sequence: out 1, out 1.03, in 1.03, in 1, out 1, out 1.03
    np.testing.assert_array_equal(cr["direction"], [1, 1, -1, -1, 1, 1])
    np.testing.assert_allclose(cr["radius"], [1.0, 1.03, 1.03, 1.0, 1.0, 1.03])


def test_follow_censors_bounded_orbit_and_checks_input():
    # below E_c the orbit never reaches r = 1: censored at t_max, no crossing
    lt, cr = _follow([[0.1, 0.0, 0.0, 0.3]], [1.0, 1.03], t_max=50.0)
    assert lt["outcome"][0] == CENSORED and lt["t_end"][0] == 50.0 and cr["t"].size == 0
    with pytest.raises(SceneError, match="r_far"):
        _follow([[0.1, 0.0, 0.0, 0.3]], [1.0, 20.0], r_far=10.0)


def test_follow_matches_the_scalar_reference_and_plain_escape_times():
    # the batch follow mode against the scalar driver in long double (same events, independent
    # precision), and its escape times against a plain run (follow compiles more events, which
    # enter step-size control, so only short orbits agree to rounding)
    from hhscatter.integrate.engine import run_chunk, simulate_orbit
    from hhscatter.scene.ics import region_ics
    from hhscatter.scene.scene import Follow, Scene

    sc = Scene(energy=0.3, n=120, seed=5, r_esc=1.03, t_max=200.0, follow=Follow((1.0, 1.03, 1.5)))
    ics = region_ics(sc, 0, sc.n)
    res = run_chunk(sc, ics, np.arange(sc.n))
    plain = run_chunk(sc.replace(follow=None), ics, np.arange(sc.n)).lifetimes
    lt, cr = res.lifetimes, res.crossings
    short = lt["t_end"] < 15
    assert short.sum() > 40
    np.testing.assert_allclose(lt["t_end"][short], plain["t_end"][short], rtol=1e-8, atol=1e-9)
    for k in np.flatnonzero(short)[:12]:
        ref = simulate_orbit(sc, ics[k], fp_type=np.longdouble)
        mine = cr["t"][cr["traj_id"] == k]
        theirs = np.array([float(c[0]) for c in ref.crossings])
        assert len(mine) == len(theirs), k
        np.testing.assert_allclose(mine, theirs, rtol=1e-9, atol=1e-10)
        assert float(ref.t_end) == pytest.approx(lt["t_end"][k], rel=1e-9)


# ---------------------------------------------------------------------------
# paired κ differences on synthetic lifetimes
# ---------------------------------------------------------------------------
def _exp_sample(rng, kappa, n, t_max=np.inf):
    t = rng.exponential(1 / kappa, n)
    obs = t <= t_max
    return np.minimum(t, t_max), obs


def test_paired_shift_constant_delay_and_extra_hazard():
    rng = np.random.default_rng(7)
    k, n = 0.2, 200000
    t0, o0 = _exp_sample(rng, k, n, t_max=60.0)
    # a constant delay of every escape: no change of κ, and the pairing shrinks the error
    ps = paired_mle_shift(t0, o0, t0 + 1.5, o0, 5.0, 30.0)
    assert abs(ps.shift) < 3 * ps.shift_err
    assert ps.shift_err < 0.5 * ps.shift_err_unpaired
    rs = survival_ratio_slope(t0, o0, np.minimum(t0 + 1.5, 60.0), o0, (5.0, 30.0))
    assert abs(rs.shift) < 3 * rs.shift_err
    assert rs.offset == pytest.approx(k * 1.5, abs=0.01)  # log P ratio = κ × delay
    # an extra independent hazard Δ (thinning): κ_alt = κ + Δ exactly
    d = 0.02
    extra = rng.exponential(1 / d, n)
    t1, o1 = np.minimum(t0, extra), o0 | (extra < t0)
    ps = paired_mle_shift(t0, o0, t1, o1, 5.0, 30.0)
    assert abs(ps.shift - d) < 3 * ps.shift_err
    rs = survival_ratio_slope(t0, o0, t1, o1, (5.0, 30.0))
    assert abs(rs.shift - d) < 3 * rs.shift_err


def test_paired_shift_independent_samples_error():
    # for independent samples the paired error reduces to the unpaired one, ≈ √(κ²/D + κ'²/D')
    rng = np.random.default_rng(8)
    t0, o0 = _exp_sample(rng, 0.2, 100000)
    t1, o1 = _exp_sample(rng, 0.25, 100000)
    ps = paired_mle_shift(t0, o0, t1, o1, 2.0, 20.0)
    assert ps.shift_err == pytest.approx(ps.shift_err_unpaired, rel=0.05)
    assert abs(ps.shift - 0.05) < 3 * ps.shift_err
    with pytest.raises(ConfigError, match="t_alt must have one value per orbit of t_ref"):
        paired_mle_shift(t0, o0, t1[:10], o1[:10], 2.0, 20.0)


# ---------------------------------------------------------------------------
# end to end at scale 'tiny'
# ---------------------------------------------------------------------------
def test_resc_study_tiny_end_to_end(tiny_studies):
    import json

    import pandas as pd

    out = tiny_studies / "resc" / "out" / "tiny"
    assert (out / "resc.png").stat().st_size > 10000
    doc = json.loads((out / "resc.json").read_text())
    assert doc["default_r_esc"]["recommended"] > doc["default_r_esc"]["lyapunov_r_max_at_max_energy"]
    k = pd.read_parquet(out / "derived" / "kappa.parquet")
    assert len(k) == 12 and np.all(k.kappa > 0)
    for _, g in k.groupby("energy"):
        g = g.sort_values("r_esc")
        assert np.all(np.diff(g.flight_mean) > 0)  # farther radius, later escape
    ret = pd.read_parquet(out / "derived" / "returns.parquet")
    assert np.all((ret.frac >= 0) & (ret.frac <= 1))
    # beyond every Lyapunov orbit nothing comes back
    assert ret[ret.r_esc >= 1.5].n_returned.sum() == 0
    ch = pd.read_parquet(out / "derived" / "channels.parquet")
    sums = ch.groupby(["energy", "r_esc", "subset"]).frac.sum()
    np.testing.assert_allclose(sums.to_numpy(), 1.0)
