"""The estimators of ``hhscatter.analysis.survival`` name the argument they refuse.

Each call gets valid arguments but one, which is a word; the ConfigError must name that argument (the sweep of
every exported function over many wrong things is tests/analysis/test_every_estimator.py).
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis import survival
from hhscatter.errors import ConfigError

N = 40
T_END = np.linspace(0.5, 20.0, N)
OBS = np.arange(N) % 4 > 0
T = np.linspace(0.0, 20.0, 41)
P = np.exp(-0.2 * T)
LIFETIMES = pd.DataFrame({"t_end": T_END, "outcome": np.where(OBS, "escaped", "censored")})

#: {function: valid keyword arguments}
VALID = {
    "choose_t_max": {"t_end": T_END, "observed": OBS, "n_main": 1000},
    "fit_plateau_exponential": {"t_end": T_END, "observed": OBS, "t0": 1.0},
    "rate_status": {"t_end": T_END, "observed": OBS, "tau0": 1.0, "t_stop": 15.0},
    "escape_rate_p_levels": {"t_end": T_END, "observed": OBS, "p_hi": 0.5, "p_lo": 0.01},
    "paired_mle_shift": {
        "t_ref": T_END,
        "observed_ref": OBS,
        "t_alt": 0.9 * T_END,
        "observed_alt": OBS,
        "t_start": 1.0,
        "t_stop": 15.0,
    },  # fmt: skip
    "survival_ratio_slope": {
        "t_ref": T_END,
        "observed_ref": OBS,
        "t_alt": 0.9 * T_END,
        "observed_alt": OBS,
        "window": (1.0, 15.0),
    },  # fmt: skip
    "fit_exponential": {"t": T, "P": P, "window": (1.0, 15.0)},
    "fit_power_law_tail": {"t": T, "P": P, "window": (1.0, 15.0)},
    "mean_kappa_stat_err": {"t": T, "P": P, "P_err": 0.01 * P, "windows": [(1.0, 15.0)]},
    "fit_kappa_energy": {
        "E": np.linspace(0.2, 0.4, 8),
        "kappa": np.linspace(0.1, 0.5, 8),
        "kappa_err": np.full(8, 0.01),
        "E_c": 1 / 6,
    },  # fmt: skip
    "kappa_from_cmeasure": {"return_times": np.linspace(1.0, 5.0, 20), "n_exit": 4},
    "p_level_windows": {"t": T, "P": P},
    "plateau_check": {"P_end": 0.2, "f_censored": 0.01},
    "dead_time_check": {"tau0": 1.0, "t_first": 1.5, "kappa": 0.2},
    "lifetimes_to_arrays": {"lifetimes": LIFETIMES},
    "survival_from_lifetimes": {"lifetimes": LIFETIMES},
}
CASES = [(name, arg) for name, kwargs in VALID.items() for arg in kwargs]


@pytest.mark.parametrize(("name", "arg"), CASES)
def test_a_word_in_place_of_an_argument_is_refused_naming_it(name, arg):
    kwargs = {**VALID[name], arg: "x"}
    with pytest.raises(ConfigError, match=rf"^{re.escape(arg)}\b"):
        getattr(survival, name)(**kwargs)


@pytest.mark.parametrize("name", ["choose_t_max", "fit_plateau_exponential", "rate_status", "escape_rate_p_levels"])
def test_a_mask_one_short_is_refused_naming_it(name):
    with pytest.raises(ConfigError, match="observed"):
        getattr(survival, name)(**{**VALID[name], "observed": OBS[:-1]})


def test_a_table_without_its_columns_is_refused_naming_them():
    with pytest.raises(ConfigError, match="lifetimes lacks the column"):
        survival.lifetimes_to_arrays(LIFETIMES.drop(columns="outcome"))


def test_no_windows_are_refused():
    with pytest.raises(ConfigError, match="windows"):
        survival.mean_kappa_stat_err(T, P, 0.01 * P, [])
