"""The uncertainty algorithm on exit-basin maps: f(ε), its power law and cut-off, the local exponent.

Functions here are pure (arrays in, frozen result dataclasses or DataFrames
out; no file I/O, no integration, no plotting):

* :func:`uncertainty_fraction`, :func:`uncertainty_exponent` — the
  uncertainty algorithm (Grebogi, McDonald, Ott and Yorke, Phys. Lett. A 99,
  415 (1983); McDonald, Grebogi, Ott and Yorke, Physica D 17, 125 (1985)):
  f(ε), the fraction of initial conditions whose outcome changes under a
  perturbation of size ε, scales as f ∝ ε^α; the uncertainty dimension of
  the boundary is d = D − α in a D-dimensional space of initial conditions.
* :func:`uncertainty_cutoff` — a scale ε_c below which f(ε) leaves the power
  law (broken power law against a single one), or an upper bound on ε_c.
* :func:`local_exponent`, :func:`slim_fractal` — the exponent between
  neighbouring resolutions and the "slim fractal" test on it.

Outcome labels as in :mod:`hhscatter.analysis.geometry.basins` (``outside``
marks initial conditions outside the allowed region).

Uncertainty algorithm and its fit
---------------------------------
For each ε a sample of n initial conditions x is classified with their
outcome at x and at perturbed points (x ± ε along one or more axes); the
initial condition is *uncertain* when any perturbed outcome differs.  With
k uncertain out of n, f = k/n is binomial.  :func:`uncertainty_exponent` fits
the model p(ε) = c ε^α to the counts by maximum likelihood (a binomial
generalised linear model with log link, ln p = ln c + α ln ε: each f
weighted by its binomial information n p/(1 − p), zero counts included),
with errors from the Fisher information and goodness of fit by Pearson's χ²
(dof = points − 2).  The errors assume independent samples for each ε
(fresh random initial conditions per ε, the original algorithm); if the same
initial conditions serve every ε the f(ε) are positively correlated and the
error of α is too small.

Cut-off
-------
:func:`uncertainty_cutoff` compares the single power law with a broken one,
ln p = ln c + α·max(x − x_c, 0) + β·min(x − x_c, 0) with x = ln ε: slope α
above ε_c = e^{x_c}, slope β below.  By default β = 1 is fixed — the slope of
a smooth boundary, which is what a fractal boundary whose fine structure is
cut off below ε_c looks like — and x_c is profiled over a grid between the
smallest and largest ε (x_c at the smallest ε is the single power law).
A cut-off is *detected* when the broken law lowers the AIC
(ΔAIC = 2Δℓ − 2·(extra parameters) > 0) and at least ``min_points`` values
of ε lie below the break.  The interval of ε_c is the profile-likelihood set
{x_c : 2(ℓ_max − ℓ(x_c)) ≤ z²}, its ends found by root finding; when no
cut-off is detected ε_c is reported as NaN with the interval (0, upper end]:
any break above the upper end is excluded at z σ.  With β free the break can
mimic the single law at every x_c, so no useful upper bound can be given.
The errors of α and β come from the expected information of (ln c, α, β, x_c)
and so include the uncertainty of the break.  The break is not a regular
parameter (ℓ(x_c) has kinks at the sampled ε): in synthetic replicates of
a sharply broken law (13 ε over 4 decades, 2·10^4 ICs each) the ±1σ
interval of ε_c and the errors of α (β fixed, tested) and of β (β free,
measured) cover the truth in about 68 % of cases, down to ≈ 60 % when ε_c
lies next to a sampled ε.  The
interval presumes that both laws describe the data (check the χ² of the
single fit above and below ε_c); a smooth crossover fitted by a sharp break
gives an interval that is too narrow.

Units: ε in the units of the initial conditions (the caller's coordinates).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize, stats

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.intervals import wilson_interval
from hhscatter.analysis.stats.measured import WithErrors
from hhscatter.errors import ConfigError

__all__ = [
    "UncertaintyCutoff",
    "UncertaintyExponent",
    "UncertaintyFraction",
    "local_exponent",
    "slim_fractal",
    "uncertainty_cutoff",
    "uncertainty_exponent",
    "uncertainty_fraction",
    "weighted_line",
]


# ---------------------------------------------------------------------------
# input checks
# ---------------------------------------------------------------------------
def _int_labels(a, name: str, ndim: int | None = None) -> np.ndarray:
    """``a`` as an integer array (whole-valued floats accepted), else ValueError naming ``name``."""
    a = np.asarray(a)
    if ndim is not None and a.ndim != ndim:
        raise ConfigError(f"{name} must be a {ndim}-D array of labels, got shape {a.shape}")
    if a.size == 0:
        raise ConfigError(f"{name} is empty")
    if a.dtype.kind in "iu":
        return a.astype(np.int64, copy=False)
    if a.dtype.kind == "b":
        return a.astype(np.int64)
    if a.dtype.kind == "f" and np.all(np.isfinite(a)) and np.all(a == np.round(a)):
        return a.astype(np.int64)
    raise ConfigError(f"{name} must hold integer labels, got dtype {a.dtype}")


def _positive_int(v, name: str, minimum: int = 1) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not math.isfinite(v):
        raise ConfigError(f"{name} must be an integer ≥ {minimum}, got {v!r}")
    if not float(v).is_integer() or int(v) < minimum:
        raise ConfigError(f"{name} must be an integer ≥ {minimum}, got {v!r}")
    return int(v)


# ---------------------------------------------------------------------------
# uncertainty algorithm
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class UncertaintyFraction:
    """Result of :func:`uncertainty_fraction`.

    f = k/n, lo, hi (Wilson at ±z), k (uncertain initial conditions),
    n (decided ones), n_excluded (a reference or perturbed outcome outside).
    """

    f: float
    lo: float
    hi: float
    k: int
    n: int
    n_excluded: int


def uncertainty_fraction(outcome_ref, outcome_perturbed, *, outside: int = -1, z: float = 1.0) -> UncertaintyFraction:
    """uncertainty_fraction(outcome_ref, outcome_perturbed, *, outside=-1, z=1.0) -> UncertaintyFraction(f, lo, hi, k, n).

    The fraction f of initial conditions whose outcome changes under the
    perturbation (Grebogi et al. 1983).  ``outcome_ref``: labels at the
    initial conditions (any shape S); ``outcome_perturbed``: labels at the
    perturbed initial conditions, shape S (one perturbation each) or (m, *S)
    (m perturbations each, e.g. x ± ε: uncertain if any differs).  An initial
    condition with any outcome equal to ``outside`` is excluded.  Binomial
    Wilson interval at ±z.

    Examples
    --------
    Four initial conditions, each perturbed once: one changes its outcome, one lands outside (excluded): f = 1/3.

    >>> r = uncertainty_fraction([0, 0, 1, 1], [0, 1, 1, -1])
    >>> r.k, r.n, round(r.f, 4)
    (1, 3, 0.3333)
    """
    ref = _int_labels(outcome_ref, "outcome_ref")
    per = _int_labels(outcome_perturbed, "outcome_perturbed")
    if per.shape == ref.shape:
        per = per[None]
    elif per.shape[1:] != ref.shape:
        raise ConfigError(f"outcome_perturbed must have shape {ref.shape} or (m, *{ref.shape}), got {per.shape}")
    ok = (ref != outside) & np.all(per != outside, axis=0)
    changed = np.any(per != ref[None], axis=0) & ok
    n = int(np.count_nonzero(ok))
    if n == 0:
        raise ConfigError("outcome_ref: no initial condition with every outcome inside")
    k = int(np.count_nonzero(changed))
    p, lo, hi = wilson_interval(k, n, z)
    return UncertaintyFraction(float(p), float(lo), float(hi), k, n, int(ref.size - n))


def _loglin_binomial(X, k, n, offset):
    """Maximum-likelihood fit of k ~ Binomial(n, exp(X b + offset)) with exp(·) < 1.

    Fisher scoring with step halving.  Returns (b, cov, loglik) with cov the
    inverse expected information; loglik without the binomial coefficients.
    """
    k = k.astype(float)
    n = n.astype(float)

    def loglik(eta):
        if np.any(eta >= 0.0):
            return -math.inf
        return float(np.sum(k * eta + (n - k) * np.log1p(-np.exp(eta))))

    # start: weighted least squares on the log of the (shrunk) fractions
    y = np.log((k + 0.5) / (n + 1.0)) - offset
    w = k + 0.5
    sw = np.sqrt(w)
    b = np.linalg.lstsq(X * sw[:, None], y * sw, rcond=None)[0]
    eta = X @ b + offset
    if np.max(eta) > -1e-3:  # X[:, 0] is the intercept: shift the start into p < 1
        b[0] -= np.max(eta) + 1e-2
        eta = X @ b + offset
    ll = loglik(eta)
    for _ in range(200):
        p = np.exp(eta)
        g = X.T @ (k - (n - k) * p / (1.0 - p))
        info = (X * (n * p / (1.0 - p))[:, None]).T @ X
        step = np.linalg.solve(info, g)
        t = 1.0
        for _ in range(60):
            bn = b + t * step
            en = X @ bn + offset
            ln = loglik(en)
            if ln >= ll - 1e-12 * abs(ll):
                break
            t *= 0.5
        else:
            break
        converged = np.max(np.abs(bn - b)) < 1e-11 * (1.0 + np.max(np.abs(b)))
        b, eta, ll = bn, en, ln
        if converged:
            break
    p = np.exp(eta)
    info = (X * (n * p / (1.0 - p))[:, None]).T @ X
    return b, np.linalg.inv(info), ll


@dataclass(frozen=True)
class UncertaintyExponent(WithErrors):
    """Result of :func:`uncertainty_exponent`.

    alpha, alpha_err (uncertainty exponent, 1σ), dim (D of the space of
    initial conditions), d = D − α and d_err (uncertainty dimension),
    prefactor c and its relative error (f = c ε^α), eps_range (smallest and
    largest ε fitted), n_points, chi2 (Pearson), dof, p_value; eps, f, n and
    fitted (mask of the points used) for plots.
    """

    method = "least squares of log f(ε)"
    n_field = "n_points"

    alpha: float
    alpha_err: float
    dim: float
    d: float
    d_err: float
    prefactor: float
    prefactor_rel_err: float
    eps_range: tuple
    n_points: int
    chi2: float
    dof: int
    p_value: float
    eps: np.ndarray = field(repr=False)
    f: np.ndarray = field(repr=False)
    n: np.ndarray = field(repr=False)
    fitted: np.ndarray = field(repr=False)


def _uncertainty_counts(eps, f, n, eps_range):
    """Validated arrays (eps, f, k, n, mask of eps_range)."""
    eps = check.numbers(eps, "eps", positive=True)
    f = check.numbers(f, "f")
    if eps.size != f.size:
        raise ConfigError(f"eps and f differ in length: {eps.size} != {f.size}")
    if np.any((f < 0) | (f > 1)):
        raise ConfigError("f must be fractions in [0, 1]")
    n_given = check.numbers(n, "n", minimum=1.0)
    if n_given.size not in (1, f.size):
        raise ConfigError(f"n must be one count or one count per ε: {n_given.size} != {f.size}")
    n = np.broadcast_to(n_given, f.shape).astype(float)
    if np.any(n != np.round(n)):
        raise ConfigError("n must be whole counts ≥ 1 (initial conditions per ε)")
    k = np.round(f * n)
    if np.any(np.abs(f * n - k) > 1e-6 * np.maximum(n, 1.0)):
        raise ConfigError("f·n must be whole counts (f = k/n with the n given)")
    if eps_range is None:
        use = np.ones(eps.size, dtype=bool)
    else:
        try:
            lo, hi = (check.number(v, "eps_range") for v in eps_range)
        except (TypeError, ValueError):
            raise ConfigError(f"eps_range must be (lo, hi) with 0 < lo < hi, got {eps_range!r}") from None
        if not 0 < lo < hi:
            raise ConfigError(f"eps_range must be (lo, hi) with 0 < lo < hi, got {eps_range!r}")
        use = (eps >= lo) & (eps <= hi)
    if np.unique(eps[use]).size < 3:
        raise ConfigError("eps: need at least 3 distinct values of ε in the fitted range (eps_range)")
    if np.any(k[use] >= n[use]):
        raise ConfigError("f = 1 in the fitted range: saturated, outside the power-law regime; narrow eps_range")
    if np.count_nonzero(k[use]) < 2:
        raise ConfigError("f: need at least 2 values of ε with uncertain initial conditions")
    return eps, f, k, n, use


def _pearson(k, n, p, n_par):
    chi2 = float(np.sum((k - n * p) ** 2 / (n * p * (1.0 - p))))
    dof = int(k.size - n_par)
    pv = float(stats.chi2.sf(chi2, dof)) if dof > 0 else math.nan
    return chi2, dof, pv


def _fit_single(x, k, n):
    """Single power law in x = ln ε, centred: (b = (ln c + α x̄, α), cov, loglik, x̄, fitted p)."""
    xm = float(x.mean())
    X = np.column_stack([np.ones(x.size), x - xm])
    b, cov, ll = _loglin_binomial(X, k, n, 0.0)
    return b, cov, ll, xm, np.exp(X @ b)


def uncertainty_exponent(eps, f, n, *, eps_range=None, dim: float = 2.0) -> UncertaintyExponent:
    """uncertainty_exponent(eps, f, n, *, eps_range=None, dim=2.0) -> UncertaintyExponent(alpha, alpha_err, d, ...).

    Fits f(ε) = c ε^α to the uncertain fractions ``f`` measured with ``n``
    initial conditions each (scalar or per ε) by binomial maximum likelihood
    (see the module notes), over the ε in ``eps_range`` (inclusive; default
    all).  Reports α ± σ_α, the uncertainty dimension d = dim − α of the
    boundary in a ``dim``-dimensional space of initial conditions (2 for a
    plane, 1 for a line), Pearson's χ² and its p-value.  Points with f = 0
    are fitted (they carry information); f = 1 in the range is refused.

    Examples
    --------
    Uncertain fractions drawn from f = 0.5 ε^0.3 with 10⁵ initial conditions per ε: α near 0.3, d = 2 − α near 1.7.

    >>> rng = np.random.default_rng(0)
    >>> eps = np.logspace(-6, -2, 9)
    >>> f = rng.binomial(100_000, 0.5 * eps**0.3) / 100_000
    >>> r = uncertainty_exponent(eps, f, 100_000)
    >>> round(r.alpha, 2), round(r.d, 2), r.n_points
    (0.3, 1.7, 9)
    """
    if not float(dim) > 0:
        raise ConfigError(f"dim must be > 0, got {dim}")
    eps, f, k, n, use = _uncertainty_counts(eps, f, n, eps_range)
    b, cov, _, xm, p = _fit_single(np.log(eps[use]), k[use], n[use])
    chi2, dof, pv = _pearson(k[use], n[use], p, 2)
    alpha, a_err = float(b[1]), float(math.sqrt(cov[1, 1]))
    return UncertaintyExponent(
        alpha=alpha,
        alpha_err=a_err,
        dim=float(dim),
        d=float(dim) - alpha,
        d_err=a_err,
        prefactor=float(math.exp(b[0] - b[1] * xm)),
        prefactor_rel_err=float(math.sqrt(cov[0, 0] + xm * xm * cov[1, 1] - 2 * xm * cov[0, 1])),
        eps_range=(float(eps[use].min()), float(eps[use].max())),
        n_points=int(np.count_nonzero(use)),
        chi2=chi2,
        dof=dof,
        p_value=pv,
        eps=eps,
        f=f,
        n=n,
        fitted=use,
    )


@dataclass(frozen=True)
class UncertaintyCutoff(WithErrors):
    """Result of :func:`uncertainty_cutoff`.

    detected (bool), eps_c (best break; NaN when not detected), eps_c_lo,
    eps_c_hi (profile-likelihood interval at ±z; when not detected eps_c_lo
    is 0 and eps_c_hi the upper bound), alpha, alpha_err (slope above the
    break; the single law's when not detected), beta, beta_err (below; err 0
    when fixed), beta_fixed, lr = 2(ℓ_broken − ℓ_single), delta_aic
    (AIC_single − AIC_broken), n_below (ε values below the break), single
    (the :class:`UncertaintyExponent` fit of the same points); profile_eps and
    profile_2ll (2ℓ(x_c), for plots).
    """

    method = "least squares of log f(ε) with a cutoff"

    detected: bool
    eps_c: float
    eps_c_lo: float
    eps_c_hi: float
    alpha: float
    alpha_err: float
    beta: float
    beta_err: float
    beta_fixed: bool
    lr: float
    delta_aic: float
    n_below: int
    single: UncertaintyExponent
    profile_eps: np.ndarray = field(repr=False)
    profile_2ll: np.ndarray = field(repr=False)


def _broken_fit(x, k, n, xc, beta):
    """Fit of the broken law with the break at ln ε = xc: (b, cov, loglik), b = (ln c, α, β).

    A slope with no point on its side is not fitted (NaN in b and cov).
    """
    up, dn = np.maximum(x - xc, 0.0), np.minimum(x - xc, 0.0)
    cols = [np.ones(x.size), up] + ([dn] if beta is None else [])
    use = [0] + [i for i in range(1, len(cols)) if np.any(cols[i] != 0)]
    offset = 0.0 if beta is None else beta * dn
    b, cov, ll = _loglin_binomial(np.column_stack([cols[i] for i in use]), k, n, offset)
    B = np.full(len(cols), np.nan)
    C = np.full((len(cols), len(cols)), np.nan)
    B[use] = b
    C[np.ix_(use, use)] = cov
    return B, C, ll


def uncertainty_cutoff(
    eps,
    f,
    n,
    *,
    beta: float | None = 1.0,
    eps_range=None,
    z: float = 1.0,
    min_points: int = 3,
    n_grid: int = 120,
    dim: float = 2.0,
) -> UncertaintyCutoff:
    """uncertainty_cutoff(eps, f, n, *, beta=1.0, eps_range=None, z=1.0, min_points=3) -> UncertaintyCutoff(detected, eps_c, eps_c_lo, eps_c_hi, ...).

    Looks for a scale ε_c below which f(ε) departs from the power law: the
    broken power law (slope α above ε_c, ``beta`` below; ``beta=None`` fits
    it) against the single one, both by binomial maximum likelihood on the
    counts (see the module notes for the model, the AIC rule and the
    interval or upper bound of ε_c).  ``n_grid`` break positions are profiled,
    uniform in ln ε between the smallest and largest fitted ε.

    Examples
    --------
    f = 0.5 ε^0.3 down to ε_c = 10⁻⁴ and ∝ ε below it (β = 1), 10⁶ initial conditions per ε: the break is found
    at ε_c near 10⁻⁴ with α near 0.3.

    >>> rng = np.random.default_rng(0)
    >>> eps = np.logspace(-8, -2, 13)
    >>> f = rng.binomial(10**6, np.where(eps >= 1e-4, 0.5 * eps**0.3, 0.5 * 1e-4**0.3 * eps / 1e-4)) / 10**6
    >>> r = uncertainty_cutoff(eps, f, 10**6)
    >>> r.detected, round(math.log10(r.eps_c), 1), round(r.alpha, 2)
    (True, -4.0, 0.3)
    """
    eps, f, k, n, use = _uncertainty_counts(eps, f, n, eps_range)
    min_points = _positive_int(min_points, "min_points")
    n_grid = _positive_int(n_grid, "n_grid", 3)
    if beta is not None and not math.isfinite(float(beta)):
        raise ConfigError(f"beta must be a finite slope or None, got {beta!r}")
    if not z > 0:
        raise ConfigError(f"z must be > 0, got {z}")
    beta = None if beta is None else float(beta)
    single = uncertainty_exponent(eps, f, n, eps_range=eps_range, dim=dim)
    x, kk, nn = np.log(eps[use]), k[use], n[use]
    ll0 = _fit_single(x, kk, nn)[2]

    def prof2(xc):
        return 2.0 * _broken_fit(x, kk, nn, xc, beta)[2]

    # x_c = min(x) is the single law (no point below the break)
    grid = np.linspace(x.min(), x.max(), n_grid)
    prof = np.array([prof2(xc) for xc in grid])
    below = np.array([np.count_nonzero(x < xc - 1e-12) for xc in grid])
    candidate = (below >= min_points) & (x.size - below >= 2)
    xc_best, top_best = float(grid[0]), float(prof[0])
    if np.any(candidate):
        i = int(np.argmax(np.where(candidate, prof, -np.inf)))
        lo_b, hi_b = grid[max(i - 1, 0)], grid[min(i + 1, n_grid - 1)]
        opt = optimize.minimize_scalar(
            lambda v: -prof2(v), bounds=(lo_b, hi_b), method="bounded", options={"xatol": 1e-6}
        )
        xc_best, top_best = (float(opt.x), -float(opt.fun)) if -opt.fun > prof[i] else (float(grid[i]), float(prof[i]))
    n_below = int(np.count_nonzero(x < xc_best - 1e-12))
    lr = float(max(top_best - 2.0 * ll0, 0.0))
    delta_aic = lr - 2.0 * (1 if beta is not None else 2)
    detected = bool(n_below >= min_points and x.size - n_below >= 2 and delta_aic > 0)
    # profile-likelihood set {x_c : 2ℓ(x_c) ≥ 2ℓ_max − z²}, its ends interpolated between grid points
    at = int(np.searchsorted(grid, xc_best))
    gx, gp = np.insert(grid, at, xc_best), np.insert(prof, at, top_best)
    level = float(gp.max()) - z * z
    inside = np.flatnonzero(gp >= level)
    x_lo = _crossing(prof2, gx, gp, level, inside[0], -1)
    x_hi = _crossing(prof2, gx, gp, level, inside[-1], +1)
    if detected:
        eps_c, lo, hi = math.exp(xc_best), math.exp(min(x_lo, xc_best)), math.exp(max(x_hi, xc_best))
        b, cov = _broken_cov(x, kk, nn, xc_best, beta)
        alpha, a_err = float(b[1]), float(math.sqrt(cov[1, 1]))
        bt, bt_err = (float(b[2]), float(math.sqrt(cov[2, 2]))) if beta is None else (beta, 0.0)
    else:
        eps_c, lo, hi = math.nan, 0.0, math.exp(x_hi)
        alpha, a_err = single.alpha, single.alpha_err
        bt, bt_err = (beta, 0.0) if beta is not None else (math.nan, math.nan)
        n_below = 0
    return UncertaintyCutoff(
        detected,
        eps_c,
        lo,
        hi,
        alpha,
        a_err,
        bt,
        bt_err,
        beta is not None,
        lr,
        delta_aic,
        n_below,
        single,
        np.exp(grid),
        prof,
    )


def _crossing(prof2, grid, prof, level, i, side):
    """x beyond grid[i] on ``side`` (−1 left, +1 right) where prof2(x) falls to ``level`` (brentq)."""
    j = i + side
    if j < 0 or j >= grid.size:
        return float(grid[i])
    a, b = sorted((float(grid[i]), float(grid[j])))
    try:
        return float(optimize.brentq(lambda v: prof2(v) - level, a, b, xtol=1e-9))
    except ValueError:  # no sign change (kink at a data point): the grid point
        return float(grid[i])


def _broken_cov(x, k, n, xc, beta):
    """Parameters (ln c, α, β) at the break xc and their covariance with xc free too.

    The expected information of (ln c, α[, β], x_c) — ∂η/∂x_c = −α above the
    break, −β below — so that σ_α and σ_β include the uncertainty of the break.
    """
    b, _, _ = _broken_fit(x, k, n, xc, beta)
    alpha = b[1]
    bt = b[2] if beta is None else beta
    up, dn = x > xc, x < xc
    cols = [np.ones(x.size), np.where(up, x - xc, 0.0)]
    if beta is None:
        cols.append(np.where(dn, x - xc, 0.0))
    cols.append(-alpha * up - bt * dn)
    X = np.column_stack(cols)
    p = np.exp(b[0] + np.where(up, alpha * (x - xc), 0.0) + np.where(dn, bt * (x - xc), 0.0))
    info = (X * (n * p / (1.0 - p))[:, None]).T @ X
    cov = np.linalg.pinv(info)
    out = np.full((3, 3), np.nan)
    m = 3 if beta is None else 2
    out[:m, :m] = cov[:m, :m]
    return b, out


def weighted_line(x, y, err):
    """weighted_line(x, y, err) -> (intercept, slope, cov (2, 2), chi2, dof): weighted least-squares line.

    Weights 1/err²; the covariance is scaled by χ²/dof when the points scatter
    more than their errors (never narrowed).

    Examples
    --------
    >>> b0, b1, cov, chi2, dof = weighted_line([0, 1, 2], [1, 3, 5], [0.1, 0.1, 0.1])
    >>> round(b1, 6), dof
    (2.0, 1)
    """
    xs = check.numbers(x, "x", min_size=2)
    if check.numbers(y, "y").size != xs.size or check.numbers(err, "err", positive=True).size != xs.size:
        raise ConfigError(f"x, y and err must have one value per point ({np.size(x)}, {np.size(y)}, {np.size(err)})")
    if np.unique(xs).size < 2:
        raise ConfigError("x must hold at least 2 distinct values (a line through one x is not determined)")
    x, y, err = (np.asarray(v, dtype=float).ravel() for v in (x, y, err))
    w = 1.0 / err**2
    X = np.column_stack([np.ones_like(x), x])
    cov = np.linalg.inv(X.T @ (w[:, None] * X))
    b = cov @ (X.T @ (w * y))
    dof = x.size - 2
    chi2 = float(np.sum(w * (y - X @ b) ** 2))
    if dof > 0:
        cov = cov * max(1.0, chi2 / dof)
    return float(b[0]), float(b[1]), cov, chi2, dof


def local_exponent(eps, k, n) -> pd.DataFrame:
    """local_exponent(eps, k, n) -> DataFrame(eps_lo, eps_hi, eps_mid, alpha, alpha_err, d, d_err).

    The local uncertainty exponent between consecutive resolutions,
    α(ε) = ln(f_{i+1}/f_i) / ln(ε_{i+1}/ε_i) with f_i = k_i/n_i, at the
    geometric mid-point ε_mid = √(ε_i ε_{i+1}); d(ε) = 2 − α(ε) is the
    dimension of the boundary measured at resolution ε (Chen, Nishikawa and
    Motter, PRX 7, 021040 (2017): constant for a fractal, falling towards 1
    as ε → 0 for a "slim fractal").  The errors assume independent initial
    conditions at each ε (fresh samples per ε, the independent unit): the
    delta method on the two binomial counts,
    σ_α² = [(1 − f_i)/k_i + (1 − f_{i+1})/k_{i+1}] / ln²(ε_{i+1}/ε_i).
    Pairs with a zero count give NaN.

    Parameters
    ----------
    eps : array of ε (any order; sorted decreasing here), same units as the initial conditions.
    k, n : uncertain counts and sample sizes per ε.

    Examples
    --------
    >>> local_exponent([1e-2, 1e-4], [1000, 100], [10000, 10000]).alpha.round(3).tolist()
    [0.5]
    """
    check.numbers(eps, "eps", positive=True)
    check.numbers(k, "k", minimum=0.0)
    if check.numbers(n, "n", minimum=1.0).size not in (1, np.size(k)):
        raise ConfigError(f"n must be one sample size or one per ε ({np.size(n)} vs {np.size(k)})")
    eps = np.asarray(eps, dtype=float).ravel()
    k = np.asarray(k, dtype=float).ravel()
    n = np.broadcast_to(np.asarray(n, dtype=float), k.shape).astype(float)
    if eps.size != k.size or eps.size < 2:
        raise ConfigError("eps and k must have the same length ≥ 2")
    if np.any(eps <= 0) or not np.all(np.isfinite(eps)) or np.unique(eps).size != eps.size:
        raise ConfigError("eps must be distinct, finite and > 0")
    if np.any(k < 0) or np.any(k > n) or np.any(n < 1):
        raise ConfigError("need 0 ≤ k ≤ n and n ≥ 1")
    o = np.argsort(-eps)
    eps, k, n = eps[o], k[o], n[o]
    f = k / n
    with np.errstate(divide="ignore", invalid="ignore"):
        lx = np.log(eps[1:] / eps[:-1])
        alpha = np.log(f[1:] / f[:-1]) / lx
        var = ((1 - f[:-1]) / k[:-1] + (1 - f[1:]) / k[1:]) / lx**2
    bad = (k[:-1] == 0) | (k[1:] == 0)
    alpha[bad] = np.nan
    err = np.sqrt(np.where(bad, np.nan, var))
    return pd.DataFrame(
        {
            "eps_lo": eps[1:],
            "eps_hi": eps[:-1],
            "eps_mid": np.sqrt(eps[1:] * eps[:-1]),
            "alpha": alpha,
            "alpha_err": err,
            "d": 2.0 - alpha,
            "d_err": err,
        }
    )


def slim_fractal(local: pd.DataFrame, *, z: float = 3.0) -> dict:
    """slim_fractal(local_exponent table) -> dict(slope, slope_err, d_coarse, d_fine, slim, fractal_coarse).

    Chen, Nishikawa and Motter's "slim fractal" test on the local dimension
    d(ε) of :func:`local_exponent`: the weighted least-squares slope of d
    against log10 ε (per decade; > 0 when the dimension measured at
    resolution ε decreases as the resolution increases) and its error;
    ``slim`` when the slope is positive by more than ``z`` σ while the
    coarsest resolved d exceeds 1 by more than z σ (fractal-looking at coarse
    resolution, thinning at fine resolution).  NaN rows are ignored.

    Examples
    --------
    >>> t = pd.DataFrame({"eps_mid": [1e-2, 1e-4, 1e-6], "d": [1.8, 1.8, 1.8], "d_err": [0.01] * 3})
    >>> slim_fractal(t)["slim"]
    False
    """
    check.table(local, "local", ("eps_mid", "d", "d_err"), min_rows=0)
    z = check.number(z, "z", positive=True)
    t = local[np.isfinite(local["d"]) & np.isfinite(local["d_err"]) & (local["d_err"] > 0)]
    out = {
        "slope": math.nan,
        "slope_err": math.nan,
        "d_coarse": math.nan,
        "d_coarse_err": math.nan,
        "d_fine": math.nan,
        "d_fine_err": math.nan,
        "slim": False,
        "fractal_coarse": False,
        "n_points": len(t),
    }
    if len(t) < 2:
        return out
    t = t.sort_values("eps_mid", ascending=False)
    y = t["d"].to_numpy()
    _, slope, cov, _, _ = weighted_line(np.log10(t["eps_mid"].to_numpy()), y, t["d_err"].to_numpy())
    se = math.sqrt(cov[1, 1])
    out.update(
        slope=slope,
        slope_err=se,
        d_coarse=float(y[0]),
        d_coarse_err=float(t["d_err"].iloc[0]),
        d_fine=float(y[-1]),
        d_fine_err=float(t["d_err"].iloc[-1]),
    )
    out["fractal_coarse"] = bool(y[0] - 1.0 > z * out["d_coarse_err"])
    out["slim"] = bool(out["fractal_coarse"] and slope > z * se)
    return out
