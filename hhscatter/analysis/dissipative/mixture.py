"""Mixture survival model: sub-ensembles of a dissipative ensemble, each with its own energy decay.

Reference: the extension proposed at the end of Sec. III.B.3 of Burton, Dullin & Altmann (2023):
"An improved agreement would be obtained by avoiding the approximation of
homogeneous energy decay ... a mixture model for P(t) involving multiple
sub-ensembles, each with their own energy decay exponent μ."  Design:

1. Reference time t_ref (default τ0).  Every orbit alive at t_ref (snapshot
   table) gets its own decay law ln E_i(t) = a_i − μ_i γ t, least squares over
   its snapshot energies.
2. The orbits alive at t_ref are split into K sub-ensembles by the quantiles
   of their energy E_i(t_ref) (``by="energy"``, default: the fractions w_k,
   Σ w_k = 1, discretise the measured density ρ(E(t_ref)) of Eq.
   (eqn:c-measure_model)) or of their exponent μ_i (``by="rate"``).  Each
   sub-ensemble gets μ_k = ⟨μ_i⟩_k and A_k = exp⟨a_i⟩_k, i.e. an energy path
   E_k(t) = A_k e^{−μ_k γ t}, a rate κ0(E_k(t)) and a settling time
   τ2,k = ln(A_k/E_c)/(μ_k γ).  Per-orbit exponents are averaged (instead of
   fitting the sub-ensemble's mean energy) to avoid survivor bias: once the
   fast members settle, the mean over the survivors follows the slow ones.
3. Every sub-ensemble follows Eq. (eqn:surv_prob_model) with its own path:

       P(t) = Σ_k P_k(t),
       P_k(t) = f_ne,k + f_e,k exp(−X_k(t))           τ0 ≤ t ≤ τ2,k
              = f_ne,k exp(−g_k(t)(t − τ2,k))          t > τ2,k
       f_ne,k + f_e,k = w_k P(τ0),   g_k = L/(1 + e^{−b(t−τ2,k)})²,

   with X_k the (instantaneous or integrated) escape exponent along E_k(t).
   Free parameters: the K never-escaping fractions f_ne,k (``fne_mode="free"``) or a
   single never-escaping share φ with f_ne,k = φ w_k P(τ0) (``fne_mode="shared"``,
   as many free parameters as the homogeneous model), and the shared L, b.
   The component paths (A_k, μ_k) are measured, not fitted to P(t).

With t_ref = τ0 the constraint Σ_k (f_ne,k + f_e,k) = P(τ0) is exact; with a
later t_ref the weights refer to the population at t_ref (an approximation).
K = 1 with A = E0 reproduces the homogeneous model with a measured μ.

The fit returns a :class:`~hhscatter.analysis.dissipative.survival_model.SurvivalFit` with the same goodness-of-fit
measures as the homogeneous model (:func:`~hhscatter.analysis.dissipative.model_comparison.compare_fits`).

Units: time in model units, energies in model units, rates in 1/time.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pandas as pd

from hhscatter.analysis.dissipative.curve_fit import _fit_stats, _lsq, _residual_fn
from hhscatter.analysis.dissipative.survival_model import (
    HAZARDS,
    SurvivalFit,
    _component,
    _fit_data,
    _survival_fit,
)
from hhscatter.analysis.dissipative.transitions import tau2_predicted
from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = [
    "MixtureComponents",
    "MixtureModelParams",
    "fit_mixture_model",
    "mixture_components",
    "mixture_components_arrays",
    "mixture_survival_model",
]


# ---------------------------------------------------------------------------
# mixture model
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class MixtureComponents:
    """Energy sub-ensembles measured from the snapshots (see module docstring).

    ``t_ref``    snapshot grid time at which the sub-ensembles are defined;
    ``by``       "energy" or "rate": the quantity binned into quantiles;
    ``edges``    (K+1,) its quantile edges;
    ``weights``  (K,) fractions w_k of the orbits alive at t_ref (Σ = 1);
    ``n_ref``    (K,) their counts; ``E_ref`` (K,) mean energy at t_ref;
    ``A, mu, mu_err``  (K,) paths E_k(t) = A_k exp(−μ_k γ t);
    ``fit_window`` time window of the per-orbit fits; ``gamma`` the drag.
    Build with :func:`mixture_components`, or directly for known paths.

    Units: t_ref and fit_window in time, E_ref and A in energy, gamma in 1/time; mu and weights dimensionless.
    The arguments are checked when the components are built: t_ref a finite number, ``by`` "energy" or "rate",
    K ≥ 1 weights ≥ 0 summing to 1, K + 1 non-decreasing edges, K whole counts n_ref ≥ 0, K finite E_ref and mu,
    K amplitudes A > 0, K errors mu_err ≥ 0 (NaN where a sub-ensemble has one member), fit_window a pair lo < hi
    (hi may be inf) and gamma > 0; a wrong one (a word, a bool, NaN or inf, a wrong length or a value out of range)
    is refused with a ConfigError naming it. The arrays are kept as float arrays (n_ref as integers).

    Examples
    --------
    Two sub-ensembles on paths E_k(t) = A_k e^{−μ_k γ t} from A = 0.3 with μ = 0.8 and 1.2 at γ = 0.01: at t = 50
    their energies are 0.3 e^{−0.4} and 0.3 e^{−0.6}.

    >>> c = MixtureComponents(t_ref=5.0, by="rate", edges=[0.7, 1.0, 1.3], weights=[0.5, 0.5], n_ref=[3, 3],
    ...                       E_ref=[0.29, 0.28], A=[0.3, 0.3], mu=[0.8, 1.2], mu_err=[0.0, 0.0],
    ...                       fit_window=(0.0, np.inf), gamma=0.01)
    >>> c.K, np.allclose(c.energy(50.0)[:, 0], 0.3 * np.exp([-0.4, -0.6]))
    (2, True)
    >>> MixtureComponents(t_ref=5.0, by="rate", edges=[0.7, 1.0, 1.3], weights=[0.5, 0.4], n_ref=[3, 3],
    ...                   E_ref=[0.29, 0.28], A=[0.3, 0.3], mu=[0.8, 1.2], mu_err=[0.0, 0.0],
    ...                   fit_window=(0.0, np.inf), gamma=0.01)
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: weights must sum to 1 (fractions of the orbits alive at t_ref), got 0.9
    """

    t_ref: float
    by: str
    edges: np.ndarray
    weights: np.ndarray
    n_ref: np.ndarray
    E_ref: np.ndarray
    A: np.ndarray
    mu: np.ndarray
    mu_err: np.ndarray
    fit_window: tuple
    gamma: float

    def __post_init__(self):
        check.number(self.t_ref, "t_ref")
        if not isinstance(self.by, str) or self.by not in ("energy", "rate"):
            raise ConfigError(f"by must be 'energy' or 'rate', got {self.by!r}")
        weights = _per_component(self.weights, "weights", None, minimum=0.0)
        if abs(weights.sum() - 1.0) > 1e-9:
            raise ConfigError(
                f"weights must sum to 1 (fractions of the orbits alive at t_ref), got {weights.sum():.6g}"
            )
        K = weights.size
        edges = _per_component(self.edges, "edges", K + 1)
        if np.any(np.diff(edges) < 0):
            raise ConfigError("edges must be non-decreasing (the quantile edges of the bins)")
        n_ref = _per_component(self.n_ref, "n_ref", K, minimum=0.0)
        if np.any(n_ref != np.round(n_ref)):
            raise ConfigError("n_ref must hold whole counts of orbits")
        arrays = {"weights": weights, "edges": edges, "n_ref": n_ref.astype(np.int64)}
        arrays["E_ref"] = _per_component(self.E_ref, "E_ref", K)
        arrays["A"] = _per_component(self.A, "A", K, positive=True)
        arrays["mu"] = _per_component(self.mu, "mu", K)
        if np.ndim(self.mu_err) != 1:
            raise ConfigError(f"mu_err must be a 1-D array of numbers, got {type(self.mu_err).__name__}")
        mu_err = check.floats(self.mu_err, "mu_err", size=K, of="sub-ensemble")
        if np.any(np.isinf(mu_err)) or np.any(mu_err < 0):
            raise ConfigError("mu_err must be ≥ 0 and finite (NaN where a sub-ensemble has one member)")
        arrays["mu_err"] = mu_err
        window = check.interval(self.fit_window, "fit_window", open_end=True)
        check.number(self.gamma, "gamma", positive=True)
        for name, value in {**arrays, "fit_window": window}.items():
            object.__setattr__(self, name, value)

    @property
    def K(self) -> int:
        """Number of sub-ensembles."""
        return int(self.weights.size)

    def energy(self, t):
        """energy(t) -> (K, len(t)) array of E_k(t)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return self.A[:, None] * np.exp(-self.mu[:, None] * self.gamma * t[None, :])

    def tau2(self, E_c: float):
        """tau2(E_c) -> (K,) τ2,k = ln(A_k/E_c)/(μ_k γ), Eq. (eq:tau2) per sub-ensemble."""
        return np.asarray(tau2_predicted(self.A, E_c, self.mu, self.gamma), dtype=float)

    def to_frame(self, E_c: float) -> pd.DataFrame:
        """One row per sub-ensemble: bin_lo, bin_hi (of ``by``), weight, n_ref, E_ref, A, mu, mu_err, tau2 (at E_c)."""
        return pd.DataFrame(
            {
                "bin_lo": self.edges[:-1],
                "bin_hi": self.edges[1:],
                "weight": self.weights,
                "n_ref": self.n_ref,
                "E_ref": self.E_ref,
                "A": self.A,
                "mu": self.mu,
                "mu_err": self.mu_err,
                "tau2": self.tau2(E_c),
            }
        )


