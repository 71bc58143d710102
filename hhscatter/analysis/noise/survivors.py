"""The energy distribution of the orbits still inside at a time: which orbits a noisy ensemble keeps.

With noise and no drag every orbit's energy diffuses (⟨E⟩ of the whole ensemble grows by σ² t for dp = σ dW on two
momenta), but the orbits that gain energy leave first: the survivors at time t are a selection. Their energies
(the censored orbits' energies at the end of a run to t) tell whether the orbits that stay have gained or lost
energy, and what share of them lies below the threshold E_c, where no exit is open until the noise lifts them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.intervals import fraction_with_bound
from hhscatter.analysis.stats.measured import WithErrors
from hhscatter.errors import ConfigError

__all__ = ["SurvivorEnergies", "noise_energy_gain", "survivor_energies"]


@dataclass(frozen=True)
class SurvivorEnergies(WithErrors):
    """The energies of ``n`` orbits still inside (energy units): ``mean`` ± ``mean_err`` (the standard error),
    ``sd``, the ``quantiles`` {q: E_q}, and ``below`` ± ``below_err``, the fraction below ``threshold`` (at 0 or
    ``n`` of them: ``below_err`` is None and ``below_upper`` / ``below_lower`` the one-sided 95 % bound)."""

    method = "sample of the survivors' energies"
    n_field = "n"

    n: int
    mean: float
    mean_err: float
    sd: float
    quantiles: dict
    threshold: float
    below: float
    below_err: float | None
    below_upper: float | None = None
    below_lower: float | None = None


def survivor_energies(energies, threshold: float, quantiles=(0.1, 0.5, 0.9)) -> SurvivorEnergies:
    """survivor_energies(energies, threshold, quantiles=(0.1, 0.5, 0.9)) -> SurvivorEnergies: the distribution of
    the survivors' energies (energy units) and the fraction of them below ``threshold`` (module docstring).

    ``energies``: the energies of the orbits still inside at one time (at least 2); ``threshold``: an energy (e.g.
    E_c); ``quantiles``: levels in (0, 1).

    Examples
    --------
    Energies evenly spread on [0.1, 0.3]: mean 0.2, its error sd/√n, a quarter below 0.15:

    >>> e = np.linspace(0.1, 0.3, 401)
    >>> s = survivor_energies(e, 0.15)
    >>> round(s.mean, 12), round(s.mean_err / float(e.std(ddof=1) / math.sqrt(401)), 12), round(s.below, 4)
    (0.2, 1.0, 0.2494)
    >>> round(s.quantiles[0.5], 12)
    0.2

    None below: a bound, not 0 ± 0:

    >>> t = survivor_energies(e, 0.05)
    >>> t.below, t.below_err, round(t.below_upper, 5)
    (0.0, None, 0.00744)
    """
    e = check.numbers(energies, "energies", min_size=2)
    threshold = check.number(threshold, "threshold")
    qs = tuple(check.numbers(quantiles, "quantiles").tolist())
    if not all(0 < q < 1 for q in qs):
        raise ConfigError(f"quantiles must lie in (0, 1), got {quantiles!r}")
    sd = float(e.std(ddof=1))
    f = fraction_with_bound(int(np.count_nonzero(e < threshold)), e.size)
    return SurvivorEnergies(
        n=int(e.size),
        mean=float(e.mean()),
        mean_err=sd / math.sqrt(e.size),
        sd=sd,
        quantiles={q: float(np.quantile(e, q)) for q in qs},
        threshold=float(threshold),
        below=float(f.value),
        below_err=f.err,
        below_upper=f.upper,
        below_lower=f.lower,
    )


def noise_energy_gain(sigma, t):
    """noise_energy_gain(σ, t) -> σ² t (energy units): the growth of the whole ensemble's mean energy ⟨E⟩ after a
    time t of noise dp = σ dW on both momenta without drag (each momentum's variance grows by σ² t, ⟨p²/2⟩ by
    σ² t/2); ``sigma`` in momentum/√time, ``t`` in time units, arrays broadcast.

    Examples
    --------
    >>> noise_energy_gain(0.02, 100.0)
    0.04
    >>> noise_energy_gain(np.array([0.0, 0.1]), 50.0).tolist()
    [0.0, 0.5000000000000001]
    """
    sigma, t = (
        np.reshape(check.numbers(v, name, minimum=0.0), np.shape(v))
        if np.ndim(v)
        else check.number(v, name, minimum=0.0)
        for v, name in ((sigma, "sigma"), (t, "t"))
    )
    try:
        np.broadcast_shapes(np.shape(sigma), np.shape(t))
    except ValueError:
        raise ConfigError(f"sigma and t must broadcast, got shapes {np.shape(sigma)} and {np.shape(t)}") from None
    return sigma * sigma * t
