"""Bad arguments to the estimators of the paired bootstrap, noise, the chaotic saddle and its checks, and censoring,
and to the classes of analysis built from numbers (the κ0(E) law, the survival models' parameters and sub-ensembles,
the homogeneous fit's problem, the Kaplan–Meier grid, the Kramers–Langer rate and its saddles' terms) (hypothesis).

Each call gets one argument replaced by a wrong thing (a wrong type, NaN, a negative time or count, an empty array,
a mismatched length, a window outside the data) and must refuse with a ConfigError that names that argument,
before any work. The profile is bounded and derandomized, as in tests/api/test_properties.py.
"""

from __future__ import annotations

import ast
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hhscatter.analysis.dissipative.mixture import MixtureComponents, MixtureModelParams
from hhscatter.analysis.dissipative.survival_model import HomogeneousProblem, SurvivalModelParams
from hhscatter.analysis.geometry import saddle, saddle_checks
from hhscatter.analysis.noise import (
    KramersLanger,
    SaddleTerm,
    energy_diffusion_rate,
    exit_fractions,
    finite_barrier_fit,
    kramers_langer,
    laplace_coefficient,
    noise_energy_gain,
    reactivation_check,
    reactivation_survival,
    survivor_energies,
    thermal_rate,
    transition_state_correction,
    turnover_rate,
    well_barrier,
    well_energy_diffusion,
    well_shells,
    window_constancy,
)
from hhscatter.analysis.survival.escape_rate import escape_rate_mle
from hhscatter.analysis.survival.kaplan_meier import KaplanMeierGrid
from hhscatter.analysis.survival.kappa_conventions import censored_fraction
from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
from hhscatter.analysis.survival.paired import paired_bootstrap_ratio
from hhscatter.errors import ConfigError
from hhscatter.model import HenonHeiles

PROFILE = settings(max_examples=15)  # the rest from the suite's profile (conftest.py)

#: what is no array of numbers at all
NOT_NUMBERS = st.one_of(
    st.none(), st.booleans(), st.text(max_size=4), st.dictionaries(st.text(max_size=2), st.integers(), max_size=2)
)
#: what is no finite number
NOT_A_NUMBER = st.one_of(
    st.none(), st.booleans(), st.text(max_size=4), st.sampled_from([math.nan, math.inf, -math.inf]), st.just([1.0])
)
N = 12
T = np.linspace(1.0, 12.0, N)
OBS = np.arange(N) % 3 > 0


def _mle(t, obs):
    return obs.sum() / t.sum()


def _bad_array(draw, good: np.ndarray, *, negative=True):
    """A wrong thing in place of the numbers array ``good``: no numbers, empty, NaN/inf, negative, or one short."""
    how = draw(st.sampled_from(["junk", "empty", "nan", "inf", "short"] + (["negative"] if negative else [])))
    if how == "junk":
        return draw(NOT_NUMBERS)
    if how == "empty":
        return np.array([])
    if how == "short":
        return good[:-1]
    bad = good.astype(float).copy()
    bad[draw(st.integers(0, good.size - 1))] = {"nan": math.nan, "inf": math.inf, "negative": -1.0}[how]
    return bad


def _refused(name, f, *args, **kwargs):
    with pytest.raises(ConfigError, match=name):
        f(*args, **kwargs)


# -- paired bootstrap ---------------------------------------------------------------------------------------------
@PROFILE
@given(data=st.data(), which=st.sampled_from(["t_ref", "t_alt", "observed_ref", "observed_alt", "n_boot", "seed"]))
def test_paired_bootstrap_ratio_names_the_bad_argument(data, which):
    args = {"t_ref": T, "observed_ref": OBS, "t_alt": 0.9 * T, "observed_alt": OBS, "n_boot": 10, "seed": 0}
    if which.startswith("t_"):
        args[which] = _bad_array(data.draw, T)
    elif which.startswith("observed"):
        args[which] = data.draw(st.one_of(NOT_NUMBERS, st.just(OBS[:-1]), st.just(np.full(N, 0.5))))
    else:
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.integers(-5, 1 if which == "n_boot" else -1), st.just(2.5)))
    kw = {k: args.pop(k) for k in ("n_boot", "seed")}
    _refused(which, paired_bootstrap_ratio, args["t_ref"], args["observed_ref"], args["t_alt"], args["observed_alt"],
             _mle, **kw)  # fmt: skip


@PROFILE
@given(f=st.one_of(NOT_A_NUMBER, st.integers()))
def test_paired_bootstrap_ratio_needs_a_function(f):
    _refused("estimator", paired_bootstrap_ratio, T, OBS, T, OBS, f)


# -- noise --------------------------------------------------------------------------------------------------------
X = np.array([4.0, 6.0, 8.0, 10.0])


@PROFILE
@given(data=st.data(), which=st.sampled_from(["barrier_over_T", "ratio", "ratio_err"]))
def test_finite_barrier_fit_names_the_bad_argument(data, which):
    args = {"barrier_over_T": X, "ratio": 1 - 0.2 / X, "ratio_err": np.full(4, 0.01)}
    args[which] = _bad_array(data.draw, args[which], negative=which != "ratio")
    _refused("barrier_over_T|ratio|ratio_err" if str(args[which]) == str(X[:-1]) else which, finite_barrier_fit,
             **args)  # fmt: skip


