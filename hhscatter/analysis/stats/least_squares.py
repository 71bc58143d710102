"""Weighted linear least squares: the one helper every linear fit of the analysis uses.

The model y ≈ X β with weights w_i = 1/σ_i² (or none: ordinary least
squares) is solved through the normal equations, F = XᵀWX,

    β = A y,   A = F⁻¹ XᵀW   (the fit as a linear operator on the data),
    χ² = Σ w r²,  r = y − Xβ,  dof = n − p.

``A`` is returned too, so a fit can be propagated under a correlated data
covariance C (Cov β = A C Aᵀ; e.g. the independent-increment covariance of
Kaplan–Meier log-survival estimates, :mod:`hhscatter.analysis.survival.fits`).

The parameter covariance has three readings (``errors``):

* ``"absolute"`` — F⁻¹: the σ_i are the data's true errors
  (``scipy.optimize.curve_fit(..., absolute_sigma=True)``);
* ``"scaled"`` — F⁻¹ χ²/dof: only the relative weights are known
  (``absolute_sigma=False``; ordinary least squares with residual errors);
* ``"inflated"`` — F⁻¹ max(1, χ²/dof): absolute errors, enlarged when the
  points scatter more than their error bars.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = ["LinearFit", "least_squares_operator", "weighted_least_squares"]

ERRORS = ("absolute", "scaled", "inflated")


@dataclass(frozen=True)
class LinearFit:
    """Result of :func:`weighted_least_squares`.

    coef       β, shape (p,)
    cov        covariance of β, shape (p, p) (reading chosen by ``errors``)
    chi2       Σ w r² (with unit weights: the residual sum of squares)
    dof        n − p
    resid      r = y − X β, shape (n,)
    operator   A = (XᵀWX)⁻¹XᵀW, shape (p, n): β = A y
    """

    coef: np.ndarray
    cov: np.ndarray
    chi2: float
    dof: int
    resid: np.ndarray
    operator: np.ndarray

    @property
    def err(self) -> np.ndarray:
        """1σ errors of β (√diag cov)."""
        return np.sqrt(np.diag(self.cov))

    @property
    def chi2_red(self) -> float:
        return self.chi2 / self.dof if self.dof > 0 else float("nan")


def _design(X, weights):
    check.numbers(X, "X")
    X = np.asarray(X, dtype=float)
    if X.ndim not in (1, 2):
        raise ConfigError(f"X must be a design matrix (n, p) or one column (n,), got {X.ndim} dimension(s)")
    if X.ndim == 1:
        X = X[:, None]
    n = X.shape[0]
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=float).ravel()
    if w.size != n or np.any(~np.isfinite(w)) or np.any(w < 0):
        raise ConfigError("weights must be finite, non-negative and one per point")
    return X, w


def least_squares_operator(X, weights=None):
    """least_squares_operator(X, weights=None) -> (A, F): β = A y for any data y, F = XᵀWX (its inverse is the
    absolute covariance of β). The fit as a linear map, for errors under a correlated data covariance.

    Examples
    --------
    >>> X = np.column_stack([np.ones(3), [0.0, 1.0, 2.0]])    # a straight line a + b x through x = 0, 1, 2
    >>> A, F = least_squares_operator(X)
    >>> F.tolist()                                  # XᵀX = [[n, Σx], [Σx, Σx²]]
    [[3.0, 3.0], [3.0, 5.0]]
    >>> (A @ [1.0, 3.0, 5.0]).round(12).tolist()    # the points of y = 1 + 2x give back a = 1, b = 2
    [1.0, 2.0]
    >>> (A @ A.T).round(4).tolist()                 # Cov β = A C Aᵀ with unit data covariance C: F⁻¹
    [[0.8333, -0.5], [-0.5, 0.5]]
    """
    X, w = _design(X, weights)
    XtW = X.T * w
    F = XtW @ X
    try:
        return np.linalg.solve(F, XtW), F
    except np.linalg.LinAlgError:
        raise ConfigError(
            f"X with these weights does not determine its {F.shape[0]} parameter(s) (XᵀWX is singular)"
        ) from None


def weighted_least_squares(X, y, weights=None, *, errors: str = "absolute") -> LinearFit:
    """weighted_least_squares(X, y, weights=None, *, errors="absolute") -> LinearFit.

    ``X`` the design matrix (n, p) (a 1-d array is one column), ``y`` the
    data (n,), ``weights`` 1/σ² (n,) or None (unit weights). ``errors``:
    "absolute", "scaled" or "inflated" (module docstring); with fewer points
    than parameters + 1 the scaled readings are NaN.

    Examples
    --------
    A weighted mean is the fit of one constant column: (1 + 2 + 2·4)/4 = 2.75, error 1/√Σw = 0.5.

    >>> f = weighted_least_squares(np.ones(3), [1.0, 2.0, 4.0], weights=[1.0, 1.0, 2.0])
    >>> f.coef.tolist(), f.err.tolist(), f.chi2, f.dof    # χ² = 1.75² + 0.75² + 2 · 1.25²
    ([2.75], [0.5], 6.75, 2)

    A line through points of y = 1 + 2x with σ = 0.1 (weights 1/σ² = 100) recovers its coefficients within errors:

    >>> rng = np.random.default_rng(0)
    >>> x = np.linspace(0.0, 1.0, 50)
    >>> y = 1 + 2 * x + rng.normal(0.0, 0.1, 50)
    >>> f = weighted_least_squares(np.column_stack([np.ones(50), x]), y, np.full(50, 100.0))
    >>> bool(np.all(np.abs(f.coef - [1.0, 2.0]) < 3 * f.err)), f.err.round(3).tolist()
    (True, [0.028, 0.048])
    """
    X, w = _design(X, weights)
    y = check.numbers(y, "y")
    n, p = X.shape
    if y.size != n:
        raise ConfigError(f"X has {n} rows but y has {y.size} values")
    if errors not in ERRORS:
        raise ConfigError(f"errors must be one of {ERRORS}, got {errors!r}")
    A, F = least_squares_operator(X, w)
    coef = A @ y
    resid = y - X @ coef
    chi2 = float(np.sum(w * resid * resid))
    dof = n - p
    cov = np.linalg.inv(F)
    if errors != "absolute":
        s = chi2 / dof if dof > 0 else float("nan")
        cov = cov * (s if errors == "scaled" else max(1.0, s))
    return LinearFit(coef, cov, chi2, dof, resid, A)
