"""Escape from P(t): Kaplan–Meier curves, exponential and power-law fits, κ and its windows, κ from the c-measure, the κ(E) law.

Every public name of its modules is importable from here (loaded on first use); the functions named like their module (escape_rate.escape_rate) from their module.
"""
import importlib

_EXPORTS = {
    "CMeasureKappa": "cmeasure",
    "cmeasure_sample_from_sections": "cmeasure",
    "kappa_from_cmeasure": "cmeasure",
    "EscapeRateResult": "escape_rate",
    "EscapingTail": "escape_rate",
    "MLERate": "escape_rate",
    "choose_t_max": "escape_rate",
    "escape_rate_from_lifetimes": "escape_rate",
    "escape_rate_mle": "escape_rate",
    "escaping_tail": "escape_rate",
    "power_law_exponent_mle": "escape_rate",
    "CENSORED_OUTCOME": "fits",
    "ExponentialFit": "fits",
    "PowerLawFit": "fits",
    "crossover_time": "fits",
    "detect_power_law_tail": "fits",
    "fit_exponential": "fits",
    "fit_power_law_tail": "fits",
    "lifetimes_to_arrays": "fits",
    "mean_kappa_stat_err": "fits",
    "observed_from_outcome": "fits",
    "survival_from_lifetimes": "fits",
    "KaplanMeierGrid": "kaplan_meier",
    "SurvivalCurve": "kaplan_meier",
    "km_steps": "kaplan_meier",
    "survival_curve": "kaplan_meier",
    "survival_on_grid": "kaplan_meier",
    "ConventionRate": "kappa_conventions",
    "convention_rows": "kappa_conventions",
    "escape_rate_p_levels": "kappa_conventions",
    "fit_laws": "kappa_conventions",
    "law_spread": "kappa_conventions",
    "p_level_windows": "kappa_conventions",
    "plateau_check": "kappa_conventions",
    "plateau_rate": "kappa_conventions",
    "stable_energies": "kappa_conventions",
    "trapped_fraction": "kappa_conventions",
    "KappaEnergyFit": "kappa_energy",
    "fit_kappa_energy": "kappa_energy",
    "PAPER_KAPPA": "kappa_law",
    "PiecewiseKappa": "kappa_law",
    "PairedShift": "paired",
    "RatioSlope": "paired",
    "paired_mle_shift": "paired",
    "survival_ratio_slope": "paired",
    "cmeasure_windows": "summaries",
    "kappa_cmeasure_shifts": "summaries",
    "kappa_cmeasure_z": "summaries",
    "kappa_law_curves": "summaries",
    "kappa_law_summary": "summaries",
    "plot_grid": "summaries",
    "rate_summary": "summaries",
    "sticky_tail_summary": "summaries",
    "survival_tables": "summaries",
    "value_err": "summaries",
    "WindowChoice": "windows",
    "choose_windows": "windows",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
