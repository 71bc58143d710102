"""Escape rate κ of the conservative Hénon–Heiles system (paper Sec. II, Fig. 2).

* :func:`choose_windows` — data-driven τ0 and the 4 fitting windows of the
  exponential regime of Eq. (eqn:kappa_hyperbolic);
* :func:`escape_rate` — κ as the mean of 4 least-squares fits of log P(t)
  (Fig. 2b caption), with τ0, the windows, an MLE cross-check and the optional
  power-law tail / crossover time τ* of Eq. (eqn:kappa_nonhyperbolic);
* :func:`escape_rate_mle` — constant-hazard maximum likelihood on [t_start, t_stop];
* :func:`escape_rate_from_lifetimes` — DataFrame wrapper;
* :func:`fit_kappa_energy` — the piecewise κ(E) law of Fig. 2b with an
  estimated break energy;
* :func:`choose_t_max` — a per-energy integration time t_max from a small pilot
  ensemble, bounding the cost of long-lived and KAM-trapped orbits;
* :func:`escaping_tail` — the power-law tail and τ* of Eq. (eqn:kappa_nonhyperbolic)
  on the orbits that leave before t_max (KAM-trapped orbits removed);
* :func:`kappa_from_cmeasure` — κ from the c-measure of the true-time map,
  Eq. (eqn:kappa_cmeasure_truetime); :func:`cmeasure_sample_from_sections`
  builds its input from the engine's ``sections`` table.

Pure functions (no I/O, no plotting).  Times in the model's natural time units,
κ in 1/time, energies in the model's energy units (E_c = 1/6 for ω = λ = 1).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize
from scipy.special import logsumexp

from .least_squares import weighted_least_squares
from .survival import (
    PowerLawFit,
    SurvivalCurve,
    _floor_time,
    _resolve_n_total,
    crossover_time,
    detect_power_law_tail,
    fit_exponential,
    lifetimes_to_arrays,
    mean_kappa_stat_err,
    survival_curve,
)

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

E_C_HH = 1.0 / 6.0  # critical energy of the Hénon–Heiles potential with ω = λ = 1


# ---------------------------------------------------------------------------
# window choice
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class WindowChoice:
    """Result of :func:`choose_windows` (all times in time units).

    tau0        end of the irregular initial regime of Eq. (eqn:kappa_hyperbolic)
    t_stop      end of the exponential regime used for fitting
    windows     4 (t_lo, t_hi): full, first half, second half, middle half of [tau0, t_stop]
    kappa_ref   median local slope on the selected plateau (1/time)
    width       smoothing width w of the local slope
    t_floor     last time with ≥ min_survivors survivors
    converged   False if the iteration hit max_iter
    slope_t, slope, slope_err   the local-slope curve s(t) and its Poisson error (diagnostics)
    """

    tau0: float
    t_stop: float
    windows: tuple
    kappa_ref: float
    width: float
    t_floor: float
    converged: bool
    slope_t: np.ndarray = field(repr=False)
    slope: np.ndarray = field(repr=False)
    slope_err: np.ndarray = field(repr=False)


def _step(t, P, x):
    """Right-continuous step function (t, P) evaluated at x ≥ t[0]."""
    idx = np.searchsorted(t, x, side="right") - 1
    return P[np.clip(idx, 0, None)]


def _local_slope(t, P, N, w, t_floor):
    """Secant slope s(c) = [log P(c − w/2) − log P(c + w/2)]/w at grid centres c, and its Poisson error.

    s is the mean hazard over the window (the MLE of a constant rate there);
    its error is s/√d with d = N (P(c − w/2) − P(c + w/2)) leaving orbits.
    """
    c = t[(t - 0.5 * w >= t[0]) & (t + 0.5 * w <= t_floor)]
    Pa, Pb = _step(t, P, c - 0.5 * w), _step(t, P, c + 0.5 * w)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (np.log(Pa) - np.log(Pb)) / w
        d = N * (Pa - Pb)
        err = np.where(d > 0, np.abs(s) / np.sqrt(d), np.inf)
    return c, s, err


def _runs_arrays(c, inside, gap):
    """Maximal runs of indices with inside=True, merging holes shorter than ``gap`` in c: (starts, ends)."""
    idx = np.flatnonzero(inside)
    if idx.size == 0:
        return idx, idx
    cut = np.flatnonzero(np.diff(c[idx]) > gap)
    starts = np.concatenate([[idx[0]], idx[cut + 1]])
    ends = np.concatenate([idx[cut], [idx[-1]]])
    return starts, ends


def _first_long_segment(c, inside, b, e, min_len):
    """Start index of the first unbroken inside-segment of length ≥ min_len (in c) within the run [b, e].

    Runs merge holes shorter than the smoothing width; at the *start* of a run
    that lets a short accidental agreement (e.g. the secant over the flat
    first time units and the fast early escape averaging to κ) be joined to
    the true plateau across the hole of the early regime, which would put τ0
    inside the irregular regime.  Returns b when no segment is long enough.
    """
    idx = np.flatnonzero(inside[b : e + 1]) + b
    if idx.size == 0:
        return b
    cut = np.flatnonzero(np.diff(idx) > 1)
    starts = np.concatenate([[idx[0]], idx[cut + 1]])
    ends = np.concatenate([idx[cut], [idx[-1]]])
    long_enough = np.flatnonzero(c[ends] - c[starts] >= min_len)
    return int(starts[long_enough[0]]) if long_enough.size else b


def _runs(c, inside, gap):
    """Runs of :func:`_runs_arrays` as a list of (start, end)."""
    st, en = _runs_arrays(c, inside, gap)
    return list(zip(st.tolist(), en.tolist()))


def choose_windows(
    t,
    P,
    P_err=None,
    *,
    n_total=None,
    min_survivors: float = 100.0,
    p_start: float = 0.1,
    core_decades: float = 2.0,
    rel_tol: float = 0.1,
    n_sigma: float = 3.0,
    min_width: float = 2.0 * math.pi,
    n_levels: int = 200,
    max_iter: int = 20,
) -> WindowChoice:
    """choose_windows(t, P, P_err=None, *, n_total=None, ...) -> WindowChoice(tau0, t_stop, windows, ...).

    Data-driven τ0 (end of the irregular regime) and 4 fitting windows for the
    exponential regime f0 e^{−κt} of Eq. (eqn:kappa_hyperbolic), from a survival
    curve (t, P) on an increasing grid (time units).  The same rule, with the
    same defaults, is meant for every energy: nothing is tuned per energy.

    Rule
    ----
    0. *Floor.*  Only times with at least ``min_survivors`` survivors are used:
       t_floor = last t with N·P(t) ≥ min_survivors (N = ``n_total``, or
       estimated from binomial ``P_err``).  Below it the counting noise of
       log P exceeds ~10 % per e-fold.
    1. *Pilot rate* (only sets the first smoothing width): κ_p =
       log(P(t_a)/P(t_b)) / (t_b − t_a), t_a = first time with P ≤ ``p_start``
       (0.1), t_b = first time with P ≤ max(P_floor, p_start·10^−core_decades).
    2. *Local slope.*  s(t) = [log P(t − w/2) − log P(t + w/2)]/w, the mean
       hazard over a window of width w = max(``min_width``, 1/κ) (one e-fold,
       but at least 2π = one period of the small oscillations for ω = 1, so
       the period-modulated, bursty escape of the flow is averaged out; capped
       at a third of [t[0], t_floor] for very short curves), with Poisson
       error σ_s = s/√d (d = orbits leaving in the window).
    3. *Plateau.*  For a level κ_ref a centre t is *inside* when
       |s(t) − κ_ref| ≤ max(``rel_tol``·κ_ref, ``n_sigma``·σ_s(t)) (10 %, or 3σ
       where counting noise is larger); inside points form runs, excursions
       shorter than w being tolerated (merged).  Scanning ``n_levels`` levels
       (quantiles of s), the plateau is the run that covers the most e-folds
       of P, log P(start) − log P(end): the exponential regime is the one that
       carries the decay.  (Measuring in e-folds, not in time, keeps a slow
       power-law tail — whose local slope z/t stays in a 10 % band only over
       a factor 1.2 in t — or the irregular start from winning; a median over
       a fixed P range, e.g. 10^−1…floor, fails when a tail or a second, slower
       component starts inside that range.)
    4. *Iterate* steps 2–3 with κ_ref = median of s on the plateau and
       w = max(min_width, 1/κ_ref) until the plateau ends move by ≤ w/20 and
       κ_ref by ≤ 1 % (κ_ref only sets the band and w, not the result; at
       most ``max_iter`` times); each time the plateau is the run overlapping
       most with the previous one.
    5. τ0 = first centre of the plateau, i.e. the first time after which the
       local slope *stays* within tolerance (t[0] if that is the first centre
       available): leading pieces of the run shorter than w/2 that are joined
       to the rest only across a hole are dropped (an accidental agreement of
       the secant over the flat start and the fast early escape must not
       pull τ0 back into the irregular regime); t_stop = last centre of the plateau, i.e. where the slope
       leaves the band for good (the onset of a power-law tail, or any other
       change of regime), or t_floor when the plateau reaches the floor.
    6. Windows, with L = t_stop − τ0: full [τ0, t_stop], first half
       [τ0, τ0 + L/2], second half [τ0 + L/2, t_stop], middle half
       [τ0 + L/4, τ0 + 3L/4].  Their spread measures the residual curvature of
       log P (systematics) on top of the statistical error.

    The grid should resolve the decay (spacing ≪ w).  Warns, and returns the
    pilot range [t_a, t_b] as the window, if the band ever becomes empty.
    """
    t = np.asarray(t, dtype=float).ravel()
    P = np.asarray(P, dtype=float).ravel()
    if t.shape != P.shape:
        raise ValueError("t and P differ in length")
    if np.any(np.diff(t) <= 0):
        raise ValueError("t must be strictly increasing")
    N = _resolve_n_total(P, P_err, n_total)
    t_floor = _floor_time(t, P, N, min_survivors)
    if t_floor is None or t_floor <= t[0]:
        raise ValueError(f"fewer than {min_survivors} survivors at every grid time: nothing to fit")
    use = np.flatnonzero((t <= t_floor) & np.isfinite(P))
    tu, Pu = t[use], P[use]
    P_floor = min_survivors / N

    ia = np.flatnonzero(Pu <= p_start)
    ia = int(ia[0]) if ia.size else 0
    ib = np.flatnonzero(Pu <= max(P_floor, p_start * 10.0 ** (-core_decades)))
    ib = int(ib[0]) if ib.size else tu.size - 1
    if ib <= ia:
        ia, ib = 0, tu.size - 1
    t_a, t_b = float(tu[ia]), float(tu[ib])
    kappa_p = math.log(Pu[ia] / Pu[ib]) / (t_b - t_a)
    w_max = (t_floor - t[0]) / 3.0

    def width(k):
        w = max(min_width, 1.0 / k) if k > 0 else min_width
        return min(w, w_max)

    w = width(kappa_p)
    c, s, se = _local_slope(t, P, N, w, t_floor)
    fin = np.isfinite(s) & (s > 0)
    if not fin.any():
        raise ValueError("the survival curve does not decay above the counting floor")
    # plateau search: the level whose band holds the run covering most e-folds of P
    logPc = np.log(_step(t, P, c))
    best = (-1.0, kappa_p, 0, c.size - 1)
    for level in np.unique(np.quantile(s[fin], np.linspace(0.0, 1.0, n_levels))):
        inside = fin & (np.abs(s - level) <= np.maximum(rel_tol * level, n_sigma * se))
        st, en = _runs_arrays(c, inside, w)
        if st.size:
            efolds = logPc[st] - logPc[en]
            i = int(np.argmax(efolds))
            if efolds[i] > best[0]:
                best = (float(efolds[i]), float(level), int(st[i]), int(en[i]))
    _, kappa_ref, b, e = best
    target = (float(c[b]), float(c[e]))
    prev = None
    converged = False
    for _ in range(max_iter):
        c, s, se = _local_slope(t, P, N, w, t_floor)
        tol = np.maximum(rel_tol * abs(kappa_ref), n_sigma * se)
        inside = np.isfinite(s) & (np.abs(s - kappa_ref) <= tol)
        runs = _runs(c, inside, w)
        if not runs:
            warnings.warn("no exponential plateau found; using the pilot range [t_a, t_b]")
            tau0, t_stop = t_a, t_b
            break
        overlap = [max(0.0, min(c[e], target[1]) - max(c[b], target[0])) for b, e in runs]
        length = [c[e] - c[b] for b, e in runs]
        k = max(range(len(runs)), key=lambda i: (overlap[i], length[i], -i))
        b, e = runs[k]
        b = _first_long_segment(c, inside, b, e, 0.5 * w)
        tau0 = float(t[0]) if b == 0 else float(c[b])
        t_stop = float(t_floor) if e == c.size - 1 else float(c[e])
        sel = inside[b : e + 1]
        new_kappa = float(np.median(s[b : e + 1][sel]))
        new_w = width(new_kappa)
        state = (tau0, t_stop)
        if (
            prev is not None
            and abs(tau0 - prev[0]) <= 0.05 * w
            and abs(t_stop - prev[1]) <= 0.05 * w
            and abs(new_kappa - kappa_ref) <= 0.01 * abs(kappa_ref)
        ):
            converged = True
            break
        prev, target = state, (float(c[b]), float(c[e]))
        kappa_ref, w = new_kappa, new_w
    if not t_stop > tau0:
        raise ValueError(f"degenerate exponential range [{tau0}, {t_stop}]")
    L = t_stop - tau0
    windows = (
        (tau0, t_stop),
        (tau0, tau0 + 0.5 * L),
        (tau0 + 0.5 * L, t_stop),
        (tau0 + 0.25 * L, tau0 + 0.75 * L),
    )
    return WindowChoice(
        tau0=tau0,
        t_stop=t_stop,
        windows=windows,
        kappa_ref=kappa_ref,
        width=w,
        t_floor=float(t_floor),
        converged=converged,
        slope_t=c,
        slope=s,
        slope_err=se,
    )


# ---------------------------------------------------------------------------
# escape rate
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class MLERate:
    """Result of :func:`escape_rate_mle`: κ = events / exposure on [t_start, t_stop].

    kappa, kappa_err (1/time; err = κ/√events), n_events, exposure (orbit·time),
    n_at_risk (orbits alive at t_start), t_start, t_stop.
    """

    kappa: float
    kappa_err: float
    n_events: int
    exposure: float
    n_at_risk: int
    t_start: float
    t_stop: float


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
    """
    t_end = np.asarray(t_end, dtype=float).ravel()
    observed = np.asarray(observed).ravel()
    if observed.dtype != bool:
        raise TypeError("observed must be a boolean mask")
    if not t_stop > t_start:
        raise ValueError("need t_start < t_stop")
    at_risk = t_end > t_start
    exposure = float(np.sum(np.minimum(t_end[at_risk], t_stop) - t_start))
    D = int(np.count_nonzero(observed & at_risk & (t_end <= t_stop)))
    kappa = D / exposure if exposure > 0 else math.nan
    err = kappa / math.sqrt(D) if D > 0 else math.nan
    return MLERate(kappa, err, D, exposure, int(np.count_nonzero(at_risk)), float(t_start), float(t_stop))


