"""The Hénon–Heiles model with linear drag (paper, Eqs. (eq:H), (eqn:hh_potential), (eqn:hh_ham)).

    V(x, y) = ω²/2 (x² + y²) + λ (x² y − y³/3)
    H       = (p_x² + p_y²)/2 + V(x, y)
    ṗ       = −∇V − γ p            (dissipative system, γ ≥ 0)

All quantities are in the model's natural units (unit mass; time t, energy E).
Numeric helpers work on numpy arrays; the heyoka expressions are built by :func:`equations` with the heyoka
module it is handed (the engine's): the model never imports heyoka.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from hhscatter.errors import ConfigError
from hhscatter.model.base import DISSIPATIONS, Exit, System

if TYPE_CHECKING:  # annotations only
    from numpy.typing import ArrayLike

#: E_c = ω⁶/(6λ²) and the saddle distance ω²/λ must lie in [SCALE_MIN, SCALE_MAX]: far outside, squares of
#: momenta and positions leave the floating-point range (the dynamics is scale-invariant, so nothing is lost)
SCALE_MIN, SCALE_MAX = 1e-100, 1e100


@dataclass(frozen=True)
class HenonHeiles(System):
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
    dissipation : {'linear', 'quadratic'}
        The drag law for γ > 0: −γp (the paper's, default) or −γ|p|p.

    Raises
    ------
    ValueError
        ω or λ not positive and finite, or an unknown dissipation law.

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
    dissipation: str = "linear"

    def __post_init__(self):
        for name, value in (("omega", self.omega), ("lam", self.lam)):
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
        if self.dissipation not in DISSIPATIONS:
            raise ValueError(f"dissipation must be one of {DISSIPATIONS}, got {self.dissipation!r}")
        try:  # E_c = ω⁶/(6λ²) and the saddle distance ω²/λ must be ordinary numbers (not 0, inf or subnormal)
            scales = {"E_c = ω⁶/(6λ²)": self.omega**6 / (6.0 * self.lam**2), "ω²/λ": self.omega**2 / self.lam}
        except (OverflowError, ZeroDivisionError):
            scales = {"E_c = ω⁶/(6λ²)": math.inf}
        for what, v in scales.items():
            if not SCALE_MIN <= v <= SCALE_MAX:
                raise ConfigError(
                    f"omega = {self.omega!r}, lam = {self.lam!r} give {what} = {v:.3g}, outside "
                    f"[{SCALE_MIN:g}, {SCALE_MAX:g}]: the dynamics does not depend on the scale (lengths in ω²/λ, "
                    "energies in E_c), so use ω and λ nearer 1"
                )

    # -- identity (the System contract) -------------------------------------
    @property
    def name(self) -> str:
        return "henon_heiles"

    @property
    def params(self) -> dict[str, float]:
        return {"omega": float(self.omega), "lam": float(self.lam)}

    @property
    def potential_text(self) -> str:
        return "0.5*omega**2*(x**2 + y**2) + lam*(x**2*y - y**3/3)"

    def hash_items(self) -> dict[str, Any] | None:
        """None for linear drag (ω and λ are scene fields of their own); the drag law otherwise."""
        return None if self.dissipation == "linear" else {"dissipation": self.dissipation}

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

    @property
    def exits(self) -> tuple[Exit, ...]:
        """The three exits (channels 0, 1, 2 at π/2, 7π/6, 11π/6), all opening at E_c."""
        ec = self.critical_energy
        return tuple(Exit(float(x), float(y), ec) for x, y in self.saddles)

    @property
    def frequency(self) -> float:
        """ω (1/time)."""
        return self.omega

    def nonfinite_point(self, radius: float) -> None:
        """None: a polynomial potential is finite everywhere."""
        return None

    def force(self, x: ArrayLike, y: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(F_x, F_y) = (−ω²x − 2λxy, −ω²y − λ(x² − y²)) on numpy arrays."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        w2, lam = self.omega**2, self.lam
        return -w2 * x - 2.0 * lam * x * y, -w2 * y - lam * (x * x - y * y)

    def default_escape_radius(self, energy: float | None) -> float:
        """1.5 (ω = λ = 1; 1.5 r_s when r_s > 1): beyond every exit's Lyapunov orbit up to E = 0.5 (study resc).

        The project's r_esc since its first scenes; above E = 0.375 it lies inside R(E) = √(6E), where an
        outward crossing is not yet final (the resc study measures how rarely orbits return from there).
        """
        return max(1.5, 1.5 * self.saddle_radius)

    def no_return_radius(self, energy: float) -> float:
        """R(E) = √(6E)/ω (≥ r_s): beyond it −∂V/∂r > 0 wherever V ≤ E (length).

        In polar form V = ω²r²/2 + λr³ sin(3φ)/3; V ≤ E gives λ sin 3φ ≤ 3E/r³ − 3ω²/(2r), which is
        < −ω²/r (an outward radial force) exactly when r² > 6E/ω². At E = E_c it is the saddle distance.
        """
        return max(math.sqrt(6.0 * max(float(energy), 0.0)) / self.omega, self.saddle_radius)

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

    def potential_expression(self, x: Any, y: Any, hy: Any = None) -> Any:
        """V as a heyoka expression of the variables x, y (arithmetic only: ``hy`` is not needed)."""
        return 0.5 * self.omega**2 * (x**2 + y**2) + self.lam * (x**2 * y - y**3 / 3.0)

    def inside_well(self, x: ArrayLike, y: ArrayLike) -> np.ndarray:
        """The well's part of {V < E_c}: the open triangle of the saddles (:meth:`inside_triangle`)."""
        return self.inside_triangle(x, y)

    def scalar_energy(self) -> Callable[[float, float, float, float], float]:
        """H(x, y, px, py) in plain float arithmetic for the engine's per-record path."""
        half_w2, lam = 0.5 * self.omega**2, self.lam

        def energy(x, y, px, py):
            return 0.5 * (px * px + py * py) + half_w2 * (x * x + y * y) + lam * (x * x * y - y * y * y / 3.0)

        return energy

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

    # -- heyoka (expressions() and equations() come from System) ---------
    def force_expressions(self, x: Any, y: Any, hy: Any = None) -> tuple[Any, Any]:
        """(F_x, F_y) = −∇V simplified (−ω²x − 2λxy, −ω²y − λ(x² − y²)): no redundant products per Taylor step."""
        w2, lam = self.omega**2, self.lam
        return -(w2 * x) - (2.0 * lam) * (x * y), -(w2 * y) - lam * (x**2 - y**2)


