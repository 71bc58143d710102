"""The Kramers–Langer escape rate over a system's saddles, and the measured thermal rate it is compared with.

Kramers–Langer (multidimensional Kramers theory in the spatial-diffusion regime, γ ≳ ω_b; Hänggi, Talkner &
Borkovec, Rev. Mod. Phys. 62, 251 (1990), Eq. (4.49)) for unit mass and the linear drag −γp:

    k = Σ_saddles (λ₊/2π) √(det H_min / |det H_s|) e^{−ΔE_s/T},    λ₊ = −γ/2 + √(γ²/4 + ω_b²),

with H_min, H_s the Hessians of V at the well's minimum and at saddle s (exact, from the potential's
expression: :func:`hessian`), ω_b² = −(the negative eigenvalue of H_s) and ΔE_s = V(s) − V(min). Everything comes from the system object: its exits are the saddles, its
potential gives the Hessians (:func:`hessian`), the minimum is the origin (the System contract). The formula
is the leading term of an expansion in T/ΔE: the measured rate's ratio to it tends to 1 as the barrier grows.

The measured rate (:func:`thermal_rate`) is the constant-hazard maximum-likelihood rate on a window after the
orbits have relaxed in the well: left-truncated at t_start, right-censored at t_stop and at each orbit's
censoring (:func:`hhscatter.analysis.survival.escape_rate.escape_rate_mle`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.intervals import BoundedFraction, fraction_with_bound
from hhscatter.analysis.stats.measured import Measured, WithErrors
from hhscatter.analysis.survival.escape_rate import escape_rate_mle
from hhscatter.errors import ConfigError

__all__ = [
    "KramersLanger",
    "SaddleTerm",
    "ThermalRate",
    "WindowConstancy",
    "exit_fractions",
    "hessian",
    "kramers_langer",
    "thermal_rate",
    "well_barrier",
    "window_constancy",
]

#: relative central-difference step of :func:`hessian` for a potential given as a function only: the step is
#: this times the point's length scale max(|x|, |y|, the saddles' distance), so a rescaled system keeps the same
#: relative error (about step² times the ratio of the fourth to the second derivative: 1e-8 for smooth V)
HESSIAN_STEP = 1e-4

_LANDSCAPES: dict = {}


def _landscape(model):
    """The exact derivatives of ``model``'s potential (its text and parameters), built once per potential."""
    from hhscatter.model.landscape import Landscape  # deferred: sympy loads on first use
    from hhscatter.model.parse import parse_potential, substitute  # deferred: sympy loads on first use

    params = dict(model.params)
    key = (model.potential_text, tuple(sorted(params.items())))
    if key not in _LANDSCAPES:
        _LANDSCAPES[key] = Landscape(substitute(parse_potential(model.potential_text, params), params))
    return _LANDSCAPES[key]


def hessian(model, x: float, y: float, step: float | None = None) -> np.ndarray:
    """hessian(model, x, y) -> (2, 2) Hessian of the system's potential V at (x, y) (energy/length²).

    Exact: the second derivatives of the system's potential expression (``model.potential_text`` with
    ``model.params``, :class:`hhscatter.model.landscape.Landscape`), so the result is right at every scale of
    the system (a Hénon–Heiles with λ = 1e-5 has its saddles at distance 10⁵). An object with only a
    ``potential`` function, or an explicit ``step``, gets central differences with the step ``step`` (default
    :data:`HESSIAN_STEP`) times the point's length scale max(|x|, |y|, the saddles' distance).

    Examples
    --------
    >>> from hhscatter.model import HenonHeiles
    >>> hessian(HenonHeiles(), 0.0, 1.0)     # the saddle (0, 1): V_xx = 1 + 2y, V_yy = 1 − 2y
    array([[ 3.,  0.],
           [ 0., -1.]])
    >>> hessian(HenonHeiles(lam=1e-5), 0.0, 1e5)      # the same saddle of a system 10⁵ times larger
    array([[ 3.,  0.],
           [ 0., -1.]])
    """
    if not callable(getattr(model, "potential", None)):
        raise ConfigError(f"model must be a System (hhscatter.model) or have a potential, got {type(model).__name__}")
    x, y = check.number(x, "x"), check.number(y, "y")
    if step is not None:
        check.number(step, "step", positive=True)
    if step is None and hasattr(model, "potential_text") and hasattr(model, "params"):
        a, b, c = (float(v) for v in _landscape(model).hessian(float(x), float(y)))
        return np.array([[a, b], [b, c]])

    def v(a, b):
        return float(model.potential(np.array(a, dtype=float), np.array(b, dtype=float)))

    scale = max(abs(x), abs(y), float(getattr(model, "saddle_radius", 1.0)))
    h = (HESSIAN_STEP if step is None else step) * scale
    vxx = (v(x + h, y) - 2 * v(x, y) + v(x - h, y)) / h**2
    vyy = (v(x, y + h) - 2 * v(x, y) + v(x, y - h)) / h**2
    vxy = (v(x + h, y + h) - v(x + h, y - h) - v(x - h, y + h) + v(x - h, y - h)) / (4 * h * h)
    return np.array([[vxx, vxy], [vxy, vyy]])


