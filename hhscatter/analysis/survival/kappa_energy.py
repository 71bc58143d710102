"""The piecewise escape-rate law κ0(E): κ = a x² + b x below the break energy E_b, c x above, x = E − E_c.

:func:`fit_kappa_energy` fits the piecewise law to κ(E) points with their
errors, continuous at E_b (the break estimated by profiling χ² over E_b) or
as two separate laws on either side of the best partition (as Burton, Dullin & Altmann (2023)),
with covariance and bootstrap errors. E_c comes from the system
(``scene.model.critical_energy``, :class:`hhscatter.model.System`); no default. Pure functions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize

from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.least_squares import weighted_least_squares
from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.analysis.stats.measured import Measured, WithErrors
from hhscatter.errors import ConfigError

__all__ = ["KappaEnergyFit", "fit_kappa_energy", "kappa_law_summary"]


# ---------------------------------------------------------------------------
# κ(E): piecewise law of Fig. 2b
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class KappaEnergyFit(WithErrors):
    """Result of :func:`fit_kappa_energy`; with x = E − E_c,

        κ = a x² + b x   for E < E_b   (non-linear regime),
        κ = c x          for E ≥ E_b   (linear regime).

    a (1/(time·energy²)), b, c (1/(time·energy)), E_b (energy) and their 1σ
    errors from the fit covariance (``cov``, order a, b, c, E_b; scaled by
    χ²/dof when no κ errors were given) and from the bootstrap over points
    (``boot_err``, same order; ``boot`` holds the replicates).  ``continuous``
    tells which model was fitted (then c = a x_b + b).  ``chi2``/``dof`` of the best fit.
    """

    method = "weighted least squares of κ(E)"

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
        raise ConfigError("need at least 4 distinct energies")
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
        raise ConfigError("no admissible break between the energies")
    chi2, k, p1, p2, F1, F2 = best
    xb = 0.5 * (xs[k - 1] + xs[k])
    var_xb = (xs[k] - xs[k - 1]) ** 2 / 12.0  # uniform over the gap where χ² is flat
    return float(p1[0]), float(p1[1]), float(p2[0]), float(xb), float(chi2), F1, F2, var_xb


def fit_kappa_energy(
    E,
    kappa,
    kappa_err,
    E_c: float,
    *,
    continuous: bool = True,
    n_grid: int = 400,
    n_boot: int = 200,
    rng=None,
) -> KappaEnergyFit:
    """fit_kappa_energy(E, kappa, kappa_err, E_c, *, continuous=True, n_boot=200, rng=None) -> KappaEnergyFit.

    Piecewise fit of the escape rate against energy (x = E − E_c,
    energies in energy units, κ in 1/time):

        κ = a x² + b x  (E < E_b),     κ = c x  (E ≥ E_b).

    The break E_b is estimated, not imposed:

    * ``continuous=True`` (default): κ(x) = b x + a x·min(x, x_b), i.e. the two
      laws are forced to meet at the break (c = a x_b + b).  For each x_b the model is linear in
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

    Examples
    --------
    Points on a known law (a = 13.63, b = 0.03, break at E_b = 0.27, E_c = 1/6) give it back, with
    c = a (E_b − E_c) + b = 1.438 (the continuous law).

    >>> E_c = 1 / 6
    >>> E = np.linspace(0.18, 0.40, 12)
    >>> x = E - E_c
    >>> kappa = 0.03 * x + 13.63 * x * np.minimum(x, 0.27 - E_c)
    >>> f = fit_kappa_energy(E, kappa, 0.01 * kappa, E_c, n_boot=0)
    >>> round(f.a, 3), round(f.b, 3), round(f.c, 3), round(f.E_b, 3)
    (13.63, 0.03, 1.438, 0.27)
    """
    x, y, w, given = _kappa_points(E, kappa, kappa_err, E_c)
    n = x.size
    if continuous:
        a, b, c, xb, chi2 = _fit_continuous(x, y, w, n_grid)
        cov, dof = _continuous_covariance(x, w, a, xb, chi2, given)
    else:
        a, b, c, xb, chi2, F1, F2, var_xb = _fit_discontinuous(x, y, w)
        cov, dof = _discontinuous_covariance(F1, F2, var_xb, chi2, n, given)
    boot = _bootstrap_replicates(x, y, w, continuous, n_grid, n_boot, rng)
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


# the steps of fit_kappa_energy
def _kappa_points(E, kappa, kappa_err, E_c):
    """The checked κ(E) points: (x = E − E_c (energy), κ (1/time), weights 1/σ², whether σ was given)."""
    E = check.numbers(E, "E")
    y = check.numbers(kappa, "kappa")
    if E.shape != y.shape:
        raise ConfigError("E and kappa differ in length")
    if kappa_err is not None and check.numbers(kappa_err, "kappa_err").shape != E.shape:
        raise ConfigError("kappa_err and kappa differ in length")
    E_c = check.number(E_c, "E_c")
    x = E - E_c
    if np.any(x <= 0):
        raise ConfigError("all energies must exceed E_c (no escape below)")
    given = kappa_err is not None
    sig = np.asarray(kappa_err, dtype=float).ravel() if given else np.ones_like(y)
    if np.any(~(sig > 0)):
        raise ConfigError("kappa_err must be positive")
    return x, y, 1.0 / sig**2, given


def _continuous_covariance(x, w, a, xb, chi2, given):
    """Covariance of (a, b, c, x_b) of the continuous law: Gauss–Newton (JᵀWJ)⁻¹ of (a, b, x_b), c = a x_b + b.

    Scaled by χ²/dof when no κ errors were ``given``; returns (cov (4, 4), dof).
    """
    J = np.column_stack([x * np.minimum(x, xb), x, a * x * (x > xb)])
    cov3 = np.linalg.pinv((J.T * w) @ J)
    dof = x.size - 3
    if not given:
        cov3 = cov3 * (chi2 / dof if dof > 0 else np.nan)
    T = np.array([[1.0, 0, 0], [0, 1.0, 0], [xb, 1.0, a], [0, 0, 1.0]])
    return T @ cov3 @ T.T, dof


def _discontinuous_covariance(F1, F2, var_xb, chi2, n, given):
    """Covariance of (a, b, c, x_b) of the two separate fits (x_b: uniform over the gap); returns (cov, dof).

    Scaled by χ²/dof when no κ errors were ``given``.
    """
    dof = n - 4
    s = (chi2 / dof if dof > 0 else np.nan) if not given else 1.0
    cov = np.zeros((4, 4))
    cov[:2, :2] = F1 * s
    cov[2, 2] = F2[0, 0] * s
    cov[3, 3] = var_xb
    return cov, dof


def _bootstrap_replicates(x, y, w, continuous, n_grid, n_boot, rng):
    """(n_boot, 4) pairs-bootstrap refits (a, b, c, x_b) over the points; NaN rows where a refit fails."""
    n = x.size
    gen = np.random.default_rng(rng)
    boot = np.full((int(n_boot), 4), np.nan)
    for i in range(int(n_boot)):
        idx = gen.integers(0, n, n)
        try:
            with counted("survival.kappa_energy.bootstrap"):
                if continuous:
                    r = _fit_continuous(x[idx], y[idx], w[idx], max(n_grid // 4, 50))
                    boot[i] = r[:4]
                else:
                    r = _fit_discontinuous(x[idx], y[idx], w[idx])
                    boot[i] = r[:4]
        except (ValueError, np.linalg.LinAlgError):
            continue
    return boot


def kappa_law_summary(fit) -> dict:
    """A fitted κ(E) law (:func:`fit_kappa_energy`) as numbers: a, b, c, E_b each with err = max(covariance,
    bootstrap) and both errors, and the fit's χ², dof, χ²/dof.

    Parameters
    ----------
    fit : KappaEnergyFit
        Or any object with a, b, c, E_b (a, b in 1/(time·energy²) and 1/(time·energy), c in 1/(time·energy),
        E_b in energy units), their ``*_err``, ``boot_err`` (same order, or empty), ``continuous``, ``chi2``, ``dof``.

    Returns
    -------
    dict
        {"a"|"b"|"c"|"E_b": {"value", "err", "err_cov", "err_boot"}, "continuous", "chi2", "dof", "chi2_per_dof"}.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> fit = NS(a=1.0, b=0.5, c=0.2, E_b=0.3, a_err=0.1, b_err=0.05, c_err=0.02, E_b_err=0.01,
    ...          boot_err=(0.2, 0.01, 0.01, 0.02), continuous=True, chi2=4.0, dof=2)
    >>> s = kappa_law_summary(fit)
    >>> s["a"]["err"], s["E_b"]["err"], s["chi2_per_dof"]
    (0.2, 0.02, 2.0)
    """
    needed = ("a", "b", "c", "E_b", "a_err", "b_err", "c_err", "E_b_err", "boot_err", "continuous", "chi2", "dof")
    check.having(fit, "fit", needed, "a KappaEnergyFit (fit_kappa_energy)")
    boot = fit.boot_err if fit.boot_err else (math.nan,) * 4
    out = {}
    for i, name in enumerate(("a", "b", "c", "E_b")):
        cov_err = getattr(fit, f"{name}_err")
        out[name] = {
            **Measured.of(getattr(fit, name), max(cov_err, boot[i])).to_dict(),
            "err_cov": float(cov_err),
            "err_boot": float(boot[i]),
        }
    out.update(
        continuous=fit.continuous,
        chi2=fit.chi2,
        dof=fit.dof,
        chi2_per_dof=fit.chi2 / fit.dof if fit.dof > 0 else math.nan,
    )
    return out
