"""The finite-barrier correction of the Kramers–Langer rate: the measured ratio k/k_KL against T/ΔE, and the first
correction term of the transition-state part of the rate.

Kramers–Langer (:func:`~hhscatter.analysis.noise.kramers.kramers_langer`) is the leading term of an expansion in
T/ΔE. Its first correction is linear:

    k / k_KL = 1 + c · T/ΔE + O((T/ΔE)²).

:func:`finite_barrier_fit` measures c: the weighted straight-line fit of the measured ratio against x = T/ΔE
(weights 1/σ², σ the ratios' errors), with its intercept free (it should be 1) and with the intercept fixed at 1.

:func:`transition_state_correction` derives the part of c that comes from the equilibrium populations, the
transition-state (TST) term. The rate is k = κ k_TST, with κ the transmission factor (λ₊/ω_b for a parabolic
barrier) and k_TST = √(T/2π) Z_s / Z_well the flux through the dividing line at each saddle s, the line through s
along the Hessian's stable eigenvector. Laplace's expansion of both configuration integrals (e.g. Bender &
Orszag, *Advanced Mathematical Methods for Scientists and Engineers*, § 6.4) gives Z = Z_harmonic (1 + A T + O(T²)),
with, for the well's minimum (two dimensions, g = H⁻¹, V_ijk and V_ijkl the third and fourth derivatives),

    A_well = −(1/8) V_ijkl g^ij g^kl + (1/8) V_ijk V_lmn g^ij g^kl g^mn + (1/12) V_ijk V_lmn g^il g^jm g^kn,

and, for the dividing line (one dimension, f(s) = V(s + s·e), f₂ = ω_s²),

    A_s = −f₄/(8 f₂²) + 5 f₃²/(24 f₂³),

so that k_TST = k_TST,harmonic (1 + (A_s − A_well) T) and c_TST = ΔE (A_s − A_well). For Hénon–Heiles the line
through the saddle (0, 1) is y = 1, where V = 3x²/2 + 1/6 exactly (A_s = 0), and A_well = (1/12)(3·2² + 2²) = 4/3:
c_TST = −(1/6)(4/3) = −2/9. A softer well holds more population than its harmonic estimate, so the rate falls below
Kramers–Langer at finite T/ΔE.

The correction of the transmission factor κ itself, from the barrier's anharmonicity along its unstable direction
and its coupling to the stable one, is the rest of the first term (Pollak & Talkner, Phys. Rev. E 47, 922 (1993),
in the spatial-diffusion regime); it is not derived here, so c_TST is the sign and size of the equilibrium part,
not the whole first term.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.noise.kramers import _landscape, hessian, kramers_langer
from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.least_squares import weighted_least_squares
from hhscatter.analysis.stats.measured import WithErrors
from hhscatter.errors import ConfigError

__all__ = [
    "FiniteBarrierFit",
    "TransitionStateCorrection",
    "finite_barrier_fit",
    "laplace_coefficient",
    "transition_state_correction",
]


@dataclass(frozen=True)
class FiniteBarrierFit(WithErrors):
    """The ratio k/k_KL against x = T/ΔE (dimensionless): ``intercept`` + ``slope`` · x fitted with weights 1/σ²
    (``chi2`` for ``dof`` degrees of freedom, ``p_value`` of χ²), and ``slope_unit`` the slope with the intercept
    fixed at 1 (``chi2_unit`` for ``dof_unit``); every estimate with its 1σ ``…_err`` from the ratios' errors."""

    method = "weighted least squares of k/k_KL against T/ΔE"
    n_field = "n"

    intercept: float
    intercept_err: float
    slope: float
    slope_err: float
    chi2: float
    dof: int
    p_value: float
    slope_unit: float
    slope_unit_err: float
    chi2_unit: float
    dof_unit: int
    n: int
    x_range: tuple


