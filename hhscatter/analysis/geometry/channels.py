"""Exit channels of an open system: channel fractions, Lyapunov orbits, returns after an escape (r > r_esc).

Reference: App. "Escape Condition" of Burton, Dullin & Altmann (2023).

That reference deems an orbit escaped when r = √(x² + y²) first exceeds a radius
r_esc "slightly larger than 1" (the saddle distance), and states that
"various specific values of r_esc ... all [lead] to the same observations".
The exact criterion is the outward crossing of the Lyapunov orbit that
straddles each exit channel (ibid., Sec. II, "Scattering dynamics"); this
module measures how well r_esc approximates it:

* :func:`lyapunov_orbit` — the Lyapunov (brake) orbit of an exit at energy E
  above its saddle, for any system (:mod:`hhscatter.model`: the saddle and V
  come from the system object): its brake points, radial extent r_min … r_max
  and period;
* :func:`return_statistics` — from the crossings of a set of radii recorded
  by the engine's ``follow`` scenes (table ``crossings``): for a given r_esc, the
  first escape time, whether the orbit comes back inside r < r_in, when, and
  when it escapes again;
* :func:`channel_fractions` — escape fractions per exit channel against the 1/3
  of the three-fold symmetry, with Wilson score intervals
  (:func:`~hhscatter.analysis.stats.intervals.wilson_interval`).

The paired κ shifts between two criteria are in :mod:`hhscatter.analysis.survival.paired`.

Units: the system's (unit mass): lengths, energies; times in time units, κ in 1/time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import integrate, optimize, stats

from hhscatter.analysis.noise.kramers import hessian
from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.intervals import wilson_interval
from hhscatter.errors import ConfigError
from hhscatter.model.base import System

__all__ = [
    "ChannelFractions",
    "LyapunovOrbit",
    "channel_fractions",
    "lyapunov_orbit",
    "return_statistics",
]

_EPS = float(np.finfo(float).eps)


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

    Examples
    --------
    100 escapes, 50 : 30 : 20 against 1/3 each: χ² = Σ (o − 100/3)² / (100/3) = 14.0 with 2 degrees of freedom,
    p = e^{−χ²/2} = 9.1e-4. The −1 (an orbit that did not escape) is ignored.

    >>> r = channel_fractions([0] * 50 + [1] * 30 + [2] * 20 + [-1])
    >>> r.counts.tolist(), r.n, round(r.chi2, 4), f"{r.p_value:.2g}"
    ([50, 30, 20], 100, 14.0, '0.00091')
    """
    n_channels = check.count(n_channels, "n_channels", 1)
    z = check.number(z, "z", positive=True)
    c = check.numbers(channel, "channel", min_size=0)
    if not np.all(c == np.round(c)):
        raise ConfigError("channel must hold integer labels (negative: not escaped)")
    c = c[c >= 0].astype(np.int64)
    if c.size and c.max() >= n_channels:
        raise ConfigError(f"channel labels must be < n_channels = {n_channels}")
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
    """Result of :func:`lyapunov_orbit`: the Lyapunov orbit of one exit at one energy.

    Parameters
    ----------
    energy : float
        E (energy).
    exit : int
        The exit's channel index (``system.exits[exit]``).
    x_b, y_b : float
        The brake point where the orbit starts at rest on V = E (length): the end on the side +v of the
        channel's axis (v: the saddle's stable direction, the channel's outward direction turned by −90°).
    x_axis, y_axis : float
        Where the orbit crosses the channel's axis (the line through the saddle along its unstable
        direction) from the +v side, half way between the brake points (length).
    r_min, r_max : float
        The orbit's radial extent, r = √(x² + y²) (the radius r_esc is compared with), over the samples
        ``states`` (length).
    period : float
        The period, twice the time between the brake points (time).
    t : numpy.ndarray
        ``n_samples + 1`` times over one period from 0 to ``period`` (time).
    states : numpy.ndarray
        (x, y, p_x, p_y) at ``t``, shape (n_samples + 1, 4); ``states[0]`` is (x_b, y_b, 0, 0).
    """

    energy: float
    exit: int
    x_b: float
    y_b: float
    x_axis: float
    y_axis: float
    r_min: float
    r_max: float
    period: float
    t: np.ndarray = field(repr=False)
    states: np.ndarray = field(repr=False)