def _per_component(a, name: str, size: int | None, *, minimum: float | None = None, positive: bool = False):
    """``a`` as a 1-D float array of finite numbers with ``size`` values (one per sub-ensemble, or K + 1 edges)."""
    arr = check.numbers(a, name, minimum=minimum, positive=positive, flat=True)
    if size is not None and arr.size != size:
        raise ConfigError(
            f"{name} must have {size} values (K = {size - 1 if name == 'edges' else size}), got {arr.size}"
        )
    return arr


def _per_orbit_decay(ids, t, e, lo, hi):
    """Per-orbit least squares of ln E = a − β t on lo ≤ t ≤ hi: (unique ids, a, β, n points)."""
    ok = (t >= lo) & (t <= hi) & np.isfinite(e) & (e > 0)
    ids, t, y = ids[ok], t[ok], np.log(e[ok])
    uid, inv = np.unique(ids, return_inverse=True)
    m = uid.size
    n = np.bincount(inv, minlength=m).astype(float)
    st = np.bincount(inv, weights=t, minlength=m)
    sy = np.bincount(inv, weights=y, minlength=m)
    stt = np.bincount(inv, weights=t * t, minlength=m)
    sty = np.bincount(inv, weights=t * y, minlength=m)
    den = n * stt - st * st
    with np.errstate(invalid="ignore", divide="ignore"):
        slope = np.where(den > 0, (n * sty - st * sy) / den, np.nan)
        a = np.where(n > 0, (sy - slope * st) / n, np.nan)
    return uid, a, -slope, n