@dataclass(frozen=True)
class SaddleTerm:
    """One saddle's term of the Kramers–Langer rate.

    x, y (length), barrier ΔE = V(s) − V(min) (energy), omega_b (1/time, the unstable frequency),
    lambda_plus (1/time, the growth rate with drag), prefactor (λ₊/2π)√(det H_min/|det H_s|) (1/time), rate
    (1/time, prefactor · e^{−ΔE/T}).

    The numbers are checked when the term is built: x, y finite, barrier, omega_b, lambda_plus and prefactor
    finite and > 0 (a saddle above the well's minimum, an unstable direction), rate finite and ≥ 0 (e^{−ΔE/T} may
    underflow); a wrong one (a word, a bool, NaN or inf, a value out of range) is refused with a ConfigError naming
    it.

    Examples
    --------
    :func:`kramers_langer` builds one per exit; a saddle below the well's minimum is no barrier:

    >>> SaddleTerm(x=0.0, y=1.0, barrier=-0.1, omega_b=1.0, lambda_plus=0.6, prefactor=0.057, rate=0.001)
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: barrier must be > 0, got -0.1
    """

    x: float
    y: float
    barrier: float
    omega_b: float
    lambda_plus: float
    prefactor: float
    rate: float

    def __post_init__(self):
        check.number(self.x, "x")
        check.number(self.y, "y")
        for name in ("barrier", "omega_b", "lambda_plus", "prefactor"):
            check.number(getattr(self, name), name, positive=True)
        check.number(self.rate, "rate", minimum=0.0)


@dataclass(frozen=True)
class KramersLanger:
    """The Kramers–Langer rate of a system at (γ, T): ``rate`` (1/time), the lowest ``barrier`` ΔE (energy),
    ``barrier_over_T`` = ΔE/T, and the per-saddle ``terms`` (:class:`SaddleTerm`).

    Checked when built: gamma, temperature, barrier and barrier_over_T finite and > 0, rate finite and ≥ 0, terms
    a tuple of at least one SaddleTerm; a wrong one is refused with a ConfigError naming it.

    >>> KramersLanger(gamma=1.0, temperature=0.0, rate=0.001, barrier=1 / 6, barrier_over_T=6.0, terms=())
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: temperature must be > 0, got 0.0
    """

    gamma: float
    temperature: float
    rate: float
    barrier: float
    barrier_over_T: float
    terms: tuple

    def __post_init__(self):
        for name in ("gamma", "temperature", "barrier", "barrier_over_T"):
            check.number(getattr(self, name), name, positive=True)
        check.number(self.rate, "rate", minimum=0.0)
        if (
            not isinstance(self.terms, tuple)
            or not self.terms
            or not all(isinstance(t, SaddleTerm) for t in self.terms)
        ):
            raise ConfigError(f"terms must be a tuple of at least one SaddleTerm, got {self.terms!r}")


def well_barrier(model) -> float:
    """well_barrier(model) -> ΔE = E_c − V(0, 0) (energy units): the lowest exit's energy above the well's minimum
    at the origin (the System contract), the barrier a thermal rate's ΔE/T refers to.

    Examples
    --------
    Hénon–Heiles: E_c = 1/6, V(0, 0) = 0:

    >>> from hhscatter.model import HenonHeiles
    >>> well_barrier(HenonHeiles()) == 1 / 6
    True
    """
    check.system(model)
    return model.critical_energy - float(model.potential(np.array(0.0), np.array(0.0)))


