"""The paper's claims tested on a system, and the evidence behind their readings (regular orbits, long-time escape).

Every public name of its modules is importable from here (loaded on first use).
"""

from hhscatter.analysis._exports import lazy_exports

_EXPORTS = {
    "analyze_claims": "chain",
    "analyze_evidence": "chain",
    "check_params": "chain",
    "c5_window": "cmeasure",
    "claim2": "cmeasure",
    "claim5_distance": "cmeasure",
    "cm_sample": "cmeasure",
    "claim4": "dissipative",
    "claim6": "dissipative",
    "claim7": "dissipative",
    "fit_claim6": "dissipative",
    "taus": "dissipative",
    "decay_curves": "evidence",
    "first_below": "evidence",
    "long_time_record": "evidence",
    "regular_record": "evidence",
    "validity_map": "evidence",
    "claim1": "kappa",
    "exponents": "kappa",
    "fit_law": "kappa",
    "kappa_rows": "kappa",
    "rate_or_reason": "kappa",
    "window_rate": "kappa",
    "alt_key": "keys",
    "cm_key": "keys",
    "cm_ratios": "keys",
    "diss_key": "keys",
    "ev_key": "keys",
    "grid_key": "keys",
    "probe_key": "keys",
    "ps_key": "keys",
    "resc_key": "keys",
    "sec_key": "keys",
    "analyze_mu": "mu",
    "claim3": "mu",
    "claim5_moment": "mu",
    "mu_conservative": "mu",
    "mu_measured": "mu",
    "mu_of_E": "mu",
    "mu_own": "mu",
    "mu_predicted": "mu",
    "mu_windows": "mu",
    "own_path_mu": "mu",
    "probe_window": "mu",
    "Claims": "records",
    "across": "records",
    "ve": "records",
    "with_ids": "records",
    "z_verdict": "records",
    "resc_rows": "resc",
    "resc_values": "resc",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
