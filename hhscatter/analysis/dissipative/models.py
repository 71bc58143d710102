"""The survival models of dissipative scattering, Eq. (eqn:surv_prob_model), by concept:

* :mod:`hhscatter.analysis.survival.kappa_law` — κ0(E), the conservative escape-rate law;
* :mod:`hhscatter.analysis.dissipative.decay` — the energy path E(t) = E0 e^{−μγt} and its inverse t*;
* :mod:`hhscatter.analysis.dissipative.survival_model` — the homogeneous model, its fit, the
  τ1 it predicts, and the comparison of fits;
* :mod:`hhscatter.analysis.dissipative.mixture` — the mixture of sub-ensembles with their own
  measured energy paths (the extension proposed by Burton, Dullin & Altmann (2023)).

This module only gathers their names (``from hhscatter.analysis.dissipative import models``).
"""

from __future__ import annotations

from hhscatter.analysis.dissipative.decay import energy_path, time_to_energy
from hhscatter.analysis.dissipative.mixture import (
    MixtureComponents,
    MixtureModelParams,
    fit_mixture_model,
    mixture_components,
    mixture_components_arrays,
    mixture_survival_model,
)
from hhscatter.analysis.dissipative.model_comparison import better_fit, compare_fits, predict_tau1
from hhscatter.analysis.dissipative.survival_model import (
    HAZARDS,
    SurvivalFit,
    SurvivalModelParams,
    fit_survival_model,
    settling_rate,
    survival_model,
    survival_model_sample,
)
from hhscatter.analysis.survival.kappa_law import PiecewiseKappa

__all__ = [
    "HAZARDS",
    "MixtureComponents",
    "MixtureModelParams",
    "PiecewiseKappa",
    "SurvivalFit",
    "SurvivalModelParams",
    "better_fit",
    "compare_fits",
    "energy_path",
    "fit_mixture_model",
    "fit_survival_model",
    "mixture_components",
    "mixture_components_arrays",
    "mixture_survival_model",
    "predict_tau1",
    "settling_rate",
    "survival_model",
    "survival_model_sample",
    "time_to_energy",
]
