"""The geometry estimators refuse a wrong argument before any work, with a ConfigError that names it.

Each case is one valid call with one argument replaced by a wrong thing; the valid call itself is checked to run.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.geometry import (
    basins,
    channels,
    cutoff,
    distance,
    flux,
    paired_distance,
    regularity,
    transfer,
    ulam,
    ulam_convergence,
    uncertainty,
)
from hhscatter.errors import ConfigError
from hhscatter.model import HenonHeiles

LAB = np.zeros((6, 6), int)
RNG = np.random.default_rng(0)
PTS = RNG.random((40, 2))
IDS = np.arange(40)
SECTIONS = pd.DataFrame({"traj_id": [0, 1], "t": [2.0, 3.0], "x": [0.1, 0.2], "y": [0.0, 0.1], "px": [0.1, 0.2],
                         "py": [0.3, 0.1]})  # fmt: skip
TABLE = distance.distance_vs_scale(PTS, PTS[::-2], [0.5, 0.25], n_splits=3)
G = np.random.default_rng(1)
TR = transfer.Transitions(src=G.integers(0, 3, 60), dst=G.integers(-1, 3, 60), T=G.uniform(0.5, 2, 60), n_states=3)
T_END = G.uniform(0.5, 3, 60)
KER, HOLD, LAG = transfer.lag_kernels(TR, T_END, 1.0)
CROSS = transfer.propagate(np.ones(3), KER, LAG, 5)
DIST = lambda A, B: distance.sliced_wasserstein(A, B, 4)  # noqa: E731

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
    "orbit_stretch": (
        cutoff.orbit_stretch,
        {"e0": [0.3, 0.3], "e_end": [0.2, 0.15], "t_end": [10.0, 20.0], "energies": [0.2, 0.3], "lam": [0.4, 0.6]},
    ),
    "stretch_tail": (cutoff.stretch_tail, {"stretch": [1.0, 5.0, 12.0], "eps": [1e-2, 1e-4]}),
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
    "percentile_interval": (paired_distance.percentile_interval, {"values": np.arange(10.0), "level": 0.9}),
    "paired_hellinger_replicates": (
        paired_distance.paired_hellinger_replicates,
        {
            "sets": {"A": (PTS, IDS, "a"), "R": (PTS[::-1], IDS, "r")},
            "pairs": [("A", "R")],
            "boxes": [0.5],
            "extent": (0, 1, 0, 1),
            "n_boot": 3,
        },
    ),  # fmt: skip
    "paired_hellinger_difference": (
        paired_distance.paired_hellinger_difference,
        {
            "A": PTS,
            "B": PTS[:20],
            "R": PTS[::-1],
            "box": 0.5,
            "extent": (0, 1, 0, 1),
            "units_a": IDS,
            "units_b": IDS[:20],
            "units_r": IDS,
            "n_boot": 3,
        },
    ),  # fmt: skip
    "shadow_ics": (
        regularity.shadow_ics,
        {"states": np.array([[0.1, 0.0, 0.3, 0.2]]), "potential": lambda x, y: 0.5 * (x**2 + y**2)},
    ),
    "shadow_indicator": (
        regularity.shadow_indicator,
        {"base_sections": SECTIONS, "shadow_sections": SECTIONS, "traj_ids": [0, 1], "d0": [1e-9, 1e-9], "t_from": 1.0},
    ),  # fmt: skip
    "regular_fraction": (regularity.regular_fraction, {"n_orbits": 10, "n_regular": 2}),
    "threshold_systematic": (regularity.threshold_systematic, {"n_orbits": 10, "growth": [10.0, np.inf, np.nan]}),
    "weighted_line": (uncertainty.weighted_line, {"x": [0, 1, 2], "y": [1, 3, 5], "err": [0.1, 0.1, 0.1]}),
    "local_exponent": (uncertainty.local_exponent, {"eps": [1e-2, 1e-4], "k": [1000, 100], "n": [10000, 10000]}),
    "slim_fractal": (
        uncertainty.slim_fractal,
        {"local": pd.DataFrame({"eps_mid": [1e-2, 1e-4], "d": [1.8, 1.8], "d_err": [0.01, 0.01]})},
    ),
    "points": (distance.points, {"df": SECTIONS}),
    "first_crossings": (distance.first_crossings, {"sections": SECTIONS, "t_from": 1.0}),
    "hellinger": (distance.hellinger, {"p": [0.5, 0.5], "q": [1.0, 0.0]}),
    "total_variation": (distance.total_variation, {"p": [0.5, 0.5], "q": [1.0, 0.0]}),
    "box_histograms": (distance.box_histograms, {"P": PTS, "Q": PTS[::2], "box": 0.5}),
    "histogram_distance": (distance.histogram_distance, {"P": PTS, "Q": PTS[::2], "box": 0.5}),
    "box_distances": (distance.box_distances, {"P": PTS, "Q": PTS[::2], "boxes": [0.5, 0.25]}),
    "distance_vs_scale": (distance.distance_vs_scale, {"P": PTS, "Q": PTS[::2], "boxes": [0.5], "n_splits": 2}),
    "agreement_scale": (distance.agreement_scale, {"table": TABLE}),
    "debiased_distance": (distance.debiased_distance, {"table": TABLE}),
    "agreement_scale_debiased": (distance.agreement_scale_debiased, {"table": TABLE}),
    "wasserstein_1d": (distance.wasserstein_1d, {"x": [0.0, 1.0], "y": [0.5]}),
    "sliced_wasserstein": (distance.sliced_wasserstein, {"P": PTS, "Q": PTS[::2], "n_proj": 4}),
    "bootstrap_distance": (distance.bootstrap_distance, {"P": PTS, "Q": PTS[::2], "fn": DIST, "n_boot": 3}),
    "split_half_noise": (distance.split_half_noise, {"P": PTS, "Q": PTS[::2], "fn": DIST, "n_splits": 2}),
    "split_half_baseline": (distance.split_half_baseline, {"P": PTS, "fn": DIST, "n_splits": 2}),
    "transfer_matrix": (transfer.transfer_matrix, {"tr": TR, "kappa": 0.1}),
    "leading_left": (transfer.leading_left, {"A": np.array([[0.5, 0.5], [0.2, 0.3]])}),
    "spectral_radius": (transfer.spectral_radius, {"A": np.array([[0.5, 0.5], [0.2, 0.3]])}),
    "map_escape_rate": (transfer.map_escape_rate, {"tr": TR}),
    "true_time_kappa": (transfer.true_time_kappa, {"tr": TR}),
    "bootstrap_kappa": (transfer.bootstrap_kappa, {"tr": TR, "n_boot": 2, "rng": 0}),
    "communicating_classes": (transfer.communicating_classes, {"tr": TR}),
    "saddle_class": (transfer.saddle_class, {"tr": TR}),
    "saddle_measure": (transfer.saddle_measure, {"tr": TR, "kappa": 0.1, "keep": [True, True, True]}),
    "sprinkler_weights": (transfer.sprinkler_weights, {"tr": TR, "nu": [0.3, 0.3, 0.4], "kappa": 0.1}),
    "section_flux_density": (
        transfer.section_flux_density,
        {"model": HenonHeiles(), "x": [0.1, 0.2], "y": [0.0, 0.1], "energy": 0.1},
    ),
    "box_index": (transfer.box_index, {"x": [0.1, 0.9], "y": [0.2, 0.5], "extent": (0, 1, 0, 1), "box": 0.5}),
    "lag_kernels": (transfer.lag_kernels, {"tr": TR, "t_end": T_END, "dt": 1.0}),
    "capped_share": (transfer.capped_share, {"tr": TR, "dt": 1.0, "max_lag": 1}),
    "propagate": (transfer.propagate, {"n0": np.ones(3), "K": KER, "L": LAG, "n_steps": 5}),
    "survival_from_crossings": (transfer.survival_from_crossings, {"crossings": CROSS, "H": HOLD}),
    "first_crossing_weights": (
        transfer.first_crossing_weights,
        {"crossings": CROSS, "tr": TR, "dt": 1.0, "k_star": 2},
    ),
    "first_crossing_after": (transfer.first_crossing_after, {"crossings": CROSS, "K": KER, "L": LAG, "k_star": 2}),
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
    ("orbit_stretch", "e0", [0.3, -0.1]),
    ("orbit_stretch", "e_end", [0.2, math.nan]),
    ("orbit_stretch", "e_end", [0.2]),
    ("orbit_stretch", "t_end", [10.0, -1.0]),
    ("orbit_stretch", "t_end", "x"),
    ("orbit_stretch", "lam", [0.5]),
    ("orbit_stretch", "energies", {"a": 1}),
    ("cutoff_comparison", "mu_err", "x"),
    ("cutoff_comparison", "lam_err", [0.01]),
    ("cutoff_comparison", "e_c", math.inf),
    ("initial_escape_rate", "model", "x"),
    ("initial_escape_rate", "radius", 0.0),
    ("initial_escape_rate", "n_phi", 1.5),
    ("percentile_interval", "values", 1.0),
    ("percentile_interval", "values", "x"),
    ("percentile_interval", "level", math.nan),
    ("paired_hellinger_replicates", "sets", [PTS]),
    ("paired_hellinger_replicates", "sets", {"A": (PTS, IDS[:-1], "a"), "R": (PTS, IDS, "r")}),
    ("paired_hellinger_replicates", "pairs", "AR"),
    ("paired_hellinger_replicates", "boxes", [-0.5]),
    ("paired_hellinger_replicates", "extent", None),
    ("paired_hellinger_replicates", "n_boot", 1),
    ("paired_hellinger_difference", "A", PTS[:, :1]),
    ("paired_hellinger_difference", "R", np.full((3, 2), math.nan)),
    ("paired_hellinger_difference", "box", "x"),
    ("paired_hellinger_difference", "units_b", IDS),
    ("paired_hellinger_difference", "level", 1.5),
    ("shadow_ics", "states", "x"),
    ("shadow_ics", "potential", 1.0),
    ("shadow_ics", "delta", -1.0),
    ("shadow_indicator", "base_sections", {"a": 1}),
    ("shadow_indicator", "shadow_sections", SECTIONS.drop(columns="px")),
    ("shadow_indicator", "traj_ids", [0.5, 1]),
    ("shadow_indicator", "d0", [1e-9, 1e-9, 1e-9]),
    ("shadow_indicator", "t_from", None),
    ("regular_fraction", "n_orbits", 0),
    ("regular_fraction", "n_regular", 11),
    ("regular_fraction", "n_regular", "x"),
    ("threshold_systematic", "n_orbits", math.nan),
    ("threshold_systematic", "growth", "x"),
    ("threshold_systematic", "g_max", -1.0),
    ("weighted_line", "x", [1.0, 1.0]),
    ("weighted_line", "y", [1.0]),
    ("weighted_line", "err", [0.1, 0.0, 0.1]),
    ("local_exponent", "eps", [0.0, 1e-4]),
    ("local_exponent", "k", ["a", "b"]),
    ("local_exponent", "n", [1, 2, 3]),
    ("slim_fractal", "local", [1.0]),
    ("slim_fractal", "z", "x"),
    ("points", "df", PTS),
    ("points", "columns", "xy"),
    ("first_crossings", "sections", None),
    ("first_crossings", "t_from", "x"),
    ("first_crossings", "e_min", math.nan),
    ("hellinger", "p", [0.5, -0.5]),
    ("hellinger", "q", [1.0]),
    ("total_variation", "p", "x"),
    ("box_histograms", "P", PTS[:, 0]),
    ("box_histograms", "Q", np.empty((0, 2))),
    ("box_histograms", "box", 0.0),
    ("box_histograms", "extent", (0, 1, 1, 0)),
    ("box_histograms", "weights_P", np.ones(3)),
    ("histogram_distance", "kind", "l2"),
    ("box_distances", "boxes", [math.nan]),
    ("box_distances", "kinds", "hellinger"),
    ("distance_vs_scale", "n_splits", -1),
    ("distance_vs_scale", "m", 0),
    ("distance_vs_scale", "Q", [[math.inf, 0.0]]),
    ("agreement_scale", "table", {"box": [1.0]}),
    ("agreement_scale", "kind", None),
    ("agreement_scale", "z", math.nan),
    ("debiased_distance", "table", pd.DataFrame({"x": [1.0]})),
    ("agreement_scale_debiased", "delta", "x"),
    ("agreement_scale_debiased", "noise_max", -1.0),
    ("wasserstein_1d", "x", []),
    ("wasserstein_1d", "y", [math.nan]),
    ("wasserstein_1d", "p", 0.5),
    ("sliced_wasserstein", "n_proj", 0),
    ("sliced_wasserstein", "seed", "x"),
    ("bootstrap_distance", "fn", "x"),
    ("bootstrap_distance", "n_boot", 0),
    ("split_half_noise", "n_splits", 0),
    ("split_half_baseline", "P", None),
    ("split_half_baseline", "size", 0),
    ("split_half_baseline", "n_splits", 0),
    ("transfer_matrix", "tr", {"src": [0]}),
    ("transfer_matrix", "kappa", "x"),
    ("leading_left", "A", [[0.5, -0.5], [0.2, 0.3]]),
    ("leading_left", "A", np.ones((2, 3))),
    ("leading_left", "tol", 0.0),
    ("spectral_radius", "A", "x"),
    ("map_escape_rate", "tr", None),
    ("true_time_kappa", "xtol", math.nan),
    ("bootstrap_kappa", "n_boot", -1),
    ("communicating_classes", "tr", np.array([])),
    ("saddle_class", "tr", "x"),
    ("saddle_measure", "keep", [True, True]),
    ("saddle_measure", "keep", [False, False, False]),
    ("saddle_measure", "kappa", None),
    ("sprinkler_weights", "nu", [0.5, 0.5]),
    ("sprinkler_weights", "nu", [0.5, -0.5, 1.0]),
    ("section_flux_density", "model", "x"),
    ("section_flux_density", "x", [math.nan, 0.1]),
    ("section_flux_density", "energy", [0.1, 0.1, 0.1]),
    ("section_flux_density", "h", -1.0),
    ("box_index", "x", [0.1]),
    ("box_index", "extent", [0, 1]),
    ("box_index", "box", 0.0),
    ("lag_kernels", "t_end", [1.0]),
    ("lag_kernels", "t_end", np.where(TR.dst < 0, math.nan, T_END)),
    ("lag_kernels", "dt", 0.0),
    ("lag_kernels", "max_lag", 0),
    ("capped_share", "dt", -1.0),
    ("capped_share", "max_lag", "x"),
    ("propagate", "n0", np.ones(2)),
    ("propagate", "K", "x"),
    ("propagate", "L", 0),
    ("propagate", "n_steps", -1),
    ("survival_from_crossings", "crossings", np.ones(3)),
    ("survival_from_crossings", "H", np.ones((2, 2))),
    ("first_crossing_weights", "crossings", np.ones((6, 2))),
    ("first_crossing_weights", "k_star", 9),
    ("first_crossing_weights", "dt", math.inf),
    ("first_crossing_after", "K", np.ones((3, 3))),
    ("first_crossing_after", "k_star", -1),
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


def test_transitions_without_a_return_have_no_finite_kappa():
    every_one_escapes = transfer.Transitions(src=[0, 1], dst=[-1, -1], T=[1.0, 1.0], n_states=2)
    with pytest.raises(ConfigError, match="κ is not finite"):
        transfer.true_time_kappa(every_one_escapes)


# -- Ulam's method: the one-return samples of the module's examples (16 boxes, κ = ln(4/3)/2) ----------------
def _samples() -> pd.DataFrame:
    cell, rank = np.repeat(np.arange(16), 16), np.tile(np.arange(16), 16)
    nxt = np.where(rank % 4 == 1, cell, (cell + 1) % 16)
    return pd.DataFrame({"cell": cell, "rank": rank, "w": 1.0, "censored": False, "ret": rank % 4 > 0, "T": 2.0,
                         "t_end": 2.0, "x1": -0.75 + 0.5 * (nxt % 4), "y1": -0.75 + 0.5 * (nxt // 4), "e1": 0.3})  # fmt: skip


SAMPLES = _samples()
ULAM = dict(tab=SAMPLES, extent=(-1, 1, -1, 1), box=0.5)
RES = ulam_convergence.energy_results(SAMPLES, (-1, 1, -1, 1), 0.5, [1, 2], [4, 16], 16, 3, 2, 1, 0.3)

ULAM_VALID = {
    "grid_shape": (ulam.grid_shape, {"extent": (-1, 1, -1, 1), "box": 0.5}),
    "coarse_index": (ulam.coarse_index, {"cell": np.array([0, 1, 4]), "nx": 4, "c": 2}),
    "sample_transitions": (ulam.sample_transitions, ULAM),
    "saddle_kappa": (ulam.saddle_kappa, {"tr": RES["tr"]}),
    "measure_points": (ulam.measure_points, {"res": RES, "kind": "flux", "n": 5, "rng": np.random.default_rng(0)}),
    "empirical_survival": (ulam.empirical_survival, {"t_end": [1.0, 2.0], "leaving": [True, False], "grid": [1.5]}),
    "hellinger_row": (
        ulam.hellinger_row,
        {"tab": ulam.hellinger_by_box(PTS, PTS[::-2], [0.5], None, 3, 0, 0.5)[0], "j": 0},
    ),  # fmt: skip
    "energy_results": (
        ulam_convergence.energy_results,
        {
            **ULAM,
            "coarsen": [1],
            "subsets": [16],
            "samples": 16,
            "n_boot": 2,
            "n_boot_grid": 0,
            "seed": 1,
            "energy": 0.3,
        },
    ),  # fmt: skip
    "measure_on_cut_boxes": (ulam_convergence.measure_on_cut_boxes, {"res": RES, "samples": 16}),
    "residuals": (ulam_convergence.residuals, {"value": 0.102, "err": 0.003, "ref": 0.1, "ref_err": 0.004}),
    "convergence_record": (
        ulam_convergence.convergence_record,
        {"E": 0.3, "grid": RES["grid"], "boot_grid": None, "kappa_finest": 0.14, "refs": {"kappa0": (0.14, 0.01)}},
    ),
}

ULAM_WRONG = [
    ("grid_shape", "extent", "x"),
    ("grid_shape", "box", -0.5),
    ("coarse_index", "cell", [0.5]),
    ("coarse_index", "nx", 0),
    ("coarse_index", "c", None),
    ("sample_transitions", "tab", SAMPLES.drop(columns="ret")),
    ("sample_transitions", "c", 0),
    ("sample_transitions", "m_max", "x"),
    ("saddle_kappa", "tr", {"a": 1}),
    ("measure_points", "res", {"t": 1}),
    ("measure_points", "kind", "l2"),
    ("measure_points", "n", 0),
    ("measure_points", "rng", 0),
    ("empirical_survival", "t_end", []),
    ("empirical_survival", "leaving", [True]),
    ("empirical_survival", "grid", [math.nan]),
    ("hellinger_row", "tab", SAMPLES),
    ("hellinger_row", "j", 5),
    ("energy_results", "tab", SAMPLES.drop(columns="t_end")),
    ("energy_results", "coarsen", []),
    ("energy_results", "subsets", [0]),
    ("energy_results", "n_boot", -1),
    ("energy_results", "energy", "x"),
    ("measure_on_cut_boxes", "res", None),
    ("measure_on_cut_boxes", "samples", 0.5),
    ("residuals", "ref", 0.0),
    ("residuals", "err", -1.0),
    ("residuals", "value", "x"),
    ("convergence_record", "grid", None),
    ("convergence_record", "refs", [0.14]),
    ("convergence_record", "refs", {"kappa0": "x"}),
    ("convergence_record", "kappa_finest", math.nan),
]


@pytest.mark.parametrize("name", sorted(ULAM_VALID))
def test_the_valid_call_of_ulams_method_runs(name):
    f, kwargs = ULAM_VALID[name]
    assert f(**kwargs) is not None


@pytest.mark.parametrize(
    ("name", "arg", "bad"), ULAM_WRONG, ids=[f"{n}-{a}-{i}" for i, (n, a, _) in enumerate(ULAM_WRONG)]
)
def test_a_wrong_argument_of_ulams_method_is_refused_naming_it(name, arg, bad):
    f, kwargs = ULAM_VALID[name]
    with pytest.raises(ConfigError, match=arg):
        f(**{**kwargs, arg: bad})
