"""Energy decay of a dissipative ensemble: E(t), the decay exponent μ, energy histograms.

Reference: Sec. III.A.1 of Burton, Dullin & Altmann (2023).

With linear drag the energy of every orbit decays as dE/dt = −γ v², Eq.
(eqn:energy_diffeq).  Approximating the potential, on average along an orbit,
by V = (μ/2) E gives the homogeneous law, Eq. (eqn:energy_exp_decay),

    E(t) = E0 exp(−μ γ t),

with μ ≈ 1 (exactly 1 for damped oscillations about the stable fixed point).
μ is fitted to ⟨E⟩(t), the mean over orbits still inside Ω at t, by least
squares on log⟨E⟩; the local exponent on a late window tests whether it
tends to 1 at late times.

Functions here are pure (no file I/O, no plotting):

* :func:`energy_path`, :func:`time_to_energy` — the law itself and its
  inverse (the time t* to reach E1; τ2 of Eq. (eq:tau2) is the case E1 = E_c);
* :func:`mean_energy` / :func:`mean_energy_arrays` — ⟨E⟩, σ_E and its standard
  error per snapshot grid time (the mean curve and its 3σ ribbon);
* :func:`pool_mean_energy` — the same statistics pooled over several tables
  (e.g. one per part file, so that N = 10^7 never sits in memory at once);
* :func:`inside_mean_energy` — ⟨E⟩(t) of every orbit not escaped by t and of
  those still above E_c, pooled over the part tables of one run;
* :func:`snapshot_grid` — the snapshot times of a run, from [start, stop, step] pieces;
* :func:`fit_energy_decay` — μ with the intercept fixed at log E0 (the
  homogeneous law) and with a free intercept (the local exponent);
* :func:`mu_by_window` — the same fits over a list of windows (μ → 1 test);
* :func:`bootstrap_mu` — statistical errors of those fits (bootstrap over orbits),
  :func:`bootstrap_mu_first_orbits` on the first K orbits with errors scaled to N;
* :func:`decay_exponent` — μ of ⟨E⟩(t) over every orbit not escaped, with its bootstrap error, in one call;
* :func:`orbit_decay_exponent` — μ of a chosen set of orbits from their own start and end energies
  (Σ ln(E0/E_end) / (γ Σ t)), not the ensemble mean;
* :func:`energy_histograms` — energy distributions at chosen times.

Units: the model's natural units (unit mass); t in time units, E in energy
units, γ in 1/time; μ is dimensionless.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.least_squares import weighted_least_squares
from hhscatter.analysis.stats.measured import WithErrors
from hhscatter.errors import ConfigError

__all__ = [
    "DecayExponent",
    "EnergyDecayFit",
    "EnergyHistograms",
    "InsideMeanEnergy",
    "bootstrap_mu",
    "bootstrap_mu_first_orbits",
    "decay_exponent",
    "energy_path",
    "energy_histograms",
    "energy_histograms_arrays",
    "fit_energy_decay",
    "fit_energy_decay_table",
    "mean_energy",
    "mean_energy_arrays",
    "inside_mean_energy",
    "mu_by_window",
    "OrbitDecay",
    "orbit_decay_exponent",
    "pool_mean_energy",
    "snapshot_grid",
    "time_to_energy",
]


def _sequence(v, name: str):
    """``v`` if it is a list, tuple, array or other iterable of items (not a word, a mapping or a number)."""
    if isinstance(v, (str, bytes, dict, pd.DataFrame)) or v is None or not hasattr(v, "__iter__"):
        raise ConfigError(f"{name} must be a list, got {type(v).__name__}")
    return v


def _windows(windows, name: str = "windows") -> list:
    """``windows`` as a non-empty list of (t_lo, t_hi) pairs (time units, t_lo < t_hi)."""
    _sequence(windows, name)
    out = [check.interval(w, f"{name}[{i}]", open_end=True) for i, w in enumerate(windows)]
    if not out:
        raise ConfigError(f"{name} must hold at least one (t_lo, t_hi) window")
    return out


def snapshot_grid(pieces) -> np.ndarray:
    """snapshot_grid(pieces) -> increasing array of times from [[start, stop, step], ...].

    Each piece is the uniform grid start, start + step, ..., ≤ stop (values
    rounded to 1e-9 so that equal times compare equal across tables).
    Pieces must not overlap.

    Examples
    --------
    >>> snapshot_grid([[0, 10, 5], [20, 100, 40]]).tolist()
    [0.0, 5.0, 10.0, 20.0, 60.0, 100.0]
    """
    _sequence(pieces, "pieces")
    for p in pieces:
        if isinstance(p, (str, bytes, dict)) or not hasattr(p, "__len__") or len(p) != 3:
            raise ConfigError(f"snapshot_grid pieces must be [start, stop, step], got {p!r}")
        for v in p:
            check.number(v, "a snapshot_grid piece's start, stop and step")
    out = []
    for p in pieces:
        start, stop, step = (float(v) for v in p)
        if not step > 0 or stop < start:
            raise ConfigError(f"snapshot_grid piece needs step > 0 and stop ≥ start, got {p!r}")
        k = np.arange(int(np.floor((stop - start) / step + 1e-9)) + 1)
        out.append(np.round(start + step * k, 9))
    g = np.concatenate(out) if out else np.empty(0)
    if g.size == 0 or np.any(np.diff(g) <= 0):
        raise ConfigError("snapshot_grid must give strictly increasing times (pieces in order, no overlap)")
    return g


# ---------------------------------------------------------------------------
# the homogeneous law E(t) = E0 exp(−μγt)
# ---------------------------------------------------------------------------
def energy_path(t, E0: float, mu: float, gamma: float):
    """energy_path(t, E0, mu, gamma) -> E(t) = E0 exp(−μγt), Eq. (eqn:energy_exp_decay).

    Examples
    --------
    >>> energy_path([0.0, 100.0], 0.3, 1.0, 0.01).round(4).tolist()      # one e-fold at t = 1/(μγ) = 100
    [0.3, 0.1104]
    """
    check.numbers(t, "t", min_size=0)
    for value, name in ((E0, "E0"), (mu, "mu"), (gamma, "gamma")):
        check.real(value, name)  # NaN (a value not measured) gives NaN, as the law does
    return _energy_path(t, E0, mu, gamma)


def _energy_path(t, E0, mu, gamma):
    """:func:`energy_path` without its checks, for the models that evaluate it at every step of a fit."""
    return E0 * np.exp(-mu * gamma * np.asarray(t, dtype=float))


def time_to_energy(E0, E1, mu, gamma):
    """time_to_energy(E0, E1, mu, gamma) -> t* with E0 exp(−μγt*) = E1, i.e. ln(E0/E1)/(μγ).

    Inverse of Eq. (eqn:energy_exp_decay): the time t* at which the law
    reaches E1 from E0.  Eq. (eq:tau2) is the
    special case E1 = E_c.  Broadcasts; needs E0 ≥ E1 > 0 and μγ > 0.

    Examples
    --------
    >>> round(time_to_energy(0.35, 0.30, 0.91, 0.01), 2)     # ln(0.35/0.30)/(0.91 · 0.01)
    16.94
    >>> time_to_energy([0.3, 0.4], 1 / 6, 1.0, 0.01).round(1).tolist()     # down to E_c = 1/6
    [58.8, 87.5]
    """
    check.numbers(E1, "E1")
    for value, name in ((E0, "E0"), (mu, "mu"), (gamma, "gamma")):
        check.floats(value, name)  # NaN (a value not measured) gives NaN
    E0, E1, mu, gamma = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (E0, E1, mu, gamma)))
    if np.any(E1 <= 0) or np.any(E0 < E1):
        raise ConfigError("need E0 >= E1 > 0")
    if np.any(mu * gamma <= 0):
        raise ConfigError("need mu*gamma > 0")
    out = np.log(E0 / E1) / (mu * gamma)
    return float(out) if out.ndim == 0 else out


# ---------------------------------------------------------------------------
# mean energy per grid time
# ---------------------------------------------------------------------------
def mean_energy_arrays(t, energy) -> pd.DataFrame:
    """mean_energy_arrays(t, energy) -> DataFrame[t, n, mean_E, std_E, sem_E, lo_3sigma, hi_3sigma].

    Groups the samples ``energy`` by their (exactly equal) grid time ``t`` and
    returns, sorted by t, one row per grid time with

    * ``n``        number of orbits alive at t (int),
    * ``mean_E``   ⟨E⟩(t), the ensemble mean energy,
    * ``std_E``    sample standard deviation of E (ddof = 1; NaN when n = 1),
    * ``sem_E``    standard error of the mean, std_E / √n,
    * ``lo_3sigma``, ``hi_3sigma``  ⟨E⟩ ∓ 3 std_E, the spread's ribbon.

    NaN energies are ignored.  Energy in model units, t in time units.

    Examples
    --------
    >>> m = mean_energy_arrays([0.0, 0.0, 10.0, 10.0, 10.0], [0.3, 0.3, 0.2, 0.25, 0.3])
    >>> m[["t", "n", "mean_E", "std_E"]].round(4).values.tolist()        # at t = 10: mean 0.25, std 0.05
    [[0.0, 2.0, 0.3, 0.0], [10.0, 3.0, 0.25, 0.05]]
    >>> round(float(m["sem_E"].iloc[1]), 4)                                 # 0.05/√3
    0.0289
    """
    t = check.floats(t, "t")
    e = check.floats(energy, "energy", size=t.size, of="time t")
    ok = np.isfinite(e) & np.isfinite(t)
    t, e = t[ok], e[ok]
    grid, inv = np.unique(t, return_inverse=True)
    n = np.bincount(inv, minlength=grid.size)
    s1 = np.bincount(inv, weights=e, minlength=grid.size)
    mean = s1 / np.maximum(n, 1)
    dev2 = np.bincount(inv, weights=(e - mean[inv]) ** 2, minlength=grid.size)
    with np.errstate(invalid="ignore", divide="ignore"):
        std = np.where(n > 1, np.sqrt(dev2 / np.maximum(n - 1, 1)), np.nan)
        sem = std / np.sqrt(n)
    return pd.DataFrame(
        {
            "t": grid,
            "n": n.astype(np.int64),
            "mean_E": mean,
            "std_E": std,
            "sem_E": sem,
            "lo_3sigma": mean - 3 * std,
            "hi_3sigma": mean + 3 * std,
        }
    )


def mean_energy(snapshots: pd.DataFrame) -> pd.DataFrame:
    """mean_energy(snapshots) -> DataFrame[t, n, mean_E, std_E, sem_E, lo_3sigma, hi_3sigma].

    DataFrame wrapper of :func:`mean_energy_arrays` for the engine's
    ``snapshots`` table (columns ``traj_id, t, energy``).  The table holds only
    orbits still alive (neither escaped nor settled) at each grid time, so
    ``mean_E`` is the ⟨E⟩(t) over orbits still inside Ω at t
    and ``n`` is N·P(t) on the snapshot grid.

    Examples
    --------
    >>> snapshots = pd.DataFrame({"traj_id": [0, 1, 0, 1, 0], "t": [0.0, 0.0, 10.0, 10.0, 20.0],
    ...                           "energy": [0.3, 0.3, 0.25, 0.27, 0.2]})
    >>> m = mean_energy(snapshots)
    >>> m["n"].tolist(), m["mean_E"].round(4).tolist()      # orbit 1 is gone by t = 20
    ([2, 2, 1], [0.3, 0.26, 0.2])
    """
    check.table(snapshots, "snapshots", ("t", "energy"), min_rows=0)
    return mean_energy_arrays(snapshots["t"].to_numpy(), snapshots["energy"].to_numpy())


def pool_mean_energy(tables) -> pd.DataFrame:
    """pool_mean_energy(tables) -> DataFrame[t, n, mean_E, std_E, sem_E, lo_3sigma, hi_3sigma].

    Combines outputs of :func:`mean_energy` computed on disjoint sets of
    snapshot rows (e.g. one per part file) into the statistics of their
    union, exactly (up to rounding) as :func:`mean_energy` of the
    concatenated rows: per grid time n = Σ n_i, mean = Σ n_i m_i / n and the
    pooled sum of squared deviations Σ [(n_i − 1) s_i² + n_i (m_i − mean)²]
    (Chan et al.'s parallel variance), so memory stays O(grid) for any N.

    Examples
    --------
    Two parts of one snapshots table give, pooled, what the whole table gives:

    >>> snapshots = pd.DataFrame({"traj_id": [0, 1, 0, 1, 0], "t": [0.0, 0.0, 10.0, 10.0, 20.0],
    ...                           "energy": [0.3, 0.3, 0.25, 0.27, 0.2]})
    >>> pooled = pool_mean_energy([mean_energy(snapshots.iloc[:3]), mean_energy(snapshots.iloc[3:])])
    >>> whole = mean_energy(snapshots)
    >>> pooled["n"].tolist(), pooled["mean_E"].round(4).tolist(), round(float(pooled["std_E"].iloc[1]), 4)
    ([2, 2, 1], [0.3, 0.26, 0.2], 0.0141)
    >>> bool(np.allclose(pooled["std_E"], whole["std_E"], equal_nan=True))
    True
    """
    tables = list(_sequence(tables, "tables"))
    for i, t in enumerate(tables):
        check.table(t, f"tables[{i}]", ("t", "n", "mean_E", "std_E"), min_rows=0)
    tabs = [t for t in tables if len(t)]
    cols = ["t", "n", "mean_E", "std_E", "sem_E", "lo_3sigma", "hi_3sigma"]
    if not tabs:
        return pd.DataFrame({c: pd.Series(dtype=float) for c in cols})
    d = pd.concat([t[["t", "n", "mean_E", "std_E"]] for t in tabs], ignore_index=True)
    d["n"] = d["n"].astype(float)
    d["s1"] = d["n"] * d["mean_E"]
    d["m2"] = np.where(d["n"] > 1, (d["n"] - 1) * d["std_E"].fillna(0.0) ** 2, 0.0)
    g = d.groupby("t", sort=True)
    n_s = g["n"].sum()
    mean_s = g["s1"].sum() / n_s
    d["dev"] = d["n"] * (d["mean_E"] - d["t"].map(mean_s)) ** 2
    m2 = (d.groupby("t", sort=True)["m2"].sum() + d.groupby("t", sort=True)["dev"].sum()).to_numpy()
    n, mean = n_s.to_numpy(), mean_s.to_numpy()
    with np.errstate(invalid="ignore", divide="ignore"):
        std = np.where(n > 1, np.sqrt(m2 / np.maximum(n - 1, 1)), np.nan)
        sem = std / np.sqrt(n)
    return pd.DataFrame(
        {
            "t": n_s.index.to_numpy(dtype=float),
            "n": n.astype(np.int64),
            "mean_E": mean,
            "std_E": std,
            "sem_E": sem,
            "lo_3sigma": mean - 3 * std,
            "hi_3sigma": mean + 3 * std,
        }
    )


@dataclass(frozen=True)
class InsideMeanEnergy:
    """⟨E⟩(t) statistics of one run (columns of :func:`mean_energy`).

    inside         every orbit not escaped by t (settled orbits continued past E_c
                   count: the scene option ``continue_settled``)
    above          the orbits still above E_c at t (neither escaped nor settled)
    rows_below_ec  number of snapshot rows at or below E_c (the continued settled orbits)
    """

    inside: pd.DataFrame
    above: pd.DataFrame
    rows_below_ec: int


def inside_mean_energy(parts, e_c: float) -> InsideMeanEnergy:
    """inside_mean_energy(parts, e_c) -> InsideMeanEnergy pooled over snapshot tables (columns t, energy).

    ``parts``: an iterable of DataFrames, e.g. one per part file of a run
    whose settled orbits were continued (⟨E⟩ over the orbits
    inside Ω at time t); E decreases monotonically for γ > 0, so the rows
    with E > E_c are those of orbits neither escaped nor settled. Memory stays
    O(grid + one part) for any N.

    Examples
    --------
    Orbit 0 falls below E_c = 0.26 at t = 10 (settled, continued): it counts in ``inside``, not in ``above``.

    >>> snapshots = pd.DataFrame({"traj_id": [0, 1, 0, 1, 0], "t": [0.0, 0.0, 10.0, 10.0, 20.0],
    ...                           "energy": [0.3, 0.3, 0.25, 0.27, 0.2]})
    >>> m = inside_mean_energy([snapshots.iloc[:3], snapshots.iloc[3:]], 0.26)
    >>> m.inside["mean_E"].round(4).tolist(), m.above["mean_E"].round(4).tolist(), m.rows_below_ec
    ([0.3, 0.26, 0.2], [0.3, 0.27], 2)
    """
    _sequence(parts, "parts")
    check.number(e_c, "e_c")
    inside, above = [], []
    n_below = 0
    for df in parts:
        check.table(df, "a table of parts", ("t", "energy"), min_rows=0)
        up = df["energy"] > e_c
        inside.append(mean_energy(df))
        above.append(mean_energy(df[up]))
        n_below += int((~up).sum())
    return InsideMeanEnergy(pool_mean_energy(inside), pool_mean_energy(above), n_below)


# ---------------------------------------------------------------------------
# fitting μ
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class EnergyDecayFit(WithErrors):
    """Result of :func:`fit_energy_decay` (all μ dimensionless).

    Fixed intercept, Eq. (eqn:energy_exp_decay) with E(0) = E0:
        ``mu``, ``mu_err``, ``rms_log_residual``.
    Free intercept, log⟨E⟩ = a − μ γ t (the local decay exponent):
        ``mu_free``, ``mu_free_err``, ``log_E0_free``, ``log_E0_free_err``,
        ``rms_log_residual_free``.
    ``window`` is the (t_lo, t_hi) used, ``n_points`` the number of grid times
    in it.  Errors are 1σ (NaN when not determinable, e.g. too few points).
    """

    method = "least squares of log ⟨E⟩"
    n_field = "n_points"

    mu: float
    mu_err: float
    mu_free: float
    mu_free_err: float
    log_E0_free: float
    log_E0_free_err: float
    window: tuple
    n_points: int
    rms_log_residual: float
    rms_log_residual_free: float

    @property
    def E0_free(self) -> float:
        """exp(log_E0_free): the fitted E(0) of the free-intercept fit."""
        return float(np.exp(self.log_E0_free))


def fit_energy_decay(
    t,
    mean_E,
    E0: float,
    gamma: float,
    window=(0.0, 200.0),
    weights=None,
    *,
    absolute_sigma: bool = False,
) -> EnergyDecayFit:
    """fit_energy_decay(t, mean_E, E0, gamma, window=(0, 200), weights=None) -> EnergyDecayFit.

    Weighted least squares of the log-transformed mean energy against the
    exponential law of Eq. (eqn:energy_exp_decay):

    * fixed intercept (homogeneous law): log⟨E⟩ − log E0 = −μ γ t,
    * free intercept (local exponent):    log⟨E⟩ = a − μ γ t.

    Parameters
    ----------
    t, mean_E : arrays
        Grid times and ⟨E⟩(t) (e.g. columns of :func:`mean_energy`).  Points
        with non-finite or non-positive ⟨E⟩ are dropped.
    E0 : float
        Initial energy (intercept of the fixed fit).
    gamma : float
        Drag coefficient γ > 0; μ is the fitted slope divided by −γ.
    window : (t_lo, t_hi)
        Inclusive time window of the fit.
    weights : array or None
        Inverse variances of log⟨E⟩ per point, e.g. (mean_E / sem_E)²;
        None = unit weights (ordinary least squares).
    absolute_sigma : bool
        If True (only meaningful with ``weights``) the errors use the weights
        as absolute variances; otherwise (default) the covariance is scaled
        by the reduced χ² of the fit, as in ``scipy.optimize.curve_fit``.

    Returns
    -------
    EnergyDecayFit with μ and 1σ errors of both variants.

    Examples
    --------
    ⟨E⟩ = 0.3 e^{−0.9 γ t}: both fits give μ = 0.9. ⟨E⟩ = 0.28 e^{−γ t} (an early drop, then μ = 1): the
    free intercept finds μ = 1 and E(0) = 0.28, the intercept tied to E0 = 0.3 makes up for the drop with a larger
    μ.

    >>> t = np.arange(0.0, 201.0, 10.0)
    >>> f = fit_energy_decay(t, 0.3 * np.exp(-0.9 * 0.01 * t), 0.3, 0.01)
    >>> round(f.mu, 9), round(f.mu_free, 9)
    (0.9, 0.9)
    >>> f = fit_energy_decay(t, 0.28 * np.exp(-0.01 * t), 0.3, 0.01)
    >>> round(f.mu, 3), round(f.mu_free, 9), round(f.E0_free, 9)
    (1.05, 1.0, 0.28)
    """
    t, y, w, (t_lo, t_hi) = _decay_window(t, mean_E, E0, gamma, window, weights)
    n = t.size
    errors = "absolute" if absolute_sigma and weights is not None else "scaled"
    mu, mu_err, rms = _fit_fixed_intercept(t, y, w, E0, gamma, errors)
    mu_free, mu_free_err, a, a_err, rms_f = _fit_free_intercept(t, y, w, gamma, errors)
    return EnergyDecayFit(
        mu=float(mu),
        mu_err=float(mu_err),
        mu_free=float(mu_free),
        mu_free_err=float(mu_free_err),
        log_E0_free=float(a),
        log_E0_free_err=float(a_err),
        window=(t_lo, t_hi),
        n_points=int(n),
        rms_log_residual=float(rms),
        rms_log_residual_free=float(rms_f),
    )


def _decay_window(t, mean_E, E0, gamma, window, weights):
    """The fit's points: checked inputs, the window's usable (t, log⟨E⟩, weight) and the window (t_lo, t_hi).

    Drops points outside the inclusive window, with non-finite or non-positive ⟨E⟩, or with non-finite or
    non-positive weight; ``weights`` None gives unit weights.
    """
    check.number(gamma, "gamma", positive=True)
    check.number(E0, "E0", positive=True)
    t = check.floats(t, "t")
    m = check.floats(mean_E, "mean_E", size=t.size, of="time t")
    w = np.ones_like(t) if weights is None else check.floats(weights, "weights", size=t.size, of="time t")
    t_lo, t_hi = check.interval(window, "window", open_end=True)
    sel = (t >= t_lo) & (t <= t_hi) & np.isfinite(m) & (m > 0) & np.isfinite(w) & (w > 0)
    return t[sel], np.log(m[sel]), w[sel], (t_lo, t_hi)


def _fit_fixed_intercept(t, y, w, E0, gamma, errors):
    """The fit with the intercept fixed at log E0, y − log E0 = −μ γ t: (μ, σ_μ, rms log residual); NaN without a
    usable point (the fit of Burton, Dullin & Altmann (2023))."""
    nan = float("nan")
    if t.size >= 1 and np.sum(w * t * t) > 0:
        fit = weighted_least_squares(-t, y - np.log(E0), w, errors=errors)
        return fit.coef[0] / gamma, fit.err[0] / gamma, float(np.sqrt(np.mean(fit.resid**2)))
    return nan, nan, nan


def _fit_free_intercept(t, y, w, gamma, errors):
    """The local exponent, y = a − μ γ t: (μ, σ_μ, a, σ_a, rms log residual); NaN with < 2 distinct times."""
    nan = float("nan")
    n = t.size
    if n >= 2 and np.ptp(t) > 0:
        fit = weighted_least_squares(np.column_stack([np.ones(n), -t]), y, w, errors=errors)
        a, beta_f = fit.coef
        return beta_f / gamma, fit.err[1] / gamma, a, fit.err[0], float(np.sqrt(np.mean(fit.resid**2)))
    return nan, nan, nan, nan, nan


def fit_energy_decay_table(
    table: pd.DataFrame,
    E0: float,
    gamma: float,
    window=(0.0, 200.0),
    *,
    weighted: bool = False,
) -> EnergyDecayFit:
    """fit_energy_decay_table(table, E0, gamma, window=(0, 200), weighted=False) -> EnergyDecayFit.

    Wrapper of :func:`fit_energy_decay` for the output of :func:`mean_energy`.
    ``weighted=True`` uses inverse-variance weights (mean_E / sem_E)² of
    log⟨E⟩ (rows with n < 2 are then dropped); False gives the
    unweighted log fit of Eq. (eqn:energy_exp_decay).

    Examples
    --------
    >>> t = np.repeat([0.0, 50.0, 100.0], 2)
    >>> snapshots = pd.DataFrame({"t": t, "energy": np.tile([0.29, 0.31], 3) * np.exp(-0.8 * 0.01 * t)})
    >>> f = fit_energy_decay_table(mean_energy(snapshots), 0.3, 0.01, (0.0, 100.0))
    >>> round(f.mu, 9), f.n_points               # ⟨E⟩ = 0.3 e^{−0.8 γ t}
    (0.8, 3)
    """
    check.table(table, "table", ("t", "mean_E", "sem_E") if weighted else ("t", "mean_E"), min_rows=0)
    weights = None
    if weighted:
        with np.errstate(divide="ignore", invalid="ignore"):
            weights = (table["mean_E"].to_numpy() / table["sem_E"].to_numpy()) ** 2
        weights = np.where(np.isfinite(weights), weights, 0.0)
    return fit_energy_decay(table["t"].to_numpy(), table["mean_E"].to_numpy(), E0, gamma, window, weights)


def mu_by_window(
    t,
    mean_E,
    E0: float,
    gamma: float,
    windows,
    weights=None,
    *,
    absolute_sigma: bool = False,
) -> pd.DataFrame:
    """mu_by_window(t, mean_E, E0, gamma, windows, weights=None) -> DataFrame.

    Runs :func:`fit_energy_decay` on each (t_lo, t_hi) of ``windows`` and
    returns one row per window with columns ``t_lo, t_hi, n_points, mu,
    mu_err, mu_free, mu_free_err``.

    ``mu_free`` is the local exponent on the window, −d log⟨E⟩/d(γt); it is
    the quantity for testing whether μ → 1 at late times (Sec. III.A.1 of
    Burton, Dullin & Altmann (2023), below Eq. (eqn:energy_exp_decay)).  ``mu`` (intercept tied
    to E0) is the cumulative mean exponent ln(E0/⟨E⟩)/(γt) weighted over the
    window and lags behind the local value.

    Examples
    --------
    A local exponent rising from 0.8 to 1, 1 − 0.2 e^{−t/100}: ``mu_free`` follows it (≈ 0.88 early, ≈ 1 late),
    ``mu`` (tied to E0) lags behind.

    >>> t = np.arange(0.0, 501.0, 10.0)
    >>> mean_E = 0.3 * np.exp(-0.01 * (t - 20 * (1 - np.exp(-t / 100))))
    >>> m = mu_by_window(t, mean_E, 0.3, 0.01, [(0, 100), (300, 500)])
    >>> m[["t_lo", "n_points", "mu", "mu_free"]].round(3).values.tolist()
    [[0.0, 11.0, 0.861, 0.875], [300.0, 21.0, 0.952, 0.996]]
    """
    windows = _windows(windows)
    _decay_window(t, mean_E, E0, gamma, windows[0], weights)  # the arguments checked before the first fit
    rows = []
    for lo, hi in windows:
        f = fit_energy_decay(t, mean_E, E0, gamma, (lo, hi), weights, absolute_sigma=absolute_sigma)
        rows.append(
            {
                "t_lo": float(lo),
                "t_hi": float(hi),
                "n_points": f.n_points,
                "mu": f.mu,
                "mu_err": f.mu_err,
                "mu_free": f.mu_free,
                "mu_free_err": f.mu_free_err,
            }
        )
    return pd.DataFrame(rows, columns=["t_lo", "t_hi", "n_points", "mu", "mu_err", "mu_free", "mu_free_err"])


# ---------------------------------------------------------------------------
# energy histograms
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class EnergyHistograms:
    """Result of :func:`energy_histograms`.

    ``t_requested`` (k,) the requested times; ``t`` (k,) the snapshot grid time
    actually used for each (the nearest one); ``edges`` (b+1,) common energy
    bin edges; ``counts`` (k, b) orbit counts per bin; ``density`` (k, b)
    normalised so that Σ density·Δedge = 1 per row (NaN row if nobody alive);
    ``n_alive`` (k,) orbits alive at t; ``mean_E`` (k,) their mean energy.
    """

    t_requested: np.ndarray
    t: np.ndarray
    edges: np.ndarray
    counts: np.ndarray
    density: np.ndarray
    n_alive: np.ndarray
    mean_E: np.ndarray


def energy_histograms_arrays(t, energy, times, bins=50) -> EnergyHistograms:
    """energy_histograms_arrays(t, energy, times, bins=50) -> EnergyHistograms.

    Histograms of the energies of orbits alive at each requested time (they
    estimate the density ρ(E(t)) of Eq.
    (eqn:c-measure_model)).  Each requested time is mapped to the nearest
    snapshot grid time.  ``bins`` is a number of bins (then common edges span
    the min..max energy over the selected times) or an array of edges.

    Examples
    --------
    The time 9 is read at the nearest snapshot time, 10:

    >>> h = energy_histograms_arrays([0.0, 0.0, 0.0, 10.0, 10.0], [0.30, 0.31, 0.32, 0.25, 0.27], [0.0, 9.0],
    ...                              bins=[0.2, 0.28, 0.36])
    >>> h.t.tolist(), h.counts.tolist(), h.n_alive.tolist(), h.mean_E.round(4).tolist()
    ([0.0, 10.0], [[0, 3], [2, 0]], [3, 2], [0.31, 0.26])
    >>> h.density.round(4).tolist()             # each row integrates to 1: 3/(3 · 0.08)
    [[0.0, 12.5], [12.5, 0.0]]
    """
    t = check.floats(t, "t")
    e = check.floats(energy, "energy", size=t.size, of="time t")
    check.numbers(times, "times")
    if np.ndim(bins) == 0:
        check.count(bins, "bins", 1)
    elif np.any(np.diff(check.numbers(bins, "bins", min_size=2)) <= 0):
        raise ConfigError("bins must be increasing edges")
    times = np.atleast_1d(np.asarray(times, dtype=float))
    grid = np.unique(t[np.isfinite(t)])
    if grid.size == 0:
        raise ConfigError("no snapshot times")
    idx = np.clip(np.searchsorted(grid, times), 1, grid.size - 1) if grid.size > 1 else np.zeros(times.size, int)
    if grid.size > 1:
        left, right = grid[idx - 1], grid[idx]
        idx = np.where(np.abs(times - left) <= np.abs(right - times), idx - 1, idx)
    used = grid[idx]
    samples = [e[(t == tk) & np.isfinite(e)] for tk in used]
    if np.ndim(bins) == 0:
        allv = np.concatenate(samples) if samples else np.array([])
        lo, hi = (float(allv.min()), float(allv.max())) if allv.size else (0.0, 1.0)
        if hi <= lo:
            lo, hi = lo - 0.5e-3 * max(abs(lo), 1.0), hi + 0.5e-3 * max(abs(hi), 1.0)
        edges = np.linspace(lo, hi, int(bins) + 1)
    else:
        edges = np.asarray(bins, dtype=float)
    counts = np.array([np.histogram(s, edges)[0] for s in samples], dtype=np.int64).reshape(used.size, -1)
    widths = np.diff(edges)
    tot = counts.sum(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        density = np.where(tot > 0, counts / (tot * widths), np.nan)
    n_alive = np.array([s.size for s in samples], dtype=np.int64)
    means = np.array([s.mean() if s.size else np.nan for s in samples])
    return EnergyHistograms(times, used, edges, counts, density, n_alive, means)


def energy_histograms(snapshots: pd.DataFrame, times, bins=50) -> EnergyHistograms:
    """energy_histograms(snapshots, times, bins=50) -> EnergyHistograms.

    DataFrame wrapper of :func:`energy_histograms_arrays` for the engine's
    ``snapshots`` table (columns ``traj_id, t, energy``).

    Examples
    --------
    >>> snapshots = pd.DataFrame({"traj_id": [0, 1, 2, 0, 1], "t": [0.0, 0.0, 0.0, 10.0, 10.0],
    ...                           "energy": [0.30, 0.31, 0.32, 0.25, 0.27]})
    >>> h = energy_histograms(snapshots, [0.0, 10.0], bins=2)       # 2 bins over the energies seen, 0.25 to 0.32
    >>> h.edges.round(4).tolist(), h.counts.tolist()
    ([0.25, 0.285, 0.32], [[0, 3], [2, 0]])
    """
    check.table(snapshots, "snapshots", ("t", "energy"), min_rows=0)
    return energy_histograms_arrays(snapshots["t"].to_numpy(), snapshots["energy"].to_numpy(), times, bins)


# ---------------------------------------------------------------------------
# bootstrap over orbits
# ---------------------------------------------------------------------------
def bootstrap_mu(
    traj_id,
    t,
    energy,
    E0: float,
    gamma: float,
    windows,
    *,
    n_boot: int = 200,
    seed: int = 0,
) -> pd.DataFrame:
    """bootstrap_mu(traj_id, t, energy, E0, gamma, windows, n_boot=200, seed=0) -> DataFrame.

    Bootstrap over orbits of the unweighted log fits of :func:`fit_energy_decay`
    (Eq. (eqn:energy_exp_decay)) on each window: every replicate redraws the
    ensemble by giving each orbit (all its snapshot rows together) a
    Poisson(1) multiplicity — the large-N limit of resampling N orbits with
    replacement, which keeps the correlation of one orbit's energies across
    times — recomputes ⟨E⟩(t) and refits.  The standard deviation of a column
    over replicates is the statistical (sampling) error of that estimate;
    the fit's own ``mu_err`` measures the misfit of the model instead.

    Parameters: ``traj_id``, ``t``, ``energy`` the rows of a snapshots table
    (orbit id, grid time, energy); ``windows`` a list of (t_lo, t_hi).
    Returns one row per (replicate, window): ``replicate, t_lo, t_hi, mu,
    mu_free`` (dimensionless).

    Examples
    --------
    200 orbits whose own exponents scatter by 0.1 about 0.9: the replicates' spread of μ is the statistical error of
    the ensemble's μ, of the order of 0.1/√200 = 0.007.

    >>> rng = np.random.default_rng(0)
    >>> n, t = 200, np.arange(0.0, 101.0, 10.0)
    >>> mu_i = rng.normal(0.9, 0.1, n)
    >>> traj_id, times = np.repeat(np.arange(n), t.size), np.tile(t, n)
    >>> energy = 0.3 * np.exp(-mu_i[traj_id] * 0.01 * times)
    >>> b = bootstrap_mu(traj_id, times, energy, 0.3, 0.01, [(0.0, 100.0)], n_boot=50, seed=0)
    >>> len(b), round(float(b["mu"].mean()), 2), round(float(b["mu"].std()), 4)
    (50, 0.9, 0.0057)
    """
    check.count(n_boot, "n_boot", 1)
    t = check.floats(t, "t")
    check.floats(traj_id, "traj_id", size=t.size, of="time t")
    tid = np.asarray(traj_id).ravel()
    e = check.floats(energy, "energy", size=t.size, of="time t")
    check.number(E0, "E0", positive=True)
    check.number(gamma, "gamma", positive=True)
    windows = _windows(windows)
    ok = np.isfinite(t) & np.isfinite(e)
    tid, t, e = tid[ok], t[ok], e[ok]
    _, orb = np.unique(tid, return_inverse=True)
    grid, ti = np.unique(t, return_inverse=True)
    n_orb = int(orb.max()) + 1 if orb.size else 0
    rng = np.random.default_rng(seed)
    rows = []
    for b in range(n_boot):
        w = rng.poisson(1.0, n_orb).astype(float)[orb]
        n_t = np.bincount(ti, weights=w, minlength=grid.size)
        s_t = np.bincount(ti, weights=w * e, minlength=grid.size)
        with np.errstate(invalid="ignore", divide="ignore"):
            mean = np.where(n_t > 0, s_t / n_t, np.nan)
        for lo, hi in windows:
            f = fit_energy_decay(grid, mean, E0, gamma, (lo, hi))
            rows.append({"replicate": b, "t_lo": float(lo), "t_hi": float(hi), "mu": f.mu, "mu_free": f.mu_free})
    return pd.DataFrame(rows, columns=["replicate", "t_lo", "t_hi", "mu", "mu_free"])


def _first_orbits(n_orbits, k) -> None:
    """``n_orbits`` an integer ≥ 1 and ``k`` an integer in [1, n_orbits]."""
    check.count(n_orbits, "n_orbits", 1)
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k <= n_orbits:
        raise ConfigError(f"k must be in [1, n_orbits = {n_orbits}], got {k!r}")


def bootstrap_mu_first_orbits(
    rows: pd.DataFrame, n_orbits: int, k: int, E0: float, gamma: float, windows, *, n_boot: int = 200, seed: int = 0
):
    """bootstrap_mu_first_orbits(rows, n_orbits, k, E0, gamma, windows, n_boot, seed) -> (replicates, scale).

    :func:`bootstrap_mu` on the snapshot rows (traj_id, t, energy) of the
    orbits traj_id < k only; their standard deviations times ``scale`` =
    √(k/N) are those of the N orbits (i.i.d. orbits: errors ∝ 1/√N), which
    keeps the bootstrap affordable at N = 10^7. ``rows`` may already be
    restricted to those orbits (e.g. by a filter pushed down to the reader).

    Examples
    --------
    The first 200 of 20000 orbits: their bootstrap spread times √(200/20000) = 0.1 is that of all the orbits.

    >>> rng = np.random.default_rng(0)
    >>> n, t = 200, np.arange(0.0, 101.0, 10.0)
    >>> mu_i = rng.normal(0.9, 0.1, n)
    >>> traj_id, times = np.repeat(np.arange(n), t.size), np.tile(t, n)
    >>> rows = pd.DataFrame({"traj_id": traj_id, "t": times, "energy": 0.3 * np.exp(-mu_i[traj_id] * 0.01 * times)})
    >>> b, scale = bootstrap_mu_first_orbits(rows, 20000, 200, 0.3, 0.01, [(0.0, 100.0)], n_boot=50, seed=0)
    >>> scale, round(float(b["mu"].std()) * scale, 5)
    (0.1, 0.00057)
    """
    check.table(rows, "rows", ("traj_id", "t", "energy"), min_rows=0)
    _first_orbits(n_orbits, k)
    sub = rows[rows["traj_id"] < k]
    boot = bootstrap_mu(sub["traj_id"], sub["t"], sub["energy"], E0, gamma, windows, n_boot=n_boot, seed=seed)
    return boot, float(np.sqrt(k / n_orbits))


@dataclass(frozen=True)
class DecayExponent(WithErrors):
    """Result of :func:`decay_exponent`: μ (dimensionless), its bootstrap error, the snapshot rows at or below E_c
    and the fit window (time units)."""

    method = "least squares of log ⟨E⟩, bootstrap over orbits"

    mu: float
    mu_err: float
    rows_below_ec: int
    window: tuple


def decay_exponent(
    parts, rows: pd.DataFrame, n_orbits: int, k: int, E0: float, gamma: float, e_c: float, window, *, n_boot=200, seed=0
) -> DecayExponent:
    """decay_exponent(parts, rows, n_orbits, k, E0, gamma, e_c, window, n_boot=200, seed=0) -> DecayExponent.

    The exponent μ of E(t) = E0 e^{−μγt}, Eq. (eqn:energy_exp_decay), fitted (log fit, intercept log E0,
    :func:`fit_energy_decay`) on ``window`` to ⟨E⟩(t) over every orbit not escaped by t
    (:func:`inside_mean_energy` of ``parts``, the snapshot tables with columns t, energy), and its statistical
    error: the bootstrap over the orbits traj_id < k of ``rows`` (columns traj_id, t, energy) scaled to the
    ``n_orbits`` orbits (:func:`bootstrap_mu_first_orbits`). E0 and ``e_c`` in energy units, ``gamma`` in 1/time.

    Examples
    --------
    >>> t = np.repeat(np.arange(0.0, 101.0, 10.0), 3)
    >>> rows = pd.DataFrame({"traj_id": np.tile([0, 1, 2], 11), "t": t, "energy": 0.3 * np.exp(-0.8 * 0.01 * t)})
    >>> d = decay_exponent([rows], rows, 3, 3, 0.3, 0.01, 0.15, (0.0, 100.0), n_boot=20, seed=1)
    >>> round(d.mu, 9), round(d.mu_err, 9), d.rows_below_ec
    (0.8, 0.0, 6)
    """
    _sequence(parts, "parts")
    check.table(rows, "rows", ("traj_id", "t", "energy"), min_rows=0)
    _first_orbits(n_orbits, k)
    check.number(E0, "E0", positive=True)
    check.number(gamma, "gamma", positive=True)
    check.number(e_c, "e_c")
    check.interval(window, "window", open_end=True)
    check.count(n_boot, "n_boot", 1)
    ime = inside_mean_energy(parts, e_c)
    me = ime.inside
    win = tuple(window)
    mu = fit_energy_decay(me["t"], me["mean_E"], E0, gamma, win).mu
    boot, scale = bootstrap_mu_first_orbits(rows, n_orbits, k, E0, gamma, [win], n_boot=n_boot, seed=seed)
    return DecayExponent(mu, float(boot["mu"].std(ddof=1)) * scale, ime.rows_below_ec, win)


@dataclass(frozen=True)
class OrbitDecay(WithErrors):
    """Result of :func:`orbit_decay_exponent`: mu, mu_err (bootstrap over orbits, 1σ), n_orbits (dimensionless μ)."""

    method = "Σ ln(E0/E_end) / (γ Σ t) over the orbits, bootstrap over orbits"
    n_field = "n_orbits"

    mu: float
    mu_err: float
    n_orbits: int


def orbit_decay_exponent(e0, e_end, duration, gamma: float, *, n_boot: int = 200, seed: int = 0) -> OrbitDecay:
    """orbit_decay_exponent(e0, e_end, duration, gamma, *, n_boot=200, seed=0) -> OrbitDecay(mu, mu_err, n_orbits).

    The decay exponent μ of Eq. (eqn:energy_exp_decay), E(t) = E0 e^{−μγt}, of a chosen set of orbits from their
    own start and end energies: μ = Σ ln(E0_i/E_end,i) / (γ Σ t_i), the time-weighted mean of the orbits' own
    exponents ln(E0/E_end)/(γt) (each orbit from its start to its end, e.g. its escape or its settling at E_c),
    not the fit to the ensemble's mean ⟨E⟩(t). The error is the bootstrap over orbits (0 replicates: NaN).
    Energies in energy units (> 0), durations in time units (> 0), γ in 1/time (> 0).

    Examples
    --------
    >>> t = np.array([10.0, 20.0, 40.0])
    >>> r = orbit_decay_exponent(0.3 * np.ones(3), 0.3 * np.exp(-0.8 * 0.01 * t), t, 0.01, n_boot=20)
    >>> round(r.mu, 12), round(r.mu_err, 12), r.n_orbits
    (0.8, 0.0, 3)
    """
    arrays = {}
    for name, v in (("e0", e0), ("e_end", e_end), ("duration", duration)):
        try:
            a = np.asarray(v, dtype=float).ravel()
        except (TypeError, ValueError):
            raise ConfigError(f"{name} must be an array of numbers") from None
        if a.size == 0 or not np.all(np.isfinite(a)) or np.any(a <= 0):
            raise ConfigError(f"{name} must be a non-empty array of finite numbers > 0")
        arrays[name] = a
    if not arrays["e0"].shape == arrays["e_end"].shape == arrays["duration"].shape:
        raise ConfigError("e0, e_end and duration must have one value per orbit")
    if isinstance(gamma, bool) or not isinstance(gamma, (int, float, np.integer, np.floating)) or not gamma > 0:
        raise ConfigError(f"gamma must be a number > 0 (the drag, 1/time), got {gamma!r}")
    if isinstance(n_boot, bool) or int(n_boot) != n_boot or n_boot < 0:
        raise ConfigError(f"n_boot must be an integer ≥ 0, got {n_boot!r}")
    L = np.log(arrays["e0"] / arrays["e_end"])
    T = float(gamma) * arrays["duration"]
    mu = float(L.sum() / T.sum())
    n = L.size
    err = float("nan")
    if n_boot and n >= 2:
        rng = np.random.default_rng(seed)
        idx = rng.integers(0, n, (int(n_boot), n))
        err = float(np.std(L[idx].sum(axis=1) / T[idx].sum(axis=1), ddof=1))
    return OrbitDecay(mu=mu, mu_err=err, n_orbits=int(n))
