"""The contract of a system: an open two-degree-of-freedom potential with a dissipation law.

Everything hhscatter integrates or analyses reads the system through this contract (a system is
data): the scene's validation, the events (escape radius, the closure E = E_c inside Ω, the section ṙ = 0,
φ̇ > 0 about the well's minimum), the IC regions, the outcome rules and exit channels, the analysis (E_c) and
the tables' provenance. Nothing outside a system's own definition may know which potential it is.

A system is

    H = (p_x² + p_y²)/2 + V(x, y)                                      Eq. (eq:H)
    ṗ = −∇V − γ p           (dissipation = "linear", the paper's drag)
    ṗ = −∇V − γ |p| p       (dissipation = "quadratic")

with unit mass, V's well minimum at the origin with V(0, 0) = 0, and exits: saddles of V through which
orbits from the well reach infinity. Both drag laws lower the energy (dE/dt = −γ|p|² or −γ|p|³ ≤ 0), so an
orbit inside Ω at E = E_c stays trapped: the closure event of the paper (Eq. (eqn:energy_diffeq)) holds.

A new system implements :class:`System` (a built-in such as :class:`hhscatter.model.HenonHeiles` with closed
forms, or a declared one whose quantities are derived from its expression). The contract, member by member:

| member | meaning | units |
|---|---|---|
| ``name`` | the built-in's name, or ``"declared"`` | — |
| ``params`` | the potential's parameters, name → value | — |
| ``dissipation`` | ``"linear"`` (−γp) or ``"quadratic"`` (−γ∣p∣p) | — |
| ``potential_text`` | V as text in x, y and the parameters' names | — |
| ``critical_energy`` | E_c: the lowest saddle energy through which orbits from the well reach infinity | energy |
| ``exits`` | the exits (:class:`Exit`), in channel order | — |
| ``saddle_radius`` | distance of the nearest exit saddle from the minimum: the length scale of bounds and IC regions | length |
| ``omega_radius`` | Ω = {r ≤ omega_radius}: the closure rule's well (contains the well part of V ≤ E_c, meets no other part) | length |
| ``potential(x, y)`` | V on numpy arrays | energy |
| ``expressions(hy)`` | ``((x, y, px, py), V, H)`` as heyoka expressions (``hy``: the heyoka module the engine hands in) | — |
| ``equations(hy, gamma_par)`` | the heyoka ODE system, with the drag when ``gamma_par`` is given | — |
| ``no_return_radius(E)`` | R such that an orbit of energy ≤ E at r ≥ R moving outward (ṙ > 0) never returns | length |
| ``inside_well(x, y)`` | in the well's part of {V < E_c} (the ``well`` IC region) | — |
| ``exit_channel(x, y)`` | index of the exit nearest in angle | — |
| ``scalar_energy()`` | a plain-float H(x, y, px, py) for the engine's per-record path | energy |
| ``frequency`` | √(largest eigenvalue of V's Hessian at the minimum): the time scale of bounds | 1/time |
| ``force(x, y)`` | −∇V on numpy arrays | energy/length |
| ``nonfinite_point(r)`` | a point of the disk r ≤ r where V or −∇V is not finite, or None | length |
| ``default_ic_radius()`` | the disk radius of region ICs when a scene gives none: r_s/2 | length |
| ``default_escape_radius(E)`` | r_esc when a scene gives none: beyond every exit's Lyapunov orbit at E | length |
| ``spec()`` | the plain-data spec that rebuilds the system (:mod:`hhscatter.model.spec`) | — |
| ``provenance()`` | what the tables' metadata records of the system | — |
| ``hash_items()`` | what enters a scene's hash (None: the paper's default system, left out of the hash) | — |
"""

from __future__ import annotations

import abc
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # annotations only
    from numpy.typing import ArrayLike

#: the dissipation laws: the drag force for γ > 0
DISSIPATIONS = ("linear", "quadratic")


