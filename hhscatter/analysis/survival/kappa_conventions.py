"""κ0(E) under several conventions, and the κ(E) law with its spread across them.

The escape rate of Eq. (eqn:kappa_hyperbolic) near E_c depends on how it is
defined: the region of the initial conditions and the fitting windows move κ
where the escape is slow, and a region that reaches regular orbits brings a
plateau of orbits still inside at t_max (censored: regular orbits on KAM tori
and chaotic ones not yet out) on which a local-slope window rule locks,
returning κ near 0. How large these effects are is a property of a run: it is
measured on the run and written with it, not here. This module holds the pure
pieces (arrays and DataFrames in, results out):

* :func:`p_level_windows` — the 4 windows (full, halves, middle) between the
  times where P(t) first falls to ``p_hi`` and to ``p_lo``: a rule fixed by
  P levels, beside the data-driven plateau of
  :func:`hhscatter.analysis.survival.windows.choose_windows`;
* :func:`escape_rate_p_levels` — κ = mean of the 4 least-squares fits of
  log P on those windows, error √(spread² + stat²), as
  :func:`hhscatter.analysis.survival.escape_rate.escape_rate`;
* :func:`plateau_check` — whether the censored fraction makes κ of a window
  ill-defined: with a fraction f∞ of orbits that never escape, log P(t) of
  the Kaplan–Meier curve flattens and its slope underestimates κ by
  f∞/P(t) at time t; a window ending where this exceeds ``max_bias`` gives
  no κ;
* :func:`dead_time_check` — whether a window measures an exponential regime
  rather than the prompt burst of escapes;
* :func:`plateau_rate` — the plateau check applied to the windows of
  :func:`hhscatter.analysis.survival.escape_rate.escape_rate`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.measured import WithErrors
from hhscatter.analysis.survival.fits import (
    fit_exponential,
    mean_kappa_stat_err,
    survival_curve,
)
from hhscatter.errors import ConfigError


@dataclass(frozen=True)
class ConventionRate(WithErrors):
    """κ of one convention at one energy (1/time); ``defined`` False with a ``reason`` when ill-defined.

    ``censored_fraction`` is the fraction of orbits still inside at the end (censored: regular, or chaotic but
    not yet out; not classified), of all.
    """

    method = "plateau windows of one convention"

    kappa: float
    kappa_err: float
    kappa_stat: float
    kappa_spread: float
    t_lo: float
    t_hi: float
    censored_fraction: float
    bias_at_end: float  # f∞/P(t_hi): relative underestimate of the local slope at the window end
    defined: bool
    reason: str = ""

    @property
    def trapped_fraction(self) -> float:
        """The name of :attr:`censored_fraction` before the survivors' vocabulary (kept so that callers do not
        break)."""
        return self.censored_fraction


def _levels(p_hi, p_lo) -> None:
    check.number(p_hi, "p_hi")
    check.number(p_lo, "p_lo")
    if not 0 < p_lo < p_hi < 1:
        raise ConfigError(f"need 0 < p_lo < p_hi < 1, got p_hi={p_hi}, p_lo={p_lo}")


def censored_fraction(t_end, observed) -> float:
    """censored_fraction(t_end, observed) -> fraction of orbits still inside at the end (censored), in [0, 1].

    ``t_end`` are the lifetimes (time units) and ``observed`` the mask (False = censored: still inside at t_max),
    one value per orbit. The censored orbits are not classified: the fraction is an upper bound of the regular
    fraction P∞ (chaotic orbits still inside at t_max, sticky or confined, count too). At least one orbit.

    Examples
    --------
    >>> censored_fraction([1.0, 2.5, 10.0, 10.0], [True, True, False, False])
    0.5
    """
    t_end = check.numbers(t_end, "t_end", minimum=0.0)
    observed = check.mask(observed, "observed", t_end.size)
    return float((~observed).sum() / observed.size)


def p_level_windows(t, P, p_hi: float = 0.5, p_lo: float = 1e-2):
    """p_level_windows(t, P, p_hi=0.5, p_lo=1e-2) -> 4 windows (t_lo, t_hi) or None (time units).

    t_a = first t with P ≤ ``p_hi``, t_b = first t with P ≤ ``p_lo``; windows
    [t_a, t_b], its halves and its middle half (the layout of
    :func:`hhscatter.analysis.survival.windows.choose_windows`). None when P never
    falls to ``p_lo`` (e.g. a plateau of censored orbits above it).

    Examples
    --------
    P = e^{−t/10} on a grid of step 1: it falls to 1/2 at 10 ln 2 = 6.9 (grid: 7) and to 1/100 at 10 ln 100 = 46.1
    (grid: 47).

    >>> t = np.linspace(0.0, 50.0, 51)
    >>> p_level_windows(t, np.exp(-t / 10.0))
    ((7.0, 47.0), (7.0, 27.0), (27.0, 47.0), (17.0, 37.0))
    >>> p_level_windows(t, 0.5 + 0.5 * np.exp(-t / 10.0)) is None      # a plateau at 1/2: never reaches 1/100
    True
    """
    t = check.floats(t, "t")
    P = check.floats(P, "P", size=t.size, of="t")
    _levels(p_hi, p_lo)
    ia, ib = np.flatnonzero(P <= p_hi), np.flatnonzero(P <= p_lo)
    if ia.size == 0 or ib.size == 0:
        return None
    ta, tb = float(t[ia[0]]), float(t[ib[0]])
    if tb <= ta:
        return None
    L = tb - ta
    return ((ta, tb), (ta, ta + L / 2), (ta + L / 2, tb), (ta + L / 4, ta + 3 * L / 4))


def plateau_check(P_end: float, f_censored: float, max_bias: float = 0.1):
    """plateau_check(P(t_hi), f∞, max_bias=0.1) -> (defined, bias, reason).

    bias = f∞/P(t_hi): at the window end that share of the survivors never
    escapes, so the slope of log P there is (1 − bias) κ. Above ``max_bias``
    the window measures the plateau, not κ. f∞ counts every orbit still
    inside at t_max, sticky ones included: near E_c, where the power-law
    tail starts early, the check also flags windows that reach into it
    (the decay there is no longer the exponential of κ either).

    Examples
    --------
    >>> plateau_check(0.05, 0.001)          # 0.1 % censored against 5 % alive: a 2 % bias
    (True, 0.02, '')
    >>> defined, bias, reason = plateau_check(0.01, 0.003)
    >>> defined, round(bias, 6)
    (False, 0.3)
    >>> print(reason)
    plateau: censored orbits (still inside at t_max) are 0.30%, 30% of P at the window end (> 10%); κ ill-defined
    """
    check.real(P_end, "P_end")  # NaN (P not known at the window end) counts as no survivors: κ ill-defined
    check.number(f_censored, "f_censored", minimum=0.0)
    check.number(max_bias, "max_bias", positive=True)
    bias = f_censored / P_end if P_end > 0 else math.inf
    if bias > max_bias:
        return (
            False,
            bias,
            (
                f"plateau: censored orbits (still inside at t_max) are {f_censored:.2%}, "
                f"{bias:.0%} of P at the window end (> {max_bias:.0%}); κ ill-defined"
            ),
        )
    return True, bias, ""


def dead_time_check(
    tau0: float,
    t_first: float,
    kappa: float,
    max_dead: float = 0.5,
    *,
    t_hi: float | None = None,
    min_efolds: float = 1.0,
    min_span: float = 2.0 * math.pi,
):
    """dead_time_check(τ0, t_first, κ, max_dead=0.5, *, t_hi=None, min_efolds=1.0, min_span=2π) -> (defined, reason):
    whether a
    window [τ0, t_hi] (time units) with rate κ (1/time) measures an exponential regime rather than the prompt burst
    of escapes. Two conditions, each a reason for "κ ill-defined":

    * *dead time*: the window starts before the first escape ``t_first`` (time units) by more than ``max_dead``
      e-folds of its κ, i.e. κ·(t_first − τ0) > ``max_dead``;
    * *inside the burst* (with ``t_hi``): the window spans less than ``min_efolds`` e-folds of its κ and is shorter
      than ``min_span`` (time units; 2π, one period of the small oscillations for ω = 1, the plateau rule's
      smallest smoothing width), i.e. κ·(t_hi − τ0) < ``min_efolds`` and t_hi − τ0 < ``min_span``: it averages
      neither the decay nor the period-modulated escape, and its slope is the local slope of P where the burst
      hands over to the regime, not a rate that holds. (A window of less than an e-fold that lasts many periods,
      as near the threshold where κ is small, is not judged here.)

    An exponential regime P ∝ e^{−κt} has no stretch without escapes, and it is measured over at least an e-fold.
    A window that starts in the flat start of P(t), before any orbit has had time to reach the exit, is the prompt
    burst of escapes, not the regime: the window rule picks it when the burst covers more e-folds of P above the
    counting floor than the regime after it (a small ensemble, whose floor of ``min_survivors`` orbits sits high),
    and its κ then moves with N. The same small ensemble can also give a short window at the burst's end, after
    the first escape, whose escapes are all burst orbits: the second condition. A window of an e-fold or more
    after the first escape passes, even within a fast population's decay that a slower regime follows: it is a
    measured exponential stretch (far above threshold the regime's own windows are that short), and which of two
    stretches is the regime is the window rule's choice over the orbits it has, not this check's.

    Examples
    --------
    >>> dead_time_check(0.0, 1.56, 1.257)[0], dead_time_check(0.0, 3.0, 0.01), dead_time_check(8.3, 1.56, 0.263)
    (False, (True, ''), (True, ''))
    >>> print(dead_time_check(0.0, 1.56, 1.257)[1])
    window starts 1.6 time units (2 e-folds of κ) before the first escape: a prompt burst, not an exponential regime; κ ill-defined
    >>> dead_time_check(8.3, 1.56, 0.263, t_hi=14.6)     # 1.7 e-folds after the first escape
    (True, '')
    >>> print(dead_time_check(2.78, 0.8, 0.661, t_hi=3.26)[1])
    window spans 0.32 e-folds of κ (< 1) in 0.48 time units (< 6.28): the local slope where the prompt burst hands over, not an exponential regime; κ ill-defined
    >>> dead_time_check(169.0, 5.17, 0.00398, t_hi=369.0)      # 0.8 e-fold over 200 time units: not a burst
    (True, '')
    """
    for value, name in ((tau0, "tau0"), (t_first, "t_first"), (kappa, "kappa"), (max_dead, "max_dead")):
        check.real(value, name)
    if t_hi is not None:
        check.real(t_hi, "t_hi")
    dead = (t_first - tau0) * kappa
    if math.isfinite(dead) and dead > max_dead:
        return False, (
            f"window starts {t_first - tau0:.2g} time units ({dead:.2g} e-folds of κ) before the first escape: "
            "a prompt burst, not an exponential regime; κ ill-defined"
        )
    length = math.nan if t_hi is None else t_hi - tau0
    span = length * kappa
    if math.isfinite(span) and span < min_efolds and length < min_span:
        return False, (
            f"window spans {span:.2g} e-folds of κ (< {min_efolds:g}) in {length:.2g} time units (< {min_span:.3g}): "
            "the local slope where the prompt burst hands over, not an exponential regime; κ ill-defined"
        )
    return True, ""


def _windows_rate(t, P, E, windows):
    fits = [fit_exponential(t, P, w, E) for w in windows]
    ks = np.array([f.kappa for f in fits])
    spread = float(ks.std(ddof=1))
    stat = float(mean_kappa_stat_err(t, P, E, windows))
    return float(ks.mean()), spread, stat


def escape_rate_p_levels(
    t_end, observed, *, p_hi: float = 0.5, p_lo: float = 1e-2, max_bias: float = 0.1, n_grid: int = 20001
) -> ConventionRate:
    """escape_rate_p_levels(t_end, observed, *, p_hi=0.5, p_lo=1e-2, max_bias=0.1) -> ConventionRate.

    κ (1/time) of Eq. (eqn:kappa_hyperbolic) on windows fixed by P levels
    (:func:`p_level_windows`), from lifetimes ``t_end`` (time units) and the
    ``observed`` mask (False = censored). Undefined when P never reaches
    ``p_lo`` or the plateau check fails at the window end.

    Examples
    --------
    Exponential lifetimes of rate 0.1: the windows run from P = 1/2 (t ≈ 6.9) to P = 1/100 (t ≈ 46) and κ comes out
    near 0.1; with 30 % of the orbits never escaping (censored at t_max) P never reaches 1/100 and κ is undefined.

    >>> rng = np.random.default_rng(0)
    >>> t = rng.exponential(10.0, 20000)
    >>> r = escape_rate_p_levels(np.minimum(t, 100.0), t < 100.0)
    >>> round(r.kappa, 3), round(r.kappa_err, 3), round(r.t_lo, 1), round(r.t_hi, 1), r.defined
    (0.101, 0.002, 6.9, 45.5, True)
    >>> t = np.where(rng.random(20000) < 0.3, np.inf, t)
    >>> r = escape_rate_p_levels(np.minimum(t, 100.0), t < 100.0)
    >>> r.defined, r.reason
    (False, 'P(t) never falls to 0.01 (censored fraction 29.87%)')
    """
    t_end = check.numbers(t_end, "t_end", minimum=0.0)
    observed = check.mask(observed, "observed", t_end.size)
    _levels(p_hi, p_lo)
    check.number(max_bias, "max_bias", positive=True)
    check.count(n_grid, "n_grid", 2)
    f_inf = censored_fraction(t_end, observed)
    grid = np.linspace(0.0, float(t_end.max()) if t_end.size else 1.0, int(n_grid))
    curve = survival_curve(t_end, observed, grid)
    ok = np.isfinite(curve.P)
    t, P, E = curve.t[ok], curve.P[ok], curve.P_err[ok]
    wins = p_level_windows(t, P, p_hi, p_lo)
    if wins is None:
        return ConventionRate(
            math.nan,
            math.nan,
            math.nan,
            math.nan,
            math.nan,
            math.nan,
            f_inf,
            math.inf,
            False,
            f"P(t) never falls to {p_lo:g} (censored fraction {f_inf:.2%})",
        )
    defined, bias, reason = plateau_check(float(np.interp(wins[0][1], t, P)), f_inf, max_bias)
    kappa, spread, stat = _windows_rate(t, P, E, wins)
    return ConventionRate(
        kappa, float(math.hypot(spread, stat)), stat, spread, wins[0][0], wins[0][1], f_inf, bias, defined, reason
    )


_RESULT_FIELDS = ("kappa", "kappa_err", "kappa_stat", "kappa_spread", "tau0", "t_stop", "curve")


def plateau_rate(result, t_end, observed, *, max_bias: float = 0.1) -> ConventionRate:
    """plateau_rate(EscapeRateResult, t_end, observed, *, max_bias=0.1) -> ConventionRate of the window rule.

    The κ of :func:`hhscatter.analysis.survival.escape_rate.escape_rate` (data-driven
    plateau windows), with the plateau check at its window end t_stop.

    Examples
    --------
    >>> from hhscatter.analysis.survival.escape_rate import escape_rate
    >>> rng = np.random.default_rng(0)
    >>> t = np.where(rng.random(20000) < 0.3, np.inf, rng.exponential(10.0, 20000))    # 30 % never escape
    >>> t_end, observed = np.minimum(t, 100.0), t < 100.0
    >>> r = plateau_rate(escape_rate(t_end, observed), t_end, observed)
    >>> round(r.kappa, 3), r.defined, r.censored_fraction, round(r.bias_at_end, 2)
    (0.029, False, 0.29245, 0.75)

    The window rule found a "κ" far below 0.1 on the flattening P(t); the check refuses it: at the window's end the
    censored orbits (never escaping) are 75 % of those still inside.
    """
    check.having(result, "result", _RESULT_FIELDS, "an EscapeRateResult (escape_rate)")
    t_end = check.numbers(t_end, "t_end", minimum=0.0)
    observed = check.mask(observed, "observed", t_end.size)
    check.number(max_bias, "max_bias", positive=True)
    f_inf = censored_fraction(t_end, observed)
    P_end = float(np.interp(result.t_stop, result.curve.t, result.curve.P))
    defined, bias, reason = plateau_check(P_end, f_inf, max_bias)
    return ConventionRate(
        result.kappa,
        result.kappa_err,
        result.kappa_stat,
        result.kappa_spread,
        result.tau0,
        result.t_stop,
        f_inf,
        bias,
        defined,
        reason,
    )