@PROFILE
@given(model=st.one_of(NOT_A_NUMBER, st.integers(), st.just(object())))
def test_the_noise_estimators_of_a_system_refuse_what_is_no_system(model):
    for f in (well_barrier, transition_state_correction, laplace_coefficient):
        _refused("model", f, model)
    _refused("model", well_shells, model, 1.0)
    _refused("model", well_energy_diffusion, model, 0.1, 0.1)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["energies", "phase_volume", "flux", "gamma", "temperature", "dof"]))
def test_energy_diffusion_rate_names_the_bad_argument(data, which):
    e = np.linspace(0.0, 1.0, 6)
    args = {"energies": e, "phase_volume": 2 * np.pi * e, "gamma": 0.1, "temperature": 0.2, "dof": 1}
    args["flux"] = (e > 0.5).astype(float)
    if which in ("gamma", "temperature", "dof"):
        args[which] = data.draw(NOT_A_NUMBER)
    else:
        args[which] = _bad_array(data.draw, args[which], negative=which != "energies")
    _refused(which, energy_diffusion_rate, **args)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["x", "y", "direction"]))
def test_laplace_coefficient_names_the_bad_point_or_direction(data, which):
    kw = {which: data.draw(NOT_A_NUMBER if which != "direction" else st.one_of(NOT_NUMBERS, st.just([1.0, 1.0])))}
    if which == "direction" and kw[which] is None:
        return  # None is the default: the plane
    _refused(which, laplace_coefficient, HenonHeiles(), **kw)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["energies", "threshold", "quantiles"]))
def test_survivor_energies_names_the_bad_argument(data, which):
    args = {"energies": np.linspace(0.1, 0.2, 10), "threshold": 0.15, "quantiles": (0.1, 0.5)}
    if which == "energies":
        args[which] = data.draw(st.one_of(NOT_NUMBERS, st.just(np.array([0.1])), st.just(np.array([0.1, math.nan]))))
    elif which == "threshold":
        args[which] = data.draw(NOT_A_NUMBER)
    else:
        args[which] = data.draw(st.one_of(NOT_NUMBERS, st.just((0.0, 0.5)), st.just((0.5, 1.5))))
    _refused(which, survivor_energies, **args)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["sigma", "t"]))
def test_noise_energy_gain_names_the_bad_argument(data, which):
    args = {"sigma": 0.02, "t": np.array([10.0, 20.0])}
    bad = st.one_of(NOT_NUMBERS, st.sampled_from([math.nan, math.inf, -1.0]), st.just(np.array([1.0, math.nan])))
    args[which] = data.draw(bad)
    _refused(which, noise_energy_gain, **args)


def test_noise_energy_gain_refuses_shapes_that_do_not_broadcast():
    _refused("sigma and t", noise_energy_gain, np.ones(2), np.ones(3))


@PROFILE
@given(data=st.data(), which=st.sampled_from(["rate", "z_max"]))
def test_window_constancy_names_the_bad_argument(data, which):
    args = {"rate": thermal_rate(T, OBS, 0.0, 12.0), "z_max": 2.0}
    args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.just(-2.0), st.just(0.0)))
    _refused(which, window_constancy, **args)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["t_end", "escaped", "exit_channel", "t_start", "t_stop", "n_exits"]))
def test_exit_fractions_names_the_bad_argument(data, which):
    args = {"t_end": T, "escaped": OBS, "exit_channel": np.arange(N) % 3, "t_start": 0.0, "t_stop": 12.0, "n_exits": 3}
    if which == "t_end":
        args[which] = _bad_array(data.draw, T)
    elif which == "escaped":
        args[which] = data.draw(st.one_of(NOT_NUMBERS, st.just(OBS[:-1]), st.just(np.full(N, 2))))
    elif which == "exit_channel":
        args[which] = data.draw(st.sampled_from([np.arange(N - 1) % 3, np.full(N, 5), np.full(N, "a")]))
    elif which == "n_exits":
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.integers(-3, 0), st.just(2.5)))
    elif which == "t_start":
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.just(-1.0), st.just(12.0), st.just(20.0)))
    else:
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.just(0.0)))
    _refused("t_start" if which == "t_stop" and isinstance(args[which], float) and math.isfinite(args[which])
             else which, exit_fractions, **args)  # fmt: skip


# -- the chaotic saddle -------------------------------------------------------------------------------------------
L = np.linspace(1.0, 40.0, 40)
D = np.linspace(2.0, 80.0, 40)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["log_stretch", "duration", "n_boot", "seed"]))
def test_mean_lyapunov_and_its_convergence_name_the_bad_argument(data, which):
    args = {"log_stretch": L, "duration": D, "n_boot": 20, "seed": 0}
    if which in ("log_stretch", "duration"):
        args[which] = _bad_array(data.draw, args[which], negative=which == "duration")
    else:
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.integers(-5, -1), st.just(2.5)))
    kw = {k: args.pop(k) for k in ("n_boot", "seed")}
    names = "log_stretch and duration" if which in ("log_stretch", "duration") else which
    for f in (saddle.mean_lyapunov, saddle.lyapunov_convergence):
        with pytest.raises(ConfigError, match=f"{which}|{names}"):
            f(args["log_stretch"], args["duration"], **kw)


