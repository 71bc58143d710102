"""The Kramers turnover: the Mel'nikov–Meshkov depopulation factor and the rate across the energy- and
spatial-diffusion regimes.

At weak drag the escape rate is limited by the diffusion of energy in the well, not by the crossing of the
barrier. Mel'nikov and Meshkov (J. Chem. Phys. 85, 1018 (1986)) bridge the two Kramers limits with the
depopulation factor

    Υ(δ) = exp[(1/2π) ∫ ln(1 − e^{−δ(x² + 1/4)}) dx/(x² + 1/4)],      the integral over all real x,

(equivalently (1/π) ∫ ln(1 − e^{−δ(1 + y²)/4}) dy/(1 + y²), y = 2x), where δ is the mean energy an orbit at the
barrier energy loses to the drag in one period, over T. For the linear drag −γp of unit mass the loss along an
orbit is γ ∮ p·dq = γ S, so δ = γ S/T with S the orbit's action (energy·time). Pollak, Grabert and Hänggi
(J. Chem. Phys. 91, 4073 (1989)) give the turnover rate

    k_MM = Υ(δ) · k_KL,

k_KL the Kramers–Langer rate (:func:`~hhscatter.analysis.noise.kramers.kramers_langer`). Its limits are the two
Kramers regimes: Υ → 1 for δ → ∞ (spatial diffusion, k → k_KL) and Υ → δ for δ → 0 (energy diffusion,
k → k_ED = δ · k_TST, k_TST the transition-state rate, the γ → 0 limit of k_KL). The theory assumes an
underdamped barrier crossing beside a slow loss of energy: γ ≪ ω_b and ΔE/T ≫ 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import integrate, optimize

from hhscatter.analysis.noise.kramers import KramersLanger
from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = ["TurnoverRate", "barrier_action", "depopulation_factor", "energy_loss_parameter", "turnover_rate"]


def _log_upsilon(delta: float) -> float:
    """ln Υ(δ) by adaptive quadrature over x ≥ 0 (the integrand is even), split where δ(x² + 1/4) reaches 1."""

    def f(x):
        u = x * x + 0.25
        return math.log(-math.expm1(-delta * u)) / u

    knee = math.sqrt(max(1.0 / delta - 0.25, 0.0))
    parts = [(0.0, knee), (knee, math.inf)] if knee > 0 else [(0.0, math.inf)]
    total = sum(integrate.quad(f, a, b, limit=200, epsabs=1e-13, epsrel=1e-11)[0] for a, b in parts)
    return 2.0 * total / (2.0 * math.pi)


def depopulation_factor(delta):
    """depopulation_factor(δ) -> Υ(δ) (dimensionless, in (0, 1]): the Mel'nikov–Meshkov factor (module docstring).

    ``delta``: the energy loss per period at the barrier energy over T (dimensionless, > 0), a number or an
    array (the result has its shape). Υ rises from Υ ≈ δ at δ ≪ 1 (energy diffusion) to 1 at δ ≫ 1 (spatial
    diffusion); at small δ, Υ = δ (1 + ζ(1/2) √(δ/π) + …).

    Examples
    --------
    >>> round(float(depopulation_factor(1e-6)) / 1e-6, 3), round(float(depopulation_factor(50.0)), 5)
    (0.999, 1.0)
    >>> depopulation_factor([0.1, 1.0, 10.0]).round(4)
    array([0.0771, 0.443 , 0.9742])
    """
    if isinstance(delta, (str, bytes, dict)) or delta is None:
        raise ConfigError(f"delta must be a number or an array of numbers, got {type(delta).__name__}")
    try:
        d = np.asarray(delta, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError(f"delta must be a number or an array of numbers, got {type(delta).__name__}") from None
    if not np.all(np.isfinite(d) & (d > 0)):
        raise ConfigError(f"delta must be finite and > 0 (the energy loss per period over T), got {delta!r}")
    out = np.array([math.exp(_log_upsilon(float(v))) for v in d.ravel()]).reshape(d.shape)
    return out


def energy_loss_parameter(gamma: float, action: float, temperature: float) -> float:
    """energy_loss_parameter(γ, S, T) -> δ = γ S / T (dimensionless): the energy lost to the drag −γp over one
    period of an orbit of action S = ∮ p·dq (energy·time), in units of T (energy).

    Examples
    --------
    >>> energy_loss_parameter(0.1, 0.6, 1 / 18)     # γ = 0.1, S = 0.6, ΔE/T = 3 at ΔE = 1/6
    1.08
    """
    gamma, action = check.number(gamma, "gamma", positive=True), check.number(action, "action", positive=True)
    temperature = check.number(temperature, "temperature", positive=True)
    return round(gamma * action / temperature, 15)


def barrier_action(model, exit: int = 0) -> float:
    """barrier_action(model, exit=0) -> S (energy·time): the action ∮ p·dq of the orbit at the saddle's energy
    E_s that leaves the saddle of ``model.exits[exit]`` along the line to the well's minimum (the origin),
    turns on V = E_s across the well and comes back: S = 2 ∫ √(2 (E_s − V)) ds along that line (unit mass).

    It is the orbit whose energy loss per period, γ S, sets δ = γ S/T (:func:`energy_loss_parameter`). The
    orbit stays on the line when the line is invariant (the force along it is parallel to it: a symmetry
    axis of V); otherwise S is the one-dimensional estimate along it.

    Examples
    --------
    Hénon–Heiles along x = 0: E_s − V = (1 − y)² (y + 1/2)/3, from y = −1/2 to the saddle y = 1: S = 6/5.

    >>> from hhscatter.model import HenonHeiles
    >>> round(barrier_action(HenonHeiles()), 10)
    1.2
    """
    exits = check.system(model).exits
    if isinstance(exit, bool) or not isinstance(exit, (int, np.integer)) or not 0 <= exit < len(exits):
        raise ConfigError(f"exit must be a channel index from 0 to {len(exits) - 1}, got {exit!r}")
    e = exits[exit]
    xs, ys, e_s = float(e.x), float(e.y), float(e.energy)
    r_s = math.hypot(xs, ys)
    ux, uy = xs / r_s, ys / r_s

    def gap(s):  # E_s − V at s along the line (s = r_s: the saddle, s = 0: the minimum)
        return e_s - float(model.potential(np.array(s * ux), np.array(s * uy)))

    if not gap(0.0) > 0:
        raise ConfigError("the origin is not below the saddle's energy: the system has no well there")
    lo = -r_s
    while gap(lo) > 0:  # the far turning point on V = E_s, across the well
        lo *= 2
        if lo < -1e6 * r_s:
            raise ConfigError(f"V stays below E_s along the line through exit {exit} and the minimum: no turning point")
    s_turn = optimize.brentq(gap, lo, 0.0, xtol=1e-15 * r_s, rtol=1e-15)
    f = lambda s: math.sqrt(2.0 * max(gap(s), 0.0))
    val = integrate.quad(f, s_turn, 0.0, epsabs=0, epsrel=1e-12, limit=200)[0]
    val += integrate.quad(f, 0.0, r_s, epsabs=0, epsrel=1e-12, limit=200)[0]
    return 2.0 * val


@dataclass(frozen=True)
class TurnoverRate:
    """The turnover rate at (γ, T): ``rate`` = Υ(δ) k_KL (1/time, Mel'nikov–Meshkov–Pollak–Grabert–Hänggi),
    the two Kramers limits ``energy_diffusion`` = δ k_TST and ``spatial_diffusion`` = k_KL (1/time),
    ``transition_state`` = k_TST (1/time), ``delta`` (the per-saddle δ, a tuple) and ``upsilon`` (the per-saddle
    Υ), ``gamma_over_omega_b`` (γ over the smallest ω_b: the theory assumes it ≪ 1)."""

    gamma: float
    temperature: float
    rate: float
    energy_diffusion: float
    spatial_diffusion: float
    transition_state: float
    delta: tuple
    upsilon: tuple
    gamma_over_omega_b: float


def turnover_rate(kl, actions) -> TurnoverRate:
    """turnover_rate(kl, S) -> TurnoverRate: k_MM = Σ_s Υ(δ_s) k_KL,s with δ_s = γ S_s/T (module docstring).

    ``kl``: a :class:`~hhscatter.analysis.noise.kramers.KramersLanger` (its γ, T and per-saddle terms);
    ``actions``: S (energy·time), the action ∮ p·dq of the orbit at the barrier energy that loses energy to
    the drag, one for every saddle or one number for all.

    Examples
    --------
    One saddle, ω_b = 1, unit Hessian ratio, ΔE/T = 3; at δ → ∞ the rate is Kramers–Langer's, at small δ it is
    δ k_TST:

    >>> from hhscatter.model import HenonHeiles
    >>> from hhscatter.analysis.noise import kramers_langer
    >>> kl = kramers_langer(HenonHeiles(), 1.0, 1 / 18)
    >>> tr = turnover_rate(kl, 1e4)
    >>> round(tr.rate / kl.rate, 9), round(tr.spatial_diffusion / kl.rate, 9)
    (1.0, 1.0)
    >>> weak = turnover_rate(kramers_langer(HenonHeiles(), 1e-8, 1 / 18), 0.5)
    >>> round(weak.rate / weak.energy_diffusion, 3), weak.delta[0]
    (1.0, 9e-08)
    """
    if not isinstance(kl, KramersLanger):
        raise ConfigError(f"kl must be a KramersLanger (kramers_langer's result), got {type(kl).__name__}")
    terms = kl.terms
    s = check.numbers(actions, "actions", positive=True)
    if s.size not in (1, len(terms)):
        raise ConfigError(f"actions must be one number or one per saddle ({len(terms)}), got {s.size}")
    s = np.broadcast_to(s, (len(terms),))
    deltas = tuple(energy_loss_parameter(kl.gamma, float(a), kl.temperature) for a in s)
    ups = tuple(float(u) for u in depopulation_factor(np.array(deltas)))
    tst = [t.omega_b / t.lambda_plus * t.rate for t in terms]
    return TurnoverRate(
        gamma=kl.gamma,
        temperature=kl.temperature,
        rate=float(sum(u * t.rate for u, t in zip(ups, terms))),
        energy_diffusion=float(sum(d * k for d, k in zip(deltas, tst))),
        spatial_diffusion=float(kl.rate),
        transition_state=float(sum(tst)),
        delta=deltas,
        upsilon=ups,
        gamma_over_omega_b=kl.gamma / min(t.omega_b for t in terms),
    )