def power_law_exponent_mle(t_end, observed, t_start, t_stop) -> MLERate:
    """power_law_exponent_mle(t_end, observed, t_start, t_stop) -> MLERate with ``kappa`` = z, ``kappa_err``.

    Maximum-likelihood exponent z of an algebraic survival P ∝ t^{−z}
    (Eq. (eqn:kappa_nonhyperbolic), hazard z/t) on [t_start, t_stop] (time
    units, t_start > 0), left-truncated at t_start and right-censored at
    t_stop or at the orbit's censoring time: the constant-hazard MLE of
    :func:`escape_rate_mle` in the variable log t,

        ẑ = D / Σ_{t_end > t_start} log(min(t_end, t_stop)/t_start),   σ = ẑ/√D.

    The result's ``exposure`` is that sum (dimensionless).
    """
    if not t_start > 0:
        raise ValueError(f"t_start must be > 0 for a power law, got {t_start}")
    t_end = np.asarray(t_end, dtype=float).ravel()
    return escape_rate_mle(np.log(np.maximum(t_end, 1e-300)), observed, math.log(t_start), math.log(t_stop))


@dataclass(frozen=True)
class EscapeRateResult:
    """Result of :func:`escape_rate` (κ in 1/time, times in time units).

    kappa           mean of the 4 window fits (Fig. 2b caption)
    kappa_err       √(spread² + stat²) (conservative: the spread also contains noise)
    kappa_spread    sample std (ddof=1) of the 4 window estimates (systematics)
    kappa_stat      statistical error of the mean of the 4 fits (correlation-aware,
                    :func:`~hhscatter.analysis.survival.mean_kappa_stat_err`)
    tau0, t_stop, windows   from :func:`choose_windows`
    fits            the 4 :class:`ExponentialFit` (full, first half, second half, middle half)
    mle             :class:`MLERate` on [tau0, t_stop] (cross-check)
    tail            :class:`PowerLawFit` of a detected power-law tail, or None
    tau_star        crossover time τ* (NaN without tail)
    window_choice   the full :class:`WindowChoice`
    curve           the :class:`SurvivalCurve` on the analysis grid
    n_total         N
    """

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
       (:func:`fit_exponential`); κ = mean of the 4 (paper, Fig. 2b caption);
       kappa_err = √(std(κ_i)² + σ_stat²), σ_stat the statistical error of
       that mean (Kaplan–Meier correlations and window overlaps included);
    4. cross-check :func:`escape_rate_mle` on [τ0, t_stop];
    5. with ``detect_tail``, :func:`detect_power_law_tail` after τ0 and, if a
       tail is found, τ* = :func:`crossover_time` of the full-window
       exponential and the tail power law.
    """
    t_end = np.asarray(t_end, dtype=float).ravel()
    observed = np.asarray(observed).ravel()
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
    """
    if "gamma" in lifetimes.columns and len(lifetimes) and float(lifetimes["gamma"].max()) > 0:
        msg = (f"escape_rate_from_lifetimes: this ensemble is dissipative (gamma = {float(lifetimes['gamma'].max()):g}"
               " > 0); κ is the conservative escape rate and its exponential fit does not describe P(t) with drag")
        if not allow_dissipative:
            raise ValueError(msg + " (pass allow_dissipative=True to fit it anyway)")
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
    (KAM-trapped orbits run to t_max) while keeping the whole range that the
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
    """
    t_end = np.asarray(t_end, dtype=float).ravel()
    observed = np.asarray(observed).ravel()
    if not (isinstance(n_main, (int, np.integer)) and n_main > 0):
        raise ValueError(f"n_main must be an integer > 0, got {n_main!r}")
    if not (0 < t_min <= t_cap and step > 0 and margin_efolds >= 0 and min_survivors > 0):
        raise ValueError("need 0 < t_min ≤ t_cap, step > 0, margin_efolds ≥ 0, min_survivors > 0")
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
    n_escaping  orbits that left before t_max;  n_trapped  orbits still inside at t_max
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
    """
    t_end = np.asarray(t_end, dtype=float).ravel()
    observed = np.asarray(observed).ravel()
    if observed.dtype != bool:
        raise TypeError("observed must be a boolean mask")
    t_esc = t_end[observed]
    if t_esc.size < 10:
        raise ValueError(f"escaping_tail needs ≥ 10 escaping orbits, got {t_esc.size}")
    grid = _default_grid(t_esc, n_grid) if t_grid is None else np.asarray(t_grid, dtype=float)
    curve = survival_curve(t_esc, np.ones(t_esc.size, dtype=bool), grid)
    ok = np.isfinite(curve.P)
    t, P, E = curve.t[ok], curve.P[ok], curve.P_err[ok]
    kw = {"min_survivors": float(min_survivors), **tail_kwargs}
    tail = detect_power_law_tail(t, P, tau0, E, n_total=t_esc.size, **kw)
    tau_star = math.nan
    if tail is not None and exp_fit is not None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            tau_star = crossover_time(t, P, exp_fit, tail)
    return EscapingTail(tail, float(tau_star), int(t_esc.size), int(t_end.size - t_esc.size), curve)


