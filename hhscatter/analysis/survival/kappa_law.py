"""The conservative escape-rate law κ0(E) as a callable, the input of the survival models.

:class:`PiecewiseKappa` holds the piecewise law κ0 = a2 ΔE² + a1 ΔE below
E_switch and slope·ΔE above (ΔE = E − E_c, zero below E_c); the coefficients
are fitted by :func:`hhscatter.analysis.survival.kappa_energy.fit_kappa_energy` or given. E_c comes from
the model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PiecewiseKappa"]


@dataclass(frozen=True)
class PiecewiseKappa:
    """PiecewiseKappa(E_c, a2=13.63, a1=0.03, slope=1.41, E_switch=0.27) -> callable κ0(E).

    Conservative escape rate as a function of energy, with
    ΔE = E − E_c:

        κ0 = a2 ΔE² + a1 ΔE   for E_c < E < E_switch   (non-hyperbolic regime)
        κ0 = slope · ΔE       for E ≥ E_switch         (hyperbolic, linear regime)
        κ0 = 0                for E ≤ E_c              (no escape)

    E_c is the system's (``scene.model.critical_energy``; no default: it comes from the system). Defaults of
    the coefficients are the fits of Burton, Dullin & Altmann (2023).  Calling it on an array returns an array
    (rates in 1/time).  Note the two branches do not join exactly at
    E_switch (0.1486 vs 0.1457 with the defaults).
    """

    E_c: float
    a2: float = 13.63
    a1: float = 0.03
    slope: float = 1.41
    E_switch: float = 0.27

    def __call__(self, E):
        E = np.asarray(E, dtype=float)
        d = E - self.E_c
        k = np.where(E < self.E_switch, self.a2 * d * d + self.a1 * d, self.slope * d)
        return np.where(d > 0, k, 0.0)
