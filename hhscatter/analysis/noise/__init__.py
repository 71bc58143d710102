"""Noisy and thermal scattering: the Kramers–Langer rate of a system's saddles, censoring-aware thermal rates.

Every public name of its modules is importable from here (loaded on first use).
"""

from hhscatter.analysis._exports import lazy_exports

_EXPORTS = {
    "KramersLanger": "kramers",
    "SaddleTerm": "kramers",
    "ThermalRate": "kramers",
    "hessian": "kramers",
    "kramers_langer": "kramers",
    "reactivation_survival": "reactivation",
    "thermal_rate": "kramers",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