def finite_barrier_fit(barrier_over_T, ratio, ratio_err) -> FiniteBarrierFit:
    """finite_barrier_fit(ΔE/T, k/k_KL, 1σ) -> FiniteBarrierFit: the first correction's coefficient c of
    k/k_KL = 1 + c T/ΔE measured (module docstring), with the intercept free and fixed at 1.

    ``barrier_over_T``: ΔE/T of each measurement (dimensionless, > 0); ``ratio`` and ``ratio_err``: the measured
    rate over Kramers–Langer and its 1σ error (> 0). At least 3 points (one degree of freedom with both free).

    Examples
    --------
    Ratios exactly on 1 − 0.25 T/ΔE at ΔE/T = 2, 4, 8 with equal errors 0.01: the line is recovered, χ² = 0, and
    the slope's error is 0.01/√Σ(x − x̄)² with x = 1/2, 1/4, 1/8:

    >>> f = finite_barrier_fit([2, 4, 8], [0.875, 0.9375, 0.96875], [0.01, 0.01, 0.01])
    >>> round(f.intercept, 12), round(f.slope, 12), round(f.chi2, 12), round(f.slope_unit, 12)
    (1.0, -0.25, 0.0, -0.25)
    >>> x = np.array([0.5, 0.25, 0.125])
    >>> round(f.slope_err / (0.01 / math.sqrt(((x - x.mean()) ** 2).sum())), 12)
    1.0
    """
    from scipy.stats import chi2 as chi2_dist  # deferred: scipy.stats loads on first use

    b = check.numbers(barrier_over_T, "barrier_over_T", min_size=3, positive=True)
    y = check.numbers(ratio, "ratio")
    e = check.numbers(ratio_err, "ratio_err", positive=True)
    if not (b.size == y.size == e.size):
        raise ConfigError(
            f"barrier_over_T, ratio and ratio_err must have one value each, got {b.size}, {y.size}, {e.size}"
        )
    x = 1.0 / b
    w = 1.0 / e**2
    free = weighted_least_squares(np.column_stack([np.ones_like(x), x]), y, w)
    unit = weighted_least_squares(x[:, None], y - 1.0, w)
    return FiniteBarrierFit(
        intercept=float(free.coef[0]),
        intercept_err=float(free.err[0]),
        slope=float(free.coef[1]),
        slope_err=float(free.err[1]),
        chi2=float(free.chi2),
        dof=int(free.dof),
        p_value=float(chi2_dist.sf(free.chi2, free.dof)),
        slope_unit=float(unit.coef[0]),
        slope_unit_err=float(unit.err[0]),
        chi2_unit=float(unit.chi2),
        dof_unit=int(unit.dof),
        n=int(b.size),
        x_range=(float(x.min()), float(x.max())),
    )


_DERIVATIVES: dict = {}


def _tensors(model, x: float, y: float):
    """(V_ijk, V_ijkl) at (x, y): the exact third and fourth derivative tensors of the system's potential (the
    derivatives built once per potential)."""
    import sympy as sp  # deferred: sympy loads on first use

    land = _landscape(model)
    if id(land) not in _DERIVATIVES:
        q = (land.x, land.y)
        funcs = {}
        for order in (3, 4):
            for idx in itertools.combinations_with_replacement(range(2), order):
                funcs[idx] = sp.lambdify(q, sp.diff(land.expr, *(q[i] for i in idx)), "math")
        _DERIVATIVES[id(land)] = (land, funcs)
    funcs = _DERIVATIVES[id(land)][1]
    d3 = np.zeros((2, 2, 2))
    d4 = np.zeros((2, 2, 2, 2))
    for d in (d3, d4):
        for idx in itertools.product(range(2), repeat=d.ndim):
            d[idx] = float(funcs[tuple(sorted(idx))](x, y))
    return d3, d4


