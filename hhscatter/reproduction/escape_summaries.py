"""Escape-rate results as numbers and plot tables: what a study writes of P(t), κ and the sticky tail (paper
Fig. 2a), of the κ(E) law (Fig. 2b), and of κ from the c-measure (Eq. (eqn:kappa_cmeasure_truetime)) per start
of its sampling window.

A value with an uncertainty is written ``{"value": v, "err": e}`` (:meth:`~hhscatter.analysis.stats.measured.Measured.to_dict`), the convention of every numbers
JSON. Units: time in model units, rates in 1/time, energies in model units.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.analysis.stats.measured import Measured

__all__ = [
    "cmeasure_windows",
    "kappa_cmeasure_entry",
    "kappa_cmeasure_shifts",
    "kappa_cmeasure_z",
    "kappa_law_curves",
    "plot_grid",
    "rate_row",
    "rate_summary",
    "recording_time",
    "sticky_tail_summary",
    "survival_tables",
    "tau_star_estimate",
]


def plot_grid(t_last: float, n_lin: int = 4001, n_log: int = 600) -> np.ndarray:
    """Times (time units) at which a P(t) is tabulated for a figure: linear and logarithmic, up to ``t_last``.

    Examples
    --------
    >>> g = plot_grid(100.0, n_lin=11, n_log=3)
    >>> float(g[0]), float(g[-1]), bool((np.diff(g) > 0).all())
    (0.0, 100.0, True)
    """
    return np.unique(np.concatenate([np.linspace(0.0, t_last, n_lin), np.geomspace(0.1, t_last, n_log)]))


def survival_tables(energy: float, t_end, observed, rate) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The curves of Fig. 2a at one energy: Kaplan–Meier P(t) of all orbits and of the escaping ones on
    :func:`plot_grid`, and the first window's fitted exponential f0 e^{−κt} up to 1.25 t_stop.

    Parameters
    ----------
    energy : float
        E0 of the run (a column of both tables).
    t_end, observed : array
        Lifetimes (time units) and whether each ended by an event (False: censored at t_max).
    rate : EscapeRateResult
        :func:`~hhscatter.analysis.survival.escape_rate.escape_rate` of these lifetimes.

    Returns
    -------
    (curve, line) : DataFrame, DataFrame
        ``curve``: energy, t, P, P_err, P_esc, P_esc_err; ``line``: energy, kind = "exponential", t, P.

    Examples
    --------
    >>> from hhscatter.analysis.survival.escape_rate import escape_rate
    >>> t = np.random.default_rng(1).exponential(5.0, 20000)
    >>> obs = np.ones(t.size, bool)
    >>> curve, line = survival_tables(0.3, t, obs, escape_rate(t, obs, detect_tail=False))
    >>> float(curve.P.iloc[0]), line.kind.iloc[0]
    (1.0, 'exponential')
    """
    from hhscatter.analysis.survival.fits import survival_curve  # deferred: scipy loads on first use

    t_end, observed = np.asarray(t_end, dtype=float), np.asarray(observed, dtype=bool)
    g = plot_grid(float(np.max(t_end)))
    km = survival_curve(t_end, observed, g)
    esc = survival_curve(t_end[observed], np.ones(int(observed.sum()), bool), g)
    curve = pd.DataFrame(
        {"energy": energy, "t": g, "P": km.P, "P_err": km.P_err, "P_esc": esc.P, "P_esc_err": esc.P_err}
    )
    te = np.linspace(0.0, rate.t_stop * 1.25, 300)
    return curve, pd.DataFrame({"energy": energy, "kind": "exponential", "t": te, "P": rate.fits[0].predict(te)})


