"""Every function the packages of ``hhscatter.analysis`` export shows a runnable example in its own docstring (the
examples run as doctests in the suite).

:data:`WITHOUT_EXAMPLE` lists the exported functions that have none yet; each is a strict expected failure here, so
a function that gains an example fails the suite until it leaves the list, and a new function without one fails at
once: the list only shrinks.
"""

from __future__ import annotations

import inspect

import pytest
from test_every_estimator import FUNCTIONS  # every exported function, by subpackage.name

#: exported functions without an example of their own yet (strict expected failures)
WITHOUT_EXAMPLE: frozenset[str] = frozenset(
    {
        "stats.counted",
        "stats.least_squares_operator",
        "stats.reset_warning_counts",
        "stats.warning_counts",
        "stats.weighted_least_squares",
        "stats.wilson_interval",
        "survival.choose_t_max",
        "survival.choose_windows",
        "survival.cmeasure_sample_from_sections",
        "survival.crossover_time",
        "survival.detect_power_law_tail",
        "survival.escape_rate_from_lifetimes",
        "survival.escape_rate_p_levels",
        "survival.escaping_tail",
        "survival.fit_exponential",
        "survival.fit_kappa_energy",
        "survival.fit_plateau_exponential",
        "survival.fit_power_law_tail",
        "survival.kappa_from_cmeasure",
        "survival.km_steps",
        "survival.lifetimes_to_arrays",
        "survival.mean_kappa_stat_err",
        "survival.observed_from_outcome",
        "survival.p_level_windows",
        "survival.paired_mle_shift",
        "survival.plateau_check",
        "survival.plateau_rate",
        "survival.power_law_exponent_mle",
        "survival.survival_curve",
        "survival.survival_from_lifetimes",
        "survival.survival_on_grid",
        "survival.survival_ratio_slope",
        "survival.trapped_fraction",
        "dissipative.better_fit",
        "dissipative.bootstrap_mu",
        "dissipative.bootstrap_mu_first_orbits",
        "dissipative.bootstrap_transition_times",
        "dissipative.compare_fits",
        "dissipative.energy_histograms",
        "dissipative.energy_histograms_arrays",
        "dissipative.energy_path",
        "dissipative.fit_energy_decay",
        "dissipative.fit_energy_decay_table",
        "dissipative.fit_mixture_model",
        "dissipative.fit_survival_model",
        "dissipative.inside_mean_energy",
        "dissipative.mean_energy",
        "dissipative.mean_energy_arrays",
        "dissipative.mixture_components",
        "dissipative.mixture_components_arrays",
        "dissipative.mixture_survival_model",
        "dissipative.mu_by_window",
        "dissipative.outcome_is",
        "dissipative.pool_mean_energy",
        "dissipative.power_law_exponent",
        "dissipative.predict_tau1",
        "dissipative.profile_interval",
        "dissipative.settle_quantile_interval",
        "dissipative.settle_time_quantiles",
        "dissipative.settling_rate",
        "dissipative.snapshot_grid",
        "dissipative.tau1",
        "dissipative.tau1_from_lifetimes",
        "dissipative.tau2_observed",
        "dissipative.tau2_observed_arrays",
        "dissipative.tau2_observed_interval",
        "dissipative.tau2_predicted",
        "dissipative.time_to_energy",
        "geometry.agreement_scale",
        "geometry.agreement_scale_debiased",
        "geometry.basin_entropy",
        "geometry.basin_entropy_table",
        "geometry.basin_fractions",
        "geometry.bootstrap_distance",
        "geometry.bootstrap_kappa",
        "geometry.box_distances",
        "geometry.box_histograms",
        "geometry.box_index",
        "geometry.capped_share",
        "geometry.channel_fractions",
        "geometry.communicating_classes",
        "geometry.convergence_grid",
        "geometry.convergence_record",
        "geometry.debiased_distance",
        "geometry.disk_density",
        "geometry.dissipative_operator",
        "geometry.dissipative_record",
        "geometry.distance_vs_scale",
        "geometry.eigenvector_convergence",
        "geometry.first_crossing_after",
        "geometry.first_crossing_weights",
        "geometry.first_crossings",
        "geometry.hellinger",
        "geometry.hellinger_by_box",
        "geometry.hellinger_row",
        "geometry.histogram_distance",
        "geometry.initial_escape_rate",
        "geometry.islands_record",
        "geometry.lag_kernels",
        "geometry.leading_left",
        "geometry.leading_modes",
        "geometry.map_escape_rate",
        "geometry.measure_points",
        "geometry.one_return_samples",
        "geometry.operator_survival",
        "geometry.points",
        "geometry.propagate",
        "geometry.reduced_operator",
        "geometry.reduced_survival",
        "geometry.return_statistics",
        "geometry.saddle_class",
        "geometry.saddle_kappa",
        "geometry.saddle_measure",
        "geometry.sample_transitions",
        "geometry.section_flux_density",
        "geometry.shadow_indicator",
        "geometry.sliced_wasserstein",
        "geometry.spectral_radius",
        "geometry.split_half_baseline",
        "geometry.split_half_noise",
        "geometry.sprinkler_weights",
        "geometry.stratified_section_points",
        "geometry.survival_agreement",
        "geometry.survival_from_crossings",
        "geometry.t_star_distance",
        "geometry.t_star_energies",
        "geometry.total_variation",
        "geometry.transfer_matrix",
        "geometry.true_time_kappa",
        "geometry.uncertainty_cutoff",
        "geometry.uncertainty_exponent",
        "geometry.uncertainty_fraction",
        "geometry.wada_merging",
        "geometry.wasserstein_1d",
    }
)


def has_example(f) -> bool:
    """Whether the docstring of ``f`` holds a doctest line."""
    return any(line.lstrip().startswith(">>> ") for line in (inspect.getdoc(f) or "").splitlines())


def test_the_check_tells_an_example_from_prose():
    def with_one():
        """Twice x.

        >>> 2 * 3
        6
        """

    def without():
        """Twice x (see the example >>> elsewhere)."""

    assert has_example(with_one) and not has_example(without)


def test_the_list_names_exported_functions_only():
    assert WITHOUT_EXAMPLE <= set(FUNCTIONS)


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(n, marks=pytest.mark.xfail(strict=True, reason="no example yet")) if n in WITHOUT_EXAMPLE else n
        for n in sorted(FUNCTIONS)
    ],
)
def test_every_exported_function_has_an_example(name):
    assert has_example(FUNCTIONS[name])
