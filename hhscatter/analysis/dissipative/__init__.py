"""Dissipative measures: the energy path E(t), transition times τ0, τ1, τ2, the survival model (Eq. (eqn:surv_prob_model)) and its mixture.

Every public name of its modules is importable from here (loaded on first use); the functions named like their module (survival_model.survival_model) from their module.
"""

from hhscatter._exports import lazy_exports

_EXPORTS, __getattr__, __dir__ = lazy_exports(__name__)
__all__ = sorted(_EXPORTS)
