"""Property-based tests of the notebook API and the estimators it exports (hypothesis).

Random valid inputs give finite, documented answers; random invalid inputs give one of the project's errors
(:mod:`hhscatter.errors`), never another exception. The profile is bounded and derandomized: the same examples
run on every machine, without deadlines (a loaded machine must not fail a test)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import hhscatter
from hhscatter.analysis.noise.kramers import thermal_rate
from hhscatter.analysis.survival.escape_rate import escape_rate_mle
from hhscatter.analysis.survival.long_time import fit_plateau_exponential, rate_status
from hhscatter.errors import HHScatterError

PROFILE = settings(max_examples=30)  # the rest from the suite's profile (conftest.py)
OUTCOMES = ["escaped", "settled", "censored"]


@st.composite
def lifetimes(draw, max_points=3, max_n=60):
    """A valid lifetimes frame: 1–3 points (E0, γ), each 1–60 orbits with times ≥ 0 and outcomes of the table."""
    energies = draw(st.lists(st.sampled_from([0.2, 0.25, 0.3]), min_size=1, max_size=max_points, unique=True))
    frames = []
    for e in energies:
        gamma = draw(st.sampled_from([0.0, 0.0, 0.01, 0.1]))
        n = draw(st.integers(1, max_n))
        t = draw(st.lists(st.floats(0.0, 1e4, allow_nan=False), min_size=n, max_size=n))
        oc = draw(st.lists(st.sampled_from(OUTCOMES), min_size=n, max_size=n))
        frames.append(pd.DataFrame({"traj_id": np.arange(n), "energy": e, "gamma": gamma, "t_end": t, "outcome": oc}))
    return pd.concat(frames, ignore_index=True)


def _quiet(f, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return f(*args, **kwargs)


# -- valid inputs: finite, documented answers -------------------------------------------------------------------
@PROFILE
@given(lifetimes(), st.one_of(st.none(), st.lists(st.floats(0, 2e4), min_size=1, max_size=20).map(sorted)))
def test_survival_is_a_probability_that_never_rises(lt, grid):
    curves = hhscatter.survival(lt, t_grid=grid)
    assert len(curves) == lt.groupby(["energy", "gamma"]).ngroups
    for key, c in curves:
        t, P, err = np.asarray(c.t), np.asarray(c.P), np.asarray(c.P_err)
        known = np.isfinite(P)
        assert np.all((P[known] >= 0) & (P[known] <= 1 + 1e-12)) and np.all(np.diff(P[known]) <= 1e-12)
        assert np.all(np.isfinite(err[known])) and np.all(err[known] >= 0)
        # P is unknown (NaN) only beyond the point's last end time (documented: survival_curve)
        t_last = lt[(lt["energy"] == key[0]) & (lt["gamma"] == key[1])]["t_end"].max()
        assert np.all(t[~known] > t_last)


@PROFILE
@given(lifetimes(max_n=200))
def test_escape_rates_give_a_rate_with_its_error_or_a_note(lt):
    df = _quiet(hhscatter.escape_rates, lt).to_frame()
    assert len(df) == lt.groupby(["energy", "gamma"]).ngroups
    for row in df.itertuples():
        if math.isfinite(row.kappa):
            assert row.gamma == 0 and math.isfinite(row.kappa_err) and row.kappa_err >= 0 and math.isfinite(row.tau0)
            assert row.status in ("exponential", "trapped", "non-exponential", "too few orbits", "empty")
        else:
            assert row.note  # why there is no κ


@PROFILE
@given(lifetimes(max_n=120))
def test_transition_times_give_one_row_per_dissipative_point_and_say_their_partner(lt):
    if not (lt["gamma"] > 0).any():
        with pytest.raises(hhscatter.ConfigError, match="needs dissipative"):
            hhscatter.transition_times(lt)
        return
    df = _quiet(hhscatter.transition_times, lt, t_grid=np.linspace(0, 1e4, 201)).to_frame()
    assert len(df) == lt[lt["gamma"] > 0].groupby(["energy", "gamma"]).ngroups
    for row in df.itertuples():
        for v in (row.tau0, row.tau1, row.tau2):
            assert math.isnan(v) or (math.isfinite(v) and v >= 0)
        assert math.isfinite(row.tau1) or row.note  # no τ1 without saying why


@PROFILE
@given(
    st.integers(1, 400),
    st.floats(0.01, 10.0),
    st.floats(0.0, 1.0),
    st.floats(0.0, 50.0),
    st.integers(0, 2**32 - 1),
)
def test_long_time_estimators_on_censored_exponentials(n, scale, cens_frac, t0, seed):
    """The plateau fit, the rate status and the window MLE: finite answers or the documented 'too few' refusal;
    a window without escapes is a bound."""
    rng = np.random.default_rng(seed)
    t = rng.exponential(scale, n)
    t_max = np.quantile(t, 1 - cens_frac) if cens_frac > 0 else np.inf
    obs = t < t_max
    t = np.minimum(t, t_max)
    try:
        f = fit_plateau_exponential(t, obs, t0)
    except ValueError as e:
        assert "too few orbits" in str(e)
    else:
        assert 0 <= f.q < 1 and math.isfinite(f.kappa) and f.kappa > 0 and 0 <= f.p_inf <= 1
    st_ = rate_status(t, obs, t0, t0 + 3 * scale)
    assert st_.status in ("exponential", "trapped", "non-exponential", "too few orbits", "empty")
    assert "inf%" not in st_.note and "nan%" not in st_.note
    for m in (escape_rate_mle(t, obs, t0, t0 + scale), thermal_rate(t, obs, t0, t0 + scale)):
        rate = getattr(m, "kappa", getattr(m, "rate", None))
        if m.is_bound:
            assert math.isnan(rate) and m.upper95 > 0
        else:
            assert math.isfinite(rate) and rate > 0 and math.isnan(m.upper95)


# -- invalid inputs: the project's errors, never another exception ----------------------------------------------
junk = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(),
    st.floats(),
    st.text(max_size=8),
    st.lists(st.floats(), max_size=4),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=3),
    st.tuples(st.floats(), st.floats(), st.floats()),
)


@st.composite
def broken_lifetimes(draw):
    """A frame that is not a valid lifetimes table: a column missing, or a value that is no time/outcome."""
    lt = draw(lifetimes(max_points=2, max_n=8)).copy()
    how = draw(st.sampled_from(["drop", "t_end", "gamma", "outcome", "energy", "empty"]))
    if how == "drop":
        return lt.drop(columns=draw(st.sampled_from(["t_end", "outcome"])))
    if how == "empty":
        return lt.iloc[:0]
    i = draw(st.integers(0, len(lt) - 1))
    bad = {
        "t_end": st.sampled_from([-1.0, math.nan, math.inf, "soon", None]),
        "gamma": st.sampled_from([-0.1, math.nan, "none"]),
        "outcome": st.sampled_from(["gone", "", 3, None]),
        "energy": st.sampled_from([math.inf, "high"]),
    }[how]
    col = lt[how].astype(object)
    col.iloc[i] = draw(bad)
    return lt.assign(**{how: col})


def _only_project_errors(f, *args, **kwargs):
    try:
        _quiet(f, *args, **kwargs)
    except HHScatterError:
        return
    # a call that succeeds is no failure here: the property is that nothing else is raised


CALLS = {
    "survival": lambda x: hhscatter.survival(x),
    "escape_rates": lambda x: hhscatter.escape_rates(x),
    "transition_times": lambda x: hhscatter.transition_times(x),
    "energy_decay": lambda x: hhscatter.energy_decay(x),
    "plot_survival": lambda x: hhscatter.plot_survival(x),
    "plot_escape_rates": lambda x: hhscatter.plot_escape_rates(x),
    "kappa_cmeasure": lambda x: hhscatter.kappa_cmeasure(x),
    "cmeasure_points": lambda x: hhscatter.cmeasure_points(x, t_from=0.0),
    "basin_measures": lambda x: hhscatter.basin_measures(x, [0], (1, 1)),
    "split_points": lambda x: hhscatter.api.split_points(x),
}


@pytest.mark.parametrize("name", sorted(CALLS))
@PROFILE
@given(x=st.one_of(junk, broken_lifetimes()))
def test_wrong_things_give_the_projects_errors_only(name, x):
    import matplotlib

    matplotlib.use("Agg")
    with pytest.raises(HHScatterError):
        _quiet(CALLS[name], x)


@PROFILE
@given(
    lt=lifetimes(max_points=1, max_n=20),
    t_grid=junk,
    alpha=junk,
    window=junk,
)
def test_wrong_options_give_the_projects_errors_only(lt, t_grid, alpha, window):
    _only_project_errors(hhscatter.survival, lt, t_grid=t_grid)
    _only_project_errors(hhscatter.escape_rates, lt, t_grid=t_grid)
    _only_project_errors(hhscatter.transition_times, lt.assign(gamma=0.01), alpha=alpha, t_grid=t_grid)
    snaps = pd.DataFrame({"traj_id": [0, 0], "t": [0.0, 10.0], "energy": [0.3, 0.29]})
    _only_project_errors(hhscatter.energy_decay, snaps, window=window, energy=0.3, gamma=0.01)
