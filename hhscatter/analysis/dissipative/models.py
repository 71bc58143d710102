"""The survival models of dissipative scattering, Eq. (eqn:surv_prob_model), by concept:

* :mod:`hhscatter.analysis.survival.kappa_law` — κ0(E), the conservative escape-rate law;
* :mod:`hhscatter.analysis.dissipative.decay` — the energy path E(t) = E0 e^{−μγt} and its inverse t*;
* :mod:`hhscatter.analysis.dissipative.survival_model` — the homogeneous model, its fit, the
  τ1 it predicts, and the comparison of fits;
* :mod:`hhscatter.analysis.dissipative.mixture` — the mixture of sub-ensembles with their own
  measured energy paths (the extension proposed by Burton, Dullin & Altmann (2023)).

This module only gathers their names (``from hhscatter.analysis.dissipative import models``): every public name
(``__all__``) of the modules of κ0(E), of the homogeneous model, of the mixture and of the comparison of fits, and
of the energy path its two functions; a name added to one of these modules is gathered with it. Each name is
documented in the module that defines it.
"""

from __future__ import annotations

import hhscatter.analysis.dissipative.mixture as _mixture
import hhscatter.analysis.dissipative.model_comparison as _model_comparison
import hhscatter.analysis.dissipative.survival_model as _survival_model
import hhscatter.analysis.survival.kappa_law as _kappa_law
from hhscatter.analysis.dissipative.decay import energy_path, time_to_energy
from hhscatter.analysis.dissipative.mixture import *  # noqa: F403
from hhscatter.analysis.dissipative.model_comparison import *  # noqa: F403
from hhscatter.analysis.dissipative.survival_model import *  # noqa: F403
from hhscatter.analysis.survival.kappa_law import *  # noqa: F403

#: of the energy path's module, its two functions: the path E(t) and its inverse t*
_ENERGY_PATH = (energy_path, time_to_energy)

__all__ = [
    *(f.__name__ for f in _ENERGY_PATH),
    *_kappa_law.__all__,
    *_survival_model.__all__,
    *_mixture.__all__,
    *_model_comparison.__all__,
]