def mixture_components_arrays(
    traj_id,
    t,
    energy,
    *,
    gamma: float,
    t_ref: float,
    n_components: int = 4,
    by: str = "energy",
    fit_window=(0.0, np.inf),
) -> MixtureComponents:
    """mixture_components_arrays(traj_id, t, energy, *, gamma, t_ref, n_components=4, by="energy", fit_window=(0, inf)) -> MixtureComponents.

    Sub-ensembles of the orbits alive at the snapshot grid time nearest
    ``t_ref``:

    1. every such orbit gets its own decay law ln E_i(t) = a_i − μ_i γ t,
       least squares over its snapshots in ``fit_window`` (default: its whole
       record; needs ≥ 2 snapshots, otherwise μ_i is undefined);
    2. the orbits are split into ``n_components`` quantile bins of their
       energy E_i(t_ref) (``by="energy"``: the bins discretise ρ(E(t_ref)) of
       Eq. (eqn:c-measure_model)) or of their exponent μ_i (``by="rate"``:
       sub-ensembles "each with their own energy decay exponent μ"; orbits
       with undefined μ_i are left out);
    3. each sub-ensemble k gets w_k = n_k / Σ n, μ_k = mean of its members'
       μ_i (error: standard error of that mean) and A_k = exp(mean a_i), i.e.
       the path E_k(t) = A_k e^{−μ_k γ t}, Eq. (eqn:energy_exp_decay).

    Averaging per-orbit exponents, rather than fitting the sub-ensemble's
    mean energy ⟨E⟩_k(t), avoids survivor bias: as the members with fast
    decay settle, ⟨E⟩_k(t) over those still alive is pulled towards the slow
    ones and its slope underestimates the members' decay.

    Examples
    --------
    Six orbits, three decaying with μ = 0.8 and three with μ = 1.2, split by their exponents into two sub-ensembles:

    >>> t = np.arange(0.0, 51.0, 10.0)
    >>> mu_i = np.array([0.8, 0.8, 0.8, 1.2, 1.2, 1.2])             # two kinds of orbits, from E = 0.3
    >>> traj_id, times = np.repeat(np.arange(6), t.size), np.tile(t, 6)
    >>> energy = 0.3 * np.exp(-mu_i[traj_id] * 0.01 * times)
    >>> c = mixture_components_arrays(traj_id, times, energy, gamma=0.01, t_ref=10.0, n_components=2, by="rate")
    >>> c.weights.tolist(), c.mu.round(9).tolist(), c.A.round(9).tolist()
    ([0.5, 0.5], [0.8, 1.2], [0.3, 0.3])
    >>> c.tau2(1 / 6).round(2).tolist()                             # ln(0.3/(1/6))/(μ γ)
    [73.47, 48.98]
    """
    t = check.floats(t, "t")
    check.numbers(traj_id, "traj_id")
    ids = np.asarray(traj_id).ravel()
    if ids.size != t.size:
        raise ConfigError(f"traj_id must have one value per time t: {ids.size} != {t.size}")
    e = check.floats(energy, "energy", size=t.size, of="time t")
    if not np.isfinite(t).any():
        raise ConfigError("t must hold at least one finite snapshot time")
    check.number(gamma, "gamma", positive=True)
    check.number(t_ref, "t_ref")
    check.interval(fit_window, "fit_window", open_end=True)
    if by not in ("energy", "rate"):
        raise ConfigError("by must be 'energy' or 'rate'")
    K = check.count(n_components, "n_components", 1)
    t_used, ids_ref, e_ref = _orbits_at(ids, t, e, t_ref)
    mu_i, a_ref = _member_decay_laws(ids, t, e, ids_ref, gamma, fit_window)
    edges, comp, n_ref = _quantile_bins(e_ref if by == "energy" else mu_i, K, t_used)
    A, mu, mu_err, E_mean = _sub_ensemble_paths(comp, e_ref, mu_i, a_ref, K)
    return MixtureComponents(
        t_ref=t_used,
        by=by,
        edges=edges,
        weights=n_ref / n_ref.sum(),
        n_ref=n_ref.astype(np.int64),
        E_ref=E_mean,
        A=A,
        mu=mu,
        mu_err=mu_err,
        fit_window=(float(fit_window[0]), float(fit_window[1])),
        gamma=float(gamma),
    )


