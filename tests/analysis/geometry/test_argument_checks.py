"""The geometry estimators refuse a wrong argument before any work, with a ConfigError that names it.

Each case is one valid call with one argument replaced by a wrong thing; the valid call itself is checked to run.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from hhscatter.analysis.geometry import basins, channels, cutoff, flux
from hhscatter.errors import ConfigError
from hhscatter.model import HenonHeiles

LAB = np.zeros((6, 6), int)

#: (function, valid keyword arguments)
VALID = {
    "commensurate_sides": (basins.commensurate_sides, {"sides": [0.05], "extent": (-1, 1, -1, 1), "n": 200}),
    "every_kth_cell": (basins.every_kth_cell, {"labels": LAB, "subgrids": [2]}),
    "channel_fractions": (channels.channel_fractions, {"channel": np.array([0, 1, 2, -1]), "n_channels": 3}),
    "return_statistics": (
        channels.return_statistics,
        {
            "orbit": [0, 0],
            "t": [1.0, 2.0],
            "radius": [2.0, 1.0],
            "direction": [1, -1],
            "n_orbits": 1,
            "r_esc": 2.0,
            "r_in": 1.0,
        },
    ),  # fmt: skip
    "decision_rate": (
        cutoff.decision_rate,
        {"eps": [1e-2, 1e-4], "times": [np.array([9.0, 10.0, 11.0]), np.array([18.0, 19.0, 20.0])]},
    ),
    "predicted_cutoff": (
        cutoff.predicted_cutoff,
        {"E0": 0.3, "gamma": 0.01, "mu": 1.0, "energies": [0.2, 0.3], "lam": [0.5, 0.5], "e_c": 0.15},
    ),
    "cutoff_comparison": (
        cutoff.cutoff_comparison,
        {
            "E0": 0.3,
            "gamma": 0.02,
            "e_c": 1 / 6,
            "mu": 0.94,
            "mu_err": 0.01,
            "energies": [0.2, 0.3],
            "lam": [0.5, 0.5],
            "lam_err": [0.01, 0.01],
        },
    ),  # fmt: skip
    "initial_escape_rate": (
        flux.initial_escape_rate,
        {"model": HenonHeiles(), "energy": 0.1, "radius": 0.5, "n_phi": 64, "n_r": 32},
    ),
}

#: (function, argument, wrong value)
WRONG = [
    ("commensurate_sides", "sides", "x"),
    ("commensurate_sides", "extent", (1, -1, -1, 1)),
    ("commensurate_sides", "n", None),
    ("every_kth_cell", "labels", np.zeros(6)),
    ("every_kth_cell", "subgrids", [math.nan]),
    ("channel_fractions", "channel", {"a": 1}),
    ("channel_fractions", "channel", [0.5]),
    ("channel_fractions", "n_channels", -1),
    ("channel_fractions", "z", math.nan),
    ("return_statistics", "orbit", [0, 3]),
    ("return_statistics", "t", [1.0, math.nan]),
    ("return_statistics", "radius", None),
    ("return_statistics", "direction", [1]),
    ("return_statistics", "n_orbits", "x"),
    ("return_statistics", "r_esc", -1.0),
    ("decision_rate", "eps", [0.0, 1e-4]),
    ("decision_rate", "times", "x"),
    ("decision_rate", "times", [np.ones(3), "x"]),
    ("predicted_cutoff", "E0", None),
    ("predicted_cutoff", "mu", -1.0),
    ("predicted_cutoff", "energies", {"a": 1}),
    ("predicted_cutoff", "lam", [0.5]),
    ("cutoff_comparison", "mu_err", "x"),
    ("cutoff_comparison", "lam_err", [0.01]),
    ("cutoff_comparison", "e_c", math.inf),
    ("initial_escape_rate", "model", "x"),
    ("initial_escape_rate", "radius", 0.0),
    ("initial_escape_rate", "n_phi", 1.5),
]


@pytest.mark.parametrize("name", sorted(VALID))
def test_the_valid_call_runs(name):
    f, kwargs = VALID[name]
    assert f(**kwargs) is not None


@pytest.mark.parametrize(("name", "arg", "bad"), WRONG, ids=[f"{n}-{a}-{i}" for i, (n, a, _) in enumerate(WRONG)])
def test_a_wrong_argument_is_refused_naming_it(name, arg, bad):
    f, kwargs = VALID[name]
    with pytest.raises(ConfigError, match=arg):
        f(**{**kwargs, arg: bad})


def test_an_energy_below_the_potential_in_the_whole_disk_is_refused():
    with pytest.raises(ConfigError, match="below the potential"):
        flux.initial_escape_rate(HenonHeiles(), energy=-1.0, radius=0.5, n_phi=16, n_r=8)