# ---------------------------------------------------------------------------
# κ(E): piecewise law of Fig. 2b
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class KappaEnergyFit:
    """Result of :func:`fit_kappa_energy`; with x = E − E_c,

        κ = a x² + b x   for E < E_b   (non-linear regime),
        κ = c x          for E ≥ E_b   (linear regime).

    a (1/(time·energy²)), b, c (1/(time·energy)), E_b (energy) and their 1σ
    errors from the fit covariance (``cov``, order a, b, c, E_b; scaled by
    χ²/dof when no κ errors were given) and from the bootstrap over points
    (``boot_err``, same order; ``boot`` holds the replicates).  ``continuous``
    tells which model was fitted (then c = a x_b + b).  ``chi2``/``dof`` of the best fit.
    """

    a: float
    b: float
    c: float
    E_b: float
    a_err: float
    b_err: float
    c_err: float
    E_b_err: float
    E_c: float
    continuous: bool
    chi2: float
    dof: int
    cov: np.ndarray = field(repr=False)
    boot: np.ndarray = field(repr=False)
    boot_err: tuple = ()

    def predict(self, E):
        """predict(E) -> κ(E) (1/time); 0 for E ≤ E_c, where no escape is possible."""
        x = np.asarray(E, dtype=float) - self.E_c
        xb = self.E_b - self.E_c
        k = np.where(x < xb, self.a * x**2 + self.b * x, self.c * x)
        return np.where(x > 0, k, 0.0)