# the steps of mixture_components_arrays (its docstring's steps 1-3)
def _orbits_at(ids, t, e, t_ref):
    """The orbits alive at the snapshot grid time nearest ``t_ref``: (that time, their ids (sorted), energies)."""
    grid = np.unique(t[np.isfinite(t)])
    t_used = float(grid[np.argmin(np.abs(grid - t_ref))])
    at = (t == t_used) & np.isfinite(e)
    ids_ref, e_ref = ids[at], e[at]
    order = np.argsort(ids_ref)
    return t_used, ids_ref[order], e_ref[order]


def _member_decay_laws(ids, t, e, ids_ref, gamma, fit_window):
    """Step 1, each orbit's decay law ln E_i = a_i − μ_i γ t over ``fit_window``: (μ_i, a_i), NaN if undefined."""
    member_rows = np.isin(ids, ids_ref)
    uid, a_i, beta_i, _ = _per_orbit_decay(ids[member_rows], t[member_rows], e[member_rows], *map(float, fit_window))
    pos = np.searchsorted(uid, ids_ref)
    has = (pos < uid.size) & (uid[np.minimum(pos, uid.size - 1)] == ids_ref)
    mu_i = np.full(ids_ref.size, np.nan)
    a_ref = np.full(ids_ref.size, np.nan)
    mu_i[has] = beta_i[pos[has]] / gamma
    a_ref[has] = a_i[pos[has]]
    return mu_i, a_ref


def _quantile_bins(key, K, t_used):
    """Step 2, K quantile bins of ``key`` (E_i(t_ref) or μ_i): (edges (K+1,), bin of each orbit (−1: unusable), counts)."""
    use = np.isfinite(key)
    if use.sum() < K:
        raise ConfigError(f"only {int(use.sum())} usable orbits alive at t_ref={t_used}")
    edges = np.quantile(key[use], np.linspace(0, 1, K + 1))
    comp = np.full(key.size, -1)
    comp[use] = np.clip(np.searchsorted(edges[1:-1], key[use], side="right"), 0, K - 1)
    n_ref = np.bincount(comp[use], minlength=K)
    if np.any(n_ref == 0):
        raise ConfigError("empty sub-ensemble (ties); use fewer components")
    return edges, comp, n_ref


def _sub_ensemble_paths(comp, e_ref, mu_i, a_ref, K):
    """Step 3, each sub-ensemble's path E_k(t) = A_k e^{−μ_k γ t}: (A_k, μ_k, σ(μ_k), mean E at t_ref), each (K,)."""
    A, mu, mu_err, E_mean = (np.full(K, np.nan) for _ in range(4))
    for k in range(K):
        sel = comp == k
        E_mean[k] = float(e_ref[sel].mean())
        good = sel & np.isfinite(mu_i)
        if not good.any():
            raise ConfigError(f"sub-ensemble {k}: no member with a defined decay exponent")
        mu[k] = float(mu_i[good].mean())
        mu_err[k] = float(mu_i[good].std(ddof=1) / np.sqrt(good.sum())) if good.sum() > 1 else np.nan
        A[k] = float(np.exp(a_ref[good].mean()))
    return A, mu, mu_err, E_mean


def mixture_components(
    snapshots: pd.DataFrame,
    *,
    gamma: float,
    t_ref: float,
    n_components: int = 4,
    by: str = "energy",
    fit_window=(0.0, np.inf),
) -> MixtureComponents:
    """mixture_components(snapshots, *, gamma, t_ref, n_components=4, by="energy", fit_window=(0, inf)) -> MixtureComponents.

    DataFrame wrapper of :func:`mixture_components_arrays` for the engine's
    ``snapshots`` table (columns ``traj_id, t, energy``).

    Examples
    --------
    The same orbits split by their energy at t_ref = 10 (the faster decay has the lower energy):

    >>> t = np.arange(0.0, 51.0, 10.0)
    >>> mu_i = np.array([0.8, 0.8, 0.8, 1.2, 1.2, 1.2])             # two kinds of orbits, from E = 0.3
    >>> traj_id, times = np.repeat(np.arange(6), t.size), np.tile(t, 6)
    >>> energy = 0.3 * np.exp(-mu_i[traj_id] * 0.01 * times)
    >>> snapshots = pd.DataFrame({"traj_id": traj_id, "t": times, "energy": energy})
    >>> c = mixture_components(snapshots, gamma=0.01, t_ref=10.0, n_components=2)
    >>> c.to_frame(1 / 6)[["weight", "E_ref", "mu", "tau2"]].round(4).values.tolist()
    [[0.5, 0.2661, 1.2, 48.9822], [0.5, 0.2769, 0.8, 73.4733]]
    """
    check.table(snapshots, "snapshots", ("traj_id", "t", "energy"), min_rows=0)
    return mixture_components_arrays(
        snapshots["traj_id"].to_numpy(),
        snapshots["t"].to_numpy(),
        snapshots["energy"].to_numpy(),
        gamma=gamma,
        t_ref=t_ref,
        n_components=n_components,
        by=by,
        fit_window=fit_window,
    )