P = np.random.default_rng(0).random((400, 2))


@PROFILE
@given(data=st.data(), which=st.sampled_from(["points", "weights", "groups", "min_boxes", "eps_min", "n_boot"]))
def test_the_box_counting_dimensions_name_the_bad_argument(data, which):
    kw = {"n_boot": 5}
    if which == "points":
        pts = data.draw(st.one_of(NOT_NUMBERS, st.just(np.empty((0, 2))), st.just(np.full((4, 2), math.nan))))
    else:
        pts = P
        kw[which] = data.draw(
            {
                "weights": st.one_of(NOT_NUMBERS, st.just(np.ones(399)), st.just(-np.ones(400))),
                "groups": st.just(np.zeros(399)),
                "min_boxes": st.one_of(NOT_A_NUMBER, st.integers(-3, 1), st.just(2.5)),
                "eps_min": st.one_of(NOT_A_NUMBER, st.just(-1.0)),
                "n_boot": st.one_of(NOT_A_NUMBER, st.integers(-3, -1), st.just(2.5)),
            }[which]
        )
    fs = [saddle.information_dimension] + ([saddle.capacity_dimension] if which != "weights" else [])
    for f in fs:
        with pytest.raises(ConfigError, match=which):
            f(pts, **kw)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["eps", "f", "n", "eps_range"]))
def test_dimension_from_uncertainty_names_the_bad_argument(data, which):
    eps = np.logspace(-6, -2, 9)
    args = {"eps": eps, "f": np.round(300 * eps**0.2) / 1000, "n": np.full(9, 1000), "eps_range": None}
    if which == "eps_range":
        bad = st.one_of(NOT_A_NUMBER, st.just((1e-2, 1e-6)), st.just((1.0, 2.0)))
        args[which] = data.draw(bad.filter(lambda v: v is not None))  # None is the default: every ε
    else:
        args[which] = _bad_array(data.draw, np.asarray(args[which], dtype=float))
    _refused(which, saddle.dimension_from_uncertainty, args["eps"], args["f"], args["n"], eps_range=args["eps_range"])


@PROFILE
@given(data=st.data(), which=st.sampled_from(["kappa", "kappa_err", "lyapunov", "lyapunov_err", "d1", "d1_err"]))
def test_kantz_grassberger_names_the_bad_argument(data, which):
    args = {"kappa": 0.1, "kappa_err": 0.01, "lyapunov": 0.5, "lyapunov_err": 0.02, "d1": 0.8, "d1_err": 0.05}
    args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.just(-1.0)) if which.endswith("err") else NOT_A_NUMBER)
    _refused(which, saddle.kantz_grassberger, *args.values())


LT = pd.DataFrame({"traj_id": np.arange(4), "t_end": [10.0, 20.0, 30.0, 40.0], "outcome": "escaped"})
STATES = pd.DataFrame({"traj_id": np.repeat(np.arange(4), 5), "t": np.tile(np.linspace(0, 40, 5), 4), "x": 0.1,
                       "y": 0.2})  # fmt: skip


@PROFILE
@given(data=st.data(), which=st.sampled_from(["lifetimes", "states", "t_min", "window", "t_record_end"]))
def test_saddle_points_names_the_bad_argument(data, which):
    args = {"lifetimes": LT, "states": STATES, "t_min": 5.0, "window": (0.25, 0.75), "t_record_end": math.inf}
    args[which] = data.draw(
        {
            "lifetimes": st.one_of(NOT_NUMBERS, st.just(LT.drop(columns="t_end"))),
            "states": st.one_of(NOT_NUMBERS, st.just(STATES.drop(columns="t"))),
            "t_min": st.one_of(NOT_A_NUMBER, st.just(-1.0), st.just(0.0)),
            "window": st.one_of(NOT_A_NUMBER, st.just((0.75, 0.25)), st.just((-0.5, 0.5)), st.just((0.5, 1.5))),
            "t_record_end": st.one_of(st.none(), st.booleans(), st.text(max_size=3), st.just(-1.0), st.just(0.0)),
        }[which]
    )
    _refused(which, saddle.saddle_points, args.pop("lifetimes"), args.pop("states"), **args)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["estimator", "t_mins", "windows"]))
def test_window_dependence_names_the_bad_argument(data, which):
    args = {"estimator": lambda sp: (1.0, 0.1), "t_mins": [5.0], "windows": [(0.25, 0.75)]}
    args[which] = data.draw(
        {
            "estimator": st.one_of(NOT_A_NUMBER, st.integers()),
            "t_mins": st.one_of(st.just([]), st.just([-1.0]), st.just([math.nan])),
            "windows": st.one_of(st.just([]), st.just([(0.75, 0.25)]), st.just([(0.5, 1.5)])),
        }[which]
    )
    _refused(which if which != "windows" or args[which] == [] else "window", saddle.window_dependence, LT, STATES,
             **args)  # fmt: skip


