"""Tables of the transition times of paired ensembles (paper Fig. 4 = fig:survprob, Sec. III.B.1).

Ensembles that share their initial conditions and differ in the drag γ (γ = 0: the conservative reference
P_0) give, per γ, the outcome fractions, τ0, τ1 (Eq. (eqn:tau1)), τ2 observed (the first settling time)
with its order-statistic interval and settling-time quantiles, and τ2 predicted (Eq. (eq:tau2)), each with a
paired-bootstrap error (:func:`transition_table`); the curves P_γ(t) and the ratios P_γ/P_0 drawn in the
figure (:func:`survival_ratio_tables`); the exponents p of τ ∝ γ^−p and the rows comparing them with the
paper's statements (:func:`transition_comparisons`).

Units: model time units for every time, energies in model units, γ in 1/time.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from hhscatter.analysis.dissipative.transitions import (
    power_law_exponent,
    settle_time_quantiles,
    tau1,
    tau2_observed_interval,
    tau2_predicted,
)
from hhscatter.analysis.survival.fits import survival_from_lifetimes
from hhscatter.reproduction.verdicts import comparison_row

__all__ = ["log_time_grid", "survival_ratio_tables", "transition_comparisons", "transition_table"]


def log_time_grid(t_last: float) -> np.ndarray:
    """Log-spaced times 0.2 … t_last (at least 1) for drawing P(t): 1500 points rounded to 1e-6, distinct.

    Examples
    --------
    >>> g = log_time_grid(100.0)
    >>> float(g[0]), float(g[-1]), bool(np.all(np.diff(g) > 0))
    (0.2, 100.0, True)
    """
    return np.unique(np.round(np.geomspace(0.2, max(t_last, 1.0), 1500), 6))


def transition_table(
    lifetimes: dict,
    grid,
    P: dict,
    tau0: float,
    boot: pd.DataFrame,
    boot_scale: float,
    *,
    E0: float,
    E_c: float,
    mu: float,
    mu_err: float,
    paper_mu: float,
    alpha: float,
    min_ref_orbits: float,
    key: Callable[[float], str],
) -> pd.DataFrame:
    """One row per γ of paired ensembles: outcome fractions, τ0, τ1, τ2 observed and predicted, with errors.

    Parameters
    ----------
    lifetimes : dict
        {γ: DataFrame(t_end, outcome)} of N orbits each, the same initial conditions for every γ; γ = 0.0
        (the conservative reference P_0) among them.
    grid, P : array, dict
        The time grid and {γ: P_γ on it} (:func:`~hhscatter.analysis.dissipative.transitions.survival_on_grid`).
    tau0 : float
        τ0 (time), the same for every γ.
    boot : DataFrame
        Replicates of :func:`~hhscatter.analysis.dissipative.transitions.bootstrap_transition_times`
        (columns label = γ, tau0, tau1, t_settle_q0.01, t_settle_q0.5).
    boot_scale : float
        Factor of the bootstrap standard deviations (√(K/N) when the bootstrap used the first K orbits).
    E0, E_c, mu, mu_err, paper_mu : float
        Initial energy, critical energy, μ of Eq. (eqn:energy_exp_decay) with its 1σ, and the paper's μ.
    alpha : float
        α of Eq. (eqn:tau1), P_γ(τ1) = α P_0(τ1).
    min_ref_orbits : float
        τ1 counts as resolved when N·P_0(τ1) ≥ this.
    key : callable
        γ → the run's name (column ``key``).

    Returns
    -------
    DataFrame
        Columns gamma, key, n, f_escaped, f_settled, f_censored, tau0 (+ _err), tau1 (+ _err,
        _boot_defined), n0_at_tau1, tau1_resolved, tau2_obs (+ _err, _lo, _hi, _coverage: the
        order-statistic interval of t_1/N, err its half-width), t_settle_q01, t_settle_q50 (+ _err),
        tau2_pred (Eq. (eq:tau2), + _err from σ_μ), tau2_pred_paper_mu. Errors: bootstrap σ × ``boot_scale``.

    Examples
    --------
    >>> lt = {0.0: pd.DataFrame({"t_end": [1.0, 2.0], "outcome": ["escaped"] * 2}),
    ...       0.1: pd.DataFrame({"t_end": [1.5, 3.0], "outcome": ["escaped", "settled"]})}
    >>> grid = np.arange(0.0, 3.5, 0.5)
    >>> P = {0.0: np.array([1, 1, 1, .5, 0, 0, 0.]), 0.1: np.array([1, 1, 1, 1, .5, .5, 0.])}
    >>> boot = pd.DataFrame({"label": [0.1, 0.1], "tau0": [0.0, 0.0], "tau1": [1.5, 1.5],
    ...                      "t_settle_q0.01": [3.0, 3.0], "t_settle_q0.5": [3.0, 3.0]})
    >>> t = transition_table(lt, grid, P, 0.0, boot, 1.0, E0=0.3, E_c=1 / 6, mu=1.0, mu_err=0.1, paper_mu=0.91,
    ...                      alpha=2.0, min_ref_orbits=1, key=lambda g: f"gamma{g:g}")
    >>> t[["key", "f_settled", "tau1", "tau2_obs"]].to_dict("records")[1]
    {'key': 'gamma0.1', 'f_settled': 0.5, 'tau1': 1.5, 'tau2_obs': 3.0}
    """
    min_ref = min_ref_orbits
    N = len(next(iter(lifetimes.values())))
    rows = []
    for g, lt in lifetimes.items():
        oc = lt["outcome"]  # categorical: compared on its codes
        b = boot[boot["label"] == g] if g > 0 else None
        t1 = tau1(grid, P[g], P[0.0], tau0, alpha) if g > 0 else None
        n0 = float(N * np.interp(t1, grid, P[0.0])) if t1 is not None else np.nan
        t2 = tau2_observed_interval(lt) if g > 0 else None  # first settling time, order-statistic interval
        t2 = None if t2 is None or t2.n_settled == 0 else t2
        q = settle_time_quantiles(lt["t_end"].to_numpy(), oc, (0.01, 0.5)) if g > 0 else None
        pred = float(tau2_predicted(E0, E_c, mu, g)) if g > 0 else np.inf
        pred_p = float(tau2_predicted(E0, E_c, paper_mu, g)) if g > 0 else np.inf

        def sd(col, b=b):
            if b is None:
                return np.nan
            v = b[col].to_numpy(float)
            v = v[np.isfinite(v)]
            return float(np.std(v, ddof=1)) * boot_scale if v.size > 1 else np.nan

        rows.append(
            {
                "gamma": g,
                "key": key(g),
                "n": N,
                "f_escaped": float(np.mean(oc == "escaped")),
                "f_settled": float(np.mean(oc == "settled")),
                "f_censored": float(np.mean(oc == "censored")),
                "tau0": tau0,
                "tau0_err": sd("tau0") if g > 0 else float(boot["tau0"].std(ddof=1)) * boot_scale,
                "tau1": np.nan if t1 is None else t1,
                "tau1_err": sd("tau1"),
                "tau1_boot_defined": float(np.isfinite(b["tau1"]).mean()) if b is not None else np.nan,
                "n0_at_tau1": n0,
                "tau1_resolved": bool(np.isfinite(n0) and n0 >= min_ref),
                "tau2_obs": np.nan if t2 is None else t2.value,
                "tau2_obs_err": np.nan if t2 is None else (t2.hi - t2.lo) / 2 if np.isfinite(t2.hi) else np.nan,
                "tau2_obs_lo": np.nan if t2 is None else t2.lo,
                "tau2_obs_hi": np.nan if t2 is None else t2.hi,
                "tau2_obs_coverage": np.nan if t2 is None else t2.coverage,
                "t_settle_q01": np.nan if q is None else float(q[0]),
                "t_settle_q01_err": sd("t_settle_q0.01"),
                "t_settle_q50": np.nan if q is None else float(q[1]),
                "t_settle_q50_err": sd("t_settle_q0.5"),
                "tau2_pred": pred,
                "tau2_pred_err": pred * mu_err / mu if g > 0 else np.nan,
                "tau2_pred_paper_mu": pred_p,
            }
        )
    return pd.DataFrame(rows)


def survival_ratio_tables(lifetimes: dict, grid, P: dict, dt: float, t_last: float, key: Callable[[float], str]):
    """(P_γ(t) at log-spaced times, P_γ/P_0 on the τ grid) of paired ensembles, for drawing Fig. 4.

    ``lifetimes`` {γ: DataFrame(t_end, outcome)} of N orbits each, γ = 0.0 first (the reference); ``grid`` and
    ``P`` {γ: P_γ on grid} with step ``dt`` (time); ``t_last`` the last lifetime; ``key`` γ → run name.
    Returns the exact Kaplan–Meier P(t) (columns gamma, key, t, P, P_err) on :func:`log_time_grid`, and the
    ratio every ≈ 0.5 time units while at least one reference orbit remains (columns gamma, t, ratio, n0 =
    N·P_0).

    Examples
    --------
    >>> lt = {0.0: pd.DataFrame({"t_end": [1.0, 2.0], "outcome": ["escaped"] * 2}),
    ...       0.1: pd.DataFrame({"t_end": [1.5, 3.0], "outcome": ["escaped", "settled"]})}
    >>> grid = np.arange(0.0, 3.5, 0.5)
    >>> P = {0.0: np.array([1, 1, 1, .5, 0, 0, 0.]), 0.1: np.array([1, 1, 1, 1, .5, .5, 0.])}
    >>> surv, ratio = survival_ratio_tables(lt, grid, P, 0.5, 3.0, key=lambda g: f"gamma{g:g}")
    >>> ratio[["t", "ratio", "n0"]].values.tolist()
    [[0.5, 1.0, 2.0], [1.0, 1.0, 2.0], [1.5, 2.0, 1.0]]
    """
    gs = list(lifetimes)
    N = len(lifetimes[gs[0]])
    pg = log_time_grid(t_last)
    surv = []
    for g in gs:
        c = survival_from_lifetimes(lifetimes[g][["t_end", "outcome"]], pg)
        surv.append(pd.DataFrame({"gamma": g, "key": key(g), "t": c.t, "P": c.P, "P_err": c.P_err}))
    surv = pd.concat(surv, ignore_index=True)
    keep = (grid > 0) & (np.arange(grid.size) % max(1, round(0.5 / dt)) == 0)
    ratio = []
    for g in gs[1:]:
        with np.errstate(divide="ignore", invalid="ignore"):
            r = P[g][keep] / P[0.0][keep]
        ok = np.rint(P[0.0][keep] * N) >= 1  # at least one reference orbit left (a count: rounding-proof)
        ratio.append(pd.DataFrame({"gamma": g, "t": grid[keep][ok], "ratio": r[ok], "n0": (P[0.0][keep] * N)[ok]}))
    return surv, pd.concat(ratio, ignore_index=True)


def transition_comparisons(
    taus: pd.DataFrame,
    *,
    N: int,
    E0: float,
    E_c: float,
    mu_gamma: float,
    mu_window,
    mu: float,
    mu_err: float,
    mu_other: dict | None,
    tau0: float,
    tau0_err: float,
    paper_mu: float,
):
    """(paper-comparison rows, exponents) of a :func:`transition_table`: the paper's statements on τ0, τ1, τ2.

    The paper gives the transition times only in figures; its statements are checked: τ1 and τ2 increase as γ
    decreases, τ2 ∝ 1/γ (Eq. (eq:tau2)), τ2 predicted with its μ = 0.91, τ0 independent of γ. The exponents p of
    τ ∝ γ^−p are fitted on log-log axes (:func:`~hhscatter.analysis.dissipative.transitions.power_law_exponent`):
    τ2 observed unweighted (a minimum has no Gaussian error), the median settling time and the resolved τ1
    weighted by their errors.

    Parameters
    ----------
    taus : DataFrame
        The table of :func:`transition_table`.
    N, E0, E_c : int, float, float
        Orbits per γ, initial and critical energy.
    mu_gamma, mu_window, mu, mu_err : float, (float, float), float, float
        The γ and time window μ was measured on, μ and its 1σ.
    mu_other : dict or None
        Another study's μ ({"value", ...}) for a consistency row, or None.
    tau0, tau0_err, paper_mu : float
        τ0 with its 1σ and the paper's μ.

    Returns
    -------
    rows : list of dict
        Keyword arguments of a study's ``compare`` (quantity, ours, err, paper, and unit, verdict, note).
    exponents : dict
        {"tau2" | "settle_median" | "tau1": (p, σ_p)}, (None, None) where fewer than two γ serve.

    Examples
    --------
    >>> taus = pd.DataFrame({"gamma": [0.0, 0.02, 0.04], "tau1": [np.nan, 40.0, 20.0],
    ...     "tau1_err": [np.nan, 1.0, 1.0], "tau1_resolved": [False, True, True], "tau2_obs": [np.nan, 100., 50.],
    ...     "t_settle_q50": [np.nan, 200., 100.], "t_settle_q50_err": [np.nan, 5., 5.]})
    >>> rows, p = transition_comparisons(taus, N=100, E0=0.3, E_c=1 / 6, mu_gamma=0.01, mu_window=(0, 200),
    ...     mu=0.9, mu_err=0.01, mu_other=None, tau0=5.0, tau0_err=0.5, paper_mu=0.91)
    >>> round(p["tau2"][0], 6), [r["verdict"] for r in rows if r["quantity"].startswith("τ1 increases")]
    (1.0, ['agrees'])
    """
    d = taus[taus["gamma"] > 0]
    t1v = d["tau1"].to_numpy()
    ok1 = np.isfinite(t1v)
    mono1 = bool(np.all(np.diff(t1v[ok1]) <= 0)) if ok1.sum() > 1 else None
    # unweighted: the first settling time is a minimum, its interval no Gaussian error to weight by
    p_exp, p_err = power_law_exponent(d["gamma"], d["tau2_obs"], np.full(len(d), np.nan))
    p50, p50_err = power_law_exponent(d["gamma"], d["t_settle_q50"], d["t_settle_q50_err"])
    res = d[d["tau1_resolved"]]
    p1, p1_err = power_law_exponent(res["gamma"], res["tau1"], res["tau1_err"])
    win = mu_window
    rows = [
        comparison_row(
            f"μ used for τ2 (own γ={mu_gamma:g} run, [{win[0]:g}, {win[1]:g}])",
            mu,
            mu_err,
            paper_mu,
            note="same definition as study fig3",
        )
    ]
    if mu_other is not None:
        rows.append(
            comparison_row(
                "μ: fig4's own vs fig3",
                mu,
                mu_err,
                mu_other.get("value"),
                note="consistency check between studies (same seed; grids differ)",
            )
        )
    r01 = taus[taus["gamma"] == 0.01]
    if len(r01):
        r = r01.iloc[0]
        rows.append(
            comparison_row(
                "τ2 predicted at γ = 0.01",
                r["tau2_pred"],
                r["tau2_pred_err"],
                float(tau2_predicted(E0, E_c, paper_mu, 0.01)),
                unit="time",
                note="paper value from its μ = 0.91 via Eq. (eq:tau2)",
            )
        )
        rows.append(
            comparison_row(
                "τ2 observed (first settling) at γ = 0.01",
                r["tau2_obs"],
                r["tau2_obs_err"],
                None,
                unit="time",
                note=f"N = {N}; the paper (N = 1e7) marks it only in Fig. 4; min over "
                f"{round(r['f_settled'] * N)} settlers, decreases with N; err: half-width "
                f"of the order-statistic interval [{r['tau2_obs_lo']:.4g}, "
                f"{r['tau2_obs_hi']:.4g}] of the quantile t_1/N",
            )
        )
    rows.append(
        comparison_row(
            "τ1 increases as γ decreases",
            mono1,
            None,
            True,
            verdict=None if mono1 is None else ("agrees" if mono1 else "differs"),
            note="paper: 'both τ1 and τ2 increase with decreasing γ'",
        )
    )
    if p1 is not None:
        rows.append(
            comparison_row(
                "p1 in τ1 ∝ γ^−p1",
                p1,
                p1_err,
                None,
                note="not in the paper; a linear κ0(E) with E = E0 e^{−μγt} gives P_γ/P_0 ≈ "
                "exp(κ0' E0 μ γ t²/2), i.e. p1 = 1/2",
            )
        )
    if p_exp is not None:
        rows.append(
            comparison_row(
                "p in τ2,obs ∝ γ^−p",
                p_exp,
                p_err,
                1.0,
                note="paper: τ2 ∝ 1/γ (Eq. (eq:tau2)); unweighted log-log fit over γ with settlers",
            )
        )
    if p50 is not None:
        rows.append(
            comparison_row(
                "p in median settling time ∝ γ^−p",
                p50,
                p50_err,
                1.0,
                note="N-independent companion of τ2,obs (same fit)",
            )
        )
    rows.append(
        comparison_row(
            "τ0 (data-driven, on P_0)",
            tau0,
            tau0_err,
            None,
            unit="time",
            note="paper: τ0 effectively independent of γ; no value given",
        )
    )
    return rows, {"tau2": (p_exp, p_err), "settle_median": (p50, p50_err), "tau1": (p1, p1_err)}
