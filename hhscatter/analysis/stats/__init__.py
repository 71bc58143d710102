"""Statistics shared by the analyses: weighted least squares, binomial intervals, verdict wording.

Every public name of its modules is importable from here (loaded on first use).
"""
import importlib

_EXPORTS = {
    "wilson_interval": "intervals",
    "LinearFit": "least_squares",
    "least_squares_operator": "least_squares",
    "weighted_least_squares": "least_squares",
    "Verdict": "verdicts",
    "half_unit": "verdicts",
    "quoted_verdict": "verdicts",
    "row_verdict": "verdicts",
    "verdict": "verdicts",
    "verdict_beside_authors": "verdicts",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