def rate_summary(n: int, t_max: float, rate, n_trapped: int) -> dict:
    """The numbers of one P(t): κ (the window fits and the MLE cross-check), τ0, the windows, the trapped share.

    ``n`` orbits run to ``t_max`` (time units), ``n_trapped`` of them still inside then; ``rate`` the
    :func:`~hhscatter.analysis.survival.escape_rate.escape_rate` result.
    """
    return {
        "n": int(n),
        "t_max": t_max,
        "n_trapped": n_trapped,
        "trapped_fraction": n_trapped / n,
        "kappa": rate.measured("kappa").to_dict(),
        "kappa_windows": [fi.kappa for fi in rate.fits],
        "kappa_mle": rate.mle.measured("kappa").to_dict(),
        "tau0": rate.tau0,
        "t_stop": rate.t_stop,
        "windows": [list(w) for w in rate.windows],
        "f0": rate.fits[0].f0,
        "t_floor": rate.window_choice.t_floor,
    }


def sticky_tail_summary(energy: float, t_end, observed, t_max: float, tail) -> tuple[pd.DataFrame, dict]:
    """The sticky tail of a P(t) (paper Fig. 2a): its power-law line, its numbers (z, τ*, f*) and the bounds of z
    beyond its window up to t_max.

    Beyond the tail window the orbits still inside at ``t_max`` are either on KAM tori (they never leave: removed,
    z comes out too high if some are merely sticky) or sticky (censored: kept at risk, z too low); both MLEs bound z.
    ``tail`` is :func:`~hhscatter.analysis.survival.escape_rate.escaping_tail`'s result with a detected tail.
    """
    from hhscatter.analysis.survival.escape_rate import power_law_exponent_mle  # deferred: scipy loads on first use

    tl = tail.tail
    tp = np.geomspace(tl.window[0] * 0.6, tl.window[1] * 1.5, 200)
    line = pd.DataFrame({"energy": energy, "kind": "power_law", "t": tp, "P": tl.predict(tp)})
    crossing = math.isfinite(tail.tau_star)
    entry = dict(
        tail_detected=True,
        z=Measured.of(tl.z, tl.z_err).to_dict(),
        z_mle=Measured.of(tl.z_mle, tl.z_mle_err).to_dict(),
        tail_window=list(tl.window),
        f_star=tl.f_star,
        tau_c=tl.window[0],
        tau_star=tail.tau_star if crossing else None,
        tau_star_definition="crossing of the fitted exponential and power law (crossover_time)"
        if crossing
        else "the laws do not cross; use tau_c, the likelihood change point",
        hazard_exponent=tl.hazard_exponent,
        delta_aic_split=tl.delta_aic_split,
    )
    t_end, observed = np.asarray(t_end, dtype=float), np.asarray(observed, dtype=bool)
    lo = power_law_exponent_mle(t_end, observed, tl.window[1], t_max)
    hi = power_law_exponent_mle(t_end[observed], np.ones(int(observed.sum()), bool), tl.window[1], t_max)
    entry.update(
        late_tail={
            "t_window": [tl.window[1], t_max],
            "n_events": lo.n_events,
            "z_mle_trapped_censored": Measured.of(lo.kappa, lo.kappa_err).to_dict(),
            "z_mle_trapped_removed": Measured.of(hi.kappa, hi.kappa_err).to_dict(),
        }
    )
    return line, entry


def kappa_law_curves(fits: dict, x_max: float, E_c: float) -> pd.DataFrame:
    """The κ(E) laws of Fig. 2b on a grid of x = E − E_c in [0, 1.03 x_max]: κ = a x² + b x (regime "nonlinear",
    up to 1.15 x_b) and c x ("linear", from 0.85 x_b), one pair of curves per law.

    ``fits``: {model name: an object with a, b, c, E_b} (fitted laws, or the paper's as a namespace).
    """
    x = np.linspace(0.0, x_max * 1.03, 400)
    parts = []
    for name, f in fits.items():
        xb = f.E_b - E_c
        nonlin, lin = x <= xb * 1.15, x >= xb * 0.85
        parts.append(
            pd.DataFrame(
                {"model": name, "regime": "nonlinear", "x": x[nonlin], "kappa": f.a * x[nonlin] ** 2 + f.b * x[nonlin]}
            )
        )
        parts.append(pd.DataFrame({"model": name, "regime": "linear", "x": x[lin], "kappa": f.c * x[lin]}))
    return pd.concat(parts, ignore_index=True)


