"""The estimators of ``hhscatter.analysis.dissipative`` name the argument they refuse.

Each call gets valid arguments but one, which is a word; the ConfigError must name that argument (the sweep of
every exported function over many wrong things is tests/analysis/test_every_estimator.py).
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis import dissipative
from hhscatter.errors import ConfigError

N = 40
T_END = np.linspace(0.5, 20.0, N)
OUTCOME = np.where(np.arange(N) % 3 == 0, "settled", "escaped")
T = np.linspace(0.0, 20.0, 41)
P = np.exp(-0.2 * T)
IDS = np.repeat([0, 1], 5)
TS = np.tile(np.arange(5.0), 2)
ES = 0.3 * np.exp(-0.01 * TS)
SNAPSHOTS = pd.DataFrame({"traj_id": IDS, "t": TS, "energy": ES})

#: the keyword arguments of the homogeneous survival model (a constant κ0, 1/time)
MODEL = {"kappa_of_E": lambda E: np.full(np.shape(E), 0.05), "E0": 0.3, "mu": 0.91, "gamma": 0.01, "tau0": 1.0,
         "f_ne": 0.1, "f_e": 0.4, "L": 0.1, "b": 0.2, "E_c": 1 / 6, "hazard": "integrated"}  # fmt: skip

#: {function: valid keyword arguments}
VALID = {
    "tau1": {"t": T, "P_gamma": 0.5 * P, "P_0": P, "tau0": 1.0},
    "tau2_observed_arrays": {"t_end": T_END, "outcome": OUTCOME},
    "settle_quantile_interval": {"t_end": T_END, "outcome": OUTCOME, "p": 0.1},
    "settle_time_quantiles": {"t_end": T_END, "outcome": OUTCOME, "qs": (0.1, 0.5)},
    "power_law_exponent": {"gamma": [0.01, 0.02, 0.04], "tau": [100.0, 50.0, 25.0], "tau_err": [1.0, 1.0, 1.0]},
    "fit_energy_decay": {"t": TS[:5], "mean_E": ES[:5], "E0": 0.3, "gamma": 0.01, "window": (0.0, 4.0)},
    "mu_by_window": {"t": TS[:5], "mean_E": ES[:5], "E0": 0.3, "gamma": 0.01, "windows": [(0.0, 4.0)]},
    "mean_energy_arrays": {"t": TS, "energy": ES},
    "mean_energy": {"snapshots": SNAPSHOTS},
    "energy_histograms_arrays": {"t": TS, "energy": ES, "times": [1.0], "bins": 4},
    "kinetic_fraction_by_time": {"traj_id": IDS, "t": TS, "energy": ES, "gamma": 0.01},
    "decay_path": {"t": [0.0, 1.0], "E0": 0.3, "gamma": 0.01, "mu_of_E": np.sqrt},
    "time_to_energy": {"E0": 0.35, "E1": 0.3, "mu": 0.91, "gamma": 0.01},
    "settling_rate": {"t": T, "tau2": 5.0, "L": 1.0, "b": 0.5},
    "profile_interval": {"chi2_of": np.square, "best": 0.0, "chi2_min": 0.0, "lo_edge": -3.0, "hi_edge": 3.0},
    "mixture_components": {"snapshots": SNAPSHOTS, "gamma": 0.01, "t_ref": 1.0},
    "survival_model_sample": {"t": T, "n_orbits": 100, "seed": 0, **MODEL},
}
CASES = [(name, arg) for name, kwargs in VALID.items() for arg, v in kwargs.items() if v is not None]


@pytest.mark.parametrize(("name", "arg"), CASES)
def test_a_word_in_place_of_an_argument_is_refused_naming_it(name, arg):
    kwargs = {**VALID[name], arg: "x"}
    with pytest.raises(ConfigError, match=rf"^{re.escape(arg)}\b"):
        getattr(dissipative, name)(**kwargs)


def test_outcomes_one_short_are_refused_naming_them():
    with pytest.raises(ConfigError, match="outcome must have one value per orbit"):
        dissipative.settle_time_quantiles(T_END, OUTCOME[:-1])


def test_no_windows_are_refused():
    with pytest.raises(ConfigError, match="windows must hold at least one"):
        dissipative.mu_by_window(TS[:5], ES[:5], 0.3, 0.01, [])


def test_a_snapshots_table_without_energy_is_refused_naming_the_column():
    with pytest.raises(ConfigError, match="snapshots lacks the column"):
        dissipative.mean_energy(SNAPSHOTS.drop(columns="energy"))


@pytest.mark.parametrize(("f_ne", "f_e"), [(0.8, 0.4), (-0.5, 0.4), (0.1, -0.5)])
def test_a_sample_of_a_model_whose_p_leaves_0_1_is_refused(f_ne, f_e):
    with pytest.raises(ConfigError, match=r"^model: its P\(t\) leaves \[0, 1\]"):
        dissipative.survival_model_sample(T, 100, **{**MODEL, "f_ne": f_ne, "f_e": f_e})