def _wls(M, y, w):
    """Weighted linear least squares, returns (params, chi2, (MᵀWM)^{-1})."""
    fit = weighted_least_squares(M, y, w)
    return fit.coef, fit.chi2, fit.cov


def _continuous_profile(x, y, w, xb):
    """χ² of κ = b x + a x min(x, x_b) for each x_b (vectorised closed-form WLS); returns (chi2, a, b)."""
    M1 = x[None, :] * np.minimum(x[None, :], xb[:, None])
    M2 = x[None, :]
    S11 = (w * M1 * M1).sum(1)
    S12 = (w * M1 * M2).sum(1)
    S22 = float((w * x * x).sum())
    r1 = (w * M1 * y).sum(1)
    r2 = float((w * x * y).sum())
    det = S11 * S22 - S12**2
    a = (S22 * r1 - S12 * r2) / det
    b = (S11 * r2 - S12 * r1) / det
    chi2 = (w * (y - a[:, None] * M1 - b[:, None] * M2) ** 2).sum(1)
    return chi2, a, b


def _fit_continuous(x, y, w, n_grid):
    xs = np.sort(np.unique(x))
    if xs.size < 4:
        raise ValueError("need at least 4 distinct energies")
    grid = np.linspace(xs[1], xs[-2], n_grid)
    chi2, _, _ = _continuous_profile(x, y, w, grid)
    i = int(np.nanargmin(chi2))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, n_grid - 1)]
    res = optimize.minimize_scalar(
        lambda v: float(_continuous_profile(x, y, w, np.array([v]))[0][0]),
        bounds=(lo, hi),
        method="bounded",
        options={"xatol": 1e-10},
    )
    xb = float(res.x) if res.fun <= chi2[i] else float(grid[i])
    chi2_b, a, b = (v[0] for v in _continuous_profile(x, y, w, np.array([xb])))
    return float(a), float(b), float(a * xb + b), xb, float(chi2_b)


