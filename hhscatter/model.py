"""The Hénon–Heiles model with linear drag (paper, Eqs. (eq:H), (eqn:hh_potential), (eqn:hh_ham)).

    V(x, y) = ω²/2 (x² + y²) + λ (x² y − y³/3)
    H       = (p_x² + p_y²)/2 + V(x, y)
    ṗ       = −∇V − γ p            (dissipative system, γ ≥ 0)

All quantities are in the model's natural units (unit mass; time t, energy E).
Numeric helpers work on numpy arrays; the heyoka expressions are built lazily
by :func:`equations` so that importing this module does not import heyoka.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # annotations only
    from numpy.typing import ArrayLike


@dataclass(frozen=True)
class HenonHeiles:
    """The Hénon–Heiles potential V = ω²(x² + y²)/2 + λ(x²y − y³/3), Eq. (eqn:hh_potential), and H, Eq. (eq:H).

    The paper fixes ω = λ = 1 (Sec. II.B "Model System"), for which E_c = 1/6 and the three saddles lie
    at distance 1 (Sec. II.B "Scattering dynamics").

    Parameters
    ----------
    omega : float
        ω > 0, the harmonic frequency (1/time).
    lam : float
        λ > 0, the cubic coupling (for λ < 0 the potential is the mirror image y → −y; use λ > 0 and
        reflect the data instead).

    Raises
    ------
    ValueError
        ω or λ not positive and finite.

    Examples
    --------
    >>> from hhscatter import HenonHeiles
    >>> hh = HenonHeiles()
    >>> round(hh.critical_energy, 12), round(hh.saddle_radius, 12)
    (0.166666666667, 1.0)
    >>> [round(float(v), 12) for v in hh.potential(hh.saddles[:, 0], hh.saddles[:, 1])]   # V = E_c at every saddle
    [0.166666666667, 0.166666666667, 0.166666666667]
    """

    omega: float = 1.0
    lam: float = 1.0

    def __post_init__(self):
        for name, value in (("omega", self.omega), ("lam", self.lam)):
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {value!r}")

    # -- closed forms -----------------------------------------------------
    @property
    def saddle_radius(self) -> float:
        """Distance of the three saddles from the origin: ω²/λ (= 1 for ω=λ=1)."""
        return self.omega**2 / self.lam

    @property
    def critical_energy(self) -> float:
        """E_c = ω⁶/(6λ²), the saddle energy (= 1/6 for ω=λ=1); no escape below it."""
        return self.omega**6 / (6.0 * self.lam**2)

    @property
    def channel_angles(self) -> np.ndarray:
        """Polar angles (rad) of the exit channels 0, 1, 2: π/2, 7π/6, 11π/6."""
        return np.pi / 2 + 2 * np.pi / 3 * np.arange(3)

    @property
    def saddles(self) -> np.ndarray:
        """Saddle points, shape (3, 2): row k is the saddle of exit channel k."""
        a = self.channel_angles
        return self.saddle_radius * np.column_stack([np.cos(a), np.sin(a)])

    # -- numpy evaluations ------------------------------------------------
    def potential(self, x: ArrayLike, y: ArrayLike) -> np.ndarray:
        """V(x, y), Eq. (eqn:hh_potential)."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        return 0.5 * self.omega**2 * (x * x + y * y) + self.lam * (x * x * y - y**3 / 3.0)

    def energy(self, x: ArrayLike, y: ArrayLike, px: ArrayLike, py: ArrayLike) -> np.ndarray:
        """H(x, y, p_x, p_y), Eq. (eq:H)."""
        px = np.asarray(px, dtype=float)
        py = np.asarray(py, dtype=float)
        return 0.5 * (px * px + py * py) + self.potential(x, y)

    def exit_channel(self, x: ArrayLike, y: ArrayLike) -> np.ndarray:
        """exit_channel(x, y) -> int8 array: index of the channel whose axis is nearest in angle."""
        phi = np.arctan2(np.asarray(y, dtype=float), np.asarray(x, dtype=float))
        # channel k is centred on π/2 + 2πk/3; shift so that each channel owns a 120° sector
        k = np.floor(((phi - np.pi / 2 + np.pi / 3) % (2 * np.pi)) / (2 * np.pi / 3))
        return (k.astype(np.int8)) % 3

    def inside_triangle(self, x: ArrayLike, y: ArrayLike) -> np.ndarray:
        """True where (x, y) lies strictly inside the triangle spanned by the three saddles."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        # the triangle's edges have inward normals pointing at the origin; the
        # edge opposite vertex k lies at distance r_s/2 from the origin
        inside = np.ones(np.broadcast(x, y).shape, dtype=bool)
        for a in self.channel_angles + np.pi:
            inside &= x * np.cos(a) + y * np.sin(a) < self.saddle_radius / 2
        return inside

    # -- heyoka -----------------------------------------------------------
    def expressions(self) -> tuple[tuple[Any, Any, Any, Any], Any, Any]:
        """(state_vars, V, H) as heyoka expressions; state order x, y, px, py."""
        import heyoka as hy  # deferred: heyoka loads on first use

        x, y, px, py = hy.make_vars("x", "y", "px", "py")
        w2, lam = self.omega**2, self.lam
        V = 0.5 * w2 * (x**2 + y**2) + lam * (x**2 * y - y**3 / 3.0)
        H = 0.5 * (px**2 + py**2) + V
        return (x, y, px, py), V, H


def equations(model: HenonHeiles, gamma_par=None):
    """equations(model, gamma_par) -> heyoka system [(x, ẋ), (y, ẏ), (px, ṗx), (py, ṗy)].

    Hamilton's equations of H, paper Eq. (eqn:hh_ham), plus the drag −γp of the
    dissipative system when ``gamma_par`` (a heyoka expression for γ, e.g.
    ``hy.par[0]``) is given; None builds the conservative system without drag
    terms, which saves work per step.

    The right-hand side is written in simplified form (−ω²x − 2λxy, ...):
    ``hy.diff(H, x)`` yields the same functions with redundant constant
    products such as ``0.5*(2*px)`` that would cost operations on every
    Taylor step; ``tests/test_model.py`` checks both agree.
    """
    (x, y, px, py), _, _ = model.expressions()
    w2, lam = model.omega**2, model.lam
    fx = -(w2 * x) - (2.0 * lam) * (x * y)
    fy = -(w2 * y) - lam * (x**2 - y**2)
    if gamma_par is not None:
        fx = fx - gamma_par * px
        fy = fy - gamma_par * py
    return [(x, px), (y, py), (px, fx), (py, fy)]


def hamilton_equations(model: HenonHeiles):
    """hamilton_equations(model) -> [(x, ∂H/∂px), ..., (py, −∂H/∂y)] straight from ``hy.diff``.

    Hamilton's equations of H, Eq. (eqn:hh_ham), derived symbolically: the
    reference against which the hand-simplified :func:`equations` is tested.
    """
    import heyoka as hy  # deferred: heyoka loads on first use

    (x, y, px, py), _, H = model.expressions()
    return [(x, hy.diff(H, px)), (y, hy.diff(H, py)), (px, -hy.diff(H, x)), (py, -hy.diff(H, y))]