def _check_mixture(kappa_of_E, components, tau0, f_ne, P_tau0, L, b, E_c, hazard, f_ne_name="f_ne"):
    """The checks of the mixture model's parameters (a ConfigError naming the first wrong one); the components."""
    check.function(kappa_of_E, "kappa_of_E")
    c = check.instance(components, "components", MixtureComponents)
    check.number(tau0, "tau0")
    check.floats(f_ne, f_ne_name)
    for value, name in ((P_tau0, "P_tau0"), (L, "L"), (b, "b")):
        check.real(value, name)
    check.number(E_c, "E_c", positive=True)
    if hazard not in HAZARDS:
        raise ConfigError(f"hazard must be one of {HAZARDS}, got {hazard!r}")
    return c


def mixture_survival_model(
    t,
    *,
    kappa_of_E: Callable,
    components: MixtureComponents,
    tau0: float,
    f_ne,
    P_tau0: float,
    L: float,
    b: float,
    E_c: float,
    hazard: str = "paper",
    tau2=None,
):
    """mixture_survival_model(t, *, kappa_of_E, components, tau0, f_ne, P_tau0, L, b, E_c, hazard) -> P(t).

    Mixture generalisation of Eq. (eqn:surv_prob_model):
    P(t) = Σ_k P_k(t), each sub-ensemble k following the homogeneous model
    along its own energy path E_k(t) = A_k e^{−μ_k γ t} (rate κ0(E_k(t))),
    with never-escaping fraction ``f_ne[k]``, escaping fraction
    f_e,k = w_k P_tau0 − f_ne[k], settling time τ2,k (``tau2`` (K,) or, if
    None, Eq. (eq:tau2) per sub-ensemble) and shared settling parameters L, b.
    NaN for t < τ0.

    Examples
    --------
    One sub-ensemble on the path E0 = 0.3, μ = 0.91 is the homogeneous model:

    >>> from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
    >>> one = MixtureComponents(t_ref=5.0, by="energy", edges=np.array([0.0, 1.0]), weights=np.array([1.0]),
    ...                         n_ref=np.array([1]), E_ref=np.array([0.3]), A=np.array([0.3]), mu=np.array([0.91]),
    ...                         mu_err=np.array([0.0]), fit_window=(0.0, np.inf), gamma=0.01)
    >>> from hhscatter.analysis.dissipative.survival_model import survival_model
    >>> t, kappa = np.array([10.0, 40.0, 100.0]), PiecewiseKappa(1 / 6, 13.63, 0.03, 1.41, 0.27)
    >>> P = mixture_survival_model(t, kappa_of_E=kappa, components=one, tau0=5.0, f_ne=0.1, P_tau0=0.5, L=0.1, b=0.2,
    ...                            E_c=1 / 6)
    >>> P_h = survival_model(t, kappa_of_E=kappa, E0=0.3, mu=0.91, gamma=0.01, tau0=5.0, f_ne=0.1, f_e=0.4, L=0.1,
    ...                      b=0.2, E_c=1 / 6)
    >>> P.round(4).tolist(), bool(np.allclose(P, P_h, rtol=1e-12))
    ([0.2878, 0.2663, 0.0029], True)
    """
    check.numbers(t, "t", min_size=0)
    c = _check_mixture(kappa_of_E, components, tau0, f_ne, P_tau0, L, b, E_c, hazard)
    if tau2 is not None:
        check.floats(tau2, "tau2")
    f_ne = np.broadcast_to(np.asarray(f_ne, dtype=float), (c.K,))
    tau2_k = c.tau2(E_c) if tau2 is None else np.broadcast_to(np.asarray(tau2, dtype=float), (c.K,))
    f_e = c.weights * P_tau0 - f_ne
    t_arr = np.asarray(t, dtype=float)
    out = np.zeros(t_arr.shape)
    for k in range(c.K):
        out = out + _component(
            t_arr, kappa_of_E, c.A[k], c.mu[k], c.gamma, tau0, tau2_k[k], f_ne[k], f_e[k], L, b, hazard
        )
    return float(out) if np.ndim(t) == 0 else out


@dataclass(frozen=True)
class MixtureModelParams:
    """All inputs of :func:`mixture_survival_model`; calling it evaluates P(t). The inputs are checked as
    :func:`mixture_survival_model` checks them, when the parameters are built: a wrong one is refused with a
    ConfigError naming it."""

    kappa_of_E: Callable
    components: MixtureComponents
    tau0: float
    f_ne_k: np.ndarray
    P_tau0: float
    L: float
    b: float
    E_c: float
    hazard: str = "paper"

    def __post_init__(self):
        _check_mixture(self.kappa_of_E, self.components, self.tau0, self.f_ne_k, self.P_tau0, self.L, self.b,
                       self.E_c, self.hazard, f_ne_name="f_ne_k")  # fmt: skip

    @property
    def tau2_k(self):
        """(K,) settling times τ2,k of the sub-ensembles."""
        return self.components.tau2(self.E_c)

    def __call__(self, t):
        return mixture_survival_model(
            t,
            kappa_of_E=self.kappa_of_E,
            components=self.components,
            tau0=self.tau0,
            f_ne=self.f_ne_k,
            P_tau0=self.P_tau0,
            L=self.L,
            b=self.b,
            E_c=self.E_c,
            hazard=self.hazard,
        )


