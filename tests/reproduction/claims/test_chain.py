"""The claims' chain (hhscatter.reproduction.claims.chain): parameters that contradict each other are refused by name
before any run; the escape rate of a table or the reason it has none."""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hhscatter.reproduction.claims.chain import check_params
from hhscatter.reproduction.claims.kappa import rate_or_reason

GOOD = dict(
    ratios=[1.1, 1.6, 2.0],
    probe_ratios=[1.6],
    gammas=[0.0, 0.01, 0.02],
    mu_gamma=0.01,
    mc_ratios=[0.5],
    cm_ratios=[1.6, 2.0],
    c5_ratio=1.6,
    e0_ratio=1.8,
    ev_times=[100.0, 400.0],
    ev_t_max=400.0,
    ev_window=50.0,
    ps_t_max=300.0,
    resc_ratios=[1.2, 1.8],
    cm_t_to=200.0,
    cm_t_max=300.0,
    lab_t_max=600.0,
    lab_band=[10.0, 1e7],
    lab_ftle_regular=0.003,
    lab_ftle_chaotic=0.005,
)


def test_consistent_parameters_pass():
    check_params(SimpleNamespace(**GOOD))


@pytest.mark.parametrize(
    "change, key",
    [
        ({"probe_ratios": [1.7]}, "probe_ratios"),
        ({"gammas": [0.01, 0.02]}, "gammas"),
        ({"gammas": [0.0, 0.02, 0.01]}, "gammas"),
        ({"mu_gamma": 0.05}, "gammas"),
        ({"ratios": [0.9, 1.6, 2.0]}, "ratios"),
        ({"mc_ratios": [1.2]}, "mc_ratios"),
        ({"cm_ratios": [1.7]}, "cm_ratios"),
        ({"c5_ratio": 2.0}, "c5_ratio"),
        ({"ev_times": [500.0]}, "ev_times"),
        ({"ev_window": 300.0}, "ev_window"),
        ({"resc_ratios": [1.2]}, "resc_ratios"),
        ({"cm_t_max": 200.0}, "cm_t_max"),
        ({"lab_t_max": 500.0}, "lab_t_max"),
        ({"lab_band": [1e7, 10.0]}, "lab_band"),
        ({"lab_band": [10.0]}, "lab_band"),
        ({"lab_ftle_regular": 0.01}, "lab_ftle_regular"),
    ],
)
def test_contradicting_parameters_are_refused_naming_the_key(change, key):
    with pytest.raises(ValueError, match=rf"^\[study\]\..*\b{key}\b"):
        check_params(SimpleNamespace(**{**GOOD, **change}))


def test_rate_or_reason_gives_the_rate_or_the_window_rules_message():
    t = np.random.default_rng(5).exponential(20.0, 20000)
    lt = pd.DataFrame({"traj_id": np.arange(t.size), "t_end": t, "outcome": pd.Categorical(["escaped"] * t.size)})
    res, why = rate_or_reason(lt, 50.0)
    assert why == "" and res.kappa == pytest.approx(0.05, rel=0.05)
    res, why = rate_or_reason(lt.iloc[:30], 50.0)  # 30 orbits: fewer than the 50 survivors the windows need
    assert res is None and why