# -- the estimators' own refusals ---------------------------------------------------------------------------------
# -- the saddle's checks: FTLE dimensions, the low-FTLE share, d₁ by radius, t_min trends, interval λ̄ -------------
#: booleans where numbers belong, as an array
BOOLS = st.just(np.ones(40, bool))
#: these estimators refuse before any work: every (argument, wrong thing) pair is cheap, so the profile draws more
EVERY = settings(PROFILE, max_examples=100)
RNG = np.random.default_rng(3)
TT = RNG.uniform(50.0, 150.0, 40)
LL = 0.5 * TT + np.sqrt(0.1 * TT) * RNG.normal(size=40)


def _names(which, f, *args, **kwargs):
    """f refuses with a ConfigError whose message names ``which`` as a word (``err``, not ``error``)."""
    with pytest.raises(ConfigError, match=rf"(?<![\w]){which}(?![\w])"):
        f(*args, **kwargs)


@EVERY
@given(data=st.data(), which=st.sampled_from(["log_stretch", "duration", "kappa", "kappa_err", "q", "form", "n_boot",
                                               "seed"]))  # fmt: skip
def test_ftle_dimension_names_the_bad_argument(data, which):
    args = {"log_stretch": LL, "duration": TT, "kappa": 0.15, "kappa_err": 0.01, "q": 2.0, "form": "partition",
            "n_boot": 5, "seed": 0}  # fmt: skip
    args[which] = data.draw(
        {
            "log_stretch": st.one_of(
                st.just(LL[:-1]), st.just(np.array([])), BOOLS, NOT_NUMBERS, st.just(np.r_[LL[:-1], math.nan])
            ),  # fmt: skip
            "duration": st.one_of(
                st.just(TT[:-1]), st.just(-TT), BOOLS, NOT_NUMBERS, st.just(np.r_[TT[:-1], math.inf])
            ),
            "kappa": st.one_of(NOT_A_NUMBER, st.just(0.0), st.just(-0.1)),
            "kappa_err": st.one_of(NOT_A_NUMBER, st.just(-0.01)),
            "q": NOT_A_NUMBER,
            "form": st.one_of(NOT_A_NUMBER, st.just("gaussian")),
            "n_boot": st.one_of(NOT_A_NUMBER, st.integers(-3, -1), st.just(2.5)),
            "seed": st.one_of(NOT_A_NUMBER, st.integers(-3, -1), st.just(2.5)),
        }[which]
    )
    _names(which, saddle_checks.ftle_dimension, **args)


@EVERY
@given(data=st.data(), which=st.sampled_from(["log_stretch", "duration", "threshold", "n_boot", "seed"]))
def test_low_ftle_share_names_the_bad_argument(data, which):
    args = {"log_stretch": LL, "duration": TT, "threshold": 0.5, "n_boot": 5, "seed": 0}
    args[which] = data.draw(
        {
            "log_stretch": st.one_of(
                st.just(LL[:-1]), st.just(np.array([])), BOOLS, NOT_NUMBERS, st.just(np.r_[LL[:-1], -math.inf])
            ),  # fmt: skip
            "duration": st.one_of(
                st.just(TT[:-1]), st.just(0 * TT), BOOLS, NOT_NUMBERS, st.just(np.r_[TT[:-1], math.nan])
            ),
            "threshold": st.one_of(NOT_A_NUMBER, st.just(0.0), st.just(1.0), st.just(-0.5)),
            "n_boot": st.one_of(NOT_A_NUMBER, st.integers(-3, -1), st.just(2.5)),
            "seed": st.one_of(NOT_A_NUMBER, st.integers(-3, -1), st.just(2.5)),
        }[which]
    )
    _names(which, saddle_checks.low_ftle_share, **args)


@EVERY
@given(data=st.data(), which=st.sampled_from(["points", "groups", "eps_min", "eps_max", "per_factor_two", "min_count",
                                               "max_empty", "n_boot", "seed"]))  # fmt: skip
