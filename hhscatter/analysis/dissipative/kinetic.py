"""μ of Eq. (eqn:energy_exp_decay) predicted from the conservative system: the mean kinetic energy.

With linear drag ṗ = −∇V − γp the energy of an orbit obeys dE/dt = −γ|p|² = −2γK, Eq.
(eqn:energy_diffeq). If the survivors at energy E are spread like a measure ν_E of the conservative flow
(the c-measure, Sec. III.B of Burton, Dullin & Altmann (2023)), the ensemble's energy decays as dE/dt = −γ μ(E) E with

    μ(E) = 2⟨K⟩_ν_E / E,

a property of the conservative system alone (exactly 1 for a harmonic well, where ⟨K⟩ = E/2; 2k/(k + 2)
for a homogeneous V ∝ r^k, by the virial theorem). Pure functions (no I/O):

* :func:`kinetic_fraction_from_energies` — 2⟨K⟩/E of conservative orbits, time-averaged over a window,
  measured through a vanishing drag: in a run with a probe drag γ_p ≪ 1 the energy loss of an orbit between
  two snapshots is 2γ_p ∫K dt (exact to first order in γ_p), so ⟨K⟩ over [t_k, t_k+1] is
  −ΔE/(2γ_p Δt) without any position record; averaged over the orbits alive in the window (the flow's
  conditionally invariant measure once the ensemble has relaxed), with a bootstrap over orbits;
* :func:`kinetic_fraction_by_time` — the same in a dissipative run (γ_p = γ): μ_K(t) = 2⟨K⟩/⟨E⟩ of the orbits
  alive between consecutive snapshots, the decay rate of ⟨E⟩ without the selection by escape or settling;
* :func:`microcanonical_kinetic_fraction` — the same for the microcanonical measure on
  {V < E} ∩ region: in two degrees of freedom its configuration density is uniform in area, so
  2⟨K⟩/E = 2(1 − ⟨V⟩_area/E);
* :func:`decay_path` — E(t) from dE/dt = −γ μ(E) E for a given μ(E) (the homogeneous law
  is μ constant).

Units: energies in energy units, t in time units, γ in 1/time; μ dimensionless.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = [
    "KineticFraction",
    "decay_path",
    "kinetic_fraction_by_time",
    "kinetic_fraction_from_energies",
    "microcanonical_kinetic_fraction",
]


@dataclass(frozen=True)
class KineticFraction:
    """2⟨K⟩/E (dimensionless) with its bootstrap error over orbits; the orbits and intervals it averages."""

    value: float
    err: float
    n_orbits: int
    n_intervals: int


def _checked_rows(traj_id, t, energy, gamma):
    """(traj_id, t, energy) as flat arrays of one length, and γ finite and > 0 (else ValueError)."""
    check.numbers(traj_id, "traj_id", min_size=0)
    ids = np.asarray(traj_id, dtype=np.int64).ravel()
    t = check.numbers(t, "t", min_size=0)
    e = check.numbers(energy, "energy", min_size=0)
    if not (ids.size == t.size == e.size):
        raise ConfigError("traj_id, t and energy differ in length")
    if isinstance(gamma, bool) or not isinstance(gamma, (int, float, np.integer, np.floating)):
        raise ConfigError(f"gamma must be finite and > 0, got {gamma!r}")
    if not (gamma > 0 and math.isfinite(gamma)):
        raise ConfigError(f"gamma must be finite and > 0, got {gamma}")
    return ids, t, e


def kinetic_fraction_from_energies(
    traj_id, t, energy, gamma_probe: float, t_from: float, t_to: float, *, keep=None, n_boot: int = 200, rng=None
) -> KineticFraction:
    """kinetic_fraction_from_energies(traj_id, t, energy, γ_p, t_from, t_to, *, keep=None) -> KineticFraction.

    Snapshot rows (``traj_id``, ``t``, ``energy``) of a run with the probe drag ``gamma_probe`` (1/time). Every
    pair of consecutive snapshots of the same orbit with t_from ≤ t_k < t_k+1 ≤ t_to gives the orbit's mean
    kinetic energy there, K̄ = −(E_k+1 − E_k)/(2γ_p (t_k+1 − t_k)), Eq. (eqn:energy_diffeq) (exact for linear
    drag); the result is Σ 2K̄ Δt/Ē over all pairs / Σ Δt with Ē = (E_k + E_k+1)/2 (a time average of 2K/E
    over the orbits alive in the window). ``keep``:
    optional set/array of traj_ids to use (e.g. without the censored orbits, for the c-measure proper).
    Error: bootstrap over orbits (the independent unit), ``n_boot`` replicates.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.tile(np.arange(5.0), 2); ids = np.repeat([0, 1], 5)
    >>> E = 0.3 - 2e-6 * np.where(ids == 0, 0.15, 0.12) * t      # K = 0.15 and 0.12, γ_p = 1e-6
    >>> round(kinetic_fraction_from_energies(ids, t, E, 1e-6, 0.0, 4.0, n_boot=0).value, 4)
    0.9
    """
    ids, t, e = _checked_rows(traj_id, t, energy, gamma_probe)
    check.number(t_from, "t_from")
    check.number(t_to, "t_to")
    check.count(n_boot, "n_boot", 0)
    if not t_to > t_from:
        raise ConfigError(f"need t_to > t_from, got [{t_from}, {t_to}]")
    sel = (t >= t_from) & (t <= t_to)
    if keep is not None:
        sel &= np.isin(ids, np.asarray(list(keep) if isinstance(keep, set) else keep, dtype=np.int64))
    ids, t, e = ids[sel], t[sel], e[sel]
    order = np.lexsort((t, ids))
    ids, t, e = ids[order], t[order], e[order]
    same = ids[1:] == ids[:-1]
    dt = (t[1:] - t[:-1])[same]
    num = (-(e[1:] - e[:-1]) / (gamma_probe * 0.5 * (e[1:] + e[:-1])))[same]  # 2 ∫K dt / Ē over the interval
    pid = ids[:-1][same]
    if dt.size == 0:
        return KineticFraction(math.nan, math.nan, 0, 0)
    uid, inv = np.unique(pid, return_inverse=True)
    s_num = np.bincount(inv, weights=num)
    s_dt = np.bincount(inv, weights=dt)
    value = float(s_num.sum() / s_dt.sum())
    err = math.nan
    if n_boot > 1 and uid.size > 1:
        gen = np.random.default_rng(rng)
        w = gen.poisson(1.0, size=(n_boot, uid.size))
        reps = (w @ s_num) / np.maximum(w @ s_dt, 1e-300)
        err = float(np.std(reps, ddof=1))
    return KineticFraction(value, err, int(uid.size), int(dt.size))


def kinetic_fraction_by_time(traj_id, t, energy, gamma: float):
    """kinetic_fraction_by_time(traj_id, t, energy, γ) -> DataFrame[t_lo, t_hi, mu_K, n] per snapshot interval.

    For linear drag ΔE_i = −2γ ∫K_i dt exactly, so over the orbits i present at both ends of an interval
    [t_lo, t_hi] of the snapshot grid, μ_K = Σ_i (−ΔE_i/(γ Δt)) / Σ_i Ē_i = 2⟨K̄⟩/⟨Ē⟩ (Ē_i the interval's mean
    of the end energies): the rate of d ln⟨E⟩/dt = −γ μ_K of a fixed set of orbits. The ensemble's ⟨E⟩(t)
    also changes by the orbits that leave (escape or settle) or join, which μ_K leaves out. ``n``: orbits.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.tile([0.0, 1.0], 2); ids = np.repeat([0, 1], 2)
    >>> E = np.array([0.3, 0.3 * np.exp(-0.01), 0.2, 0.2 * np.exp(-0.01)])   # d ln E/dt = −γ μ, γ = 0.01, μ = 1
    >>> round(float(kinetic_fraction_by_time(ids, t, E, 0.01)["mu_K"].iloc[0]), 4)
    1.0
    """
    import pandas as pd  # deferred: pandas loads on first use

    ids, t, e = _checked_rows(traj_id, t, energy, gamma)
    grid = np.unique(t)
    order = np.lexsort((t, ids))
    ids, t, e = ids[order], t[order], e[order]
    k = np.searchsorted(grid, t)
    pair = (ids[1:] == ids[:-1]) & (k[1:] == k[:-1] + 1)  # consecutive grid times of one orbit
    lo = k[:-1][pair]
    de = -(e[1:] - e[:-1])[pair] / (gamma * (grid[lo + 1] - grid[lo]))
    em = 0.5 * (e[1:] + e[:-1])[pair]
    m = grid.size - 1
    num = np.bincount(lo, weights=de, minlength=m)
    den = np.bincount(lo, weights=em, minlength=m)
    n = np.bincount(lo, minlength=m)
    with np.errstate(invalid="ignore", divide="ignore"):
        mu = np.where(n > 0, num / den, np.nan)
    return pd.DataFrame({"t_lo": grid[:-1], "t_hi": grid[1:], "mu_K": mu[:m], "n": n[:m].astype(np.int64)})


def microcanonical_kinetic_fraction(potential, energy: float, extent: float, *, n_grid: int = 801) -> float:
    """microcanonical_kinetic_fraction(V, E, extent, *, inside=None, n_grid=801) -> 2⟨K⟩/E (dimensionless).

    The microcanonical measure of a two-degree-of-freedom system on the energy shell E, restricted to the
    configuration set A = the connected part of {V < E} that holds the origin (the well's minimum), has a uniform density
    in area (the momentum circle |p| = √(2(E − V)) has length ∝ |p| and the shell's δ-function weight
    1/|p|), and K = E − V there: 2⟨K⟩/E = 2(1 − ⟨V⟩_A/E). Midpoint quadrature on an ``n_grid``² grid of the
    square [−extent, extent]² (length units), which must contain A (an error otherwise: for E above the
    threshold A is unbounded); A is the grid's 4-connected component of {V < E} at the origin.

    Examples
    --------
    >>> f = microcanonical_kinetic_fraction(lambda x, y: 0.5 * (x**2 + y**2), 0.3, 1.0)   # harmonic: 1
    >>> abs(f - 1.0) < 1e-3
    True
    """
    check.function(potential, "potential")
    check.number(extent, "extent", positive=True)
    check.count(n_grid, "n_grid", 1)
    if isinstance(energy, bool) or not isinstance(energy, (int, float, np.integer, np.floating)):
        raise ConfigError(f"energy must be > 0, got {energy!r}")
    if not energy > 0:
        raise ConfigError(f"energy must be > 0, got {energy}")
    h = 2.0 * extent / n_grid
    c = -extent + h * (np.arange(n_grid) + 0.5)
    X, Y = np.meshgrid(c, c, indexing="ij")
    from scipy import ndimage  # deferred: scipy loads on first use

    V = np.asarray(potential(X, Y), dtype=float)
    labels, _ = ndimage.label(V < energy)
    i0 = n_grid // 2 if n_grid % 2 else n_grid // 2 - 1
    if labels[i0, i0] == 0:
        raise ConfigError(f"the grid point next to the origin has V ≥ E = {energy}")
    m = labels == labels[i0, i0]
    edge = m[0, :].any() or m[-1, :].any() or m[:, 0].any() or m[:, -1].any()
    if edge:
        raise ConfigError(f"the region V < E = {energy} reaches the edge of the square of half side {extent}")
    return float(2.0 * (1.0 - V[m].mean() / energy))


def decay_path(t, E0: float, gamma: float, mu_of_E) -> np.ndarray:
    """decay_path(t, E0, γ, μ(E)) -> E(t) solving dE/dt = −γ μ(E) E, E(0) = E0, on the increasing times ``t``.

    ``mu_of_E``: a vectorised function of the energy. Solved as d(ln E)/dt = −γ μ(E) with scipy's
    ``solve_ivp`` (DOP853, rtol 1e-10). μ constant gives Eq. (eqn:energy_exp_decay), E0 e^{−μγt}.

    Examples
    --------
    >>> import numpy as np
    >>> E = decay_path([0.0, 100.0], 0.3, 0.01, lambda E: 0.9 + 0 * E)
    >>> bool(abs(E[-1] - 0.3 * np.exp(-0.9)) < 1e-9)
    True
    """
    from scipy.integrate import solve_ivp  # deferred: scipy loads on first use

    check.numbers(t, "t")
    check.number(E0, "E0", positive=True)
    check.number(gamma, "gamma")
    check.function(mu_of_E, "mu_of_E")
    t = np.asarray(t, dtype=float)
    if t.size == 0 or np.any(np.diff(t) < 0) or t[0] < 0:
        raise ConfigError("t must be non-empty, ≥ 0 and increasing")
    sol = solve_ivp(
        lambda _, y: [-gamma * float(mu_of_E(np.exp(y[0])))],
        (0.0, float(t[-1]) or 1.0),
        [math.log(E0)],
        t_eval=t,
        method="DOP853",
        rtol=1e-10,
        atol=1e-12,
    )
    if not sol.success:
        raise RuntimeError(f"decay_path: {sol.message}")
    return np.exp(sol.y[0])
