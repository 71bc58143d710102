"""The flux identity: the initial escape rate of a microcanonical ensemble, for any open two-degree-of-freedom system.

Let N orbits start uniformly on the energy shell H = E inside the disk r < R (the microcanonical measure
δ(E − H) restricted to the disk; in hhscatter: region ``disk`` with ``radius = R`` and ``momentum = "random"``,
since ∫ δ(E − p²/2 − V) d²p = 2π is the same at every accessible point, so positions are uniform in area on
{V < E} and momentum directions uniform). The rate at which they first cross the circle r = R outward, at
t → 0+, is the outward phase-space flux through that circle over the shell's volume (Liouville):

    κ(0+) = Φ / Ω_E,   Φ = ∮_{r=R} ds ∫ d²p δ(E − H) (p·n)₊ = ∮_{V(R, φ) < E} 2 √(2(E − V(R, φ))) R dφ,
                       Ω_E = ∫_{r<R} d²q ∫ d²p δ(E − H) = 2π · area{r < R, V < E},

using ∫ d²p δ(E − V − p²/2) (p·n)₊ = ∫ dθ |p| cos₊θ = 2|p| with |p| = √(2(E − V)). For the disk r < R
entirely accessible (V < E on it) Ω_E = 2π²R². The identity holds for every potential (and with drag, for
the first crossings): with a conservative scene's escape at r_esc = R it checks the initial conditions, the
escape event and the system's potential together.

Units: κ in 1/time, Φ in (energy·length)/… — only their ratio has a meaning here.

Examples
--------
The harmonic well V = r²/2 at E = 1 inside R = 1: Φ = 2π·2√(2 − 1) = 4π, area π, κ = 4π/(2π·π) = 2/π.

>>> from hhscatter.analysis.geometry.flux import initial_escape_rate
>>> from hhscatter.model import HenonHeiles
>>> r = initial_escape_rate(HenonHeiles(lam=1e-12), energy=1.0, radius=1.0)
>>> round(r.rate, 4), round(2 / 3.141592653589793, 4)
(0.6366, 0.6366)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = ["FluxRate", "initial_escape_rate"]


@dataclass(frozen=True)
class FluxRate:
    """Result of :func:`initial_escape_rate`: ``rate`` = ``flux``/``volume`` (1/time)."""

    energy: float
    radius: float
    flux: float
    volume: float
    rate: float


def initial_escape_rate(model, energy: float, radius: float, *, n_phi: int = 4096, n_r: int = 2048) -> FluxRate:
    """initial_escape_rate(model, E, R) -> FluxRate: κ(0+) = Φ/Ω_E of the microcanonical ensemble in r < R.

    Parameters
    ----------
    model : hhscatter.model.System
        The system (only its potential V(x, y) is used).
    energy : float
        E (energy units).
    radius : float
        R, the radius of the disk the ensemble starts in and whose outward crossing is the escape (length).
    n_phi, n_r : int
        Midpoint-rule grid in angle (flux and area) and radius (area); the relative error of the area is
        ≈ the share of boundary cells, ≈ 1e-3 at the defaults.

    Returns
    -------
    FluxRate
        flux Φ, shell volume Ω_E and rate Φ/Ω_E (module docstring).

    Examples
    --------
    The harmonic well V = r²/2 (Hénon–Heiles with λ → 0) at E = 1 inside R = 1: Φ = 2π · 2√(2 − 1) = 4π, Ω_E = 2π · π,
    κ(0+) = 2/π = 0.6366 (module docstring). V < E on the whole disk and V is constant on its edge, so a coarse grid
    is exact here.

    >>> from hhscatter.model import HenonHeiles
    >>> r = initial_escape_rate(HenonHeiles(lam=1e-12), energy=1.0, radius=1.0, n_phi=64, n_r=64)
    >>> round(r.flux / math.pi, 4), round(r.volume / math.pi**2, 3), round(r.rate, 4)
    (4.0, 2.0, 0.6366)
    """
    model = check.system(model, "model")
    E, R = check.number(energy, "energy"), check.number(radius, "radius", positive=True)
    n_phi, n_r = check.count(n_phi, "n_phi", 1), check.count(n_r, "n_r", 1)
    phi = (np.arange(n_phi) + 0.5) * (2 * math.pi / n_phi)
    v_edge = model.potential(R * np.cos(phi), R * np.sin(phi))
    flux = float(np.sum(2.0 * np.sqrt(2.0 * np.clip(E - v_edge, 0.0, None))) * R * (2 * math.pi / n_phi))
    r = (np.arange(n_r) + 0.5) * (R / n_r)
    X = r[None, :] * np.cos(phi)[:, None]
    Y = r[None, :] * np.sin(phi)[:, None]
    area = float(np.sum((model.potential(X, Y) < E) * r[None, :]) * (R / n_r) * (2 * math.pi / n_phi))
    volume = 2 * math.pi * area
    if not volume > 0:
        raise ConfigError(f"energy {E!r} is below the potential everywhere in the disk r < radius = {R!r}")
    return FluxRate(E, R, flux, volume, flux / volume)
