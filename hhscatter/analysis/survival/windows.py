"""The exponential regime of a survival curve: τ0 and the fitting windows.

The rule of Sec. II of Burton, Dullin & Altmann (2023), from the data.

:func:`choose_windows` finds, from the data alone, the end τ0 of the irregular
initial regime of Eq. (eqn:kappa_hyperbolic) (the first time after which the
local escape rate stays on its plateau) and the 4 windows of the exponential
regime that :func:`hhscatter.analysis.survival.escape_rate.escape_rate` fits. Pure
functions; times in time units, rates in 1/time.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.survival.fits import (
    _floor_time,
    _resolve_n_total,
)
from hhscatter.errors import ConfigError

__all__ = ["WindowChoice", "choose_windows"]


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

    Examples
    --------
    Exponential lifetimes of rate 0.1 censored at t = 100: no irregular start (τ0 = 0); the plateau ends where 100
    orbits are left (20000 e^{−0.1 t} = 100 at t = 53).

    >>> from hhscatter.analysis.survival.kaplan_meier import survival_curve
    >>> rng = np.random.default_rng(0)
    >>> t = rng.exponential(10.0, 20000)
    >>> c = survival_curve(np.minimum(t, 100.0), t < 100.0, t_grid=np.linspace(0.0, 100.0, 1001))
    >>> w = choose_windows(c.t, c.P, c.P_err, n_total=t.size)
    >>> w.tau0, round(w.t_stop, 1), [tuple(round(x, 1) for x in win) for win in w.windows]
    (0.0, 52.9, [(0.0, 52.9), (0.0, 26.5), (26.5, 52.9), (13.2, 39.7)])
    >>> round(w.kappa_ref, 2)
    0.1
    """
    t, P, N, t_floor = _checked_curve(t, P, P_err, n_total, min_survivors)
    t_a, t_b, kappa_p = _pilot_rate(t, P, N, t_floor, min_survivors, p_start, core_decades)
    w_max = (t_floor - t[0]) / 3.0
    w = _smoothing_width(kappa_p, min_width, w_max)
    kappa_ref, target = _plateau_level(t, P, N, w, t_floor, kappa_p, rel_tol, n_sigma, n_levels)
    tau0, t_stop, kappa_ref, w, (c, s, se), converged = _iterate_plateau(
        t, P, N, t_floor, w, kappa_ref, target, (t_a, t_b), rel_tol, n_sigma, min_width, w_max, max_iter
    )
    return WindowChoice(
        tau0=tau0,
        t_stop=t_stop,
        windows=_fitting_windows(tau0, t_stop),
        kappa_ref=kappa_ref,
        width=w,
        t_floor=float(t_floor),
        converged=converged,
        slope_t=c,
        slope=s,
        slope_err=se,
    )


# the steps of choose_windows (its docstring's rule, step by step)
def _checked_curve(t, P, P_err, n_total, min_survivors):
    """Rule step 0, the floor: (t, P) as checked float arrays, the ensemble size N and t_floor (time units)."""
    t = check.floats(t, "t")
    P = check.floats(P, "P", size=t.size, of="t")
    if P_err is not None:
        check.floats(P_err, "P_err", size=t.size, of="t")
    if n_total is not None:
        check.number(n_total, "n_total", positive=True)
    check.number(min_survivors, "min_survivors", positive=True)
    if t.size < 2 or not np.all(np.isfinite(t)):
        raise ConfigError("t must hold at least 2 finite times")
    if np.any(np.diff(t) <= 0):
        raise ConfigError("t must be strictly increasing")
    N = _resolve_n_total(P, P_err, n_total)
    t_floor = _floor_time(t, P, N, min_survivors)
    if t_floor is None or t_floor <= t[0]:
        raise ConfigError(f"fewer than {min_survivors} survivors at every grid time: nothing to fit")
    return t, P, N, t_floor


def _pilot_rate(t, P, N, t_floor, min_survivors, p_start, core_decades):
    """Rule step 1, the pilot rate κ_p = log(P(t_a)/P(t_b))/(t_b − t_a) (1/time): (t_a, t_b, κ_p)."""
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
    return t_a, t_b, math.log(Pu[ia] / Pu[ib]) / (t_b - t_a)


def _smoothing_width(k, min_width, w_max):
    """Rule step 2, the smoothing width w = max(min_width, 1/κ) capped at w_max (time units; κ in 1/time)."""
    w = max(min_width, 1.0 / k) if k > 0 else min_width
    return min(w, w_max)


def _plateau_level(t, P, N, w, t_floor, kappa_p, rel_tol, n_sigma, n_levels):
    """Rule step 3, the plateau: the level κ_ref (1/time) whose band holds the run covering most e-folds of P.

    Scans ``n_levels`` quantiles of the local slope s(t) at width w; returns (κ_ref, (first, last centre of
    that run) in time units), or (κ_p, the whole slope range) when no band holds a run.
    """
    c, s, se = _local_slope(t, P, N, w, t_floor)
    fin = np.isfinite(s) & (s > 0)
    if not fin.any():
        raise ConfigError("the survival curve does not decay above the counting floor")
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
    return kappa_ref, (float(c[b]), float(c[e]))


def _overlapping_run(c, runs, target):
    """The run (start, end) overlapping most (in time) with ``target``; ties: the longer, then the earlier."""
    overlap = [max(0.0, min(c[e], target[1]) - max(c[b], target[0])) for b, e in runs]
    length = [c[e] - c[b] for b, e in runs]
    k = max(range(len(runs)), key=lambda i: (overlap[i], length[i], -i))
    return runs[k]


def _iterate_plateau(t, P, N, t_floor, w, kappa_ref, target, pilot, rel_tol, n_sigma, min_width, w_max, max_iter):
    """Rule steps 4-5, the plateau iterated to convergence: τ0 and t_stop (time units), κ_ref (1/time), w.

    Returns (tau0, t_stop, kappa_ref, width, (slope_t, slope, slope_err), converged); warns and returns the
    ``pilot`` range (t_a, t_b) if the band ever becomes empty.
    """
    prev = None
    converged = False
    for _ in range(max_iter):
        c, s, se = _local_slope(t, P, N, w, t_floor)
        tol = np.maximum(rel_tol * abs(kappa_ref), n_sigma * se)
        inside = np.isfinite(s) & (np.abs(s - kappa_ref) <= tol)
        runs = _runs(c, inside, w)
        if not runs:
            warnings.warn("no exponential plateau found; using the pilot range [t_a, t_b]", stacklevel=2)
            tau0, t_stop = pilot
            break
        b, e = _overlapping_run(c, runs, target)
        b = _first_long_segment(c, inside, b, e, 0.5 * w)
        tau0 = float(t[0]) if b == 0 else float(c[b])
        t_stop = float(t_floor) if e == c.size - 1 else float(c[e])
        sel = inside[b : e + 1]
        new_kappa = float(np.median(s[b : e + 1][sel]))
        new_w = _smoothing_width(new_kappa, min_width, w_max)
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
    return tau0, t_stop, kappa_ref, w, (c, s, se), converged


def _fitting_windows(tau0, t_stop):
    """Rule step 6, the 4 fitting windows of [τ0, t_stop]: full, first half, second half, middle half (time units)."""
    if not t_stop > tau0:
        raise ConfigError(f"degenerate exponential range [{tau0}, {t_stop}]")
    L = t_stop - tau0
    return (
        (tau0, t_stop),
        (tau0, tau0 + 0.5 * L),
        (tau0 + 0.5 * L, t_stop),
        (tau0 + 0.25 * L, tau0 + 0.75 * L),
    )