def recording_time(kappa: float, tau0: float, rec_efolds: float) -> float:
    """The time from which an ensemble's section crossings sample the c-measure: t_rec = ceil(τ0 + n/κ) (time units).

    ``kappa`` the escape rate (1/time, finite and > 0, else ValueError), ``tau0`` the start of its exponential
    regime (time units), ``rec_efolds`` the e-folds n of relaxation towards μ_c after it.

    Examples
    --------
    >>> recording_time(0.2, 3.2, 2.0)
    14.0
    """
    if not (math.isfinite(kappa) and kappa > 0):
        raise ValueError(f"kappa must be finite and > 0, got {kappa}")
    return float(math.ceil(tau0 + rec_efolds / kappa))


def cmeasure_windows(
    kappa: float, tau0: float, rec_efolds: float, sample_efolds: float, margin: float, max_shift_efolds: float = 0.0
) -> tuple[float, float, float]:
    """The sampling window of κ from the c-measure, (t_rec, t_sample_end, t_record_end) in time units.

    t_rec = ceil(τ0 + n_rec/κ) (:func:`recording_time`): the ensemble is in its exponential regime and relaxed
    towards μ_c; crossings are
    sampled in [t_rec, t_sample_end = t_rec + n_sample/κ]; the recording goes on to t_record_end = t_sample_end +
    max_shift/κ + margin, so that the same window started up to ``max_shift_efolds``/κ later (a convergence check)
    still sees every sampled crossing's next crossing or exit.

    Examples
    --------
    >>> cmeasure_windows(0.2, 3.2, 2.0, 4.0, 40.0)
    (14.0, 34.0, 74.0)
    """
    t_rec = recording_time(kappa, tau0, rec_efolds)
    t_sample_end = t_rec + sample_efolds / kappa
    return t_rec, float(t_sample_end), float(t_sample_end + max_shift_efolds / kappa + margin)


def kappa_cmeasure_shifts(
    sections, lifetimes, t_rec: float, span: float, shifts, kappa: float, t_record_end: float, *, n_boot: int, seed: int
) -> list[dict]:
    """κ from the c-measure (Eq. (eqn:kappa_cmeasure_truetime)) of one run's section crossings, one row per start of
    the sampling window [t_rec + shift/κ, + span] (shift in e-folds of ``kappa``), bootstrapped over orbits (the
    independent unit, not their correlated crossings); orbits censored at t_max (KAM-trapped) dropped.

    Returns rows shift_efolds, t_from, t_to, t_record_end, n_samples, n_exit, n_undetermined, mu_exit, T_mean,
    T_max, kappa_cm, kappa_cm_err, kappa_cm_err_delta (a window without a sample gives no row).
    """
    from hhscatter.analysis.survival.cmeasure import (  # deferred: scipy loads on first use
        cmeasure_sample_from_sections,
        kappa_from_cmeasure,
    )

    rows = []
    for shift in shifts:
        t0 = t_rec + shift / kappa
        t1 = t0 + span
        with counted("survival.summaries"):
            T, n_exit, n_und, orb, exit_orb = cmeasure_sample_from_sections(
                sections, lifetimes, t0, t1, t_record_end=t_record_end, drop_censored=True, with_orbits=True
            )
        if T.size + n_exit == 0:
            continue
        k = kappa_from_cmeasure(T, n_exit, orbits=orb, exit_orbits=exit_orb, n_boot=n_boot, rng=seed)
        rows.append(
            {
                "shift_efolds": shift,
                "t_from": t0,
                "t_to": t1,
                "t_record_end": t_record_end,
                "n_samples": k.n_samples,
                "n_exit": k.n_exit,
                "n_undetermined": n_und,
                "mu_exit": k.mu_exit,
                "T_mean": float(T.mean()) if T.size else math.nan,
                "T_max": float(T.max()) if T.size else math.nan,
                "kappa_cm": k.kappa,
                "kappa_cm_err": k.kappa_err,
                "kappa_cm_err_delta": k.kappa_err_delta,
            }
        )
    return rows


