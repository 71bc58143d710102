"""The conservative escape-rate law κ0(E) as a callable, the input of the survival models.

:class:`PiecewiseKappa` holds the piecewise law κ0 = a2 ΔE² + a1 ΔE below
E_switch and slope·ΔE above (ΔE = E − E_c, zero below E_c); the coefficients
are fitted by :func:`hhscatter.analysis.survival.kappa_energy.fit_kappa_energy` or given by the caller. E_c
comes from the system. No coefficient has a default: a law is the data of a fit or of a reference, not of this
module.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = ["PiecewiseKappa"]


@dataclass(frozen=True)
class PiecewiseKappa:
    """PiecewiseKappa(E_c, a2, a1, slope, E_switch) -> callable κ0(E).

    Conservative escape rate as a function of energy, with
    ΔE = E − E_c:

        κ0 = a2 ΔE² + a1 ΔE   for E_c < E < E_switch   (non-hyperbolic regime)
        κ0 = slope · ΔE       for E ≥ E_switch         (hyperbolic, linear regime)
        κ0 = 0                for E ≤ E_c              (no escape)

    E_c (energy) is the system's (``scene.model.critical_energy``); a2 (1/(time·energy²)), a1 and slope
    (1/(time·energy)) and E_switch (energy) are the coefficients of a fit
    (:func:`~hhscatter.analysis.survival.kappa_energy.fit_kappa_energy`) or of a reference; all are required.
    Calling it on an array returns an array (rates in 1/time).  The two branches need not join at E_switch:
    E_switch belongs to the linear branch, and E_switch > E_c is required (else the quadratic branch is empty).
    Every argument must be a finite number (no bool, NaN or inf); a wrong one is refused with a ConfigError naming
    it.

    Examples
    --------
    E_c = 0.25, E_switch = 0.4: at E = 0.3 (ΔE = 0.05) κ0 = 2 · 0.05² + 0.5 · 0.05 = 0.03; at E = 0.5 (ΔE = 0.25)
    κ0 = 3 · 0.25 = 0.75; below E_c no escape.

    >>> law = PiecewiseKappa(E_c=0.25, a2=2.0, a1=0.5, slope=3.0, E_switch=0.4)
    >>> law([0.2, 0.3, 0.5]).round(12).tolist()
    [0.0, 0.03, 0.75]
    >>> PiecewiseKappa(E_c=0.25, a2=2.0, a1=0.5, slope=3.0, E_switch=0.2)
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: E_switch must be > E_c (the quadratic branch lies between them), got 0.2 ≤ 0.25
    """

    E_c: float
    a2: float
    a1: float
    slope: float
    E_switch: float

    def __post_init__(self):
        for name in ("E_c", "a2", "a1", "slope", "E_switch"):
            check.number(getattr(self, name), name)
        if not self.E_switch > self.E_c:
            raise ConfigError(
                f"E_switch must be > E_c (the quadratic branch lies between them), got {self.E_switch!r} ≤ {self.E_c!r}"
            )

    def __call__(self, E):
        E = np.asarray(E, dtype=float)
        d = E - self.E_c
        k = np.where(E < self.E_switch, self.a2 * d * d + self.a1 * d, self.slope * d)
        return np.where(d > 0, k, 0.0)