def test_information_dimension_radius_names_the_bad_argument(data, which):
    args = {"points": P, "groups": np.arange(400) // 4, "eps_min": 0.0, "eps_max": 0.1, "per_factor_two": 4,
            "min_count": 10.0, "max_empty": 0.01, "n_boot": 5, "seed": 0}  # fmt: skip
    args[which] = data.draw(
        {
            "points": st.one_of(
                NOT_NUMBERS,
                st.just(np.empty((0, 2))),
                st.just(np.full((4, 2), math.nan)),
                st.just(np.ones((400, 2), bool)),
            ),  # fmt: skip
            "groups": st.one_of(
                st.just(np.zeros(399)),
                st.just(np.full(400, math.nan)),
                st.just("x"),
                st.just({}),
                st.just(np.array([None, 1] * 200, dtype=object)),
            ),  # fmt: skip
            "eps_min": st.one_of(NOT_A_NUMBER, st.just(-1.0)),
            "eps_max": st.one_of(NOT_A_NUMBER, st.just(0.0), st.just(-0.1)),
            "per_factor_two": st.one_of(NOT_A_NUMBER, st.integers(-3, 0), st.just(2.5)),
            "min_count": st.one_of(NOT_A_NUMBER, st.just(0.0)),
            "max_empty": st.one_of(NOT_A_NUMBER, st.just(1.0), st.just(-0.1)),
            "n_boot": st.one_of(NOT_A_NUMBER, st.integers(-3, -1), st.just(2.5)),
            "seed": st.one_of(NOT_A_NUMBER, st.integers(-3, -1), st.just(2.5)),
        }[which]
    )
    _names(which, saddle_checks.information_dimension_radius, args.pop("points"), **args)


@EVERY
@given(data=st.data(), which=st.sampled_from(["t_min", "value", "err"]))
def test_tmin_trend_names_the_bad_argument(data, which):
    good = {"t_min": np.array([20.0, 40.0, 80.0]), "value": np.array([0.5, 0.55, 0.575]), "err": np.full(3, 0.01)}
    bad = st.one_of(NOT_NUMBERS, st.just(np.array([])), st.just(good[which][:-1]), st.just(np.ones(3, bool)),
                    st.just(np.r_[good[which][:-1], math.nan]), st.just(np.r_[good[which][:-1], math.inf]))  # fmt: skip
    if which == "t_min":
        bad = st.one_of(bad, st.just(np.array([80.0, 40.0, 20.0])), st.just(np.array([-20.0, 40.0, 80.0])))
    if which == "err":
        bad = st.one_of(bad, st.just(np.array([0.01, 0.0, 0.01])))
    args = {**good, which: data.draw(bad)}
    _names(which, saddle_checks.tmin_trend, **args)


@EVERY
@given(data=st.data(), which=st.sampled_from(["log_stretch_a", "log_stretch_b", "t_a", "t_b", "n_boot", "seed"]))
def test_interval_lyapunov_names_the_bad_argument(data, which):
    la = 0.5 + 0.3 * 20 + RNG.normal(0, 0.5, 40)
    args = {"log_stretch_a": la, "log_stretch_b": la + 12.0, "t_a": 20.0, "t_b": 60.0, "n_boot": 5, "seed": 0}
    args[which] = data.draw(
        {
            "log_stretch_a": st.one_of(
                NOT_NUMBERS, st.just(la[:-1]), st.just(np.array([])), BOOLS, st.just(np.r_[la[:-1], math.nan])
            ),  # fmt: skip
            "log_stretch_b": st.one_of(NOT_NUMBERS, st.just(la[:-1]), BOOLS, st.just(np.r_[la[:-1], math.inf])),
            "t_a": st.one_of(NOT_A_NUMBER, st.just(-1.0), st.just(np.full(39, 20.0)), st.just(np.array([]))),
            "t_b": st.one_of(NOT_A_NUMBER, st.just(10.0), st.just(np.full(39, 60.0))),
            "n_boot": st.one_of(NOT_A_NUMBER, st.integers(-3, -1), st.just(2.5)),
            "seed": st.one_of(NOT_A_NUMBER, st.integers(-3, -1), st.just(2.5)),
        }[which]
    )
    _names(which, saddle_checks.interval_lyapunov, **args)


@EVERY
@given(data=st.data(), which=st.sampled_from(["t_end", "observed"]))
def test_censored_fraction_names_the_bad_argument(data, which):
    args = {"t_end": T, "observed": OBS}
    args[which] = data.draw(
        {
            "t_end": st.one_of(
                NOT_NUMBERS,
                st.just(np.array([])),
                st.just(np.ones(N, bool)),
                st.just(np.r_[T[:-1], math.nan]),
                st.just(np.r_[T[:-1], math.inf]),
                st.just(-T),
            ),  # fmt: skip
            "observed": st.one_of(NOT_NUMBERS, st.just(OBS[:-1]), st.just(np.full(N, 0.5))),
        }[which]
    )
    _names(which, censored_fraction, **args)


ANALYSIS = Path(__file__).resolve().parents[2] / "hhscatter" / "analysis"


def _plain_raises(path: Path) -> list[str]:
    """``raise ValueError(…)`` / ``raise TypeError(…)`` statements of one module, as 'module:line'."""
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Raise) and node.exc is not None:
            exc = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
            if isinstance(exc, ast.Name) and exc.id in ("ValueError", "TypeError"):
                out.append(f"{path.relative_to(ANALYSIS)}:{node.lineno}")
    return out


def test_the_estimators_refuse_with_the_projects_own_error():
    """Every refusal of an estimator is a ConfigError (a ValueError too), never a plain ValueError or TypeError."""
    plain = [hit for f in sorted(ANALYSIS.rglob("*.py")) if f.name != "_arguments.py" for hit in _plain_raises(f)]
    assert plain == []