def equations(model: System, hy, gamma_par=None):
    """equations(model, hy, gamma_par=None) -> heyoka system [(x, ẋ), (y, ẏ), (px, ṗx), (py, ṗy)]; ``hy``: the
    heyoka module.

    Hamilton's equations of H, paper Eq. (eqn:hh_ham), plus the drag −γp of the
    dissipative system when ``gamma_par`` (a heyoka expression for γ, e.g.
    ``hy.par[0]``) is given; None builds the conservative system without drag
    terms, which saves work per step.

    The right-hand side is written in simplified form (−ω²x − 2λxy, ...):
    ``hy.diff(H, x)`` yields the same functions with redundant constant
    products such as ``0.5*(2*px)`` that would cost operations on every
    Taylor step; the two forms are checked to be the same functions.
    """
    return model.equations(hy, gamma_par)


def hamilton_equations(model: System, hy):
    """hamilton_equations(model, hy) -> [(x, ∂H/∂px), ..., (py, −∂H/∂y)] straight from ``hy.diff`` (``hy``: the
    heyoka module).

    Hamilton's equations of H, Eq. (eqn:hh_ham), derived symbolically: the
    reference against which the hand-simplified :func:`equations` is tested.
    """
    (x, y, px, py), _, H = model.expressions(hy)
    return [(x, hy.diff(H, px)), (y, hy.diff(H, py)), (px, -hy.diff(H, x)), (py, -hy.diff(H, y))]