def _checked_energy(energy: float, system: System, k: int) -> float:
    """E as a float, after the checks of :func:`lyapunov_orbit`'s arguments (ValueError naming the value)."""
    exits = system.exits
    if not exits:
        raise ConfigError(f"the system {system.name!r} has no exit (no saddle of V): it has no Lyapunov orbit")
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < len(exits):
        raise ConfigError(f"exit must be a channel index from 0 to {len(exits) - 1}, got {k!r}")
    E, e_s = float(energy), exits[k].energy
    if not (math.isfinite(E) and E > e_s):
        raise ConfigError(
            f"energy must be > the saddle energy E_s = {e_s:.6g} of exit {k} (E_c = "
            f"{system.critical_energy:.6g}), got {energy!r}"
        )
    return E


class _Shooting:
    """The brake-orbit shooting of :func:`lyapunov_orbit` for exit k of a system (validated there).

    The saddle's frame: u the unit unstable direction pointing away from the well's minimum, v = u turned by
    −90° (the stable direction), ω_v = √(the positive Hessian eigenvalue) (1/time).
    """

    def __init__(self, system: System, k: int, rtol: float):
        e = system.exits[k]
        self.k = int(k)
        self.saddle, self.e_s = np.array([e.x, e.y]), e.energy
        eig, vec = np.linalg.eigh(hessian(system, e.x, e.y))
        if not eig[0] < 0 < eig[1]:
            raise ConfigError(f"exit {k} at ({e.x:.6g}, {e.y:.6g}) is not a saddle of V: Hessian eigenvalues {eig}")
        self.u = vec[:, 0] if vec[:, 0] @ self.saddle >= 0 else -vec[:, 0]
        self.v = np.array([self.u[1], -self.u[0]])
        self.omega_v = math.sqrt(eig[1])
        self.pot, self.force = system.potential, system.force
        self.tol = {"method": "DOP853", "rtol": rtol, "atol": rtol * 1e-2}

    def rhs(self, t, s):
        fx, fy = self.force(s[0], s[1])
        return [s[2], s[3], float(fx), float(fy)]

    def axis(self, t, s):
        """Signed distance (along v) from the channel's axis, the line through the saddle along u."""
        return (s[0] - self.saddle[0]) * self.v[0] + (s[1] - self.saddle[1]) * self.v[1]

    def brake_point(self, c: float, e: float) -> np.ndarray | None:
        """The point of V = e on the +v side at c along u from the saddle (None where there is none)."""
        base = self.saddle + c * self.u
        g = lambda s: float(self.pot(*(base + s * self.v))) - e
        lo, hi = 0.0, math.sqrt(2 * (e - self.e_s)) / self.omega_v  # the linear guess A first
        if not g(lo) < 0:
            return None
        for _ in range(60):
            if g(hi) > 0:
                return base + optimize.brentq(g, lo, hi, xtol=_EPS * hi, rtol=4 * _EPS) * self.v
            lo, hi = hi, 1.5 * hi
        return None

    def momentum_at(self, z, e: float) -> np.ndarray:
        """(p_x, p_y) at time T = z[1] from rest at the brake point of energy e at c = z[0] along u."""
        c, half = z
        b = self.brake_point(c, e)
        if b is None:
            return np.ones(2)
        if half == 0:
            return np.zeros(2)
        return integrate.solve_ivp(self.rhs, (0.0, half), [b[0], b[1], 0.0, 0.0], **self.tol).y[2:, -1]

    def solve(self, e: float, guess) -> tuple[float, float] | None:
        """(c, T) of the brake orbit of energy e from ``guess``; None if it is not found near the guess."""
        sol = optimize.root(self.momentum_at, guess, args=(e,), method="hybr", options={"xtol": 1e-13})
        c, half = sol.x
        ok = np.all(np.isfinite(sol.fun)) and np.max(np.abs(sol.fun)) <= 1e-8 * math.sqrt(2 * (e - self.e_s))
        return (float(c), float(half)) if ok and 0.5 < half / guess[1] < 1.5 else None

    def family(self, energy: float) -> tuple[float, float]:
        """(c, T) at E = energy: from the linear guess, else continued in energy from the saddle."""
        start = (0.0, math.pi / self.omega_v)
        z = self.solve(energy, start)
        if z is not None:
            return z
        z, f, step = start, 0.0, 1.0 / 16  # continuation: f is the fraction of E − E_s reached
        while f < 1.0:
            f_next = min(1.0, f + step)
            z_next = self.solve(self.e_s + f_next * (energy - self.e_s), z)
            if z_next is None:
                step /= 2
                if step < 1.0 / 4096:
                    e_end = self.e_s + f * (energy - self.e_s)
                    raise RuntimeError(f"no Lyapunov orbit found at E = {energy} (the family is lost near {e_end:.6g})")
                continue
            z, f = z_next, f_next
        return z

    def orbit(self, energy: float, n_samples: int) -> LyapunovOrbit:
        """The Lyapunov orbit at E = energy, one period sampled at n_samples + 1 times."""
        c, half = self.family(energy)
        xb, yb = self.brake_point(c, energy)
        period = 2 * half
        full = integrate.solve_ivp(
            self.rhs, (0.0, period), [xb, yb, 0.0, 0.0], events=self.axis, dense_output=True, **self.tol
        )
        if full.t_events[0].size != 2:
            raise RuntimeError(
                f"the brake orbit found at E = {energy} crosses the axis of exit {self.k} {full.t_events[0].size} "
                "times per period, not twice: it is not the Lyapunov orbit"
            )
        t = np.linspace(0.0, period, int(n_samples) + 1)
        states = full.sol(t).T
        r = np.hypot(states[:, 0], states[:, 1])
        x_axis, y_axis = full.y_events[0][0][:2]
        return LyapunovOrbit(
            energy=energy,
            exit=self.k,
            x_b=float(xb),
            y_b=float(yb),
            x_axis=float(x_axis),
            y_axis=float(y_axis),
            r_min=float(r.min()),
            r_max=float(r.max()),
            period=period,
            t=t,
            states=states,
        )