def test_an_exception_class_of_the_estimators_is_the_projects():
    tree = [ast.parse(f.read_text(encoding="utf-8")) for f in sorted(ANALYSIS.rglob("*.py"))]
    bases = {b.id for t in tree for node in ast.walk(t) if isinstance(node, ast.ClassDef) for b in node.bases
             if isinstance(b, ast.Name) and b.id.endswith(("Error", "Exception"))}  # fmt: skip
    assert bases <= {"ConfigError", "HHScatterError"}


@PROFILE
@given(data=st.data(), which=st.sampled_from(["model", "gamma", "temperature"]))
def test_kramers_langer_names_the_bad_argument(data, which):
    args = {"model": HenonHeiles(), "gamma": 1.0, "temperature": 1 / 36}
    args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.just(-1.0), st.just(0.0)))
    _refused(which, kramers_langer, **args)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["kl", "actions"]))
def test_turnover_rate_names_the_bad_argument(data, which):
    args = {"kl": kramers_langer(HenonHeiles(), 1.0, 1 / 18), "actions": 0.5}
    bad = {"kl": st.one_of(NOT_A_NUMBER, st.just(object())),
           "actions": st.one_of(NOT_NUMBERS, st.just(np.array([])), st.just(np.ones(2)), st.just(-1.0),
                                st.just(math.nan))}  # fmt: skip
    args[which] = data.draw(bad[which])
    _refused(which, turnover_rate, **args)


R0 = {"t_end0": T, "escaped0": OBS, "settled0": ~OBS, "t_end": T, "escaped": OBS}


@PROFILE
@given(data=st.data(), which=st.sampled_from(["t", "t_end", "escaped", "settled", "rate"]))
def test_reactivation_survival_names_the_bad_argument(data, which):
    args = {"t": np.array([1.0, 2.0]), "t_end": T, "escaped": OBS, "settled": ~OBS, "rate": 0.1}
    if which == "t":  # a grid of its own: any length
        args[which] = data.draw(st.one_of(NOT_NUMBERS, st.sampled_from([[], [1.0, math.nan], [math.inf], [-1.0]])))
    elif which == "t_end":
        args[which] = _bad_array(data.draw, args[which])
    elif which == "rate":
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.just(-1.0)))
    else:
        args[which] = data.draw(st.one_of(NOT_NUMBERS, st.just(OBS[:-1]), st.just(np.full(N, 2))))
    _refused(which, reactivation_survival, **args)


@PROFILE
@given(data=st.data(), which=st.sampled_from([*R0, "rate", "t_max", "tail_start", "n_grid"]))
def test_reactivation_check_names_the_bad_argument(data, which):
    args = {**R0, "rate": 0.1, "t_max": 12.0, "tail_start": 6.0, "n_grid": 11}
    if which.startswith("t_end"):
        args[which] = _bad_array(data.draw, T)
    elif which in R0:
        args[which] = data.draw(st.one_of(NOT_NUMBERS, st.just(OBS[:-1]), st.just(np.full(N, 2))))
    elif which == "n_grid":
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.integers(-3, 1), st.just(2.5)))
    else:
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.just(-1.0)))
    _refused(which, reactivation_check, **args)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["t_end", "observed", "t_start", "t_stop"]))
def test_escape_rate_mle_names_the_bad_argument(data, which):
    args = {"t_end": T, "observed": OBS, "t_start": 2.0, "t_stop": 10.0}
    if which == "t_end":
        args[which] = data.draw(st.one_of(NOT_NUMBERS, st.just(T[:-1]), st.just(np.r_[T[:-1], math.nan])))
    elif which == "observed":
        args[which] = data.draw(st.one_of(NOT_NUMBERS, st.just(OBS[:-1]), st.just(np.full(N, 0.5))))
    elif which == "t_start":
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.just(-1.0)))
    else:
        args[which] = data.draw(NOT_A_NUMBER)
    _refused(which, escape_rate_mle, **args)


# -- classes built from numbers -----------------------------------------------------------------------------------
LAW = {"E_c": 0.25, "a2": 2.0, "a1": 0.5, "slope": 3.0, "E_switch": 0.4}


@PROFILE
@given(data=st.data(), which=st.sampled_from(sorted(LAW)))
def test_piecewise_kappa_names_the_bad_argument(data, which):
    args = dict(LAW, **{which: data.draw(NOT_A_NUMBER)})
    _refused(which, PiecewiseKappa, **args)


@PROFILE
@given(E_switch=st.floats(-1.0, 0.25))
def test_piecewise_kappa_needs_a_switch_above_the_critical_energy(E_switch):
    _refused("E_switch", PiecewiseKappa, **dict(LAW, E_switch=E_switch))


#: the survival model's parameters (a constant κ0); NaN may stand where the model lets it (a value not measured)
MODEL = {"E0": 0.3, "mu": 0.91, "gamma": 0.01, "tau0": 5.0, "tau2": 30.0, "f_ne": 0.1, "f_e": 0.4, "L": 0.1, "b": 0.2,
         "E_c": 1 / 6}  # fmt: skip