def fit_mixture_model(
    t,
    P,
    P_err,
    components,
    *,
    kappa_of_E: Callable,
    tau0: float,
    gamma: float | None = None,
    E_c: float,
    n_components: int = 4,
    t_ref: float | None = None,
    by: str = "energy",
    fit_window=(0.0, np.inf),
    fne_mode: str = "free",
    fixed: dict | None = None,
    p0: dict | None = None,
    P_tau0: float | None = None,
    space: str = "log",
    P_min: float = 0.0,
    t_max: float | None = None,
    hazard: str = "paper",
    absolute_sigma: bool = True,
) -> SurvivalFit:
    """fit_mixture_model(t, P, P_err, components, *, kappa_of_E, tau0, ...) -> SurvivalFit.

    The mixture model proposed at the end of Sec. III.B.3 of Burton, Dullin & Altmann (2023): sub-ensembles
    with their own energy-decay exponent μ, each following Eq. (eqn:surv_prob_model).

    Weighted least-squares fit of the mixture model (module docstring,
    :func:`mixture_survival_model`) to P(t) ± P_err, with the same data
    selection (τ0 ≤ t ≤ t_max, P > P_min), residual ``space`` and
    goodness-of-fit measures as :func:`fit_survival_model`, so that the two
    can be compared with :func:`~hhscatter.analysis.dissipative.model_comparison.compare_fits`.

    ``components`` is a :class:`MixtureComponents` or the ``snapshots``
    DataFrame, from which the sub-ensembles are built by
    :func:`mixture_components` (needs ``gamma``; ``t_ref`` defaults to τ0).
    The component energy paths are measured inputs, not fitted.

    Free parameters: ``fne_mode="free"``: f_ne_0 … f_ne_{K−1} (bounded to
    [0, w_k P(τ0)]), L, b; ``fne_mode="shared"``: phi (f_ne,k = phi w_k P(τ0),
    0 ≤ phi ≤ 1), L, b.  ``fixed`` may hold L, b, phi or f_ne_k values.
    Derived values reported: f_ne = Σ f_ne,k, f_e = P(τ0) − f_ne, the arrays
    f_ne_k, f_e_k (with propagated errors) and τ2_k.  P(τ0) is ``P_tau0``
    (exact) or interpolated from the data, its error then being propagated
    into the errors and ``cov`` by re-fitting at P(τ0) + σ.  The uncertainty
    of the measured component paths (A_k, μ_k) is not propagated, and the
    error model (independent points) is that of :func:`fit_survival_model`.

    Examples
    --------
    With one sub-ensemble on the path E0 = 0.3, μ = 0.91 the mixture is the homogeneous model: fitted to a curve that
    model made (f_ne = 0.1, L = 0.1, b = 0.2, 10⁵ orbits), it finds the parameters back.

    >>> from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
    >>> one = MixtureComponents(t_ref=5.0, by="energy", edges=np.array([0.0, 1.0]), weights=np.array([1.0]),
    ...                         n_ref=np.array([1]), E_ref=np.array([0.3]), A=np.array([0.3]), mu=np.array([0.91]),
    ...                         mu_err=np.array([0.0]), fit_window=(0.0, np.inf), gamma=0.01)
    >>> from hhscatter.analysis.dissipative.survival_model import survival_model_sample
    >>> kappa, t, N = PiecewiseKappa(1 / 6, 13.63, 0.03, 1.41, 0.27), np.arange(0.0, 301.0), 100_000
    >>> P, P_err = survival_model_sample(t, N, kappa_of_E=kappa, E0=0.3, mu=0.91, gamma=0.01, tau0=5.0, f_ne=0.1,
    ...                                  f_e=0.4, L=0.1, b=0.2, E_c=1 / 6)
    >>> f = fit_mixture_model(t, P, P_err, one, kappa_of_E=kappa, tau0=5.0, E_c=1 / 6, P_min=20 / N)
    >>> f.free, {k: round(float(f.values[k]), 3) for k in ("f_ne", "f_e", "L", "b")}
    (('f_ne_0', 'L', 'b'), {'f_ne': 0.099, 'f_e': 0.402, 'L': 0.1, 'b': 0.199})
    """
    check.function(kappa_of_E, "kappa_of_E")
    check.instance(components, "components", (MixtureComponents, pd.DataFrame))
    check.number(tau0, "tau0")
    check.number(E_c, "E_c", positive=True)
    for d, name in ((fixed, "fixed"), (p0, "p0")):
        if d is not None:
            check.mapping(d, name)
    if space not in ("log", "linear"):
        raise ConfigError(f"space must be 'log' or 'linear', got {space!r}")
    _fit_data_checked(t, P, P_err, P_tau0, t_max, P_min)
    c = _components_of(components, gamma, tau0, t_ref, n_components, by, fit_window)
    if fne_mode not in ("free", "shared"):
        raise ConfigError("fne_mode must be 'free' or 'shared'")
    if hazard not in HAZARDS:
        raise ConfigError(f"hazard must be one of {HAZARDS}, got {hazard!r}")
    fixed = dict(fixed or {})
    p0 = dict(p0 or {})
    P_tau0, P_tau0_err, tf, Pf, sf = _fit_data(t, P, P_err, tau0, P_tau0, t_max, P_min)
    names, free = _mixture_parameters(c.K, fne_mode, fixed)
    tau2_k = c.tau2(E_c)
    guess, b_starts = _mixture_start(tf, Pf, tau2_k, c.weights, P_tau0, p0)
    prob = _MixtureProblem(tf, Pf, sf, kappa_of_E, c, tau0, E_c, hazard, space, fne_mode, free, fixed, guess, b_starts)
    sol, res = prob.solve(prob.starts(), P_tau0)
    theta = sol.x if sol is not None else np.array([])
    model = prob.model(theta, P_tau0)
    r = res(theta)
    # propagate the error of the measured P(τ0) (linear sensitivity from a re-fit)
    st = _fit_stats(
        sol, model(tf), tf, Pf, r, len(free), absolute_sigma, P_tau0_err, lambda dP: prob.solve([sol.x], P_tau0 + dP)[0]
    )
    values, errors = _mixture_values_errors(prob, theta, names, st, P_tau0, P_tau0_err, tau2_k)
    return _survival_fit(model, values, errors, free, st, tf, r, sol, space)


