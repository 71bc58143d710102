"""Checks of the conservative escape criterion r > r_esc (paper, App. "Escape Condition").

The paper deems an orbit escaped when r = √(x² + y²) first exceeds a radius
r_esc "slightly larger than 1" (the saddle distance), and states that
"various specific values of r_esc ... all [lead] to the same observations".
The exact criterion is the outward crossing of the Lyapunov orbit that
straddles each exit channel (paper Sec. II, "Scattering dynamics"); this
module measures how well r_esc approximates it:

* :func:`lyapunov_orbit` — the Lyapunov (brake) orbit of exit channel 0 at
  energy E: its radial extent r_min … r_max and period;
* :func:`return_statistics` — from the crossings of a set of radii recorded
  by the engine's ``follow`` scenes (table ``crossings``): for a given r_esc, the
  first escape time, whether the orbit comes back inside r < r_in, when, and
  when it escapes again;
* :func:`wilson_interval`, :func:`channel_fractions` — binomial fractions with
  Wilson score intervals; escape fractions per exit channel against the 1/3
  of the three-fold symmetry;
* :func:`paired_mle_shift` — difference of two constant-hazard MLE escape
  rates (:func:`~hhscatter.analysis.escape_rate.escape_rate_mle`) measured on
  the same orbits (paired), with a sandwich error that includes the pairing;
* :func:`survival_ratio_slope` — κ_alt − κ_ref from the slope of
  log(P_alt/P_ref) on the same orbits (paired; a constant delay of every
  escape changes the offset, not the slope).

Units: model units (unit mass; ω = λ = 1 gives saddle distance 1, E_c = 1/6);
times in time units, κ in 1/time.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import integrate, optimize, stats

from ..model import HenonHeiles
from .least_squares import weighted_least_squares

__all__ = [
    "ChannelFractions",
    "LyapunovOrbit",
    "PairedShift",
    "RatioSlope",
    "channel_fractions",
    "lyapunov_orbit",
    "paired_mle_shift",
    "return_statistics",
    "survival_ratio_slope",
    "wilson_interval",
]


# ---------------------------------------------------------------------------
# binomial fractions
# ---------------------------------------------------------------------------
def wilson_interval(k, n, z: float = 1.0):
    """wilson_interval(k, n, z=1.0) -> (p, lo, hi): fraction k/n and its Wilson score interval.

    ``z`` is the normal quantile (1 → ±1σ, 68.3 %; 1.96 → 95 %).  Works on
    arrays; n = 0 gives NaN.  The Wilson interval stays inside [0, 1] and is
    honest for k = 0 or k = n (where the Wald interval p ± z√(p(1−p)/n) has
    zero width):  centre (p + z²/2n)/(1 + z²/n), half-width
    z√(p(1−p)/n + z²/4n²)/(1 + z²/n).
    """
    k = np.asarray(k, dtype=float)
    n = np.asarray(n, dtype=float)
    if np.any(k < 0) or np.any(k > n):
        raise ValueError("need 0 ≤ k ≤ n")
    if not z > 0:
        raise ValueError(f"z must be > 0, got {z}")
    with np.errstate(divide="ignore", invalid="ignore"):
        p = k / n
        d = 1.0 + z * z / n
        c = (p + z * z / (2 * n)) / d
        h = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return p, c - h, c + h


@dataclass(frozen=True)
class ChannelFractions:
    """Result of :func:`channel_fractions`.

    counts (per channel), n (total), frac, lo, hi (Wilson, ±z), chi2 and
    p_value of Pearson's χ² test of equal fractions (dof = channels − 1).
    """

    counts: np.ndarray
    n: int
    frac: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    chi2: float
    p_value: float


def channel_fractions(channel, n_channels: int = 3, z: float = 1.0) -> ChannelFractions:
    """channel_fractions(channel, n_channels=3, z=1.0) -> ChannelFractions.

    Fraction of escapes through each exit channel (``channel``: integer
    labels 0 … n_channels−1 of the escaped orbits; negative labels = not
    escaped are ignored) with Wilson intervals, and the χ² test of the
    three-fold symmetry prediction 1/n_channels each.
    """
    c = np.asarray(channel)
    c = c[c >= 0].astype(np.int64)
    if c.size and c.max() >= n_channels:
        raise ValueError(f"channel labels must be < n_channels = {n_channels}")
    counts = np.bincount(c, minlength=n_channels)
    n = int(counts.sum())
    p, lo, hi = wilson_interval(counts, n, z)
    if n > 0:
        chi2, pv = stats.chisquare(counts)
    else:
        chi2, pv = math.nan, math.nan
    return ChannelFractions(counts, n, p, lo, hi, float(chi2), float(pv))


# ---------------------------------------------------------------------------
# Lyapunov orbit of an exit channel
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class LyapunovOrbit:
    """Result of :func:`lyapunov_orbit` (channel 0, the saddle on the +y axis).

    energy, brake point (x_b, y_b) on V = E (one end of the orbit; the other is
    (−x_b, y_b)), y_axis (where it crosses x = 0), r_min and r_max (its radial
    extent), period; t, states: one period sampled (for plots and checks).
    """

    energy: float
    x_b: float
    y_b: float
    y_axis: float
    r_min: float
    r_max: float
    period: float
    t: np.ndarray = field(repr=False)
    states: np.ndarray = field(repr=False)


def _hh_rhs(model):
    w2, lam = model.omega**2, model.lam

    def rhs(t, s):
        x, y, px, py = s
        return [px, py, -w2 * x - 2 * lam * x * y, -w2 * y - lam * (x * x - y * y)]

    return rhs


def _wall_x(model, energy, y):
    """x > 0 with V(x, y) = E on the channel-0 wall (NaN where none)."""
    w2, lam = model.omega**2, model.lam
    num = energy - 0.5 * w2 * y * y + lam * y**3 / 3.0
    den = 0.5 * w2 + lam * y
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.sqrt(num / den)


def lyapunov_orbit(energy: float, model: HenonHeiles | None = None, *, rtol: float = 1e-12,
                   n_samples: int = 400) -> LyapunovOrbit:
    """lyapunov_orbit(energy, model=None) -> LyapunovOrbit(r_min, r_max, period, ...).

    The Lyapunov orbit of exit channel 0 at energy E > E_c: the unstable
    periodic orbit that oscillates across the channel near the saddle
    (0, ω²/λ) and bounds the scattering region Ω (paper Sec. II, "Scattering
    dynamics"; an orbit crossing it outward never returns).  It is a brake
    orbit, symmetric under x → −x: released from rest on the wall V = E at
    (x_b, y_b), it crosses x = 0 with p_y = 0.  y_b is found
    by shooting (brentq on p_y at the first x = 0 crossing), the root nearest
    the saddle.  By the three-fold symmetry the other channels' orbits are its
    rotations by ±120°.  Integration: scipy DOP853 with relative tolerance
    ``rtol``.

    As E → E_c the orbit shrinks to the saddle and its period tends to
    2π/(√3 ω), the tangential frequency there (V_xx = 3ω² at the saddle).
    """
    model = model or HenonHeiles()
    E = float(energy)
    if not E > model.critical_energy:
        raise ValueError(f"energy must be > E_c = {model.critical_energy:.6g}, got {energy}")
    rs = model.saddle_radius
    rhs = _hh_rhs(model)

    def axis_hit(t, s):
        return s[0]

    axis_hit.terminal = True
    axis_hit.direction = -1
    t_span = (0.0, 20.0 * 2 * math.pi / model.omega)

    def shoot(yb, dense=False):
        xb = float(_wall_x(model, E, yb))
        sol = integrate.solve_ivp(rhs, t_span, [xb, yb, 0.0, 0.0], method="DOP853", events=axis_hit,
                                  rtol=rtol, atol=rtol * 1e-2, dense_output=dense)
        if not sol.t_events[0].size:
            return (math.nan, sol) if dense else math.nan
        return (sol.y_events[0][0][3], sol) if dense else sol.y_events[0][0][3]

    grid = rs * np.linspace(0.9, 1.3, 161)
    vals = np.array([shoot(y) for y in grid])
    ok = np.isfinite(vals[:-1]) & np.isfinite(vals[1:]) & (np.sign(vals[:-1]) != np.sign(vals[1:]))
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        raise RuntimeError(f"no Lyapunov orbit found at E = {E}")
    i = idx[np.argmin(np.abs(grid[idx] - rs))]
    yb = optimize.brentq(shoot, grid[i], grid[i + 1], xtol=1e-15 * rs, rtol=4 * np.finfo(float).eps)
    _, sol = shoot(yb, dense=True)
    quarter = float(sol.t_events[0][0])
    # the brake orbit goes brake point → axis → mirror brake point and back: period = 4 quarters
    xb = float(_wall_x(model, E, yb))
    full = integrate.solve_ivp(rhs, (0.0, 4 * quarter), [xb, yb, 0.0, 0.0], method="DOP853", rtol=rtol,
                               atol=rtol * 1e-2, dense_output=True)
    t = np.linspace(0.0, 4 * quarter, int(n_samples) + 1)
    states = full.sol(t).T
    r = np.hypot(states[:, 0], states[:, 1])
    return LyapunovOrbit(energy=E, x_b=xb, y_b=float(yb), y_axis=float(sol.y_events[0][0][1]),
                         r_min=float(r.min()), r_max=float(r.max()), period=4 * quarter, t=t, states=states)


# ---------------------------------------------------------------------------
# following orbits past their escape
# ---------------------------------------------------------------------------
def return_statistics(orbit, t, radius, direction, n_orbits: int, r_esc: float, r_in: float = 1.0) -> dict:
    """return_statistics(orbit, t, radius, direction, n_orbits, r_esc, r_in=1.0) -> dict of per-orbit arrays.

    From a crossing record (as in :class:`FollowResult`, rows sorted by orbit
    then time; ``radius`` must hold the exact values r_esc and r_in), for each
    orbit 0 … n_orbits−1:

    ``t_esc``     first outward crossing of r_esc (the escape time the engine
                  would report with this r_esc; NaN if never);
    ``returned``  True if, after t_esc, the orbit crosses r_in inward (it is
                  back inside the saddle radius: the escape was premature);
    ``t_return``  time of that first inward crossing of r_in (NaN if none);
    ``t_reesc``   first outward crossing of r_esc after t_return (NaN if none):
                  t_reesc − t_return is how long the returned orbit stays.
    """
    orbit = np.asarray(orbit, dtype=np.int64)
    t = np.asarray(t, dtype=float)
    radius = np.asarray(radius, dtype=float)
    direction = np.asarray(direction)
    if not (orbit.shape == t.shape == radius.shape == direction.shape):
        raise ValueError("orbit, t, radius and direction differ in length")
    if orbit.size and (np.any(np.diff(orbit) < 0) or np.any((np.diff(orbit) == 0) & (np.diff(t) < 0))):
        raise ValueError("crossings must be sorted by orbit, then time")
    nan = np.full(n_orbits, np.nan)
    t_esc, t_ret, t_re = nan.copy(), nan.copy(), nan.copy()

    def first_per_orbit(mask):
        o, tt = orbit[mask], t[mask]
        first = np.ones(o.size, dtype=bool)
        first[1:] = o[1:] != o[:-1]
        return o[first], tt[first]

    out_esc = (radius == r_esc) & (direction > 0)
    o, tt = first_per_orbit(out_esc)
    t_esc[o] = tt
    te = t_esc[orbit]  # NaN for orbits that never escape
    back = (radius == r_in) & (direction < 0) & (t > te)
    o, tt = first_per_orbit(back)
    t_ret[o] = tt
    tr = t_ret[orbit]
    again = out_esc & (t > tr)
    o, tt = first_per_orbit(again)
    t_re[o] = tt
    return {"t_esc": t_esc, "returned": np.isfinite(t_ret), "t_return": t_ret, "t_reesc": t_re}


# ---------------------------------------------------------------------------
# κ shifts between escape criteria
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class PairedShift:
    """Result of :func:`paired_mle_shift` (1/time).

    kappa_ref, kappa_ref_err, kappa_alt, kappa_alt_err (each MLE with its own
    error), shift = κ_alt − κ_ref, shift_err (sandwich, pairing included),
    shift_err_unpaired (√(σ_ref² + σ_alt²), as if the samples were
    independent), correlation of the two estimates.
    """

    kappa_ref: float
    kappa_ref_err: float
    kappa_alt: float
    kappa_alt_err: float
    shift: float
    shift_err: float
    shift_err_unpaired: float
    correlation: float


def _mle_terms(t_end, observed, t_start, t_stop):
    t_end = np.asarray(t_end, dtype=float).ravel()
    observed = np.asarray(observed).ravel()
    if observed.dtype != bool:
        raise TypeError("observed must be a boolean mask")
    at_risk = t_end > t_start
    x = np.where(at_risk, np.minimum(t_end, t_stop) - t_start, 0.0)
    d = (observed & at_risk & (t_end <= t_stop)).astype(float)
    return d, x


def paired_mle_shift(t_ref, observed_ref, t_alt, observed_alt, t_start: float, t_stop: float) -> PairedShift:
    """paired_mle_shift(t_ref, observed_ref, t_alt, observed_alt, t_start, t_stop) -> PairedShift.

    κ_alt − κ_ref for two escape criteria applied to the *same* orbits
    (element i of both samples is orbit i), each κ the constant-hazard MLE
    D/X on [t_start, t_stop] of
    :func:`~hhscatter.analysis.escape_rate.escape_rate_mle` (same window for
    both).  Error by the sandwich (delta-method) estimator with per-orbit
    influence u_i = (d_i − κ x_i)/X, d_i ∈ {0, 1} the escape indicator in the
    window and x_i the orbit's exposure:

        Var(κ̂_alt − κ̂_ref) = Σ_i (u_i^alt − u_i^ref)²,

    which counts the correlation between the two lifetimes of each orbit
    (strong when an escape criterion only adds a flight time).  For
    independent samples it reduces to σ_ref² + σ_alt² with σ² ≈ κ²/D.
    """
    d0, x0 = _mle_terms(t_ref, observed_ref, t_start, t_stop)
    d1, x1 = _mle_terms(t_alt, observed_alt, t_start, t_stop)
    if d0.shape != d1.shape:
        raise ValueError("paired samples must have the same length (one entry per orbit)")
    if not t_stop > t_start:
        raise ValueError("need t_start < t_stop")
    X0, X1 = x0.sum(), x1.sum()
    if not (X0 > 0 and X1 > 0):
        raise ValueError("no exposure in the window")
    k0, k1 = d0.sum() / X0, d1.sum() / X1
    u0 = (d0 - k0 * x0) / X0
    u1 = (d1 - k1 * x1) / X1
    v0, v1 = float(np.sum(u0 * u0)), float(np.sum(u1 * u1))
    vd = float(np.sum((u1 - u0) ** 2))
    corr = float(np.sum(u0 * u1) / math.sqrt(v0 * v1)) if v0 > 0 and v1 > 0 else math.nan
    return PairedShift(float(k0), math.sqrt(v0), float(k1), math.sqrt(v1), float(k1 - k0), math.sqrt(vd),
                       math.sqrt(v0 + v1), corr)


@dataclass(frozen=True)
class RatioSlope:
    """Result of :func:`survival_ratio_slope` (κ in 1/time, times in time units).

    shift = κ_alt − κ_ref (minus the slope of log(P_alt/P_ref)), shift_err
    (from ``n_groups`` disjoint groups of orbits), offset = fitted
    log(P_alt/P_ref) at the window start, window, group_shifts.
    """

    shift: float
    shift_err: float
    offset: float
    window: tuple
    group_shifts: np.ndarray = field(repr=False)


def _log_ratio_fit(t_ref, obs_ref, t_alt, obs_alt, grid):
    from .survival import survival_curve

    p0 = survival_curve(t_ref, obs_ref, grid).P
    p1 = survival_curve(t_alt, obs_alt, grid).P
    ok = (p0 > 0) & (p1 > 0)
    if np.count_nonzero(ok) < 3:
        return math.nan, math.nan
    x = grid[ok] - grid[0]
    slope, icpt = weighted_least_squares(np.column_stack([x, np.ones(x.size)]), np.log(p1[ok] / p0[ok])).coef
    return -float(slope), float(icpt)


def survival_ratio_slope(t_ref, observed_ref, t_alt, observed_alt, window, *, n_groups: int = 16,
                         n_grid: int = 400) -> RatioSlope:
    """survival_ratio_slope(t_ref, observed_ref, t_alt, observed_alt, window, *, n_groups=16) -> RatioSlope.

    Difference of escape rates κ_alt − κ_ref of two escape criteria applied
    to the *same* orbits (element i of both samples is orbit i): minus the
    least-squares slope of log[P_alt(t)/P_ref(t)] over ``n_grid`` uniform
    times in ``window`` (Kaplan–Meier P, Eq. (eqn:kappa_hyperbolic) for
    both: the ratio of two exponentials is e^{−(κ_alt − κ_ref)t}).

    Why the ratio: orbit by orbit the two lifetimes differ only by the
    criterion (a flight time, or a premature "escape" that returns), so the
    counting noise and the period-scale modulation of the escape hazard,
    common to both curves, largely cancel; a constant delay of every escape
    changes only the offset (returned, at the window start), not the slope.
    A constant-hazard MLE on a fixed window is dominated by its first
    e-fold and picks up that modulation when one curve is delayed.

    Error: the estimate is repeated on ``n_groups`` disjoint groups of orbits
    (index mod n_groups); shift_err = std(group values)/√n_groups.
    """
    t_ref = np.asarray(t_ref, dtype=float).ravel()
    t_alt = np.asarray(t_alt, dtype=float).ravel()
    observed_ref = np.asarray(observed_ref).ravel()
    observed_alt = np.asarray(observed_alt).ravel()
    if t_ref.shape != t_alt.shape:
        raise ValueError("paired samples must have the same length (one entry per orbit)")
    lo, hi = float(window[0]), float(window[1])
    if not hi > lo:
        raise ValueError(f"window must have t_lo < t_hi, got {window}")
    if n_groups < 2:
        raise ValueError(f"n_groups must be ≥ 2, got {n_groups}")
    grid = np.linspace(lo, hi, int(n_grid))
    shift, offset = _log_ratio_fit(t_ref, observed_ref, t_alt, observed_alt, grid)
    g = np.arange(t_ref.size) % n_groups
    gs = np.array([_log_ratio_fit(t_ref[g == i], observed_ref[g == i], t_alt[g == i], observed_alt[g == i],
                                  grid)[0] for i in range(n_groups)])
    gs_ok = gs[np.isfinite(gs)]
    err = float(np.std(gs_ok, ddof=1) / math.sqrt(gs_ok.size)) if gs_ok.size > 1 else math.nan
    return RatioSlope(shift, err, offset, (lo, hi), gs)
