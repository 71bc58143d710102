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
* :func:`channel_fractions` — escape fractions per exit channel against the 1/3
  of the three-fold symmetry, with Wilson score intervals
  (:func:`~hhscatter.analysis.stats.intervals.wilson_interval`).

The paired κ shifts between two criteria are in :mod:`hhscatter.analysis.survival.paired`.

Units: model units (unit mass; ω = λ = 1 gives saddle distance 1, E_c = 1/6);
times in time units, κ in 1/time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import integrate, optimize, stats

from hhscatter.analysis.stats.intervals import wilson_interval
from hhscatter.model import HenonHeiles

__all__ = [
    "ChannelFractions",
    "LyapunovOrbit",
    "channel_fractions",
    "lyapunov_orbit",
    "return_statistics",
]


# ---------------------------------------------------------------------------
# exit channels and the Lyapunov orbit
# ---------------------------------------------------------------------------
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


def lyapunov_orbit(
    energy: float, model: HenonHeiles | None = None, *, rtol: float = 1e-12, n_samples: int = 400
) -> LyapunovOrbit:
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
    if not isinstance(model, HenonHeiles):
        raise TypeError(f"lyapunov_orbit uses Hénon–Heiles' channel-0 symmetry (x → −x); got the system {model.name!r}")
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
        sol = integrate.solve_ivp(
            rhs,
            t_span,
            [xb, yb, 0.0, 0.0],
            method="DOP853",
            events=axis_hit,
            rtol=rtol,
            atol=rtol * 1e-2,
            dense_output=dense,
        )
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
    full = integrate.solve_ivp(
        rhs, (0.0, 4 * quarter), [xb, yb, 0.0, 0.0], method="DOP853", rtol=rtol, atol=rtol * 1e-2, dense_output=True
    )
    t = np.linspace(0.0, 4 * quarter, int(n_samples) + 1)
    states = full.sol(t).T
    r = np.hypot(states[:, 0], states[:, 1])
    return LyapunovOrbit(
        energy=E,
        x_b=xb,
        y_b=float(yb),
        y_axis=float(sol.y_events[0][0][1]),
        r_min=float(r.min()),
        r_max=float(r.max()),
        period=4 * quarter,
        t=t,
        states=states,
    )


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