def laplace_coefficient(model, x: float = 0.0, y: float = 0.0, direction=None) -> float:
    """laplace_coefficient(model, x=0, y=0, direction=None) -> A (1/energy): the first correction of Laplace's
    expansion ∫ e^{−V/T} = (harmonic value)(1 + A T + O(T²)) about a nondegenerate minimum (x, y) of the system's
    potential (module docstring), over the plane, or, with a unit ``direction`` e, over the line (x, y) + s e
    (the dividing line through a saddle along its stable direction).

    Examples
    --------
    Hénon–Heiles: A = 4/3 at the well's minimum; along y = 1 through the saddle (0, 1) V is exactly quadratic:

    >>> from hhscatter.model import HenonHeiles
    >>> round(laplace_coefficient(HenonHeiles()), 12), round(laplace_coefficient(HenonHeiles(), 0, 1, (1, 0)), 12)
    (1.333333333333, 0.0)
    """
    check.system(model)
    x, y = check.number(x, "x"), check.number(y, "y")
    if direction is not None:
        e = check.numbers(direction, "direction")
        if e.shape != (2,) or not math.isclose(float(e @ e), 1.0, rel_tol=1e-9):
            raise ConfigError(f"direction must be a unit vector (2 components), got {direction!r}")
    d3, d4 = _tensors(model, x, y)
    h = hessian(model, x, y)
    if direction is not None:
        f2 = float(e @ h @ e)
        if not f2 > 0:
            raise ConfigError(f"direction: V is not convex along {tuple(e)} at ({x:g}, {y:g}): f'' = {f2:g}")
        f3 = float(np.einsum("ijk,i,j,k->", d3, e, e, e))
        f4 = float(np.einsum("ijkl,i,j,k,l->", d4, e, e, e, e))
        return -f4 / (8 * f2 * f2) + 5 * f3 * f3 / (24 * f2**3)
    if not np.all(np.linalg.eigvalsh(h) > 0):
        raise ConfigError(
            f"(x, y) = ({x:g}, {y:g}) is not a minimum of V (Hessian eigenvalues {np.linalg.eigvalsh(h)})"
        )
    g = np.linalg.inv(h)
    a4 = np.einsum("ijkl,ij,kl->", d4, g, g)
    a33 = np.einsum("ijk,lmn,ij,kl,mn->", d3, d3, g, g, g)
    a3x = np.einsum("ijk,lmn,il,jm,kn->", d3, d3, g, g, g)
    return float(-a4 / 8 + a33 / 8 + a3x / 12)


@dataclass(frozen=True)
class TransitionStateCorrection:
    """The first finite-barrier correction of the transition-state rate (module docstring): ``well`` = A_well and
    ``saddles`` = A_s per exit (1/energy), ``barrier`` ΔE of the lowest saddle (energy), ``lowest`` the exits at
    that barrier, and ``slope`` = c_TST = ΔE (Ā_s − A_well) (dimensionless, per unit T/ΔE; Ā_s the mean over the
    lowest saddles weighted by their Kramers–Langer prefactors)."""

    well: float
    saddles: tuple
    barrier: float
    lowest: tuple
    slope: float


def transition_state_correction(model) -> TransitionStateCorrection:
    """transition_state_correction(model) -> TransitionStateCorrection: c_TST of k_TST = k_TST,harmonic (1 + c_TST T/ΔE
    + …) from the system's saddles and well (module docstring). Saddles above the lowest barrier add terms smaller
    by e^{−(ΔE_s − ΔE)/T}, beyond every power of T/ΔE: the slope is the lowest saddles'.

    Examples
    --------
    >>> from hhscatter.model import HenonHeiles
    >>> c = transition_state_correction(HenonHeiles())
    >>> round(c.slope, 12), round(-2 / 9, 12), c.lowest
    (-0.222222222222, -0.222222222222, (0, 1, 2))
    """
    check.system(model)
    a_well = laplace_coefficient(model)
    kl = kramers_langer(model, 1.0, 1.0)
    a_s = []
    for e in model.exits:
        _, v = np.linalg.eigh(hessian(model, e.x, e.y))
        a_s.append(laplace_coefficient(model, e.x, e.y, v[:, 1]))
    low = min(t.barrier for t in kl.terms)
    lowest = tuple(i for i, t in enumerate(kl.terms) if t.barrier - low <= 1e-9 * max(abs(low), 1.0))
    pref = np.array([kl.terms[i].prefactor for i in lowest])
    mean_s = float(np.dot(pref, [a_s[i] for i in lowest]) / pref.sum())
    return TransitionStateCorrection(a_well, tuple(a_s), low, lowest, low * (mean_s - a_well))
