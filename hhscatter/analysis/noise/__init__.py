"""Noisy and thermal scattering: the Kramers–Langer rate of a system's saddles, censoring-aware thermal rates.

Every public name of its modules is importable from here (loaded on first use).
"""

from hhscatter._exports import lazy_exports

_EXPORTS, __getattr__, __dir__ = lazy_exports(__name__)
__all__ = sorted(_EXPORTS)