# the steps of fit_mixture_model
def _fit_data_checked(t, P, P_err, P_tau0, t_max, P_min) -> None:
    """The data arguments of :func:`fit_mixture_model` checked before the components are built."""
    size = check.floats(t, "t").size
    check.floats(P, "P", size=size, of="time t")
    check.floats(P_err, "P_err", size=size, of="time t")
    if P_tau0 is not None:
        check.number(P_tau0, "P_tau0", minimum=0.0)
    if t_max is not None:
        check.real(t_max, "t_max")
    check.number(P_min, "P_min")


def _components_of(components, gamma, tau0, t_ref, n_components, by, fit_window) -> MixtureComponents:
    """``components`` as given, or built from a snapshots DataFrame by :func:`mixture_components` (t_ref: τ0)."""
    if isinstance(components, pd.DataFrame):
        if gamma is None:
            raise ConfigError("gamma is needed to build the components from snapshots")
        components = mixture_components(
            components,
            gamma=gamma,
            t_ref=tau0 if t_ref is None else t_ref,
            n_components=n_components,
            by=by,
            fit_window=fit_window,
        )
    return components


def _mixture_parameters(K, fne_mode, fixed):
    """(all parameter names, the free ones): f_ne_0 … f_ne_{K−1} ("free") or phi ("shared"), then L, b."""
    fne_names = [f"f_ne_{k}" for k in range(K)] if fne_mode == "free" else ["phi"]
    names = fne_names + ["L", "b"]
    unknown = set(fixed) - set(names)
    if unknown:
        raise ConfigError(f"unknown parameters in fixed: {sorted(unknown)}")
    return names, [n for n in names if n not in fixed]


def _mixture_start(tf, Pf, tau2_k, weights, P_tau0, p0):
    """Starting values (``p0`` wins): never-escaping share φ ≈ P(first τ2,k)/P(τ0), L ≈ late log-slope of P (1/time).

    Returns (guess dict of phi, L and every f_ne_k = φ w_k P(τ0); the starts for b).
    """
    t_first = float(np.clip(np.min(tau2_k), tf[0], tf[-1]))
    phi0 = float(np.clip(np.exp(np.interp(t_first, tf, np.log(Pf))) / P_tau0, 1e-6, 0.9))
    late = tf > np.max(tau2_k)
    if late.sum() >= 3:
        hl = tf[late] >= np.median(tf[late])
        slope = -np.polyfit(tf[late][hl], np.log(Pf[late][hl]), 1)[0] if hl.sum() >= 2 else 0.05
        L0 = max(slope, 1e-3)
    else:
        L0 = 0.05
    guess = {"phi": phi0, "L": p0.get("L", L0)}
    for k in range(weights.size):
        guess[f"f_ne_{k}"] = phi0 * weights[k] * P_tau0
    guess.update({k: v for k, v in p0.items() if k != "b"})
    return guess, [p0["b"]] if "b" in p0 else [0.02, 0.1, 0.5]