def kramers_langer(model, gamma: float, temperature: float) -> KramersLanger:
    """kramers_langer(model, γ, T) -> KramersLanger: the escape rate over every exit saddle (module docstring).

    Parameters
    ----------
    model : hhscatter.model.System
        The system: its exits are the saddles, its minimum is at the origin.
    gamma : float
        Drag γ > 0 (1/time).
    temperature : float
        T > 0 (energy).

    Examples
    --------
    Hénon–Heiles, three saddles with det H_s = −3, ω_b = 1, ΔE = 1/6; at γ = 1 and ΔE/T = 6:
    k = 3 (0.618…/2π)(1/√3) e^{−6}:

    >>> from hhscatter.model import HenonHeiles
    >>> kl = kramers_langer(HenonHeiles(), 1.0, 1 / 36)
    >>> round(kl.barrier_over_T, 9), len(kl.terms), round(kl.terms[0].lambda_plus, 9)
    (6.0, 3, 0.618033989)
    >>> round(kl.rate / (3 * (5**0.5 - 1) / 2 / (2 * math.pi) / 3**0.5 * math.exp(-6)), 6)
    1.0
    """
    check.system(model)
    gamma = check.number(gamma, "gamma", positive=True)
    temperature = check.number(temperature, "temperature", positive=True)
    h_min = hessian(model, 0.0, 0.0)
    det_min = float(np.linalg.det(h_min))
    if not (det_min > 0 and np.all(np.linalg.eigvalsh(h_min) > 0)):
        raise ConfigError("the origin is not a minimum of V: Kramers–Langer needs a well there")
    v_min = float(model.potential(np.array(0.0), np.array(0.0)))
    terms = []
    for e in model.exits:
        hs = hessian(model, e.x, e.y)
        ev = np.linalg.eigvalsh(hs)
        if not (ev[0] < 0 < ev[1]):
            raise ConfigError(f"exit ({e.x:g}, {e.y:g}) is not a saddle of V (Hessian eigenvalues {ev})")
        wb = math.sqrt(-ev[0])
        lam = -gamma / 2 + math.sqrt(gamma * gamma / 4 + wb * wb)
        pref = lam / (2 * math.pi) * math.sqrt(det_min / abs(float(np.linalg.det(hs))))
        barrier = float(e.energy) - v_min
        terms.append(SaddleTerm(e.x, e.y, barrier, wb, lam, pref, pref * math.exp(-barrier / temperature)))
    low = min(t.barrier for t in terms)
    return KramersLanger(gamma, temperature, sum(t.rate for t in terms), low, low / temperature, tuple(terms))


@dataclass(frozen=True)
class ThermalRate(WithErrors):
    """A measured long-time escape rate: ``rate`` ± ``rate_err`` (1/time) on [t_start, t_stop], from
    ``n_events`` escapes over ``exposure`` (orbit·time); ``halves``: the rates on the window's two halves (a
    constant hazard gives equal ones within their errors), each (rate, err).

    A window without an escape holds no rate: ``rate`` and ``rate_err`` are NaN, ``is_bound`` is True and
    ``upper95`` (1/time) is the one-sided 95 % upper bound −ln(0.05)/exposure
    (:func:`~hhscatter.analysis.survival.escape_rate.escape_rate_mle`); compare it as a bound, never as a value."""

    method = "maximum likelihood (events / exposure)"
    n_field = "n_events"

    rate: float
    rate_err: float
    n_events: int
    exposure: float
    t_start: float
    t_stop: float
    halves: tuple
    upper95: float = math.nan

    @property
    def is_bound(self) -> bool:
        """True when the window holds no escape: ``upper95`` bounds the rate, ``rate`` is NaN."""
        return self.n_events == 0


def thermal_rate(t_end, escaped, t_start: float, t_stop: float) -> ThermalRate:
    """thermal_rate(t_end, escaped, t_start, t_stop) -> ThermalRate: the constant-hazard MLE on [t_start, t_stop].

    ``t_end``: each orbit's end time (time units); ``escaped``: boolean mask, True where it escaped (the rest
    are censored at their t_end). Orbits that ended before t_start do not count (left truncation).

    Examples
    --------
    Exponential lifetimes of rate 0.01, censored at 300:

    >>> rng = np.random.default_rng(1)
    >>> t = rng.exponential(100.0, 20000)
    >>> r = thermal_rate(np.minimum(t, 300.0), t < 300.0, 50.0, 300.0)
    >>> abs(r.rate - 0.01) < 3 * r.rate_err, r.n_events > 5000
    (True, True)

    No escape in the window: a bound, not a rate of 0:

    >>> b = thermal_rate(np.full(1000, 300.0), np.zeros(1000, bool), 50.0, 300.0)
    >>> b.is_bound, b.rate, round(b.upper95 * 1000 * 250.0, 4)     # −ln 0.05 over 2.5e5 orbit·time
    (True, nan, 2.9957)
    """
    t_end = check.numbers(t_end, "t_end", min_size=0)
    escaped = check.mask(escaped, "escaped", t_end.size)
    t_start, t_stop = check.window(t_start, t_stop)
    whole = escape_rate_mle(t_end, escaped, t_start, t_stop)
    mid = 0.5 * (t_start + t_stop)
    halves = tuple(
        (m.kappa, m.kappa_err)
        for m in (escape_rate_mle(t_end, escaped, a, b) for a, b in ((t_start, mid), (mid, t_stop)))
    )
    return ThermalRate(
        whole.kappa, whole.kappa_err, whole.n_events, whole.exposure, t_start, t_stop, halves, whole.upper95
    )


