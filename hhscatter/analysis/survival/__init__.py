"""Escape from P(t): Kaplan–Meier curves, exponential and power-law fits, κ and its windows, κ from the c-measure, the κ(E) law.

Every public name of its modules is importable from here (loaded on first use); the functions named like their module (escape_rate.escape_rate) from their module.
"""

from hhscatter._exports import lazy_exports

_EXPORTS, __getattr__, __dir__ = lazy_exports(__name__)
__all__ = sorted(_EXPORTS)
