"""Statistics shared by the analyses: weighted least squares, binomial intervals, verdict wording, the libraries'
warnings counted.

Every public name of its modules is importable from here (loaded on first use).
"""

from hhscatter.analysis._exports import lazy_exports

_EXPORTS = {
    "wilson_interval": "intervals",
    "counted": "library_warnings",
    "reset_warning_counts": "library_warnings",
    "warning_counts": "library_warnings",
    "LinearFit": "least_squares",
    "least_squares_operator": "least_squares",
    "weighted_least_squares": "least_squares",
    "Verdict": "verdicts",
    "REFERENCE_KINDS": "verdicts",
    "claim_verdict": "verdicts",
    "comparison_row": "verdicts",
    "reference_err": "verdicts",
    "reference_kind": "verdicts",
    "half_unit": "verdicts",
    "quoted_verdict": "verdicts",
    "row_verdict": "verdicts",
    "verdict": "verdicts",
    "verdict_beside_authors": "verdicts",
    "verdict_class": "verdicts",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