@dataclass(frozen=True)
class _MixtureProblem:
    """The least-squares problem of :func:`fit_mixture_model` on its selected points (tf, Pf ± sf).

    ``free`` the fitted parameters (in order: θ), ``fixed`` the held ones, ``guess`` the starting values and
    ``b_starts`` the starts for b. Every method takes P(τ0) (``P0``), which the error propagation shifts.
    """

    tf: np.ndarray
    Pf: np.ndarray
    sf: np.ndarray
    kappa_of_E: Callable
    components: MixtureComponents
    tau0: float
    E_c: float
    hazard: str
    space: str
    fne_mode: str
    free: list
    fixed: dict
    guess: dict
    b_starts: list

    def bounds(self, P0):
        """(lo, hi) of θ: 0 ≤ f_ne_k ≤ w_k P(τ0), 0 ≤ phi ≤ 1, L ∈ [1e-9, 1e3], b ∈ [1e-6, 1e3]."""

        def bound(n):
            if n == "phi":
                return (0.0, 1.0)
            if n.startswith("f_ne_"):
                return (0.0, float(self.components.weights[int(n[5:])] * P0))
            return {"L": (1e-9, 1e3), "b": (1e-6, 1e3)}[n]

        lo_b = np.array([bound(n)[0] for n in self.free], dtype=float)
        return lo_b, np.array([bound(n)[1] for n in self.free], dtype=float)

    def unpack(self, theta, P0):
        """(all parameter values, the never-escaping fractions f_ne,k (K,)) from θ: guess, then ``fixed``, then θ."""
        c = self.components
        v = dict(self.guess)
        v["b"] = self.b_starts[0]
        v.update(self.fixed)
        v.update(dict(zip(self.free, theta)))
        if self.fne_mode == "free":
            fk = np.array([v[f"f_ne_{k}"] for k in range(c.K)])
        else:
            fk = v["phi"] * c.weights * P0
        return v, fk

    def model(self, theta, P0) -> MixtureModelParams:
        """The mixture model P(t) of θ."""
        v, fk = self.unpack(theta, P0)
        return MixtureModelParams(
            self.kappa_of_E, self.components, self.tau0, fk, P0, v["L"], v["b"], self.E_c, self.hazard
        )

    def starts(self) -> list:
        """Starting θ, one per start of b."""
        starts = []
        for b0 in self.b_starts:
            g = dict(self.guess, b=b0)
            starts.append([g[n] for n in self.free])
        return starts

    def solve(self, starts, P0):
        """(best solution over ``starts``, or None without free parameters; residual function)."""
        res = _residual_fn(lambda th: self.model(th, P0)(self.tf), self.Pf, self.sf, self.space)
        return (_lsq(res, starts, *self.bounds(P0)) if self.free else None), res


def _mixture_values_errors(prob: _MixtureProblem, theta, names, st, P_tau0, P_tau0_err, tau2_k):
    """Values and 1σ errors of the fitted, fixed and derived parameters (f_ne, f_e, f_ne_k, f_e_k, τ2_k)."""
    c, free = prob.components, prob.free
    v, fk = prob.unpack(theta, P_tau0)
    values = {n: float(v[n]) for n in names}
    errors = {n: 0.0 for n in names}
    for i, n in enumerate(free):
        errors[n] = float(np.sqrt(max(st.cov[i, i], 0.0)))
    f_ne_err, f_e_err = _total_fraction_errors(free, prob.fne_mode, v, st, P_tau0, P_tau0_err)
    fk_err = _component_fraction_errors(free, prob.fne_mode, v, errors, c.weights, st, P_tau0, P_tau0_err)
    values.update(
        f_ne=float(fk.sum()),
        f_e=float(P_tau0 - fk.sum()),
        P_tau0=P_tau0,
        tau2_k=tau2_k,
        f_ne_k=fk,
        f_e_k=c.weights * P_tau0 - fk,
    )
    errors.update(f_ne=f_ne_err, f_e=f_e_err, P_tau0=P_tau0_err, f_ne_k=fk_err)
    return values, errors


def _total_fraction_errors(free, fne_mode, v, st, P_tau0, P_tau0_err):
    """1σ errors of the total never-escaping fraction f_ne = Σ f_ne,k and of f_e = P(τ0) − f_ne (fit and P(τ0) parts)."""
    cov_fit, sens = st.cov_fit, st.sens
    k_free = len(free)
    grad = np.zeros(k_free)
    for i, n in enumerate(free):
        if n.startswith("f_ne_"):
            grad[i] = 1.0
        elif n == "phi":
            grad[i] = P_tau0
    dfne_dP = float(grad @ sens) + (v["phi"] if fne_mode == "shared" else 0.0)
    var_fit = float(grad @ cov_fit @ grad) if k_free else 0.0
    f_ne_err = float(np.sqrt(max(var_fit, 0.0) + (dfne_dP * P_tau0_err) ** 2))
    f_e_err = float(np.sqrt(max(var_fit, 0.0) + ((1.0 - dfne_dP) * P_tau0_err) ** 2))
    return f_ne_err, f_e_err


def _component_fraction_errors(free, fne_mode, v, errors, weights, st, P_tau0, P_tau0_err):
    """(K,) 1σ errors of the never-escaping fractions f_ne,k: their own ("free") or φ w_k P(τ0)'s ("shared")."""
    cov_fit, sens = st.cov_fit, st.sens
    K = weights.size
    fk_err = np.zeros(K)
    if fne_mode == "free":
        for k in range(K):
            fk_err[k] = errors[f"f_ne_{k}"]
    else:
        i_phi = free.index("phi") if "phi" in free else None
        for k in range(K):
            g_k = weights[k] * P_tau0
            vfit = g_k**2 * cov_fit[i_phi, i_phi] if i_phi is not None else 0.0
            dP = g_k * (sens[i_phi] if i_phi is not None else 0.0) + weights[k] * v["phi"]
            fk_err[k] = float(np.sqrt(max(vfit, 0.0) + (dP * P_tau0_err) ** 2))
    return fk_err