NO_NUMBER = st.one_of(st.none(), st.booleans(), st.text(max_size=4), st.just([1.0]))


@PROFILE
@given(data=st.data(), which=st.sampled_from(["kappa_of_E", *MODEL, "hazard"]))
def test_survival_model_params_names_the_bad_argument(data, which):
    args = dict(MODEL, kappa_of_E=lambda E: np.full(np.shape(E), 0.05))
    if which == "kappa_of_E":
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.integers()))
    elif which == "hazard":
        args[which] = data.draw(st.one_of(st.none(), st.text(max_size=4), st.integers()))
    elif which in ("tau0", "E_c"):
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.just(0.0) if which == "E_c" else st.nothing()))
    else:  # tau2 = None stands for the predicted τ2
        args[which] = data.draw(NO_NUMBER.filter(lambda v: v is not None) if which == "tau2" else NO_NUMBER)
    _refused(which, SurvivalModelParams, **args)


@PROFILE
@given(grid=st.one_of(NOT_NUMBERS, st.sampled_from([[], [1.0, math.nan], [math.inf], [2.0, 1.0], [1.0, 1.0]])))
def test_kaplan_meier_grid_names_the_bad_grid(grid):
    _refused("grid", KaplanMeierGrid, grid)


@PROFILE
@given(data=st.data(), which=st.sampled_from(["kappa_of_E", "components", "tau0", "f_ne_k", "P_tau0", "L", "b", "E_c"]))
def test_mixture_model_params_names_the_bad_argument(data, which):
    one = np.array([1.0])
    components = MixtureComponents(5.0, "energy", np.array([0.2, 0.4]), one, one, 0.3 * one, 0.3 * one, 0.9 * one,
                                   0.01 * one, (5.0, 30.0), 0.01)  # fmt: skip
    args = {"kappa_of_E": lambda E: np.full(np.shape(E), 0.05), "components": components, "tau0": 5.0,
            "f_ne_k": 0.1 * one, "P_tau0": 0.5, "L": 0.1, "b": 0.2, "E_c": 1 / 6}  # fmt: skip
    if which in ("kappa_of_E", "components"):
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.integers()))
    elif which == "f_ne_k":
        args[which] = data.draw(NOT_NUMBERS)
    elif which in ("tau0", "E_c"):
        args[which] = data.draw(st.one_of(NOT_A_NUMBER, st.just(0.0) if which == "E_c" else st.nothing()))
    else:
        args[which] = data.draw(NO_NUMBER)
    _refused(which, MixtureModelParams, **args)


def _refused_first(name, f, **kwargs):
    """f(**kwargs) refused with a ConfigError whose message begins with ``name``."""
    with pytest.raises(ConfigError, match=f"^{name}"):
        f(**kwargs)


#: two sub-ensembles, as :func:`~hhscatter.analysis.dissipative.mixture.mixture_components` builds them (the second
#: has one member: its mu_err is NaN)
COMPONENTS = {"t_ref": 5.0, "by": "rate", "edges": np.array([0.7, 1.0, 1.3]), "weights": np.array([0.75, 0.25]),
              "n_ref": np.array([3, 1]), "E_ref": np.array([0.29, 0.28]), "A": np.array([0.3, 0.3]),
              "mu": np.array([0.8, 1.2]), "mu_err": np.array([0.01, math.nan]), "fit_window": (0.0, math.inf),
              "gamma": 0.01}  # fmt: skip
#: a wrong thing in place of each array of the components, besides those of _bad_array
WRONG_COMPONENT = {
    "edges": [np.array([1.3, 1.0, 0.7])],
    "weights": [np.array([0.5, 0.25]), np.array([1.25, -0.25])],
    "n_ref": [np.array([2.5, 1.0]), np.array([True, True])],
    "A": [np.array([0.3, 0.0])],
    "mu_err": [np.array([0.01, -0.01]), np.array([0.01, math.inf])],
}


def test_the_components_as_built_are_accepted():
    c = MixtureComponents(**COMPONENTS)
    assert c.K == 2 and c.n_ref.dtype == np.int64 and c.fit_window == (0.0, math.inf)


@PROFILE
@given(data=st.data(), which=st.sampled_from(sorted(COMPONENTS)))
def test_mixture_components_name_the_bad_argument(data, which):
    good = COMPONENTS[which]
    if which in ("t_ref", "gamma"):
        bad = data.draw(st.one_of(NOT_A_NUMBER, st.sampled_from([0.0, -0.01]) if which == "gamma" else st.nothing()))
    elif which == "by":
        bad = data.draw(st.one_of(st.none(), st.integers(), st.text(max_size=4).filter(lambda w: w != "rate")))
    elif which == "fit_window":
        bad = data.draw(st.one_of(NOT_A_NUMBER, st.sampled_from([(1.0, 0.0), (math.nan, 1.0), (0.0,), (0.0, True)])))
    elif data.draw(st.booleans()):
        bad = data.draw(st.sampled_from([good[None, :], *WRONG_COMPONENT.get(which, [])]))
    else:
        bad = _bad_array(data.draw, good, negative=which in ("weights", "n_ref", "A", "mu_err"))
        if which == "mu_err" and bad.size == good.size and not (np.isinf(bad) | (bad < 0)).any():
            bad = good[:-1]  # NaN stands where a sub-ensemble has one member: a wrong length instead
    _refused_first(which, MixtureComponents, **dict(COMPONENTS, **{which: bad}))


