"""Escape rate κ of an open conservative system from its orbits' lifetimes: window fits of log P(t), the MLE,
the escaping tail (Sec. II of Burton, Dullin & Altmann (2023)).

* :func:`~hhscatter.analysis.survival.windows.choose_windows` (module ``windows``) — data-driven τ0 and the 4
  fitting windows of the exponential regime of Eq. (eqn:kappa_hyperbolic);
* :func:`escape_rate` — κ as the mean of 4 least-squares fits of log P(t)
  on the windows of the exponential regime, with τ0, the windows, an MLE cross-check and the optional
  power-law tail / crossover time τ* of Eq. (eqn:kappa_nonhyperbolic);
* :func:`escape_rate_mle` — constant-hazard maximum likelihood on [t_start, t_stop];
* :func:`escape_rate_from_lifetimes` — DataFrame wrapper;
* :func:`~hhscatter.analysis.survival.kappa_energy.fit_kappa_energy` (module ``kappa_energy``) — the
  piecewise κ(E) law (quadratic, then linear above a break) with an estimated break energy;
* :func:`choose_t_max` — a per-energy integration time t_max from a small pilot
  ensemble, bounding the cost of long-lived chaotic orbits and regular ones;
* :func:`escaping_tail` — the power-law tail and τ* of Eq. (eqn:kappa_nonhyperbolic)
  on the orbits that leave before t_max (censored orbits removed);
* :func:`~hhscatter.analysis.survival.cmeasure.kappa_from_cmeasure` (module ``cmeasure``) — κ from the
  c-measure of the true-time map, Eq. (eqn:kappa_cmeasure_truetime), and its input from the
  engine's ``sections`` table.

Pure functions (no I/O, no plotting).  Times in the model's natural time units,
κ in 1/time, energies in the system's energy units (E_c from the system: ``scene.model.critical_energy``).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.intervals import rate_upper_bound
from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.analysis.stats.measured import WithErrors
from hhscatter.analysis.survival.cmeasure import (
    CMeasureKappa,
    cmeasure_sample_from_sections,
    kappa_from_cmeasure,
)
from hhscatter.analysis.survival.fits import (
    ExponentialFit,
    PowerLawFit,
    SurvivalCurve,
    crossover_time,
    detect_power_law_tail,
    fit_exponential,
    lifetimes_to_arrays,
    mean_kappa_stat_err,
    survival_curve,
)
from hhscatter.analysis.survival.kappa_energy import KappaEnergyFit, fit_kappa_energy
from hhscatter.analysis.survival.windows import WindowChoice, choose_windows
from hhscatter.errors import ConfigError

# the window choice, the κ(E) law and the c-measure estimator live in their own modules; their names stay
# importable from here
__all__ = [
    "CMeasureKappa",
    "EscapeRateResult",
    "EscapingTail",
    "KappaEnergyFit",
    "MLERate",
    "WindowChoice",
    "choose_t_max",
    "choose_windows",
    "cmeasure_sample_from_sections",
    "escape_rate",
    "escape_rate_from_lifetimes",
    "escape_rate_mle",
    "escaping_tail",
    "fit_kappa_energy",
    "kappa_from_cmeasure",
    "power_law_exponent_mle",
]


# ---------------------------------------------------------------------------
# escape rate
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class MLERate(WithErrors):
    """Result of :func:`escape_rate_mle`: κ = events / exposure on [t_start, t_stop].

    kappa, kappa_err (1/time; err = κ/√events), n_events, exposure (orbit·time),
    n_at_risk (orbits alive at t_start), t_start, t_stop.

    A window without an escape measures no rate: ``kappa`` and ``kappa_err`` are NaN and ``upper95`` is the
    one-sided 95 % upper bound −ln(0.05)/exposure ≈ 3.0/exposure (1/time; infinite without exposure);
    ``is_bound`` is True. With escapes, ``upper95`` is NaN.
    """

    method = "maximum likelihood (events / exposure)"
    n_field = "n_events"

    kappa: float
    kappa_err: float
    n_events: int
    exposure: float
    n_at_risk: int
    t_start: float
    t_stop: float
    upper95: float = math.nan

    @property
    def is_bound(self) -> bool:
        """True when the window holds no escape: the result is the upper bound ``upper95``, not a rate."""
        return self.n_events == 0


def escape_rate_mle(t_end, observed, t_start, t_stop) -> MLERate:
    """escape_rate_mle(t_end, observed, t_start, t_stop) -> MLERate(kappa, kappa_err, ...).

    Maximum-likelihood escape rate of Eq. (eqn:kappa_hyperbolic) assuming a
    constant hazard κ on [t_start, t_stop] (time units), for left-truncated
    (only orbits alive at t_start count) and right-censored data (orbits
    censored before t_stop, and every orbit still alive at t_stop):

        κ̂ = D / X,   D = #{observed, t_start < t_end ≤ t_stop},
        X = Σ_{t_end > t_start} (min(t_end, t_stop) − t_start),

    with standard error κ̂/√D (Fisher information D/κ²).  Unlike least
    squares on the cumulative P(t) it uses independent information only, so
    its error is the statistical benchmark.  O(N).

    Without an escape in the window (D = 0) there is no rate, only the one-sided 95 % upper bound
    κ < −ln(0.05)/X (the rate at which no event in the exposure X has probability 5 %): ``kappa`` is NaN and
    ``upper95`` holds the bound (:class:`MLERate`).

    Examples
    --------
    >>> m = escape_rate_mle([5.0, 7.0, 30.0], [True, True, False], 10.0, 20.0)   # one orbit at risk, no escape
    >>> m.is_bound, m.kappa, round(m.upper95, 4), m.exposure
    (True, nan, 0.2996, 10.0)
    """
    t_end = check.numbers(t_end, "t_end", min_size=0)
    observed = check.mask(observed, "observed", t_end.size)
    t_start, t_stop = check.window(t_start, t_stop, ("t_start", "t_stop"))
    return _constant_hazard_mle(t_end, observed, t_start, t_stop)


def _constant_hazard_mle(t_end: np.ndarray, observed: np.ndarray, t_start: float, t_stop: float) -> MLERate:
    """The MLE of :func:`escape_rate_mle` on checked arguments (any variable in place of the time)."""
    at_risk = t_end > t_start
    exposure = float(np.sum(np.minimum(t_end[at_risk], t_stop) - t_start))
    D = int(np.count_nonzero(observed & at_risk & (t_end <= t_stop)))
    if D == 0:  # no escape: no rate, the one-sided 95 % upper bound from the exposure
        upper = rate_upper_bound(exposure)
        return MLERate(
            math.nan, math.nan, 0, exposure, int(np.count_nonzero(at_risk)), float(t_start), float(t_stop), upper
        )
    kappa = D / exposure
    return MLERate(
        kappa, kappa / math.sqrt(D), D, exposure, int(np.count_nonzero(at_risk)), float(t_start), float(t_stop)
    )


def power_law_exponent_mle(t_end, observed, t_start, t_stop) -> MLERate:
    """power_law_exponent_mle(t_end, observed, t_start, t_stop) -> MLERate with ``kappa`` = z, ``kappa_err``.

    Maximum-likelihood exponent z of an algebraic survival P ∝ t^{−z}
    (Eq. (eqn:kappa_nonhyperbolic), hazard z/t) on [t_start, t_stop] (time
    units, t_start > 0), left-truncated at t_start and right-censored at
    t_stop or at the orbit's censoring time: the constant-hazard MLE of
    :func:`escape_rate_mle` in the variable log t,

        ẑ = D / Σ_{t_end > t_start} log(min(t_end, t_stop)/t_start),   σ = ẑ/√D.

    The result's ``exposure`` is that sum (dimensionless); its ``t_start`` and ``t_stop`` are the window asked for
    (time units).

    Examples
    --------
    A Pareto sample, P(t) = t^{−1.5} for t ≥ 1, gives z near 1.5 (within its error):

    >>> rng = np.random.default_rng(0)
    >>> t = rng.random(5000) ** (-1 / 1.5)
    >>> m = power_law_exponent_mle(t, np.ones(t.size, bool), 1.0, 100.0)
    >>> round(m.kappa, 2), round(m.kappa_err, 2), abs(m.kappa - 1.5) < 3 * m.kappa_err, (m.t_start, m.t_stop)
    (1.48, 0.02, True, (1.0, 100.0))
    """
    t_end = check.numbers(t_end, "t_end", min_size=0)
    observed = check.mask(observed, "observed", t_end.size)
    t_start, t_stop = check.window(t_start, t_stop, ("t_start", "t_stop"))
    if not t_start > 0:
        raise ConfigError(f"t_start must be > 0 for a power law, got {t_start}")
    in_log_t = _constant_hazard_mle(np.log(np.maximum(t_end, 1e-300)), observed, math.log(t_start), math.log(t_stop))
    return replace(in_log_t, t_start=t_start, t_stop=t_stop)


@dataclass(frozen=True)
class EscapeRateResult(WithErrors):
    """Result of :func:`escape_rate` (κ in 1/time, times in time units).

    kappa           mean of the 4 window fits
    kappa_err       √(spread² + stat²) (conservative: the spread also contains noise)
    kappa_spread    sample std (ddof=1) of the 4 window estimates (systematics)
    kappa_stat      statistical error of the mean of the 4 fits (correlation-aware,
                    :func:`~hhscatter.analysis.survival.fits.mean_kappa_stat_err`)
    tau0, t_stop, windows   from :func:`choose_windows`
    fits            the 4 :class:`ExponentialFit` (full, first half, second half, middle half)
    mle             :class:`MLERate` on [tau0, t_stop] (cross-check)
    tail            :class:`PowerLawFit` of a detected power-law tail, or None
    tau_star        crossover time τ* (NaN without tail)
    window_choice   the full :class:`WindowChoice`
    curve           the :class:`SurvivalCurve` on the analysis grid
    n_total         N
    """

    method = "least-squares fits of log P over plateau windows"

    kappa: float
    kappa_err: float
    kappa_spread: float
    kappa_stat: float
    tau0: float
    t_stop: float
    windows: tuple
    fits: tuple
    mle: MLERate
    tail: PowerLawFit | None
    tau_star: float
    window_choice: WindowChoice = field(repr=False)
    curve: SurvivalCurve = field(repr=False)
    n_total: int = 0


def _default_grid(t_end, n_grid):
    k = min(10, t_end.size)
    t_hi = float(np.partition(t_end, t_end.size - k)[t_end.size - k])
    if t_hi <= 0:
        t_hi = float(t_end.max()) or 1.0
    return np.linspace(0.0, t_hi, int(n_grid))


def escape_rate(
    t_end,
    observed,
    t_grid=None,
    *,
    n_grid: int = 20001,
    detect_tail: bool = True,
    tail_kwargs: dict | None = None,
    **window_kwargs,
) -> EscapeRateResult:
    """escape_rate(t_end, observed, t_grid=None, *, n_grid=20001, detect_tail=True, **window_kwargs) -> EscapeRateResult.

    Escape rate κ of Eq. (eqn:kappa_hyperbolic) (or the effective κ of the
    exponential stage of Eq. (eqn:kappa_nonhyperbolic)) from lifetimes
    ``t_end`` (time units) and the ``observed`` mask (False = right-censored):

    1. P(t) by Kaplan–Meier (:func:`survival_curve`) on ``t_grid`` (default: a
       uniform grid of ``n_grid`` points from 0 to the 10th-largest t_end);
    2. τ0 and 4 windows by :func:`choose_windows` (``window_kwargs`` go there);
    3. κ_i by weighted least squares of log P on each window
       (:func:`fit_exponential`); κ = mean of the 4 (the rule of Burton, Dullin & Altmann (2023));
       kappa_err = √(std(κ_i)² + σ_stat²), σ_stat the statistical error of
       that mean (Kaplan–Meier correlations and window overlaps included);
    4. cross-check :func:`escape_rate_mle` on [τ0, t_stop];
    5. with ``detect_tail``, :func:`detect_power_law_tail` after τ0 and, if a
       tail is found, τ* = :func:`crossover_time` of the full-window
       exponential and the tail power law.

    Examples
    --------
    Exponential lifetimes of rate κ = 0.05, every orbit escaped: the window fits give κ back within their error,
    and the MLE on the same window agrees with them.

    >>> rng = np.random.default_rng(1)
    >>> t_end = rng.exponential(1 / 0.05, 20000)
    >>> r = escape_rate(t_end, np.ones(t_end.size, bool), n_grid=2001, detect_tail=False)
    >>> len(r.windows), bool(abs(r.kappa - 0.05) < 3 * r.kappa_err), bool(abs(r.mle.kappa - 0.05) < 3 * r.mle.kappa_err)
    (4, True, True)
    """
    t_end = check.numbers(t_end, "t_end", minimum=0.0)
    observed = check.mask(observed, "observed", t_end.size)
    n_grid = check.count(n_grid, "n_grid", 2)
    if t_grid is not None:
        t_grid = check.numbers(t_grid, "t_grid", minimum=0.0)
        if np.any(np.diff(t_grid) < 0):
            raise ConfigError("t_grid must be increasing")
    if not isinstance(detect_tail, (bool, np.bool_)):
        raise ConfigError(f"detect_tail must be True or False, got {detect_tail!r}")
    if tail_kwargs is not None:
        check.mapping(tail_kwargs, "tail_kwargs")
    grid = _default_grid(t_end, n_grid) if t_grid is None else np.asarray(t_grid, dtype=float)
    curve = survival_curve(t_end, observed, grid)
    N = t_end.size
    ok = np.isfinite(curve.P)
    t, P, E = curve.t[ok], curve.P[ok], curve.P_err[ok]
    wc = choose_windows(t, P, E, n_total=N, **window_kwargs)
    fits = tuple(fit_exponential(t, P, w, E) for w in wc.windows)
    ks = np.array([f.kappa for f in fits])
    kappa = float(ks.mean())
    spread = float(ks.std(ddof=1))
    stat = mean_kappa_stat_err(t, P, E, wc.windows)
    mle = escape_rate_mle(t_end, observed, wc.tau0, wc.t_stop)
    tail, tau_star = None, math.nan
    if detect_tail:
        kw = {"min_survivors": window_kwargs.get("min_survivors", 100.0)}
        kw.update(tail_kwargs or {})
        tail = detect_power_law_tail(t, P, wc.tau0, E, n_total=N, **kw)
        if tail is not None:
            tau_star = crossover_time(t, P, fits[0], tail)
    return EscapeRateResult(
        kappa=kappa,
        kappa_err=float(math.hypot(spread, stat)),
        kappa_spread=spread,
        kappa_stat=float(stat),
        tau0=wc.tau0,
        t_stop=wc.t_stop,
        windows=wc.windows,
        fits=fits,
        mle=mle,
        tail=tail,
        tau_star=float(tau_star),
        window_choice=wc,
        curve=curve,
        n_total=N,
    )


def escape_rate_from_lifetimes(lifetimes, t_grid=None, *, allow_dissipative=False, **kwargs) -> EscapeRateResult:
    """escape_rate_from_lifetimes(lifetimes, t_grid=None, *, allow_dissipative=False, **kwargs) -> EscapeRateResult.

    :func:`escape_rate` on one (energy, gamma) ensemble of the engine's ``lifetimes``
    table ('escaped'/'settled' leave, 'censored' is right-censored); for every
    point of a grid run at once see :func:`hhscatter.escape_rates`.
    κ is the escape rate of the conservative system (Eq. (eqn:kappa_hyperbolic)):
    a dissipative ensemble (``gamma`` > 0), whose P(t) is not exponential, raises
    ValueError, or with ``allow_dissipative=True`` is fitted with a UserWarning.

    Examples
    --------
    Exponential lifetimes of rate 0.1 censored at t = 100: κ near 0.1; no irregular start (τ0 = 0) and the windows end
    where 100 orbits are left (20000 e^{−0.1 t} = 100 at t = 53).

    >>> import pandas as pd
    >>> rng = np.random.default_rng(0)
    >>> t = rng.exponential(10.0, 20000)
    >>> lifetimes = pd.DataFrame({"t_end": np.minimum(t, 100.0), "outcome": np.where(t < 100.0, "escaped", "censored")})
    >>> r = escape_rate_from_lifetimes(lifetimes)
    >>> round(r.kappa, 3), round(r.kappa_err, 3), r.tau0, round(r.t_stop), r.tail is None
    (0.101, 0.002, 0.0, 53, True)
    """
    check.table(lifetimes, "lifetimes", ("t_end", "outcome"), min_rows=0)
    if "gamma" in lifetimes.columns and len(lifetimes) and float(lifetimes["gamma"].max()) > 0:
        msg = (
            f"escape_rate_from_lifetimes: this ensemble is dissipative (gamma = {float(lifetimes['gamma'].max()):g}"
            " > 0); κ is the conservative escape rate and its exponential fit does not describe P(t) with drag"
        )
        if not allow_dissipative:
            raise ConfigError(msg + " (pass allow_dissipative=True to fit it anyway)")
        warnings.warn(msg, UserWarning, stacklevel=2)
    t_end, observed = lifetimes_to_arrays(lifetimes)
    return escape_rate(t_end, observed, t_grid, **kwargs)


# ---------------------------------------------------------------------------
# integration time per energy, and the tail of the escaping orbits
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class TMaxChoice:
    """Result of :func:`choose_t_max` (times in time units, κ in 1/time).

    t_max          the chosen maximum orbit time of the main run
    t_half         pilot median lifetime (first t with P ≤ 1/2)
    t_tenth        first t with P ≤ 1/10 in the pilot (NaN if never reached)
    kappa_pilot    constant-hazard MLE of the pilot on [t_half, t_tenth] (NaN if not measurable)
    t_floor_pred   predicted time at which the main run keeps ``min_survivors`` survivors
    reason         'rule' (formula used), 'cap' (formula exceeded t_cap) or 'slow'
                   (the pilot never decayed to 1/10: t_cap)
    """

    t_max: float
    t_half: float
    t_tenth: float
    kappa_pilot: float
    t_floor_pred: float
    reason: str


def choose_t_max(
    t_end,
    observed,
    n_main: int,
    *,
    min_survivors: float = 100.0,
    margin_efolds: float = 3.0,
    t_min: float = 100.0,
    t_cap: float = 5000.0,
    step: float = 10.0,
) -> TMaxChoice:
    """choose_t_max(t_end, observed, n_main, *, min_survivors=100, margin_efolds=3, t_min=100, t_cap=5000, step=10) -> TMaxChoice.

    Maximum orbit time (time units) for a main run of ``n_main`` orbits at one
    energy, from the lifetimes of a small pilot ensemble at the same energy.
    It bounds the cost of the orbits that live long (near E_c) or never leave
    (regular orbits on KAM tori run to t_max) while keeping the whole range that the
    κ fit of :func:`escape_rate` can use (it stops where fewer than
    ``min_survivors`` orbits are left, :func:`choose_windows` step 0).

    Rule
    ----
    1. Kaplan–Meier P(t) of the pilot; t_half = first t with P ≤ 1/2,
       t_tenth = first t with P ≤ 1/10.  If the pilot never reaches 1/10,
       t_max = ``t_cap`` (reason 'slow').
    2. κ_p = constant-hazard MLE (:func:`escape_rate_mle`) on [t_half, t_tenth].
    3. Assuming P = ½ e^{−κ_p (t − t_half)} after t_half, the main run keeps
       ``min_survivors`` orbits until t_floor = t_half + ln(n_main / (2 min_survivors))/κ_p.
    4. t_max = t_floor + ``margin_efolds``/κ_p, rounded up to a multiple of
       ``step`` and clipped to [``t_min``, ``t_cap``].

    If the decay slows down later than the pilot shows (stickiness), the fit
    windows simply end earlier: censoring at t_max is handled by Kaplan–Meier,
    never biasing P(t).

    Examples
    --------
    A pilot of 500 exponential lifetimes (κ = 0.05) for a main run of 10⁶ orbits: the pilot's rate κ_p near 0.05;
    100 survivors are left at t_floor = t_half + ln(10⁶/200)/κ_p, and t_max adds 3/κ_p, rounded up to a multiple
    of 10.

    >>> rng = np.random.default_rng(0)
    >>> pilot = rng.exponential(20.0, 500)
    >>> c = choose_t_max(pilot, np.ones(500, bool), 1_000_000)
    >>> round(c.kappa_pilot, 3), round(c.t_half, 1), round(c.t_floor_pred), c.t_max, c.reason
    (0.047, 16.0, 196, 260.0, 'rule')
    >>> round(c.t_half + math.log(1e6 / 200) / c.kappa_pilot, 6) == round(c.t_floor_pred, 6)
    True
    """
    t_end = check.numbers(t_end, "t_end", minimum=0.0)
    observed = check.mask(observed, "observed", t_end.size)
    check.count(n_main, "n_main", 1)
    if not (0 < t_min <= t_cap and step > 0 and margin_efolds >= 0 and min_survivors > 0):
        raise ConfigError("need 0 < t_min ≤ t_cap, step > 0, margin_efolds ≥ 0, min_survivors > 0")
    curve = survival_curve(t_end, observed)
    t, P = curve.t, curve.P

    def first_below(level):
        i = np.flatnonzero(P <= level)
        return float(t[i[0]]) if i.size else math.nan

    t_half, t_tenth = first_below(0.5), first_below(0.1)
    if not math.isfinite(t_tenth) or not t_tenth > t_half:
        return TMaxChoice(float(t_cap), t_half, t_tenth, math.nan, math.nan, "slow")
    kp = escape_rate_mle(t_end, observed, t_half, t_tenth).kappa
    if not (math.isfinite(kp) and kp > 0):
        return TMaxChoice(float(t_cap), t_half, t_tenth, kp, math.nan, "slow")
    t_floor = t_half + math.log(max(n_main / (2.0 * min_survivors), 1.0)) / kp
    raw = t_floor + margin_efolds / kp
    t_max = min(max(math.ceil(raw / step) * step, t_min), t_cap)
    return TMaxChoice(float(t_max), t_half, t_tenth, float(kp), float(t_floor), "cap" if raw > t_cap else "rule")


@dataclass(frozen=True)
class EscapingTail:
    """Result of :func:`escaping_tail`.

    tail        :class:`PowerLawFit` of the algebraic tail of P_esc (None if not detected)
    tau_star    crossover time τ* (time units) of ``exp_fit`` and the tail (NaN without either)
    n_escaping  orbits that left before t_max;  n_trapped  orbits still inside at t_max (censored; the field keeps
                its name ``n_trapped``)
    curve       the :class:`SurvivalCurve` P_esc(t) on the analysis grid
    """

    tail: PowerLawFit | None
    tau_star: float
    n_escaping: int
    n_trapped: int
    curve: SurvivalCurve = field(repr=False)


def escaping_tail(
    t_end,
    observed,
    tau0,
    exp_fit=None,
    t_grid=None,
    *,
    n_grid: int = 20001,
    min_survivors: float = 30.0,
    **tail_kwargs,
) -> EscapingTail:
    """escaping_tail(t_end, observed, tau0, exp_fit=None, t_grid=None, *, min_survivors=30, **tail_kwargs) -> EscapingTail.

    Power-law tail f* t^{−z} and crossover time τ* of Eq.
    (eqn:kappa_nonhyperbolic) measured on the orbits that leave before t_max.

    Orbits on KAM tori never leave: with censoring at a common t_max they
    add a constant P∞ to P(t), which ends every tail in a plateau and makes a
    power-law fit meaningless once P ~ P∞.  Stickiness is a property of the
    escaping orbits, so the tail is sought in

        P_esc(t) = Pr(lifetime > t | leaves before t_max) = (P(t) − P∞)/(1 − P∞)

    (the plain fraction of the observed lifetimes above t; exact when all
    censoring happens at t_max).  :func:`detect_power_law_tail` decides after
    ``tau0`` (time units) with a survivor floor ``min_survivors`` (default 30,
    lower than the 100 of the κ windows because the tail lives in the last
    thousands of orbits; Poisson error of log P ≤ 18 % there).  τ* =
    :func:`crossover_time` of ``exp_fit`` (an :class:`ExponentialFit` of the
    exponential regime, where P∞ ≪ P so that P and P_esc coincide) and the tail.
    ``t_grid`` defaults to ``n_grid`` uniform points from 0 to the
    10th-largest escape time.

    Examples
    --------
    10 % of the orbits never leave (regular, on KAM tori), 20 % are sticky (P ∝ 5/t after t = 5), the others leave at
    rate 0.5: the censored ones (still inside at t_max) are set aside and the tail of the escaping ones has z ≈ 1.

    >>> rng = np.random.default_rng(0)
    >>> n, t_max = 100_000, 2000.0
    >>> u = rng.random(n)
    >>> t = np.where(u < 0.1, np.inf, np.where(u < 0.3, 5.0 / rng.random(n), rng.exponential(2.0, n)))
    >>> e = escaping_tail(np.minimum(t, t_max), t < t_max, 1.0)
    >>> round(e.tail.z, 1), e.n_escaping, e.n_trapped
    (1.1, 89758, 10242)
    >>> int(np.isinf(t).sum()), int(np.sum(np.isfinite(t) & (t >= t_max)))     # never leaving, and sticky past t_max
    (10176, 66)
    """
    t_end = check.numbers(t_end, "t_end", minimum=0.0)
    observed = check.mask(observed, "observed", t_end.size)
    check.number(tau0, "tau0", minimum=0.0)
    if exp_fit is not None:
        check.instance(exp_fit, "exp_fit", ExponentialFit)
    if t_grid is not None:
        check.numbers(t_grid, "t_grid", minimum=0.0)
    t_esc = t_end[observed]
    if t_esc.size < 10:
        raise ConfigError(f"escaping_tail needs ≥ 10 escaping orbits, got {t_esc.size}")
    grid = _default_grid(t_esc, n_grid) if t_grid is None else np.asarray(t_grid, dtype=float)
    curve = survival_curve(t_esc, np.ones(t_esc.size, dtype=bool), grid)
    ok = np.isfinite(curve.P)
    t, P, E = curve.t[ok], curve.P[ok], curve.P_err[ok]
    kw = {"min_survivors": float(min_survivors), **tail_kwargs}
    tail = detect_power_law_tail(t, P, tau0, E, n_total=t_esc.size, **kw)
    tau_star = math.nan
    if tail is not None and exp_fit is not None:
        with counted("survival.escape_rate.crossover_time"):
            tau_star = crossover_time(t, P, exp_fit, tail)
    return EscapingTail(tail, float(tau_star), int(t_esc.size), int(t_end.size - t_esc.size), curve)
