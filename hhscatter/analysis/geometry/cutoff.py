"""The cut-off of fractal scaling under drag: the saddle's decision rate λ(E) and the predicted ε_c.

The probabilistic description's one-line consequence for the fractal
analysis of a dissipative scattering system: an orbit's energy decays as
E(t) = E0 e^{−μγt}, scattering ends at τ2 = ln(E0/E_c)/(μγ), and two initial
conditions ε apart can part only while they still follow the saddle, so the
power law of f(ε) (:mod:`hhscatter.analysis.geometry.uncertainty`) must end
at ε_c = e^{−Λ}, Λ = ∫_0^τ2 λ(E(t)) dt.

* :func:`decision_rate` — λ from the decision times of pairs of initial
  conditions with different outcomes, against ln(1/ε);
* :func:`predicted_cutoff` — ε_c from λ(E), μ, γ, E0 and E_c;
* :func:`orbit_stretch` — Λ of single orbits along their own energy histories (start and end energy, lifetime),
  in place of the ensemble's mean decay;
* :func:`stretch_tail` — the share of orbits whose own stretch exceeds ln(1/ε), per ε: without drag the
  uncertainty fraction f(ε) is a constant times it, and under drag it shows where the stretch runs out;
* :func:`cutoff_comparison` — measured against predicted ε_c, with the
  systematic of λ(E) (two estimators) in the predicted interval, and a plain
  statement of how far they differ.

Pure functions (arrays in, numbers out). Units: ε in position units of the
initial conditions; λ in 1/time; energies in the Hamiltonian's units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import _checks
from hhscatter.analysis.geometry.uncertainty import weighted_line
from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.intervals import wilson_interval
from hhscatter.analysis.stats.measured import WithErrors
from hhscatter.errors import ConfigError

__all__ = [
    "CutoffComparison",
    "DecisionRate",
    "cutoff_comparison",
    "decision_rate",
    "orbit_stretch",
    "predicted_cutoff",
    "StretchTail",
    "stretch_tail",
]


@dataclass(frozen=True)
class DecisionRate(WithErrors):
    """Result of :func:`decision_rate`: rate λ (1/time) with its error, offset t0 (time), per-ε table."""

    method = "least squares of the decision times"

    lam: float
    lam_err: float
    t0: float
    t0_err: float
    chi2: float
    dof: int
    table: pd.DataFrame = field(repr=False)


def decision_rate(eps, times) -> DecisionRate:
    """decision_rate(eps, times) -> DecisionRate(lam, lam_err, t0, ...): the rate at which pairs decide.

    Two initial conditions a distance ε apart separate as ε e^{λt} on a
    chaotic saddle with Lyapunov exponent λ; their outcomes part when the
    separation reaches O(1), at t ≈ t0 + ln(1/ε)/λ.  Given, for each ε, the
    decision times of the pairs whose outcomes differ (``times``: a list of
    arrays, e.g. the time until the first orbit of the pair leaves), this fits
    mean t(ε) = t0 + ln(1/ε)/λ by weighted least squares with the standard
    error of each mean (pairs independent, fresh per ε), and returns λ = 1 /
    slope with the delta-method error.  ε with fewer than 3 times are left
    out; at least 2 ε must remain.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> eps = [1e-2, 1e-4, 1e-6]
    >>> ts = [5 + np.log(1 / e) / 0.5 + rng.normal(0, 1, 400) for e in eps]
    >>> round(decision_rate(eps, ts).lam, 2)
    0.5
    """
    eps = check.numbers(eps, "eps", positive=True)
    if isinstance(times, (str, bytes, dict)) or not hasattr(times, "__len__"):
        raise ConfigError(f"times must be a list of arrays of decision times, one per ε, got {type(times).__name__}")
    if len(times) != eps.size:
        raise ConfigError("times must hold one array per ε")
    for t in times:
        _checks.values(t, "times", min_size=0)
    rows = []
    for e, t in zip(eps, times):
        t = np.asarray(t, dtype=float)
        t = t[np.isfinite(t)]
        if t.size >= 3 and e > 0:
            rows.append(
                {
                    "eps": e,
                    "x": math.log(1.0 / e),
                    "t_mean": float(t.mean()),
                    "t_sem": float(t.std(ddof=1) / math.sqrt(t.size)),
                    "m": int(t.size),
                }
            )
    tab = pd.DataFrame(rows, columns=["eps", "x", "t_mean", "t_sem", "m"])
    if len(tab) < 2 or tab["x"].nunique() < 2:
        raise ConfigError("decision_rate: need ≥ 2 values of ε with ≥ 3 decision times each")
    t0, slope, cov, chi2, dof = weighted_line(tab["x"], tab["t_mean"], np.maximum(tab["t_sem"], 1e-12))
    s_err = float(math.sqrt(cov[1, 1]))
    if not slope > 0:
        raise ConfigError(f"decision_rate: decision times do not grow with ln(1/ε) (slope {slope:.3g})")
    return DecisionRate(
        lam=1.0 / slope,
        lam_err=s_err / slope**2,
        t0=t0,
        t0_err=float(math.sqrt(cov[0, 0])),
        chi2=chi2,
        dof=dof,
        table=tab,
    )


def _rate_nodes(energies, lam, who: str) -> tuple[np.ndarray, np.ndarray]:
    """The finite (E, λ(E)) nodes in increasing E, the interpolation nodes of λ(E); refused when there are none."""
    En, lv = np.asarray(energies, dtype=float).ravel(), np.asarray(lam, dtype=float).ravel()
    ok = np.isfinite(En) & np.isfinite(lv)
    if not np.any(ok):
        raise ConfigError(f"{who}: no finite λ(E) given (no energy where both energies and lam are finite)")
    o = np.argsort(En[ok])
    return En[ok][o], lv[ok][o]


def predicted_cutoff(E0: float, gamma: float, mu: float, energies, lam, e_c: float) -> float:
    """predicted_cutoff(E0, γ, μ, energies, λ(energies), E_c) -> ε_c predicted by the probabilistic description.

    The probabilistic description (Eqs. (eqn:energy_exp_decay), (eq:tau2)): the
    energy of a surviving orbit decays as E(t) = E0 e^{−μγt} and scattering
    ends at τ2 = ln(E0/E_c)/(μγ), when E(t) = E_c; meanwhile the orbit follows
    the conservative saddle of energy E(t), where nearby orbits separate at
    the rate λ(E).  Two initial conditions ε apart can reach different exits
    only if they separate to O(1) before τ2, i.e. if
    ln(1/ε) < Λ = ∫_0^{τ2} λ(E(t)) dt = (1/(μγ)) ∫_{E_c}^{E0} λ(E)/E dE.
    Below ε_c = e^{−Λ} the outcome is decided by the settling alone and the
    power law of f(ε) must end.  λ(E) is interpolated linearly in E between
    the given ``energies`` (held constant beyond them); the integral uses
    the trapezoidal rule on a fine grid.  γ = 0 gives ε_c = 0 (no cut-off).

    Examples
    --------
    >>> round(math.log(1 / predicted_cutoff(0.3, 0.01, 1.0, [0.2, 0.3], [0.5, 0.5], 0.15)), 3)
    34.657
    """
    E0, gamma = check.number(E0, "E0"), check.number(gamma, "gamma", minimum=0.0)
    mu, e_c = check.number(mu, "mu", positive=True), check.number(e_c, "e_c", positive=True)
    n = _checks.values(energies, "energies").size
    _checks.values(lam, "lam", size=n)
    if not (E0 > e_c > 0 and gamma >= 0 and mu > 0):
        raise ConfigError(f"need E0 > E_c > 0, γ ≥ 0, μ > 0 (got E0={E0}, E_c={e_c}, γ={gamma}, μ={mu})")
    if gamma == 0:
        return 0.0
    En, lam = _rate_nodes(energies, lam, "predicted_cutoff")
    grid = np.linspace(e_c, E0, 2001)
    val = np.interp(grid, En, lam) / grid
    big_lambda = float(np.sum(0.5 * (val[1:] + val[:-1]) * np.diff(grid))) / (mu * gamma)
    return float(math.exp(-big_lambda))


def orbit_stretch(e0, e_end, t_end, energies, lam) -> np.ndarray:
    """orbit_stretch(e0, e_end, t_end, energies, λ(energies)) -> Λ of each orbit (dimensionless).

    The stretching an orbit accumulates on the conservative saddle along its own energy history, in place of the
    ensemble's mean decay that :func:`predicted_cutoff` uses: an orbit that starts at ``e0``, ends at ``e_end``
    after ``t_end`` (energies in the Hamiltonian's units, time units) and decays exponentially in between, E(t) =
    e0 (e_end/e0)^{t/t_end}, gathers Λ = ∫_0^{t_end} λ(E(t)) dt = t_end · ⟨λ⟩, the mean of λ over ln E between its
    end energies (λ(e0) when they coincide). Two initial conditions ε apart that follow it can part only if ε >
    e^{−Λ}: the distribution of e^{−Λ} over the orbits that decide an outcome is the spread of the cut-off that
    the mean history's ε_c stands for. λ(E) is interpolated linearly between ``energies`` (held constant beyond
    them), as in :func:`predicted_cutoff`; the mean uses the trapezoidal rule on 513 points in ln E. An orbit that
    ends at E_c after exactly τ2 of the mean decay has Λ = −ln ε_c of :func:`predicted_cutoff`.

    Examples
    --------
    >>> lam = orbit_stretch([0.3, 0.3], [0.3, 0.15], [10.0, 20.0], [0.1, 0.4], [0.5, 0.5])   # λ constant: λ·t_end
    >>> [round(float(v), 10) for v in lam]
    [5.0, 10.0]
    >>> mu, g = 1.0, 0.01                       # the mean history: ends at E_c = 0.15 after τ2 = ln 2/(μγ)
    >>> L = orbit_stretch([0.3], [0.15], [math.log(2) / (mu * g)], [0.2, 0.3], [0.4, 0.6])[0]
    >>> round(float(L), 4), round(-math.log(predicted_cutoff(0.3, g, mu, [0.2, 0.3], [0.4, 0.6], 0.15)), 4)
    (31.5073, 31.5073)
    """
    e0 = check.floats(e0, "e0", of="orbit")
    e_end = check.floats(e_end, "e_end", size=e0.size, of="orbit")
    t_end = check.floats(t_end, "t_end", size=e0.size, of="orbit")
    n = _checks.values(energies, "energies").size
    lam = _checks.values(lam, "lam", size=n)
    En, lv = _rate_nodes(energies, lam, "orbit_stretch")
    for name, v, low in (("e0", e0, 0.0), ("e_end", e_end, 0.0), ("t_end", t_end, None)):
        bad = ~np.isfinite(v) | ((v <= low) if low is not None else (v < 0))
        if np.any(bad):
            need = "finite and > 0 (an energy above the potential's floor)" if low is not None else "finite and ≥ 0"
            raise ConfigError(
                f"{name} must be {need} for every orbit, got {v[bad][0]!r} at orbit {np.flatnonzero(bad)[0]}"
            )
    u = np.linspace(0.0, 1.0, 513)
    out = np.empty(e0.size)
    for s in range(0, e0.size, 4096):  # (orbits × 513) at a time
        a, b = np.log(e0[s : s + 4096, None]), np.log(e_end[s : s + 4096, None])
        vals = np.interp(np.exp(a + u * (b - a)), En, lv)  # in ln E: no overflow of e_end/e0 for far-apart ends
        out[s : s + 4096] = t_end[s : s + 4096] * np.trapezoid(vals, u, axis=1)
    return out


@dataclass(frozen=True)
class StretchTail:
    """Result of :func:`stretch_tail`, one entry per ε (arrays): ``share`` S(ln 1/ε) of the orbits with Λ > ln(1/ε),
    its Wilson 1σ bounds ``lo``, ``hi``, the count ``k`` and the number of orbits ``n``."""

    method = "share of orbits whose stretch exceeds ln(1/ε), Wilson 1σ interval"

    eps: np.ndarray
    share: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    k: np.ndarray
    n: int


def stretch_tail(stretch, eps) -> StretchTail:
    """stretch_tail(Λ of each orbit, ε) -> StretchTail(eps, share, lo, hi, k, n): S(ln 1/ε) = share of Λ > ln(1/ε).

    ``stretch``: each orbit's Λ (dimensionless, e.g. :func:`orbit_stretch`); ``eps``: one or more scales ε > 0 in
    the position units of the initial conditions. A pair of initial conditions ε apart that follows an orbit can
    reach different outcomes only if the orbit stretches it to O(1), that is if Λ > ln(1/ε): where that is the
    only way to part, the uncertainty fraction f(ε) is a constant times S(ln 1/ε) (for a hyperbolic saddle without
    drag, Λ = λ t and S = e^{−κ ln(1/ε)/λ} = ε^{κ/λ}, the uncertainty exponent α = κ/λ). The ratio f/S shows
    where that holds and where pairs part otherwise. NaN stretches are refused; the share has Wilson 1σ bounds
    over the orbits.

    Examples
    --------
    >>> L = np.log(1 / np.random.default_rng(0).uniform(size=100_000)) / 0.25    # S(x) = e^{−x/4}: S(ln 1/ε) = ε^{1/4}
    >>> r = stretch_tail(L, [1e-2, 1e-4])
    >>> r.k.tolist(), r.n, bool(np.all(np.abs(r.share - np.array([1e-2, 1e-4]) ** 0.25) < 3 * (r.hi - r.lo)))
    ([31474, 10176], 100000, True)
    """
    lam = check.floats(stretch, "stretch", of="orbit")
    if lam.size == 0:
        raise ConfigError("stretch_tail: stretch needs at least one orbit")
    if not np.all(np.isfinite(lam)):
        bad = np.flatnonzero(~np.isfinite(lam))[0]
        raise ConfigError(f"stretch must be finite for every orbit, got {float(lam[bad])!r} at orbit {bad}")
    e = check.numbers(eps, "eps", positive=True)
    srt = np.sort(lam)
    with np.errstate(over="ignore"):
        x = np.log(1.0 / e)
    x = np.where(np.isinf(x), -np.log(e), x)  # 1/ε overflows below ε ≈ 5.6e-309: ln(1/ε) = −ln ε there
    k = srt.size - np.searchsorted(srt, x, side="right")  # Λ > x
    share, lo, hi = wilson_interval(k, np.full(k.shape, srt.size))
    return StretchTail(e, np.asarray(share, dtype=float), np.asarray(lo, dtype=float), np.asarray(hi, dtype=float),
                       k.astype(np.int64), int(srt.size))  # fmt: skip


@dataclass(frozen=True)
class CutoffComparison:
    """Result of :func:`cutoff_comparison` (ε in position units; logs base 10).

    predicted: ε_c from the decision rate λ(E) at μ; predicted_lo, predicted_hi: the envelope of the
    predictions over λ ± 1σ, μ ± 1σ and the second estimator of λ (the systematic of λ(E));
    predicted_alt: ε_c from the second estimator alone (NaN if not given); measured, measured_lo,
    measured_hi: the measured ε_c and its interval (NaN when not detected; then measured_hi is the upper
    bound); log10_ratio = log10(measured/predicted); factor = 10^|log10_ratio|; gap_decades: the distance
    in decades between the two intervals (0 when they overlap); z: log10_ratio over the half-widths of
    both intervals on the facing sides, combined in quadrature; overlap (bool); statement (plain words).
    """

    predicted: float
    predicted_lo: float
    predicted_hi: float
    predicted_alt: float
    measured: float
    measured_lo: float
    measured_hi: float
    log10_ratio: float
    factor: float
    gap_decades: float
    z: float
    overlap: bool
    statement: str = field(repr=False)


def cutoff_comparison(
    E0,
    gamma,
    e_c,
    mu,
    mu_err,
    energies,
    lam,
    lam_err,
    *,
    lam_alt=None,
    measured=None,
    measured_lo=None,
    measured_hi=None,
) -> CutoffComparison:
    """Measured against predicted cut-off ε_c, with the systematic of λ(E) in the predicted interval.

    The prediction (:func:`predicted_cutoff`) uses the decision rate ``lam`` (± ``lam_err``, shifted
    together at every energy: the errors of neighbouring energies share the method) and μ ± ``mu_err``;
    ``lam_alt`` is a second estimator of the same λ(E) (e.g. Kantz–Grassberger's κ/α), whose prediction
    is folded into the interval as the systematic: the predicted interval is the envelope of every
    combination (λ ± σ, μ ± σ, and the alternative λ at μ ± σ).  ``measured`` is the detected ε_c with its
    interval [``measured_lo``, ``measured_hi``] (None or NaN: not detected, ``measured_hi`` then the upper
    bound).  Returns the ratio, the factor, the gap between the intervals in decades and a one-line
    statement of how far they are apart.

    Examples
    --------
    >>> c = cutoff_comparison(0.3, 0.02, 1 / 6, 0.94, 0.01, [0.2, 0.3], [0.5, 0.5], [0.01, 0.01],
    ...                       measured=2e-5, measured_lo=1.9e-5, measured_hi=2.1e-5)
    >>> c.overlap, round(c.log10_ratio, 2)
    (False, 2.09)
    """
    E0, gamma = check.number(E0, "E0"), check.number(gamma, "gamma")
    e_c, mu = check.number(e_c, "e_c", positive=True), check.number(mu, "mu", positive=True)
    if isinstance(mu_err, bool) or not isinstance(mu_err, (int, float, np.integer, np.floating)):
        raise ConfigError(f"mu_err must be a number (NaN: not known), got {mu_err!r}")
    n = _checks.values(energies, "energies").size
    _checks.values(lam, "lam", size=n)
    _checks.values(lam_err, "lam_err", size=n)
    if lam_alt is not None:
        _checks.values(lam_alt, "lam_alt", size=n)
    for name, v in (("measured", measured), ("measured_lo", measured_lo), ("measured_hi", measured_hi)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating))):
            raise ConfigError(f"{name} must be a number or None, got {v!r}")
    mu_err = float(mu_err)
    if not gamma > 0:
        raise ConfigError(f"cutoff_comparison: γ must be > 0 (no cut-off at γ = {gamma})")
    En = np.asarray(energies, dtype=float)
    lam, lam_err = np.asarray(lam, dtype=float), np.asarray(lam_err, dtype=float)
    mus = [m for m in (mu - mu_err, mu, mu + mu_err) if m > 0] if math.isfinite(mu_err) else [mu]
    pred = predicted_cutoff(E0, gamma, mu, En, lam, e_c)
    cands = [
        predicted_cutoff(E0, gamma, m, En, np.maximum(lam + s * lam_err, 0.0), e_c)
        for m in mus
        for s in (-1.0, 0.0, 1.0)
    ]
    alt = math.nan
    if lam_alt is not None and np.any(np.isfinite(lam_alt)):
        alt = predicted_cutoff(E0, gamma, mu, En, np.asarray(lam_alt, dtype=float), e_c)
        cands += [predicted_cutoff(E0, gamma, m, En, np.asarray(lam_alt, dtype=float), e_c) for m in mus]
    p_lo, p_hi = min(cands), max(cands)
    det = measured is not None and math.isfinite(float(measured))
    m = float(measured) if det else math.nan
    m_lo = float(measured_lo) if det and measured_lo is not None else (0.0 if not det else m)
    m_hi = float(measured_hi) if measured_hi is not None else m
    lg = lambda v: math.log10(v) if v > 0 else -math.inf
    if det and pred > 0:
        r = math.log10(m / pred)
        gap = max(0.0, lg(m_lo) - lg(p_hi), lg(p_lo) - lg(m_hi))
        sm = (lg(m) - lg(m_lo)) if r > 0 else (lg(m_hi) - lg(m))
        sp = (lg(p_hi) - lg(pred)) if r > 0 else (lg(pred) - lg(p_lo))
        z = r / math.hypot(sm, sp) if math.hypot(sm, sp) > 0 else math.inf
        side = "below" if r < 0 else "above"
        words = f"measured ε_c lies a factor {10 ** abs(r):.2g} {side} the prediction; " + (
            "the intervals overlap"
            if gap == 0
            else f"the intervals are {gap:.2g} decades apart (z = {z:+.1f} with both widths)"
        )
    else:
        r, z = math.nan, math.nan
        gap = max(0.0, lg(p_lo) - lg(m_hi))
        words = f"no cut-off resolved (ε_c < {m_hi:.2g}); predicted {pred:.2g}: " + (
            "consistent, below the smallest ε resolved"
            if pred < m_hi
            else "above that bound, its interval reaching below it"
            if gap == 0
            else f"the predicted interval lies {gap:.2g} decades above that bound"
        )
    return CutoffComparison(
        pred,
        p_lo,
        p_hi,
        alt,
        m,
        m_lo if det else math.nan,
        m_hi,
        r,
        10 ** abs(r) if math.isfinite(r) else math.nan,
        gap,
        z,
        bool(gap == 0),
        words,
    )