def lyapunov_orbit(
    energy: float, system: System, *, exit: int = 0, rtol: float = 1e-12, n_samples: int = 400
) -> LyapunovOrbit:
    """lyapunov_orbit(energy, system, *, exit=0) -> LyapunovOrbit(r_min, r_max, period, ...).

    The Lyapunov orbit of an exit at energy E above its saddle's energy E_s: the unstable periodic orbit that
    oscillates across the exit channel through the saddle; the exits' Lyapunov orbits bound the scattering
    region Ω (an orbit that crosses one outward never returns). Any
    two-degree-of-freedom system: the saddle, E_s and V come from the system object.

    Method: at the saddle V's Hessian has one negative eigenvalue (direction u, along the channel) and one
    positive one, ω_v² (direction v, across it); near E_s the orbit is saddle + A v cos(ω_v t), ω_v² A²/2 =
    E − E_s. The orbit is a brake orbit, at rest on V = E at both ends. From rest at the point of V = E at
    c along u and s > 0 along v from the saddle (s solved on V = E from s = A), the unknowns (c, T) solve
    p(T) = 0 (:func:`scipy.optimize.root` from c = 0, T = π/ω_v; failing that, continued in energy from E_s:
    the root kept is the family grown from the saddle); the period is 2T. Integration: scipy's DOP853,
    relative tolerance ``rtol``, absolute ``rtol``/100.

    Parameters
    ----------
    energy : float
        E > E_s of the exit (energy).
    system : System
        The system (:mod:`hhscatter.model`), required: the saddles, E_s and V are its. The second positional
        argument (formerly ``model``).
    exit : int
        The exit's channel index, 0 ≤ exit < len(system.exits).
    rtol : float
        Relative tolerance of the integration.
    n_samples : int
        One period is sampled at n_samples + 1 equally spaced times (``t``, ``states``, r_min, r_max).

    Returns
    -------
    LyapunovOrbit

    Raises
    ------
    ValueError
        Before any integration (a :class:`~hhscatter.errors.ConfigError` naming the argument): E not finite or
        ≤ E_s, ``system`` not a System, an exit index out of range, a system without exits, an exit that is not
        a saddle of V.
    RuntimeError
        No Lyapunov orbit found at E.

    Notes
    -----
    As E → E_s the orbit shrinks to the saddle and its period tends to 2π/ω_v. Units: the system's (unit mass): lengths, energies, times.

    Examples
    --------
    >>> from hhscatter.model import make_system
    >>> L = lyapunov_orbit(0.6, make_system("barbanis"), exit=1)  # E_s = 0.5, 2π/ω_v = 4.4429
    >>> round(L.period, 4), L.states[0, 2:].tolist()
    (4.4408, [0.0, 0.0])
    """
    energy = check.number(energy, "energy")
    system = check.system(system, "system")
    rtol = check.number(rtol, "rtol", positive=True)
    n_samples = check.count(n_samples, "n_samples", 2)
    E = _checked_energy(energy, system, exit)
    return _Shooting(system, exit, rtol).orbit(E, n_samples)


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

    Examples
    --------
    Orbit 0 leaves through r_esc = 2 at t = 5 for good; orbit 1 leaves at t = 3, is back inside r_in = 1 at
    t = 4 (a premature escape) and leaves again at t = 9.

    >>> out = return_statistics(orbit=[0, 1, 1, 1], t=[5.0, 3.0, 4.0, 9.0], radius=[2.0, 2.0, 1.0, 2.0],
    ...                         direction=[1, 1, -1, 1], n_orbits=2, r_esc=2.0, r_in=1.0)
    >>> {k: v.tolist() for k, v in out.items()}
    {'t_esc': [5.0, 3.0], 'returned': [False, True], 't_return': [nan, 4.0], 't_reesc': [nan, 9.0]}
    """
    n_orbits = check.count(n_orbits, "n_orbits", 1)
    r_esc, r_in = check.number(r_esc, "r_esc", positive=True), check.number(r_in, "r_in", positive=True)
    orbit_ = check.numbers(orbit, "orbit", min_size=0, minimum=0)
    if not np.all(orbit_ == np.round(orbit_)) or (orbit_.size and orbit_.max() >= n_orbits):
        raise ConfigError(f"orbit must hold orbit indices from 0 to n_orbits − 1 = {n_orbits - 1}")
    t_ = check.numbers(t, "t", min_size=0)
    radius_ = check.numbers(radius, "radius", min_size=0, positive=True)
    check.numbers(direction, "direction", min_size=0)
    if not (orbit_.size == t_.size == radius_.size == np.asarray(direction).size):
        raise ConfigError("orbit, t, radius and direction must have one value per crossing (their lengths differ)")
    orbit = np.asarray(orbit, dtype=np.int64)
    t = np.asarray(t, dtype=float)
    radius = np.asarray(radius, dtype=float)
    direction = np.asarray(direction)
    if not (orbit.shape == t.shape == radius.shape == direction.shape):
        raise ConfigError("orbit, t, radius and direction differ in length")
    if orbit.size and (np.any(np.diff(orbit) < 0) or np.any((np.diff(orbit) == 0) & (np.diff(t) < 0))):
        raise ConfigError("crossings must be sorted by orbit, then time")
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