def _fit_discontinuous(x, y, w):
    order = np.argsort(x)
    xs, ys, ws = x[order], y[order], w[order]
    best = None
    for k in range(2, xs.size):
        if xs[k] == xs[k - 1]:
            continue
        if np.unique(xs[:k]).size < 2:
            continue
        p1, c1, F1 = _wls(np.column_stack([xs[:k] ** 2, xs[:k]]), ys[:k], ws[:k])
        p2, c2, F2 = _wls(xs[k:, None], ys[k:], ws[k:])
        if best is None or c1 + c2 < best[0]:
            best = (c1 + c2, k, p1, p2, F1, F2)
    if best is None:
        raise ValueError("no admissible break between the energies")
    chi2, k, p1, p2, F1, F2 = best
    xb = 0.5 * (xs[k - 1] + xs[k])
    var_xb = (xs[k] - xs[k - 1]) ** 2 / 12.0  # uniform over the gap where χ² is flat
    return float(p1[0]), float(p1[1]), float(p2[0]), float(xb), float(chi2), F1, F2, var_xb


def fit_kappa_energy(
    E,
    kappa,
    kappa_err=None,
    E_c: float = E_C_HH,
    *,
    continuous: bool = True,
    n_grid: int = 400,
    n_boot: int = 200,
    rng=None,
) -> KappaEnergyFit:
    """fit_kappa_energy(E, kappa, kappa_err=None, E_c=1/6, *, continuous=True, n_boot=200, rng=None) -> KappaEnergyFit.

    Piecewise fit of the escape rate against energy (paper Fig. 2b, x = E − E_c,
    energies in energy units, κ in 1/time):

        κ = a x² + b x  (E < E_b),     κ = c x  (E ≥ E_b).

    Paper values for ω = λ = 1: a = 13.63, b = 0.03, c = 1.41, E_b ≈ 0.27.
    The break E_b is estimated, not imposed:

    * ``continuous=True`` (default): κ(x) = b x + a x·min(x, x_b), i.e. the two
      laws are forced to meet at the break (c = a x_b + b; the paper's separate
      fits meet within 2 % at 0.27).  For each x_b the model is linear in
      (a, b), so the weighted χ² is profiled over x_b on a fine grid between
      the second and second-to-last energy, refined by bounded minimisation;
      covariance of (a, b, x_b) from the Gauss–Newton matrix (JᵀWJ)⁻¹ and
      propagated to c.
    * ``continuous=False``: independent fits on either side, the χ² profiled
      over the partitions of the points; E_b is the midpoint of the gap
      between the two points bracketing the best break (its variance
      gap²/12); a, b and c errors from the two linear fits.

    Weights 1/kappa_err² (all 1 and covariance scaled by χ²/dof if omitted).
    ``boot_err`` comes from ``n_boot`` pairs-bootstrap refits over points
    (``rng``: seed or numpy Generator).
    """
    E = np.asarray(E, dtype=float).ravel()
    y = np.asarray(kappa, dtype=float).ravel()
    if E.shape != y.shape:
        raise ValueError("E and kappa differ in length")
    x = E - E_c
    if np.any(x <= 0):
        raise ValueError("all energies must exceed E_c (no escape below)")
    given = kappa_err is not None
    sig = np.asarray(kappa_err, dtype=float).ravel() if given else np.ones_like(y)
    if np.any(~(sig > 0)):
        raise ValueError("kappa_err must be positive")
    w = 1.0 / sig**2
    n = x.size

    if continuous:
        a, b, c, xb, chi2 = _fit_continuous(x, y, w, n_grid)
        J = np.column_stack([x * np.minimum(x, xb), x, a * x * (x > xb)])
        cov3 = np.linalg.pinv((J.T * w) @ J)
        dof = n - 3
        if not given:
            cov3 = cov3 * (chi2 / dof if dof > 0 else np.nan)
        T = np.array([[1.0, 0, 0], [0, 1.0, 0], [xb, 1.0, a], [0, 0, 1.0]])
        cov = T @ cov3 @ T.T
    else:
        a, b, c, xb, chi2, F1, F2, var_xb = _fit_discontinuous(x, y, w)
        dof = n - 4
        s = (chi2 / dof if dof > 0 else np.nan) if not given else 1.0
        cov = np.zeros((4, 4))
        cov[:2, :2] = F1 * s
        cov[2, 2] = F2[0, 0] * s
        cov[3, 3] = var_xb

    gen = np.random.default_rng(rng)
    boot = np.full((int(n_boot), 4), np.nan)
    for i in range(int(n_boot)):
        idx = gen.integers(0, n, n)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                if continuous:
                    r = _fit_continuous(x[idx], y[idx], w[idx], max(n_grid // 4, 50))
                    boot[i] = r[:4]
                else:
                    r = _fit_discontinuous(x[idx], y[idx], w[idx])
                    boot[i] = r[:4]
        except (ValueError, np.linalg.LinAlgError):
            continue
    boot[:, 3] += E_c
    boot_err = tuple(float(v) for v in np.nanstd(boot, axis=0, ddof=1)) if n_boot > 1 else ()
    err = np.sqrt(np.diag(cov))
    return KappaEnergyFit(
        a=a,
        b=b,
        c=c,
        E_b=xb + E_c,
        a_err=float(err[0]),
        b_err=float(err[1]),
        c_err=float(err[2]),
        E_b_err=float(err[3]),
        E_c=float(E_c),
        continuous=continuous,
        chi2=chi2,
        dof=dof,
        cov=cov,
        boot=boot,
        boot_err=boot_err,
    )


# ---------------------------------------------------------------------------
# κ from the c-measure of the true-time map
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class CMeasureKappa:
    """Result of :func:`kappa_from_cmeasure` (κ in 1/time).

    kappa, kappa_err (bootstrap std), kappa_err_delta (delta method),
    mu_exit = n_exit/M (the c-measure of the exit set, μ_c(𝓔)), n_samples M,
    n_exit, boot (bootstrap replicates of κ).
    """

    kappa: float
    kappa_err: float
    kappa_err_delta: float
    mu_exit: float
    n_samples: int
    n_exit: int
    boot: np.ndarray = field(repr=False)


def _solve_renewal(T, M):
    """Root κ > 0 of log Σ_i e^{κ T_i} = log M (returning points only)."""
    if T.size == 0:
        return math.inf
    if T.size >= M:
        return 0.0
    logM = math.log(M)

    def h(k):
        return float(logsumexp(k * T)) - logM

    hi = 1.0 / max(float(np.mean(T)), 1e-300)
    while h(hi) <= 0:
        hi *= 2.0
        if hi > 1e300:
            return math.inf
    return float(optimize.brentq(h, 0.0, hi, xtol=1e-14, rtol=1e-12))


def kappa_from_cmeasure(return_times, n_exit, *, n_boot: int = 200, rng=None) -> CMeasureKappa:
    """kappa_from_cmeasure(return_times, n_exit, *, n_boot=200, rng=None) -> CMeasureKappa(kappa, kappa_err, ...).

    Escape rate κ (1/time) from section data via the true-time-map relation
    Eq. (eqn:kappa_cmeasure_truetime),  ∫_Ω e^{κT} dμ_c = 1 + μ_c(𝓔).

    Input: a sample of M points on the Poincaré section distributed by the
    c-measure μ_c; ``return_times`` are the times T_i (time units) to the next
    section crossing of the points that return, ``n_exit`` the number of
    sample points that leave Ω before crossing again (the set 𝓔), so
    M = len(return_times) + n_exit.

    Estimator
    ---------
        (1/M) Σ_{i returns} e^{κ T_i} = 1,      κ > 0 its unique root,

    equivalently (1/M)[Σ_{returns} e^{κT_i} + Σ_{exits} e^{κ·0}] = 1 + n_exit/M,
    the sample version of Eq. (eqn:kappa_cmeasure_truetime) in which exiting
    points carry T = 0 (their exit times do not enter).

    Derivation.  In the asymptotic regime the flux of section crossings
    decays as the survival probability: crossings at y during [t, t + dt]
    occur at rate j(y, t) = e^{−κt} ρ(y), and μ_c (dμ_c = ρ dy / ∫ρ) is the
    distribution of crossing points, conditionally invariant under the flow.
    Every crossing at x ∉ 𝓔 at time t produces the crossing h(x) at time
    t + T(x); crossings at x ∈ 𝓔 produce none.  Conservation of crossings,
    j(y, t) = Σ_{h(x)=y} j(x, t − T(x)) |Dh(x)|⁻¹, integrated over y, gives
        ∫ρ = ∫_{Ω∖𝓔} ρ(x) e^{κT(x)} dx   ⇔   ∫_{Ω∖𝓔} e^{κT} dμ_c = 1,
    which is Eq. (eqn:kappa_cmeasure_truetime) once 𝓔 is included with T = 0
    (∫_𝓔 e^{0} dμ_c = μ_c(𝓔)).  Checks: for T ≡ 1 (a plain map) it gives
    e^κ (1 − μ_c(𝓔)) = 1, i.e. Eq. (eqn:kappa_cmeasure_discrete); for a renewal
    process (return with probability q after T ~ F, else exit) it is the
    Lotka equation q E_F[e^{κT}] = 1 of the exponential decay of P(t).
    Exit times are irrelevant provided they are short compared with 1/κ
    (light-tailed).

    Sampling.  The measure is the *flux* measure: take every section crossing
    of the ensemble that occurs in a late time window [t1, t2] (t1 ≫ τ0) as
    one sample point (see :func:`cmeasure_sample_from_sections`).  Taking
    instead the first crossing after t* of each survivor (sprinkler method)
    weights a point by 1 − e^{−κ T_back} (T_back: time since its previous
    crossing), which is harmless only when T_back and T are uncorrelated.

    Errors: ``kappa_err`` is the std of ``n_boot`` bootstrap replicates
    (resampling the M points, exits included; ``rng`` seed or Generator);
    ``kappa_err_delta`` the delta-method value
    √(Var(Y)/M) / mean(T Y), Y_i = e^{κT_i} (0 for exits).
    """
    T = np.asarray(return_times, dtype=float).ravel()
    if np.any(~np.isfinite(T)) or np.any(T <= 0):
        raise ValueError("return times must be finite and > 0")
    n_exit = int(n_exit)
    if n_exit < 0:
        raise ValueError("n_exit must be ≥ 0")
    M = T.size + n_exit
    if M == 0:
        raise ValueError("empty sample")
    kappa = _solve_renewal(T, M)
    if math.isfinite(kappa) and kappa > 0:
        Y = np.exp(kappa * T)
        var_Y = (float(np.sum(Y * Y)) / M) - (float(np.sum(Y)) / M) ** 2
        slope = float(np.sum(T * Y)) / M
        err_delta = math.sqrt(max(var_Y, 0.0) / M) / slope
    else:
        err_delta = math.nan if not math.isfinite(kappa) else 0.0
    gen = np.random.default_rng(rng)
    boot = np.empty(int(n_boot))
    for i in range(int(n_boot)):
        ne = int(gen.binomial(M, n_exit / M))
        Tb = T[gen.integers(0, T.size, M - ne)] if T.size else T
        boot[i] = _solve_renewal(Tb, M)
    err = float(np.std(boot, ddof=1)) if n_boot > 1 else math.nan
    return CMeasureKappa(
        kappa=float(kappa),
        kappa_err=err,
        kappa_err_delta=float(err_delta),
        mu_exit=n_exit / M,
        n_samples=M,
        n_exit=n_exit,
        boot=boot,
    )


def cmeasure_sample_from_sections(sections, lifetimes, t_from, t_to, *, t_record_end=math.inf,
                                  drop_censored: bool = False):
    """cmeasure_sample_from_sections(sections, lifetimes, t_from, t_to, *, t_record_end=inf, drop_censored=False) -> (return_times, n_exit, n_undetermined).

    Builds the input of :func:`kappa_from_cmeasure` from the engine's tables
    (one conservative ensemble).  Every crossing in ``sections`` with
    t_from ≤ t ≤ t_to (time units) is a sample point of the flux c-measure;
    its return time is the time to the same orbit's next recorded crossing.
    A crossing with no later crossing is an *exit* if the orbit left
    ('escaped'/'settled') at t_end ≤ ``t_record_end`` (the end of the section
    recording, ``SectionWindow.t_to``), otherwise *undetermined* (censored, or
    a crossing after the recording may have been missed) and dropped — choose
    t_to well before min(t_record_end, t_max) so that this count is ~0.
    ``sections`` must hold every crossing (SectionWindow without energy
    filter and first_only=False) from t_from to t_record_end.

    ``drop_censored=True`` removes every orbit that is still inside at its
    t_end (outcome 'censored') before sampling.  With t_max ≫ t_record_end
    these are the orbits on KAM tori: they cross the section for ever, are
    not part of the c-measure of the chaotic saddle, and would bias κ low by
    their share of the late crossings.
    """
    if drop_censored:
        keep = lifetimes.loc[lifetimes["outcome"].astype(object) != "censored", "traj_id"]
        sections = sections[sections["traj_id"].isin(keep)]
    s = sections[["traj_id", "t"]].sort_values(["traj_id", "t"], kind="stable")
    nxt = s.groupby("traj_id", sort=False)["t"].shift(-1)
    s = s.assign(t_next=nxt.to_numpy())
    s = s[(s["t"] >= t_from) & (s["t"] <= t_to)]
    ret = s["t_next"].notna().to_numpy()
    T = (s["t_next"] - s["t"]).to_numpy()[ret]
    last = s.loc[~ret, ["traj_id"]]
    lt = lifetimes[["traj_id", "outcome", "t_end"]].copy()
    lt["outcome"] = lt["outcome"].astype(object)
    last = last.merge(lt, on="traj_id", how="left")
    if last["outcome"].isna().any():
        raise ValueError("sections refer to traj_ids missing from lifetimes")
    leaves = last["outcome"].isin(["escaped", "settled"]).to_numpy() & (last["t_end"].to_numpy() <= t_record_end)
    n_exit = int(np.count_nonzero(leaves))
    n_und = int(leaves.size - n_exit)
    if n_und:
        warnings.warn(f"{n_und} sample crossings have an undetermined fate and were dropped")
    return T.astype(float), n_exit, n_und