def kappa_cmeasure_z(table: pd.DataFrame, references=("grid", "same_run")) -> pd.DataFrame:
    """``table`` with z = (κ_cm − κ_ref)/√(σ_cm² + σ_ref²) against each reference κ from P(t): a column
    ``z_vs_<ref>`` from ``kappa_pt_<ref>`` and ``kappa_pt_<ref>_err``.

    Examples
    --------
    >>> t = pd.DataFrame({"kappa_cm": [0.25], "kappa_cm_err": [0.03], "kappa_pt_grid": [0.21],
    ...                   "kappa_pt_grid_err": [0.0]})
    >>> round(float(kappa_cmeasure_z(t, ["grid"]).z_vs_grid.iloc[0]), 12)
    1.333333333333
    """
    out = table.copy()
    for ref in references:
        out[f"z_vs_{ref}"] = (out["kappa_cm"] - out[f"kappa_pt_{ref}"]) / np.hypot(
            out["kappa_cm_err"], out[f"kappa_pt_{ref}_err"]
        )
    return out


def kappa_cmeasure_entry(row, later: pd.DataFrame) -> dict:
    """The numbers of κ from the c-measure at one energy: its sample and window, κ_cm beside κ from P(t) (the grid
    run and the same run) with their z, and κ_cm of the ``later`` window starts ({"+<shift>/kappa": κ_cm}).

    ``row``: the unshifted row of :func:`kappa_cmeasure_shifts` completed with the references and
    :func:`kappa_cmeasure_z`; ``later``: the rows of the same energy with shift_efolds > 0.
    """
    return {
        "energy": row["energy"],
        "t_window": [row["t_from"], row["t_to"]],
        "t_record_end": row["t_record_end"],
        "n_samples": int(row["n_samples"]),
        "n_exit": int(row["n_exit"]),
        "n_undetermined": int(row["n_undetermined"]),
        "mu_exit": row["mu_exit"],
        "kappa_cm": Measured.of(row["kappa_cm"], row["kappa_cm_err"]).to_dict(),
        "kappa_pt_grid": Measured.of(row["kappa_pt_grid"], row["kappa_pt_grid_err"]).to_dict(),
        "kappa_pt_same_run": Measured.of(row["kappa_pt_same_run"], row["kappa_pt_same_run_err"]).to_dict(),
        "z_vs_grid": row["z_vs_grid"],
        "z_vs_same_run": row["z_vs_same_run"],
        "kappa_cm_later_starts": {
            f"+{s:g}/kappa": v for s, v in later[["shift_efolds", "kappa_cm"]].itertuples(index=False)
        },
    }


def rate_row(rate) -> dict:
    """One row of a κ(E) table: κ (1/time) with its error and parts, the four window estimates and windows, τ0,
    t_stop and the MLE cross-check, from an :func:`~hhscatter.analysis.survival.escape_rate.escape_rate` result."""
    return {
        "kappa": rate.kappa,
        "kappa_err": rate.kappa_err,
        "kappa_spread": rate.kappa_spread,
        "kappa_stat": rate.kappa_stat,
        **{f"kappa_w{i + 1}": f.kappa for i, f in enumerate(rate.fits)},
        **{f"window_w{i + 1}": f"{w[0]:.3f}-{w[1]:.3f}" for i, w in enumerate(rate.windows)},
        "tau0": rate.tau0,
        "t_stop": rate.t_stop,
        "kappa_mle": rate.mle.kappa,
        "kappa_mle_err": rate.mle.kappa_err,
    }


def tau_star_estimate(tail) -> tuple[float, float | None, str]:
    """τ* of a detected sticky tail (time units) with its systematic error and how it was defined: the crossing of
    the fitted exponential and power law, err = its distance to the likelihood change point τ_c; where the laws do
    not cross, τ* = τ_c without an error."""
    tl = tail.tail
    if math.isfinite(tail.tau_star):
        return (
            tail.tau_star,
            abs(tail.tau_star - tl.window[0]),
            "crossing of the exponential and power-law fits; err = |crossing − change point τ_c|",
        )
    return tl.window[0], None, "the fitted laws do not cross: τ* = τ_c, the likelihood change point of the hazard"
