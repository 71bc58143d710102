"""Phase-space geometry: distances of section-point sets, exit basins (fractality, Wada), the transfer operator, exit channels.

Every public name of its modules is importable from here (loaded on first use).
"""
import importlib

_EXPORTS = {
    "BasinEntropy": "basins",
    "BasinFractions": "basins",
    "BoxCountingDimension": "basins",
    "DecisionRate": "basins",
    "UncertaintyCutoff": "basins",
    "UncertaintyExponent": "basins",
    "UncertaintyFraction": "basins",
    "WadaTest": "basins",
    "basin_entropy": "basins",
    "basin_entropy_table": "basins",
    "basin_fractions": "basins",
    "box_counting_dimension": "basins",
    "decision_rate": "basins",
    "local_exponent": "basins",
    "predicted_cutoff": "basins",
    "slim_fractal": "basins",
    "uncertainty_cutoff": "basins",
    "uncertainty_exponent": "basins",
    "uncertainty_fraction": "basins",
    "wada_merging": "basins",
    "weighted_line": "basins",
    "ChannelFractions": "channels",
    "LyapunovOrbit": "channels",
    "channel_fractions": "channels",
    "lyapunov_orbit": "channels",
    "return_statistics": "channels",
    "BootstrapResult": "distance",
    "agreement_scale": "distance",
    "agreement_scale_debiased": "distance",
    "bootstrap_distance": "distance",
    "box_distances": "distance",
    "box_histograms": "distance",
    "debiased_distance": "distance",
    "distance_vs_scale": "distance",
    "first_crossings": "distance",
    "hellinger": "distance",
    "histogram_distance": "distance",
    "points": "distance",
    "sliced_wasserstein": "distance",
    "split_half_baseline": "distance",
    "split_half_noise": "distance",
    "total_variation": "distance",
    "wasserstein_1d": "distance",
    "FluxRate": "flux",
    "initial_escape_rate": "flux",
    "PairedDifference": "paired_distance",
    "UnitSet": "paired_distance",
    "paired_hellinger_difference": "paired_distance",
    "paired_hellinger_replicates": "paired_distance",
    "percentile_interval": "paired_distance",
    "ClassInfo": "transfer",
    "DENSE_MAX": "transfer",
    "Transitions": "transfer",
    "bootstrap_kappa": "transfer",
    "box_index": "transfer",
    "capped_share": "transfer",
    "communicating_classes": "transfer",
    "first_crossing_after": "transfer",
    "first_crossing_weights": "transfer",
    "lag_kernels": "transfer",
    "leading_left": "transfer",
    "map_escape_rate": "transfer",
    "propagate": "transfer",
    "saddle_class": "transfer",
    "saddle_measure": "transfer",
    "section_flux_density": "transfer",
    "spectral_radius": "transfer",
    "sprinkler_weights": "transfer",
    "transfer_matrix": "transfer",
    "true_time_kappa": "transfer",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
