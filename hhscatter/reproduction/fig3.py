"""The paper's Fig. 3 (fig:energy_decay) in tables: the μ of Eq. (eqn:energy_exp_decay) on the paper's window and
on others, its bootstrap errors, the inset's energy histograms, μ in the authors' conventions beside ours and the
ribbons of the figure.

The inputs are the ⟨E⟩(t) table of a dissipative run (columns t, n, mean_E, std_E, sem_E and, for the authors'
selections, mean_E_above and n_above: :func:`~hhscatter.analysis.dissipative.decay.inside_mean_energy`) and the
results of :mod:`~hhscatter.analysis.dissipative.decay`; nothing here reads a file. Units: t in time units, E in
energy units, γ in 1/time; μ is dimensionless.

Examples
--------
>>> import pandas as pd
>>> t = np.arange(0.0, 401.0, 2.0)
>>> me = pd.DataFrame({"t": t, "mean_E": 0.3 * np.exp(-0.9 * 0.01 * t)})
>>> windows, kinds = fit_windows((0.0, 200.0), [(200.0, 400.0)], [200.0, 200.0], (0.0, 100.0), 400.0)
>>> tab = mu_table(me, 0.3, 0.01, windows, kinds)
>>> list(tab["kind"]), [round(m, 6) for m in tab["mu"]]
(['paper', 'later', 'sliding', 'sliding', 'alt'], [0.9, 0.9, 0.9, 0.9, 0.9])
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pandas as pd

from hhscatter.analysis.dissipative.decay import fit_energy_decay, mu_by_window
from hhscatter.analysis.dissipative.transitions import tau2_predicted
from hhscatter.analysis.stats.measured import Measured
from hhscatter.reproduction.verdicts import quoted_verdict, verdict_beside_authors

__all__ = [
    "FIG3_SELECTIONS",
    "DecayResults",
    "decay_results",
    "fit_overshoot",
    "add_bootstrap_errors",
    "authors_convention",
    "fit_windows",
    "histogram_edges",
    "histogram_rows",
    "mean_energy_table",
    "mu_table",
    "nearest_times",
    "paper_fit",
    "ribbons",
]

#: which orbits ⟨E⟩(t) averages over (the keys of a study's ``authors_selection``)
FIG3_SELECTIONS = {
    "inside": "every orbit not escaped by t (settled ones continued below E_c)",
    "above": "orbits with E > E_c only (an orbit leaves at settling, as for P(t))",
}

_WHO = {"inside": "every orbit inside Ω", "above": "orbits with E > E_c only"}  # short, for row names


def _window_text(w) -> str:
    return f"[{w[0]:g}, {w[1]:g}]"


def mean_energy_table(inside: pd.DataFrame, above: pd.DataFrame) -> pd.DataFrame:
    """Fig. 3's ⟨E⟩(t) table: the mean over the orbits inside Ω with its ± 3 SEM band, beside the mean over those
    above E_c.

    ``inside`` and ``above``: :func:`~hhscatter.analysis.dissipative.decay.mean_energy` tables (t, n, mean_E,
    sem_E, …) of the two selections (:func:`~hhscatter.analysis.dissipative.decay.inside_mean_energy`). Returns
    ``inside`` with lo_3sem, hi_3sem = mean_E ∓ 3 sem_E and, per t, n_above (0 where no orbit is above E_c),
    mean_E_above and sem_E_above (NaN there). Energies in model units, t in time units.

    Examples
    --------
    >>> inside = pd.DataFrame({"t": [0.0, 10.0], "n": [4, 4], "mean_E": [0.3, 0.2], "sem_E": [0.0, 0.01]})
    >>> above = pd.DataFrame({"t": [0.0], "n": [4], "mean_E": [0.3], "sem_E": [0.0]})
    >>> me = mean_energy_table(inside, above)
    >>> me[["lo_3sem", "hi_3sem", "n_above"]].round(6).values.tolist()
    [[0.3, 0.3, 4.0], [0.17, 0.23, 0.0]]
    """
    me = inside.assign(lo_3sem=inside["mean_E"] - 3 * inside["sem_E"], hi_3sem=inside["mean_E"] + 3 * inside["sem_E"])
    ma = above.rename(columns={"n": "n_above", "mean_E": "mean_E_above", "sem_E": "sem_E_above"})
    me = me.merge(ma[["t", "n_above", "mean_E_above", "sem_E_above"]], on="t", how="left")
    me["n_above"] = me["n_above"].fillna(0).astype(np.int64)
    return me


def histogram_edges(energies, E0: float, bins: int) -> np.ndarray:
    """The energy bin edges of the inset's histograms: ``bins`` geometric bins from just below the lowest of
    ``energies`` (floored at 1e-12) to just above the initial energy ``E0`` (energy units).

    Examples
    --------
    >>> histogram_edges([0.05, 0.2], 0.3, 2).round(6).tolist()
    [0.049, 0.121304, 0.3003]
    """
    lo = max(float(np.nanmin(energies)), 1e-12)
    return np.geomspace(lo * 0.98, E0 * 1.001, bins + 1)


def paper_fit(me: pd.DataFrame, E0: float, gamma: float, window):
    """The paper's fit of Fig. 3: log⟨E⟩ by E0 e^{−μγt}, Eq. (eqn:energy_exp_decay), on ``window``.

    Adds the column ``fit_E`` (the fitted curve on every t of ``me``) and returns the
    :func:`~hhscatter.analysis.dissipative.decay.fit_energy_decay` result.

    Examples
    --------
    >>> import pandas as pd
    >>> me = pd.DataFrame({"t": [0.0, 100.0, 200.0], "mean_E": 0.3 * np.exp(-0.91 * 0.01 * np.array([0, 100, 200]))})
    >>> round(paper_fit(me, 0.3, 0.01, (0.0, 200.0)).mu, 10), "fit_E" in me
    (0.91, True)
    """
    fit = fit_energy_decay(me["t"], me["mean_E"], E0, gamma, window)
    me["fit_E"] = E0 * np.exp(-fit.mu * gamma * me["t"])
    return fit


def fit_windows(window, later, sliding_window, alt, t_last: float):
    """The fit windows of μ and their kinds (paper, later, sliding, alt), times in time units.

    The sliding windows ``[lo, lo + width]`` start at 0, stride, 2·stride, ... while they end by ``t_last``
    (``sliding_window`` = [width, stride]).

    Examples
    --------
    >>> fit_windows((0, 200), [(200, 400)], [100.0, 50.0], (0, 100), 250.0)[1]
    ['paper', 'later', 'sliding', 'sliding', 'sliding', 'sliding', 'alt']
    """
    width, stride = sliding_window
    sliding = [(lo, lo + width) for lo in np.arange(0.0, t_last - width + 1e-9, stride)]
    windows = [window] + later + sliding + [alt]
    kinds = ["paper"] + ["later"] * len(later) + ["sliding"] * len(sliding) + ["alt"]
    return windows, kinds


def mu_table(me: pd.DataFrame, E0: float, gamma: float, windows, kinds) -> pd.DataFrame:
    """μ (E(0) = E0) and μ_free (free intercept) of log⟨E⟩ on every window, with their fit errors (mu_fit_err,
    mu_free_fit_err) and the window's kind (see the module's example)."""
    tab = mu_by_window(me["t"], me["mean_E"], E0, gamma, windows)
    tab["kind"] = kinds
    return tab.rename(columns={"mu_err": "mu_fit_err", "mu_free_err": "mu_free_fit_err"})


def add_bootstrap_errors(tab: pd.DataFrame, me: pd.DataFrame, boot: pd.DataFrame, scale, n_windows, n_boot) -> None:
    """Add to ``tab`` the bootstrap errors of μ and μ_free per window, the window centres and ⟨E⟩ there.

    ``boot``: the replicates of :func:`~hhscatter.analysis.dissipative.decay.bootstrap_mu_first_orbits`, one row per
    (replicate, window), replicate-major; the error is the replicates' standard deviation × ``scale`` (√(K/N): the
    bootstrap ran on K of N orbits). ``mean_E_mid``: ⟨E⟩ interpolated linearly at the window centre ``t_mid``,
    where on the energy axis the local exponent is measured.

    Examples
    --------
    >>> import pandas as pd
    >>> tab = pd.DataFrame({"t_lo": [0.0], "t_hi": [200.0]})
    >>> boot = pd.DataFrame({"mu": [0.9, 1.1], "mu_free": [0.9, 1.1]})
    >>> add_bootstrap_errors(tab, pd.DataFrame({"t": [0.0, 200.0], "mean_E": [0.3, 0.1]}), boot, 1.0, 1, 2)
    >>> round(float(tab["mu_err"][0]), 4), round(float(tab["mean_E_mid"][0]), 6)
    (0.1414, 0.2)
    """
    boot["w"] = np.tile(np.arange(n_windows), n_boot)
    err = boot.groupby("w")[["mu", "mu_free"]].std(ddof=1)
    tab["mu_err"] = err["mu"].to_numpy() * scale
    tab["mu_free_err"] = err["mu_free"].to_numpy() * scale
    tab["t_mid"] = 0.5 * (tab["t_lo"] + tab["t_hi"])
    tab["mean_E_mid"] = np.interp(tab["t_mid"], me["t"], me["mean_E"])


def nearest_times(grid, times) -> np.ndarray:
    """The times of the increasing ``grid`` nearest to each of ``times`` (the earlier one on a tie).

    Examples
    --------
    >>> nearest_times(np.array([0.0, 2.0, 4.0]), [1.0, 2.9, 10.0]).tolist()
    [0.0, 2.0, 4.0]
    """
    idx = np.clip(np.searchsorted(grid, times), 1, len(grid) - 1)
    left, right = grid[idx - 1], grid[idx]
    return np.where(np.abs(np.asarray(times) - left) <= np.abs(right - np.asarray(times)), left, right)


def histogram_rows(h, edges) -> pd.DataFrame:
    """The inset's histograms as rows: t, bin edges, count and the density in log10 E (Σ density · Δlog10 E = 1 per
    time; NaN where no orbit is inside).

    ``h``: an :func:`~hhscatter.analysis.dissipative.decay.energy_histograms` result (t_requested, t, counts
    (times × bins), n_alive, mean_E); ``edges``: the energy bin edges (energy units).

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> h = NS(t_requested=[10.0], t=[10.0], counts=np.array([[1, 3]]), n_alive=[4], mean_E=[0.2])
    >>> histogram_rows(h, np.array([0.01, 0.1, 1.0]))["density_log10E"].tolist()
    [0.25, 0.75]
    """
    dlog = np.diff(np.log10(edges))
    hrows = []
    for k in range(len(h.t)):
        tot = h.counts[k].sum()
        for b in range(len(edges) - 1):
            hrows.append(
                {
                    "t_requested": h.t_requested[k],
                    "t": h.t[k],
                    "e_lo": edges[b],
                    "e_hi": edges[b + 1],
                    "count": int(h.counts[k, b]),
                    "density_log10E": h.counts[k, b] / (tot * dlog[b]) if tot else np.nan,
                    "n_inside": int(h.n_alive[k]),
                    "mean_E": h.mean_E[k],
                }
            )
    return pd.DataFrame(hrows)


def authors_convention(
    me: pd.DataFrame,
    boot_err: dict,
    window,
    alt,
    E0: float,
    gamma: float,
    n_orbits: int,
    *,
    paper_mu: float,
    half_unit: float,
    selection: str,
    authors_window,
    setup: str,
) -> dict:
    """μ of Eq. (eqn:energy_exp_decay) in each selection × window, flagged and judged against the paper's.

    Parameters
    ----------
    me : DataFrame
        ⟨E⟩(t) (columns t, mean_E, mean_E_above, n_above). Selection "inside" averages every orbit not escaped by t,
        "above" only the orbits with E > E_c (its curve ends when the last orbit settles: its fit uses the points up
        to then, whatever the window says).
    boot_err : dict
        {(selection, window): 1σ bootstrap error of μ}.
    window, alt : (float, float)
        Our fit window and the alternative one (time units).
    E0, gamma : float
        Initial energy and drag coefficient; ``n_orbits`` the ensemble's size (for the note).
    paper_mu, half_unit : float
        The paper's μ and half a unit of its last printed digit.
    selection, authors_window
        The authors' reading: one of :data:`FIG3_SELECTIONS` and ``window`` or ``alt``.
    setup : str
        Our setup in words (the study's convention label), appended to every row's convention.

    Returns
    -------
    dict
        The reading and a row per (selection, window) under ``"mu"``: value, bootstrap err, fit_err, n_points,
        t_last, ours, authors, convention, verdict (:func:`~hhscatter.reproduction.verdicts.quoted_verdict`;
        ours names an authors' row that agrees, :func:`~hhscatter.reproduction.verdicts.verdict_beside_authors`),
        note. Each fit is the unweighted log fit with E(0) = E0; the row in (window, "inside") is ours.

    Raises
    ------
    ValueError
        An unknown selection, or an authors' window that is neither ``window`` nor ``alt``.
    """
    a_win = tuple(authors_window)
    if selection not in FIG3_SELECTIONS:
        raise ValueError(f"[study] authors_selection must be one of {sorted(FIG3_SELECTIONS)}, got {selection!r}")
    if a_win not in (window, alt):
        raise ValueError(
            f"[study] authors_window must be fit_window {list(window)} or alt_window {list(alt)}, got {list(a_win)}"
        )
    column = {"inside": "mean_E", "above": "mean_E_above"}
    t = me["t"].to_numpy()
    t_end_above = float(t[me["n_above"].to_numpy() > 0].max())
    out = []
    for sel in ("inside", "above"):
        for w in (window, alt):
            f = fit_energy_decay(t, me[column[sel]].to_numpy(), E0, gamma, w)
            used = (t >= w[0]) & (t <= w[1]) & np.isfinite(me[column[sel]].to_numpy())
            t_last = float(t[used].max())
            is_ours = sel == "inside" and w == window
            is_authors = sel == selection and w == a_win
            who = (
                "authors' and ours"
                if is_ours and is_authors
                else ("authors'" if is_authors else ("ours" if is_ours else "alternative"))
            )
            ends = f" (its points end at t = {t_last:g}: no orbit is above E_c later)" if t_last < w[1] else ""
            err = boot_err[(sel, w)]
            out.append(
                {
                    "selection": sel,
                    "window": list(w),
                    "label": f"{sel}, fit {_window_text(w)}",
                    "quantity": (
                        f"μ on {_window_text(w)} (log fit, E(0)=E0)"
                        if is_ours
                        else f"μ on {_window_text(w)}, {_WHO[sel]}"
                    ),
                    **Measured(f.mu, err).to_dict(),
                    "fit_err": f.mu_err,
                    "n_points": f.n_points,
                    "t_last": t_last,
                    "ours": is_ours,
                    "authors": is_authors,
                    "convention": (
                        f"{who}: {FIG3_SELECTIONS[sel]}; unweighted log fit on {_window_text(w)}{ends}; {setup}"
                    ),
                    "verdict": quoted_verdict(f.mu, err, paper_mu, half_unit),
                    "note": (
                        f"bootstrap (orbits) error; fit misfit error {f.mu_err:.2g}; N = {n_orbits}; "
                        f"{abs(f.mu - paper_mu) / err:.1f}σ from {paper_mu:g}"
                    ),
                }
            )
    ours = next(r for r in out if r["ours"])
    ours["verdict"] = verdict_beside_authors(ours["verdict"], [r for r in out if r["authors"] and not r["ours"]])
    return {
        "authors_selection": selection,
        "authors_window": list(a_win),
        "selections": FIG3_SELECTIONS,
        "reading": (
            "the paper's Fig. 3: μ = 0.91 on [0, 200] of ⟨E⟩ 'over an ensemble of trajectories "
            "inside Ω at time t'; selection and window flagged authors=True: [study] "
            "authors_selection, authors_window"
        ),
        "paper_mu": paper_mu,
        "paper_mu_half_unit": half_unit,
        "t_end_above": t_end_above,
        "mu": out,
    }


def ribbons(me: pd.DataFrame, ribbon_t: float, t_max: float | None = None) -> dict:
    """The two ribbons of Fig. 3 at the grid time nearest ``ribbon_t``: ± 3 SD of the energies (the caption's "3
    standard deviations", the ensemble's spread) and ± 3 SEM (ours, = 3 SD/√n: how well ⟨E⟩ is known), in energy
    units, with a comparison row for each; also the largest half-width relative to ⟨E⟩ of each up to ``t_max``
    (the figure's time axis; None: the whole grid).

    Examples
    --------
    >>> import pandas as pd
    >>> me = pd.DataFrame({"t": [0.0, 10.0], "n": [100, 100], "mean_E": [0.3, 0.2], "std_E": [0.1, 0.1],
    ...                    "sem_E": [0.01, 0.01]})
    >>> r = ribbons(me, 9.0)
    >>> r["t"], round(r["half_width_3sd"], 6), round(r["max_rel_half_width_3sem"], 6)
    (10.0, 0.3, 0.15)
    """
    t = me["t"].to_numpy()
    i = int(np.argmin(np.abs(t - ribbon_t)))
    r = me.iloc[i]
    vis = t <= (t[-1] if t_max is None else float(t_max))
    rel_sd = float((3 * me["std_E"] / me["mean_E"])[vis].max())
    rel_sem = float((3 * me["sem_E"] / me["mean_E"])[vis].max())
    n = int(r["n"])
    tr = f"t = {float(r['t']):g}"
    rows = [
        {
            "quantity": f"ribbon half-width at {tr}: 3 standard deviations of E",
            "value": float(3 * r["std_E"]),
            "authors": True,
            "convention": "authors': ± 3 standard deviations of the energies of the orbits inside Ω "
            "(the ensemble's spread; Fig. 3 caption)",
            "note": f"{3 * r['std_E'] / r['mean_E']:.2%} of ⟨E⟩ = {r['mean_E']:.4g}; n = {n} orbits",
        },
        {
            "quantity": f"ribbon half-width at {tr}: 3 standard errors of ⟨E⟩",
            "value": float(3 * r["sem_E"]),
            "authors": False,
            "convention": "ours: ± 3 standard errors of the mean ⟨E⟩ (= 3 SD/√n)",
            "note": f"{3 * r['sem_E'] / r['mean_E']:.3%} of ⟨E⟩; SD/SEM = {r['std_E'] / r['sem_E']:.4g} = √n",
        },
    ]
    return {
        "t": float(r["t"]),
        "n": n,
        "mean_E": float(r["mean_E"]),
        "half_width_3sd": float(3 * r["std_E"]),
        "half_width_3sem": float(3 * r["sem_E"]),
        "max_rel_half_width_3sd": rel_sd,
        "max_rel_half_width_3sem": rel_sem,
        "rows": rows,
    }


def fit_overshoot(me: pd.DataFrame, window, from_fraction: float = 0.75) -> float:
    """fit_overshoot(me, window, from_fraction=0.75) -> mean of ln(fit_E / mean_E) over the last quarter of the window.

    How far the fitted law E0 e^{−μγt} lies above the measured ⟨E⟩ near the end of the fit window (the long-lived
    orbits decay faster than the fit): the mean, over the grid times ``from_fraction`` · t_hi ≤ t ≤ t_hi, of the
    natural log of the ratio of the columns ``fit_E`` and ``mean_E`` (energy units; the result is dimensionless).

    Examples
    --------
    >>> me = pd.DataFrame({"t": [0.0, 100.0, 150.0, 200.0], "mean_E": [0.3, 0.1, 0.05, 0.02]})
    >>> me["fit_E"] = me["mean_E"] * np.exp([0.0, 0.0, 0.1, 0.3])
    >>> round(fit_overshoot(me, (0.0, 200.0)), 12)
    0.2
    """
    resid = np.log(me["fit_E"] / me["mean_E"])
    late = (me["t"] >= from_fraction * window[1]) & (me["t"] <= window[1])
    return float(resid[late].mean())


class DecayResults(NamedTuple):
    """The numbers that Fig. 3's comparison with the paper and its numbers JSON share (:func:`decay_results`)."""

    p: pd.Series  # the paper window's row of the μ table
    later_tab: pd.DataFrame  # the rows of the later windows
    last: pd.Series  # the last later window
    n_settled: int  # orbits settled (trapped for ever) in the run
    over: float  # fit_overshoot at the end of the fit window
    tau2_pred: float  # τ2 of Eq. (eq:tau2) from the paper window's μ, time units
    tau2_pred_err: float
    authors: dict  # authors_convention
    ribbon: dict  # ribbons


def decay_results(
    me: pd.DataFrame,
    tab: pd.DataFrame,
    outcome,
    boot_up: pd.DataFrame,
    scale: float,
    window,
    alt,
    E0: float,
    gamma: float,
    E_c: float,
    n_orbits: int,
    *,
    n_boot: int,
    paper_mu: float,
    half_unit: float,
    selection: str,
    authors_window,
    setup: str,
    ribbon_t: float,
    t_max: float | None = None,
) -> DecayResults:
    """Fig. 3's numbers: τ2 predicted from μ, the fit's overshoot, μ in the authors' conventions, the ribbons.

    Parameters
    ----------
    me : DataFrame
        ⟨E⟩(t) with the paper fit (columns t, n, mean_E, std_E, sem_E, fit_E, mean_E_above, n_above).
    tab : DataFrame
        The μ table (:func:`mu_table` with :func:`add_bootstrap_errors`): its first row is the paper window's,
        then the rows of kind "later" and one of kind "alt".
    outcome : array-like of str
        The outcome of every orbit of the run (counts the settled ones).
    boot_up, scale : DataFrame, float
        The bootstrap replicates of μ of the average over orbits above E_c on ``window`` and ``alt``, in that
        order per replicate (``n_boot`` of each), and their scale √(k/N).
    window, alt : (float, float)
        Our fit window and the alternative one (time units).
    E0, gamma, E_c, n_orbits
        Initial energy, drag coefficient (1/time), critical energy (energy units), ensemble size.
    n_boot, paper_mu, half_unit, selection, authors_window, setup
        As for :func:`authors_convention` (``n_boot``: the replicates per window).
    ribbon_t, t_max : float
        As for :func:`ribbons`.

    Examples
    --------
    >>> t = np.arange(0.0, 201.0, 10.0)
    >>> mean_E = 0.3 * np.exp(-0.9 * 0.01 * t)
    >>> me = pd.DataFrame({"t": t, "n": 100, "mean_E": mean_E, "std_E": 0.01, "sem_E": 0.001, "fit_E": mean_E,
    ...                    "mean_E_above": mean_E, "n_above": 100})
    >>> tab = pd.DataFrame({"kind": ["paper", "later", "alt"], "mu": [0.9, 0.9, 0.9], "mu_err": [0.01, 0.02, 0.03]})
    >>> boot_up = pd.DataFrame({"mu": [0.89, 0.88, 0.91, 0.92]})
    >>> r = decay_results(me, tab, ["settled", "escaped"], boot_up, 1.0, (0.0, 200.0), (0.0, 100.0), 0.3, 0.01,
    ...                   1 / 6, 2, n_boot=2, paper_mu=0.91, half_unit=0.005, selection="inside",
    ...                   authors_window=(0.0, 200.0), setup="disk", ribbon_t=100.0)
    >>> round(r.tau2_pred, 4), r.n_settled, round(r.over, 12)
    (65.3096, 1, 0.0)
    """
    p = tab.iloc[0]
    later_tab = tab[tab["kind"] == "later"]
    last = later_tab.iloc[-1]
    n_settled = int((np.asarray(outcome) == "settled").sum())
    over = fit_overshoot(me, window)
    tau2_pred = float(tau2_predicted(E0, E_c, p["mu"], gamma))
    tau2_pred_err = float(tau2_pred * p["mu_err"] / p["mu"])

    alt_row = tab[tab["kind"] == "alt"].iloc[0]
    boot_err = {("inside", window): float(p["mu_err"]), ("inside", alt): float(alt_row["mu_err"])}
    err_up = boot_up.assign(w=np.tile(np.arange(2), n_boot)).groupby("w")["mu"].std(ddof=1).to_numpy() * scale
    boot_err.update({("above", window): float(err_up[0]), ("above", alt): float(err_up[1])})
    authors = authors_convention(
        me,
        boot_err,
        window,
        alt,
        E0,
        gamma,
        n_orbits,
        paper_mu=paper_mu,
        half_unit=half_unit,
        selection=selection,
        authors_window=authors_window,
        setup=setup,
    )
    ribbon = ribbons(me, ribbon_t, t_max)
    return DecayResults(p, later_tab, last, n_settled, over, tau2_pred, tau2_pred_err, authors, ribbon)