#: the homogeneous fit's problem on three points (a constant κ0)
PROBLEM = {"tf": np.array([5.0, 10.0, 20.0]), "Pf": np.array([0.5, 0.4, 0.3]), "sf": np.full(3, 0.01),
           "kappa_of_E": lambda E: np.full(np.shape(E), 0.05), "E0": 0.3, "mu": 0.91, "gamma": 0.01, "tau0": 5.0,
           "E_c": 0.2, "hazard": "paper", "space": "log", "free": ("f_ne", "L", "b"), "fixed": {},
           "start": {"f_ne": 0.1, "f_e": 0.4, "L": 0.05}, "b_starts": (0.02, 0.1), "constrain_total": True,
           "P_tau0": 0.5}  # fmt: skip
#: a wrong thing in place of each argument of the problem that is no number or array of numbers
WRONG_IN_PROBLEM = {
    "free": [None, "f_ne", ("f_ne", "f_ne"), ("f_ne", "tau2"), 3],
    "fixed": [None, [("L", 0.1)], {"tau2": 30.0}, {"L": math.nan}, {"L": True}, {"b": "x"}],
    "start": [None, {}, {"f_ne": 0.1, "f_e": 0.4}, {"f_ne": math.inf, "f_e": 0.4, "L": 0.05}],
    "b_starts": [None, (), (0.0,), (0.1, math.nan), (True,), "b", (-1.0,)],
    "constrain_total": [None, 1, "yes", 1.0],
    "hazard": [None, 3, "x", "Paper"],
    "space": [None, 3, "x", "Log"],
}


@PROFILE
@given(data=st.data(), which=st.sampled_from(sorted(PROBLEM)))
def test_homogeneous_problem_names_the_bad_argument(data, which):
    good = PROBLEM[which]
    if which in WRONG_IN_PROBLEM:
        bad = data.draw(st.sampled_from(WRONG_IN_PROBLEM[which]))
    elif which == "kappa_of_E":
        bad = data.draw(st.one_of(NOT_A_NUMBER, st.integers()))
    elif which in ("tf", "Pf", "sf"):
        if data.draw(st.booleans()):
            bad = data.draw(st.sampled_from([good[None, :]] + ([] if which == "tf" else [np.array([0.5, 0.0, 0.3])])))
        else:
            bad = _bad_array(data.draw, good, negative=which != "tf")
        if which == "tf" and bad.ndim == 1 and bad.size == 2:  # one short: Pf no longer matches tf
            _refused("Pf must have one value per time tf", HomogeneousProblem, **dict(PROBLEM, tf=bad))
            return
    else:
        positive = which in ("E0", "E_c", "P_tau0", "gamma")
        bad = data.draw(st.one_of(NOT_A_NUMBER, st.just(-1.0) if positive else st.nothing()))
    _refused_first(which, HomogeneousProblem, **dict(PROBLEM, **{which: bad}))


#: a saddle's term: ΔE = 1/6, ω_b = 1, λ₊ at γ = 1, its prefactor and its rate at ΔE/T = 6
TERM = {"x": 0.0, "y": 1.0, "barrier": 1 / 6, "omega_b": 1.0, "lambda_plus": 0.618, "prefactor": 0.057,
        "rate": 0.057 * math.exp(-6)}  # fmt: skip


@PROFILE
@given(data=st.data(), which=st.sampled_from(sorted(TERM)))
def test_saddle_term_names_the_bad_argument(data, which):
    out_of_range = {"x": [], "y": [], "rate": [-1e-3]}.get(which, [0.0, -1.0])
    bad = data.draw(st.one_of(NOT_A_NUMBER, st.sampled_from(out_of_range) if out_of_range else st.nothing()))
    _refused_first(which, SaddleTerm, **dict(TERM, **{which: bad}))


@PROFILE
@given(data=st.data(), which=st.sampled_from(["gamma", "temperature", "rate", "barrier", "barrier_over_T", "terms"]))
def test_the_kramers_langer_record_names_the_bad_argument(data, which):
    args = {"gamma": 1.0, "temperature": 1 / 36, "rate": TERM["rate"], "barrier": 1 / 6, "barrier_over_T": 6.0,
            "terms": (SaddleTerm(**TERM),)}  # fmt: skip
    if which == "terms":
        bad = data.draw(st.sampled_from([None, (), [SaddleTerm(**TERM)], (TERM,), (SaddleTerm(**TERM), 1.0)]))
    else:
        bad = data.draw(st.one_of(NOT_A_NUMBER, st.sampled_from([-1e-3] if which == "rate" else [0.0, -1.0])))
    _refused_first(which, KramersLanger, **dict(args, **{which: bad}))
