"""Dissipative measures: the energy path E(t), transition times τ0, τ1, τ2, the survival model (Eq. (eqn:surv_prob_model)) and its mixture.

Every public name of its modules is importable from here (loaded on first use); the functions named like their module (survival_model.survival_model) from their module.
"""

from hhscatter.analysis._exports import lazy_exports

_EXPORTS = {
    "EnergyDecayFit": "decay",
    "EnergyHistograms": "decay",
    "InsideMeanEnergy": "decay",
    "bootstrap_mu": "decay",
    "bootstrap_mu_first_orbits": "decay",
    "energy_histograms": "decay",
    "energy_histograms_arrays": "decay",
    "energy_path": "decay",
    "fit_energy_decay": "decay",
    "fit_energy_decay_table": "decay",
    "inside_mean_energy": "decay",
    "mean_energy": "decay",
    "mean_energy_arrays": "decay",
    "mu_by_window": "decay",
    "pool_mean_energy": "decay",
    "snapshot_grid": "decay",
    "time_to_energy": "decay",
    "binned_hazard": "effective_rate",
    "observed_over_expected": "effective_rate",
    "KineticFraction": "kinetic",
    "decay_path": "kinetic",
    "kinetic_fraction_by_time": "kinetic",
    "kinetic_fraction_from_energies": "kinetic",
    "microcanonical_kinetic_fraction": "kinetic",
    "MixtureComponents": "mixture",
    "MixtureModelParams": "mixture",
    "fit_mixture_model": "mixture",
    "mixture_components": "mixture",
    "mixture_components_arrays": "mixture",
    "mixture_survival_model": "mixture",
    "best_fit": "model_comparison",
    "better_fit": "model_comparison",
    "compare_fits": "model_comparison",
    "fit_homogeneous_hazards": "model_comparison",
    "plateau_level": "model_comparison",
    "predict_tau1": "model_comparison",
    "survival_fit_points": "model_comparison",
    "HAZARDS": "survival_model",
    "HomogeneousProblem": "survival_model",
    "SurvivalFit": "survival_model",
    "SurvivalModelParams": "survival_model",
    "fit_survival_model": "survival_model",
    "homogeneous_start": "survival_model",
    "profile_interval": "survival_model",
    "settling_rate": "survival_model",
    "OrderStatisticInterval": "transitions",
    "bootstrap_transition_times": "transitions",
    "power_law_exponent": "transitions",
    "settle_quantile_interval": "transitions",
    "settle_time_quantiles": "transitions",
    "tau1": "transitions",
    "tau1_from_lifetimes": "transitions",
    "tau2_observed": "transitions",
    "tau2_observed_arrays": "transitions",
    "tau2_observed_interval": "transitions",
    "tau2_predicted": "transitions",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