@dataclass(frozen=True)
class Exit:
    """One exit of a system: a saddle of V through which orbits from the well reach infinity.

    Parameters
    ----------
    x, y : float
        The saddle's position (length).
    energy : float
        V at the saddle: the exit is open for E > energy (energy).

    Examples
    --------
    >>> e = Exit(0.0, 1.0, 1 / 6)
    >>> round(e.angle, 6), e.distance
    (1.570796, 1.0)
    """

    x: float
    y: float
    energy: float

    @property
    def angle(self) -> float:
        """Polar angle of the saddle (rad), in (−π, π]."""
        return math.atan2(self.y, self.x)

    @property
    def distance(self) -> float:
        """Distance of the saddle from the well's minimum at the origin (length)."""
        return math.hypot(self.x, self.y)


class System(abc.ABC):
    """A two-degree-of-freedom open system with drag: the contract every system implements (module docstring)."""

    dissipation: str = "linear"

    # -- identity ---------------------------------------------------------
    @property
    @abc.abstractmethod
    def name(self) -> str:
        """The built-in's name, or ``"declared"``."""

    @property
    @abc.abstractmethod
    def params(self) -> dict[str, float]:
        """The potential's parameters, name → value."""

    @property
    @abc.abstractmethod
    def potential_text(self) -> str:
        """V(x, y) as text in x, y and the parameters' names (Python syntax, ``**`` for powers)."""

    # -- derived quantities ------------------------------------------------
    @property
    @abc.abstractmethod
    def critical_energy(self) -> float:
        """E_c: the lowest energy at which orbits from the well can reach infinity (energy)."""

    @property
    @abc.abstractmethod
    def exits(self) -> tuple[Exit, ...]:
        """The exits in channel order: channel k of the tables is ``exits[k]``."""

    @property
    def saddle_radius(self) -> float:
        """Distance of the nearest exit saddle from the minimum (length): the length scale of bounds and IC regions."""
        return min(e.distance for e in self.exits)

    @property
    def omega_radius(self) -> float:
        """Ω = {r ≤ omega_radius}: contains the well's part of {V ≤ E_c} and meets no other part (length)."""
        return self.saddle_radius

    @abc.abstractmethod
    def potential(self, x: ArrayLike, y: ArrayLike) -> np.ndarray:
        """V(x, y) on numpy arrays (energy)."""

    @abc.abstractmethod
    def potential_expression(self, x: Any, y: Any, hy: Any) -> Any:
        """V as a heyoka expression of the heyoka variables ``x``, ``y``; ``hy``: the heyoka module (the engine
        hands it in: the model builds expressions, it does not import heyoka)."""

    def force_source(self) -> tuple[str, str]:
        """(F_x, F_y) = −∇V as Python source in x, y (``math`` functions), derived from :attr:`potential_text` and
        :attr:`params`: the force as code for a compiled integrator (the noise scheduler's symplectic flow).

        Examples
        --------
        Hénon–Heiles, V = (x² + y²)/2 + x²y − y³/3: F = (−x − 2xy, −y − x² + y²), (−0.42, −0.25) at (0.3, 0.2):

        >>> from hhscatter.model import HenonHeiles
        >>> fx, fy = HenonHeiles().force_source()
        >>> [round(eval(f, {"x": 0.3, "y": 0.2}), 12) for f in (fx, fy)]
        [-0.42, -0.25]
        """
        from hhscatter.model.parse import force_source  # deferred: parse imports sympy lazily, base stays light

        return force_source(self.potential_text, tuple(sorted(self.params.items())))

    @abc.abstractmethod
    def no_return_radius(self, energy: float) -> float:
        """R(E): an orbit of energy ≤ E at r ≥ R with ṙ > 0 never comes back (length).

        Sufficient condition used by every implementation: at every accessible point beyond R (V ≤ E) the
        potential's radial force is outward, −∂V/∂r > 0; then ṗ_r = −∂V/∂r + L²/r³ − γ(·)p_r keeps p_r > 0
        under either drag law, and the energy only falls, so the accessible region only shrinks.
        """

    # -- generic implementations (a built-in may override with closed forms) ----
    @property
    def frequency(self) -> float:
        """√(largest eigenvalue of V's Hessian at the minimum) (1/time): the time scale of bounds on γ.

        Central differences with step 1e-4 (relative error ≈ 1e-8 for smooth potentials).
        """
        h = 1e-4
        v = lambda x, y: float(self.potential(np.array(x), np.array(y)))  # noqa: E731
        vxx = (v(h, 0) - 2 * v(0, 0) + v(-h, 0)) / h**2
        vyy = (v(0, h) - 2 * v(0, 0) + v(0, -h)) / h**2
        vxy = (v(h, h) - v(h, -h) - v(-h, h) + v(-h, -h)) / (4 * h * h)
        lam_max = 0.5 * (vxx + vyy) + math.sqrt(0.25 * (vxx - vyy) ** 2 + vxy**2)
        return math.sqrt(max(lam_max, 0.0))

    def force(self, x: ArrayLike, y: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(F_x, F_y) = −∇V on numpy arrays (central differences here; systems override with exact forms)."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        h = 1e-6 * np.maximum(1.0, np.hypot(x, y))
        fx = -(self.potential(x + h, y) - self.potential(x - h, y)) / (2 * h)
        fy = -(self.potential(x, y + h) - self.potential(x, y - h)) / (2 * h)
        return fx, fy

    def default_escape_radius(self, energy: float | None) -> float:
        """r_esc when a scene gives none (length): max(1.5 r_s, R(E)) with R the no-return radius.

        Beyond R(E) an outward-moving orbit never returns (:meth:`no_return_radius`), so an escape decided
        there is final; 1.5 r_s keeps r_esc clear of the exits' Lyapunov orbits at low E. Without an energy
        (ICs from a table) 1.5 r_s. R(E) itself lies beyond every bounded orbit of energy ≤ E, Lyapunov
        orbits included: at an orbit's farthest point ṙ = 0 and r̈ = v_⊥²/r − ∂V/∂r ≤ 0, so −∂V/∂r ≤ 0
        there, at a point with V ≤ E, and such points lie within R(E).
        """
        r = 1.5 * self.saddle_radius
        return max(r, self.no_return_radius(energy)) if energy is not None else r

    def nonfinite_point(self, radius: float) -> tuple[float, float] | None:
        """A point of the disk r ≤ radius where V or the force −∇V is not finite (or not real), or None.

        Checked on a polar grid (the origin, 400 radii × 720 angles): orbits that move there would stop the
        integrator. Systems whose potential is finite everywhere (polynomials) return None at once.
        """
        r = np.linspace(0.0, float(radius), 401)[1:]
        th = np.linspace(0.0, 2 * np.pi, 720, endpoint=False)
        R, T = np.meshgrid(r, th)
        x = np.concatenate([[0.0], (R * np.cos(T)).ravel()])
        y = np.concatenate([[0.0], (R * np.sin(T)).ravel()])
        with np.errstate(all="ignore"):
            fx, fy = self.force(x, y)
            ok = np.isfinite(self.potential(x, y)) & np.isfinite(fx) & np.isfinite(fy)
        if ok.all():
            return None
        k = int(np.argmin(np.where(ok, np.inf, np.hypot(x, y))))  # the nearest such point
        return float(x[k]), float(y[k])

    def default_ic_radius(self) -> float:
        """The disk radius of region ICs when a scene gives none (length): half the saddle distance, r_s/2.

        0.5 for Hénon–Heiles with ω = λ = 1 (the authors' code); for another system the same fraction of its own
        length scale, so that the disk samples the chaotic layer below the saddles, not a regular core.
        """
        return 0.5 * self.saddle_radius

    def spec(self) -> dict[str, Any]:
        """The plain-data spec that rebuilds this system (:func:`hhscatter.model.spec.system_from_spec`)."""
        key = ("potential", self.potential_text) if self.name == "declared" else ("name", self.name)
        return {key[0]: key[1], "params": dict(self.params), "dissipation": self.dissipation}

    def energy(self, x: ArrayLike, y: ArrayLike, px: ArrayLike, py: ArrayLike) -> np.ndarray:
        """H(x, y, p_x, p_y), Eq. (eq:H) (energy)."""
        px = np.asarray(px, dtype=float)
        py = np.asarray(py, dtype=float)
        return 0.5 * (px * px + py * py) + self.potential(x, y)

    def exit_channel(self, x: ArrayLike, y: ArrayLike) -> np.ndarray:
        """exit_channel(x, y) -> int8 array: index of the exit whose saddle is nearest in angle."""
        phi = np.arctan2(np.asarray(y, dtype=float), np.asarray(x, dtype=float))
        angles = np.array([e.angle for e in self.exits])
        d = np.abs((phi[..., None] - angles + np.pi) % (2 * np.pi) - np.pi)
        return np.argmin(d, axis=-1).astype(np.int8)

    def inside_well(self, x: ArrayLike, y: ArrayLike, samples: int = 64) -> np.ndarray:
        """True where (x, y) is joined to the minimum by a straight segment inside {V < E_c}.

        The well's part of {V < E_c} for wells star-shaped about the minimum (every built-in's); tested at
        ``samples`` points of the segment.
        """
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        ec = self.critical_energy
        ok = np.ones(np.broadcast(x, y).shape, dtype=bool)
        for s in np.linspace(1.0 / samples, 1.0, samples):
            ok &= self.potential(s * x, s * y) < ec
        return ok

    # The expression builders below take the heyoka module as ``hy``: heyoka is imported only by the engine
    # (hhscatter.integrate), which hands it in; the model says what the expressions are, in heyoka's vocabulary.
    def expressions(self, hy: Any) -> tuple[tuple[Any, Any, Any, Any], Any, Any]:
        """expressions(hy) -> (state_vars, V, H) as heyoka expressions; state order x, y, px, py; ``hy``: the
        heyoka module."""
        x, y, px, py = hy.make_vars("x", "y", "px", "py")
        V = self.potential_expression(x, y, hy)
        return (x, y, px, py), V, 0.5 * (px**2 + py**2) + V

    def force_expressions(self, x: Any, y: Any, hy: Any) -> tuple[Any, Any]:
        """(F_x, F_y) = −∇V as heyoka expressions (a built-in may give simplified forms); ``hy``: the heyoka
        module."""
        V = self.potential_expression(x, y, hy)
        return -hy.diff(V, x), -hy.diff(V, y)

    def equations(self, hy: Any, gamma_par: Any = None) -> list:
        """equations(hy, gamma_par=None) -> heyoka system [(x, ẋ), (y, ẏ), (px, ṗx), (py, ṗy)].

        Hamilton's equations of H, Eq. (eqn:hh_ham) for Hénon–Heiles, plus the drag of :attr:`dissipation`
        when ``gamma_par`` (a heyoka expression for γ, e.g. ``hy.par[0]``) is given; None builds the
        conservative system without drag terms. ``hy``: the heyoka module.
        """
        x, y, px, py = hy.make_vars("x", "y", "px", "py")
        fx, fy = self.force_expressions(x, y, hy)
        if gamma_par is not None:
            if self.dissipation == "linear":
                fx, fy = fx - gamma_par * px, fy - gamma_par * py
            else:  # quadratic: −γ |p| p
                speed = hy.sqrt(px**2 + py**2)
                fx, fy = fx - gamma_par * speed * px, fy - gamma_par * speed * py
        return [(x, px), (y, py), (px, fx), (py, fy)]

    def scalar_energy(self) -> Callable[[float, float, float, float], float]:
        """A plain-float H(x, y, px, py) for the engine's per-record path (numpy costs µs per scalar)."""
        pot = self.potential

        def energy(x, y, px, py):
            return 0.5 * (px * px + py * py) + float(pot(x, y))

        return energy

    def provenance(self) -> dict[str, Any]:
        """What the tables' metadata records of the system: name, V as text, parameters, dissipation."""
        return {
            "system": self.name,
            "potential": self.potential_text,
            "params": dict(self.params),
            "dissipation": self.dissipation,
        }

    def hash_items(self) -> dict[str, Any] | None:
        """What enters a scene's hash; None for the paper's system (Hénon–Heiles, linear drag)."""
        return self.provenance()

    def describe(self) -> str:
        """One line: name, E_c and the exits."""
        ex = ", ".join(f"({e.x:.4g}, {e.y:.4g}) at V = {e.energy:.6g}" for e in self.exits)
        return f"{self.name}: V = {self.potential_text}, E_c = {self.critical_energy:.10g}, exits {ex}"


__all__ = ["DISSIPATIONS", "Exit", "System"]