@dataclass(frozen=True)
class WindowConstancy:
    """Whether a rate is constant inside its window: the rates on the window's two halves ``first`` and ``second``
    (:class:`~hhscatter.analysis.stats.measured.Measured`, 1/time), ``z`` = (k₂ − k₁)/√(σ₁² + σ₂²) (NaN when a
    half has no error: no escape in it) and ``constant`` = |z| < ``z_max``."""

    first: Measured
    second: Measured
    z: float
    z_max: float
    constant: bool


def window_constancy(rate: ThermalRate, z_max: float) -> WindowConstancy:
    """window_constancy(rate, z_max) -> WindowConstancy: the two halves of a :class:`ThermalRate`'s window compared.

    ``rate``: a :func:`thermal_rate` result (its ``halves``); ``z_max``: the number of combined standard errors
    within which the halves agree (a constant hazard gives |z| < z_max with the normal probability).

    Examples
    --------
    Halves 0.012 ± 0.003 and 0.008 ± 0.004: z = −0.004/0.005 = −0.8, constant within 3σ but not within 0.5σ:

    >>> r = ThermalRate(0.01, 0.002, 40, 4000.0, 0.0, 100.0, ((0.012, 0.003), (0.008, 0.004)))
    >>> c = window_constancy(r, 3.0)
    >>> round(c.z, 12), c.constant, window_constancy(r, 0.5).constant
    (-0.8, True, False)
    >>> c.second.value, c.second.err
    (0.008, 0.004)
    """
    if not isinstance(rate, ThermalRate):
        raise ConfigError(f"rate must be a ThermalRate (thermal_rate's result), got {type(rate).__name__}")
    z_max = check.number(z_max, "z_max", positive=True)
    (k1, e1), (k2, e2) = rate.halves
    first, second = Measured(k1, e1, rate.method), Measured(k2, e2, rate.method)
    z = second.z(k1, e1) if e1 > 0 and e2 > 0 else math.nan
    return WindowConstancy(first, second, z, z_max, bool(abs(z) < z_max))


def exit_fractions(t_end, escaped, exit_channel, t_start: float, t_stop: float, n_exits: int) -> list[BoundedFraction]:
    """exit_fractions(t_end, escaped, exit_channel, t_start, t_stop, n_exits) -> one fraction per exit: the share
    of the escapes in (t_start, t_stop] (time units) through each exit 0 … n_exits − 1, with its binomial error or
    its one-sided 95 % bound (:func:`~hhscatter.analysis.stats.intervals.fraction_with_bound`; a window without an
    escape counts as one trial, so every share is 0 with its bound).

    ``t_end``: each orbit's end time; ``escaped``: True where it escaped; ``exit_channel``: the exit it left by
    (any value for the orbits that did not escape).

    Examples
    --------
    Five escapes in (10, 100]: three through exit 0, two through exit 1, none through exit 2; the escape at t = 5
    lies before the window:

    >>> t = np.array([5.0, 20.0, 30.0, 40.0, 50.0, 60.0, 200.0])
    >>> esc = np.array([True, True, True, True, True, True, False])
    >>> ch = np.array([1, 0, 0, 1, 0, 1, -1])
    >>> f = exit_fractions(t, esc, ch, 10.0, 100.0, 3)
    >>> [x.value for x in f], round(f[0].err, 4), round(f[2].upper, 4)     # √(0.6 · 0.4 / 5); 1 − 0.05^(1/5)
    ([0.6, 0.4, 0.0], 0.2191, 0.4507)
    """
    t_end = check.numbers(t_end, "t_end", minimum=0.0)
    escaped = check.mask(escaped, "escaped", t_end.size)
    t_start, t_stop = check.window(t_start, t_stop)
    n_exits = check.count(n_exits, "n_exits", 1)
    exit_channel = np.asarray(exit_channel).ravel()
    if exit_channel.size != t_end.size:
        raise ConfigError(f"exit_channel must have one value per orbit: {exit_channel.size} != {t_end.size}")
    inside = escaped & (t_end > t_start) & (t_end <= t_stop)
    channel = exit_channel[inside]
    if channel.dtype.kind not in "iuf" or not np.all(np.isin(channel, np.arange(n_exits))):
        raise ConfigError(f"exit_channel of an escape in the window must be an exit 0 … {n_exits - 1}")
    n = max(int(inside.sum()), 1)
    return [fraction_with_bound(int(np.count_nonzero(channel == i)), n) for i in range(n_exits)]
