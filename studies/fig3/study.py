"""Study fig3: energy decay ⟨E⟩(t) and the exponent μ (paper Fig. 3 = fig:energy_decay).

Paper: for (E0, γ) = (0.3, 0.01), the mean energy ⟨E⟩(t) "computed over an
ensemble of trajectories inside Ω at time t" is fitted by least squares of
log⟨E⟩ to Eq. (eqn:energy_exp_decay), E(t) = E0 e^{−μγt}, on t ∈ [0, 200],
giving μ = 0.91; the long-lived orbits decay faster than the fit and μ is
argued to approach 1 at long times.  The inset shows energy histograms at
marked times.

Which orbits count at time t.  An orbit is *inside Ω at t* unless it has
escaped by t.  Escaped orbits leave the average at their escape time (the
engine's t_end, the last outward crossing of r_esc).  Settled orbits
(energy reached E_c inside Ω; trapped for ever) stay in it: the engine stops
them at settling unless asked otherwise, so this study's scene sets
``continue_settled``: the engine integrates settled orbits on to the last
grid time and writes their energies there as snapshot rows after t_end.  This is the only reading
consistent with the paper's numbers: with μ = 0.91, ⟨E⟩(200) ≈ 0.049 < E_c =
1/6, impossible for an average over orbits above E_c, and the paper says
that after t ≈ 200 "the only remaining orbits will be slowly collapsing
towards the origin".  The average over orbits still above E_c (the engine's
snapshots alone) is kept as a secondary curve.

Ribbons: ours is ⟨E⟩ ± 3 standard errors of the mean (std/√n: how well
⟨E⟩ is known); the paper's caption says "3 standard deviations", the spread
of the ensemble's energies (± 3 std), wider by √n.  Both are drawn.
Errors of μ: bootstrap over orbits (statistical); the least-squares error
of the fit itself measures the model misfit and is reported separately.

The authors' conventions beside ours.  Besides our μ (every orbit
not escaped, fit on [0, 200]) the study fits μ on ``alt_window`` = [0, 100]
and fits the average over orbits with E > E_c only on both windows; each is a
row of its own (key ``authors_convention`` of fig3.json).  ``[study]``
``authors_selection`` / ``authors_window`` say which of them is the
authors' reading (default: the paper's own words, every orbit inside Ω on
[0, 200]); rows in it carry ``authors=True``.  Verdicts: agreement within 2σ
of the bootstrap error, or within 2σ plus half a unit of the last digit the
paper quotes (0.91 stands for [0.905, 0.915]); our row's "differs" names an
authors'-convention row that agrees, if there is one (:func:`mu_verdict`,
:func:`verdict_beside_authors`).

Stages: ``simulate`` (one engine run with snapshots on the grid, settled
orbits continued), ``analyze`` (derived tables ``fig3_mean_energy``,
``fig3_mu_windows``, ``fig3_histograms`` and fig3.json), ``plot`` (fig3.png).
"""

from __future__ import annotations

import json
from typing import NamedTuple

import numpy as np
import pandas as pd

from hhscatter.analysis.dissipative.decay import snapshot_grid
from hhscatter.analysis.stats.verdicts import quoted_verdict as mu_verdict
from hhscatter.analysis.stats.verdicts import verdict_beside_authors
from hhscatter.scene.schema import Integer, Number, NumberLists, Numbers, StudyParams, Text


class Params(StudyParams):
    """``[study]`` of studies/fig3/study.toml."""

    snapshot_grid: NumberLists  # pieces [start, stop, step]
    fit_window: Numbers  # [t_lo, t_hi] of the paper's μ fit
    alt_window: Numbers  # [t_lo, t_hi] of the second μ fit (beside the paper's window)
    authors_selection: Text  # "inside" or "above": the authors' reading of "inside Ω at t"
    authors_window: Numbers  # fit_window or alt_window: the authors' fit window
    paper_mu_half_unit: Number  # half a unit of the last digit of the paper's μ (quoting precision)
    ribbon_t: Number  # time of the ribbon rows (3 SD vs 3 SEM)
    later_windows: NumberLists
    sliding_window: Numbers  # [width, stride]
    hist_times: Numbers
    hist_bins: Integer
    plot_t_max: Number = None  # time axis of the figure (None: the whole grid)
    n_boot: Integer
    n_boot_orbits: Integer
    boot_seed: Integer
    paper_mu: Number


def _key(study) -> str:
    sc = study.config["scene"]
    return f"e{sc['energy']:g}_gamma{sc['gamma']:g}"


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None) -> None: one engine run with snapshots, settled orbits continued."""
    grid = snapshot_grid(study.params.snapshot_grid)
    key = _key(study)
    scene = study.scene(key, snapshots=tuple(grid), continue_settled=True)
    if not scene.dissipative:
        raise ValueError(f"fig3 needs gamma > 0 in [scene], got {scene.gamma}")
    study.run(key, scene, workers=workers, progress=progress)


def _snapshot_rows(study, key: str, filters=None) -> pd.DataFrame:
    """Snapshot rows (traj_id, t, energy) of orbits not escaped; ``filters`` pushed down to the reader."""
    from hhscatter.data.read import read_snapshots

    return read_snapshots(study.raw(key), filters=filters)


def analyze(study):
    """analyze(study) -> None: ⟨E⟩(t), μ fits (+ bootstrap), later windows, histograms, fig3.json."""
    key = _key(study)
    scene = study.scene(key)
    E0, gamma = float(scene.energy), float(scene.gamma)
    E_C = study.model.critical_energy
    me, cont, lt = _mean_energy(study, key, E_C)
    n_orbits = len(lt)

    window = tuple(study.params.fit_window)
    fit = _paper_fit(me, E0, gamma, window)
    alt = tuple(study.params.alt_window)
    windows, kinds = _fit_windows(
        window, [tuple(w) for w in study.params.later_windows], study.params.sliding_window, alt, float(me["t"].max())
    )
    tab = _mu_table(me, E0, gamma, windows, kinds)
    boot, boot_up, scale = _bootstrap_mu(study, key, n_orbits, E0, gamma, E_C, windows, window, alt)
    _add_bootstrap_errors(tab, me, boot, scale, len(windows), study.params.n_boot)
    hist, h = _histograms(study, key, me, E0)

    meta = {"E0": E0, "gamma": gamma, "definition": "mean over orbits not escaped at t (settled orbits continued)"}
    study.write_table(me, "fig3_mean_energy.parquet", **meta)
    study.write_table(tab, "fig3_mu_windows.parquet", **meta)
    study.write_table(hist, "fig3_histograms.parquet", **meta)

    res = _results(study, me, tab, lt, boot_up, scale, window, alt, E0, gamma, E_C, n_orbits)
    _compare_with_paper(study, res, window, E0, gamma, E_C)
    study.write_numbers(_numbers(study, res, fit, h, cont, key, window, E0, gamma, n_orbits))


def _mean_energy(study, key: str, E_C: float):
    """Read inputs: the ⟨E⟩(t) table (inside Ω and above E_c, ± 3 SEM), the continuation counts, the lifetimes."""
    from hhscatter.analysis.dissipative.decay import inside_mean_energy
    from hhscatter.data.read import iter_parts, read_lifetimes

    ime = inside_mean_energy(iter_parts(study.raw(key), "snapshots", ["t", "energy"]), E_C)
    me, ma, cont = ime.inside, ime.above, {"rows_below_ec": ime.rows_below_ec}
    lt = read_lifetimes(study.raw(key), columns=["outcome", "t_end"], categorical=True)

    me["lo_3sem"] = me["mean_E"] - 3 * me["sem_E"]
    me["hi_3sem"] = me["mean_E"] + 3 * me["sem_E"]
    ma = ma.rename(columns={"n": "n_above", "mean_E": "mean_E_above", "sem_E": "sem_E_above"})
    me = me.merge(ma[["t", "n_above", "mean_E_above", "sem_E_above"]], on="t", how="left")
    me["n_above"] = me["n_above"].fillna(0).astype(np.int64)
    return me, cont, lt


def _paper_fit(me, E0: float, gamma: float, window):
    """The paper's fit: log⟨E⟩ by E0 e^{−μγt} on the fit window (column fit_E added to ``me``)."""
    from hhscatter.analysis.dissipative.decay import fit_energy_decay

    fit = fit_energy_decay(me["t"], me["mean_E"], E0, gamma, window)
    me["fit_E"] = E0 * np.exp(-fit.mu * gamma * me["t"])
    return fit


def _fit_windows(window, later, sliding_window, alt, t_last: float):
    """The window chooser: the fit windows of μ and their kinds (paper, later, sliding, alt), times in model units.

    The sliding windows ``[lo, lo + width]`` start at 0, stride, 2·stride, ... while they end by ``t_last``
    (``sliding_window`` = [width, stride]).

    >>> _fit_windows((0, 200), [(200, 400)], [100.0, 50.0], (0, 100), 250.0)[1]
    ['paper', 'later', 'sliding', 'sliding', 'sliding', 'sliding', 'alt']
    """
    width, stride = sliding_window
    sliding = [(lo, lo + width) for lo in np.arange(0.0, t_last - width + 1e-9, stride)]
    windows = [window] + later + sliding + [alt]
    kinds = ["paper"] + ["later"] * len(later) + ["sliding"] * len(sliding) + ["alt"]
    return windows, kinds


def _mu_table(me, E0: float, gamma: float, windows, kinds) -> pd.DataFrame:
    """The fits: μ (E(0) = E0) and μ_free (free intercept) of log⟨E⟩ on every window, with their fit errors."""
    from hhscatter.analysis.dissipative.decay import mu_by_window

    tab = mu_by_window(me["t"], me["mean_E"], E0, gamma, windows)
    tab["kind"] = kinds
    return tab.rename(columns={"mu_err": "mu_fit_err", "mu_free_err": "mu_free_fit_err"})


def _bootstrap_mu(study, key, n_orbits, E0, gamma, E_C, windows, window, alt):
    """The bootstrap over orbits of μ on every window (inside Ω), and on the fit and alt windows above E_c."""
    import pyarrow.dataset as ds

    from hhscatter.analysis.dissipative.decay import bootstrap_mu_first_orbits

    n_boot = study.params.n_boot
    k = min(study.params.n_boot_orbits, n_orbits)
    rows = _snapshot_rows(study, key, ds.field("traj_id") < k)
    boot, scale = bootstrap_mu_first_orbits(
        rows, n_orbits, k, E0, gamma, windows, n_boot=n_boot, seed=study.params.boot_seed
    )
    # the same bootstrap for the average over orbits with E > E_c only: E decreases monotonically, so these
    # are the rows before settling (the continued rows are all below E_c). Every orbit keeps its row at
    # t = 0 (E = E0 > E_c), so the orbits, their order and, with the same seed, their Poisson
    # multiplicities are those of the replicates above: the two curves are resampled together.
    boot_up, _ = bootstrap_mu_first_orbits(
        rows[rows["energy"] > E_C], n_orbits, k, E0, gamma, [window, alt], n_boot=n_boot, seed=study.params.boot_seed
    )
    return boot, boot_up, scale


def _add_bootstrap_errors(tab, me, boot, scale, n_windows, n_boot) -> None:
    """Bootstrap errors of μ, μ_free per window (replicates' std × scale), window centres and ⟨E⟩ there."""
    boot["w"] = np.tile(np.arange(n_windows), n_boot)
    err = boot.groupby("w")[["mu", "mu_free"]].std(ddof=1)
    tab["mu_err"] = err["mu"].to_numpy() * scale
    tab["mu_free_err"] = err["mu_free"].to_numpy() * scale
    tab["t_mid"] = 0.5 * (tab["t_lo"] + tab["t_hi"])
    # ⟨E⟩ at the window centre: where on the energy axis the local exponent is measured
    tab["mean_E_mid"] = np.interp(tab["t_mid"], me["t"], me["mean_E"])


def _histograms(study, key, me, E0: float):
    """The inset: histograms of log10 E at the marked times (geometric bins from the lowest energy to E0)."""
    import pyarrow.dataset as ds

    from hhscatter.analysis.dissipative.decay import energy_histograms

    hist_times = list(study.params.hist_times)
    at = _snapshot_rows(study, key, filters=ds.field("t").isin(list(_nearest(me["t"].to_numpy(), hist_times))))
    lo = max(float(at["energy"].min()), 1e-12)
    edges = np.geomspace(lo * 0.98, E0 * 1.001, study.params.hist_bins + 1)
    h = energy_histograms(at, hist_times, bins=edges)
    return _histogram_rows(h, edges), h


def _histogram_rows(h, edges) -> pd.DataFrame:
    """The histograms as rows (t, bin edges, count, density in log10 E: Σ density · Δlog10 E = 1 per time).

    ``h``: an :func:`~hhscatter.analysis.dissipative.decay.energy_histograms` result (t_requested, t, counts
    (times × bins), n_alive, mean_E); ``edges``: the energy bin edges (model units).
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


class _Results(NamedTuple):
    """The numbers that the comparison with the paper and fig3.json share."""

    p: pd.Series  # the paper window's row of fig3_mu_windows
    later_tab: pd.DataFrame
    last: pd.Series  # the last later window
    n_settled: int
    over: float  # mean log(fit/⟨E⟩) at the end of the fit window
    tau2_pred: float
    tau2_pred_err: float
    authors: dict
    ribbon: dict


def _results(study, me, tab, lt, boot_up, scale, window, alt, E0, gamma, E_C, n_orbits) -> _Results:
    """Assemble the numbers: τ2 predicted, the fit's overshoot at the window's end, the authors' conventions."""
    p = tab.iloc[0]
    later_tab = tab[tab["kind"] == "later"]
    last = later_tab.iloc[-1]
    n_settled = int((lt["outcome"] == "settled").sum())
    resid = np.log(me["fit_E"] / me["mean_E"])
    late = (me["t"] >= 0.75 * window[1]) & (me["t"] <= window[1])
    over = float(resid[late].mean())
    tau2_pred = float(np.log(E0 / E_C) / (p["mu"] * gamma))
    tau2_pred_err = float(tau2_pred * p["mu_err"] / p["mu"])

    n_boot = study.params.n_boot
    alt_row = tab[tab["kind"] == "alt"].iloc[0]
    boot_err = {("inside", window): float(p["mu_err"]), ("inside", alt): float(alt_row["mu_err"])}
    err_up = boot_up.assign(w=np.tile(np.arange(2), n_boot)).groupby("w")["mu"].std(ddof=1).to_numpy() * scale
    boot_err.update({("above", window): float(err_up[0]), ("above", alt): float(err_up[1])})
    authors = _authors_convention(study, me, boot_err, window, alt, E0, gamma, n_orbits)
    ribbon = _ribbons(study, me)
    return _Results(p, later_tab, last, n_settled, over, tau2_pred, tau2_pred_err, authors, ribbon)


def _compare_with_paper(study, res: _Results, window, E0, gamma, E_C) -> None:
    """Compare with the paper: μ per convention, the ribbons, μ → 1, the fit's overshoot, τ2."""
    p, last, paper_mu = res.p, res.last, study.params.paper_mu
    for r in res.authors["mu"]:
        study.compare(
            r["quantity"],
            r["value"],
            r["err"],
            paper_mu,
            verdict=r["verdict"],
            convention=r["convention"],
            authors=r["authors"],
            note=r["note"],
        )
    for r in res.ribbon["rows"]:
        study.compare(
            r["quantity"],
            r["value"],
            None,
            None,
            unit="energy",
            convention=r["convention"],
            authors=r["authors"],
            note=r["note"],
        )
    study.compare(
        "μ free intercept on [0, 200]",
        float(p["mu_free"]),
        float(p["mu_free_err"]),
        None,
        note="log⟨E⟩ = a − μγt; not in the paper",
    )
    study.compare(
        f"local μ on [{last['t_lo']:g}, {last['t_hi']:g}] (μ → 1 claim)",
        float(last["mu_free"]),
        float(last["mu_free_err"]),
        1.0,
        verdict="approaches 1" if abs(last["mu_free"] - 1) < abs(p["mu"] - 1) else "does not approach 1",
        note=f"⟨E⟩ ≈ {last['mean_E_mid']:.2g} there; free-intercept slope of log⟨E⟩ on the window",
    )
    study.compare(
        "fit overestimates ⟨E⟩ at the end of [0, 200]",
        res.over,
        None,
        "yes (qualitative)",
        verdict="agrees" if res.over > 0 else "differs",
        note=f"mean log(fit/⟨E⟩) over t ∈ [{0.75 * window[1]:g}, {window[1]:g}]",
    )
    study.compare(
        "τ2 = ln(E0/E_c)/(μγ) at γ = 0.01",
        res.tau2_pred,
        res.tau2_pred_err,
        float(np.log(E0 / E_C) / (paper_mu * gamma)),
        unit="time",
        note="paper value computed from its μ = 0.91 with Eq. (eq:tau2)",
    )


def _numbers(study, res: _Results, fit, h, cont, key, window, E0, gamma, n_orbits) -> dict:
    """fig3.json: the fitted μ (bootstrap and fit errors), later windows, τ2, the authors' conventions."""
    p, n_settled = res.p, res.n_settled
    return {
        "E0": E0,
        "gamma": gamma,
        "n_orbits": n_orbits,
        "n_settled": n_settled,
        "f_settled": n_settled / n_orbits,
        "definition": (
            "⟨E⟩(t): mean energy over orbits not escaped by t; settled orbits (E reached E_c inside Ω) "
            "continued past settling by re-integration; ribbon ±3 standard errors of the mean"
        ),
        "raw_keys": {"engine": key},
        "continuation": {k: v for k, v in cont.items() if k != "key"},
        "fit_window": list(window),
        "mu": {"value": float(p["mu"]), "err": float(p["mu_err"])},
        "mu_fit_err": float(p["mu_fit_err"]),
        "mu_free": {"value": float(p["mu_free"]), "err": float(p["mu_free_err"])},
        "E0_free": float(np.exp(fit.log_E0_free)),
        "rms_log_residual": fit.rms_log_residual,
        "mu_later_windows": [
            {
                "t_lo": r.t_lo,
                "t_hi": r.t_hi,
                "mu": {"value": r.mu, "err": r.mu_err},
                "mu_local": {"value": r.mu_free, "err": r.mu_free_err},
                "mean_E_mid": r.mean_E_mid,
            }
            for r in res.later_tab.itertuples()
        ],
        "tau2_predicted": {"value": res.tau2_pred, "err": res.tau2_pred_err},
        "hist_times": [float(v) for v in h.t],
        "n_boot": study.params.n_boot,
        "n_boot_orbits": min(study.params.n_boot_orbits, n_orbits),
        "paper_mu": study.params.paper_mu,
        "authors_convention": {**res.authors, "ribbon": {k: v for k, v in res.ribbon.items() if k != "rows"}},
    }


SELECTIONS = {  # which orbits ⟨E⟩(t) averages over; the keys of [study] authors_selection
    "inside": "every orbit not escaped by t (settled ones continued below E_c)",
    "above": "orbits with E > E_c only (an orbit leaves at settling, as for P(t))",
}


WHO = {"inside": "every orbit inside Ω", "above": "orbits with E > E_c only"}  # short, for row names


def _window_text(w) -> str:
    return f"[{w[0]:g}, {w[1]:g}]"


def _authors_convention(study, me, boot_err, window, alt, E0, gamma, n_orbits) -> dict:
    """μ of Eq. (eqn:energy_exp_decay) in each selection × window, flagged and judged (key authors_convention).

    ``me``: the fig3_mean_energy table (columns t, mean_E, mean_E_above, n_above); ``boot_err``: {(selection,
    window): 1σ bootstrap error}.  Selection "inside" averages every orbit not escaped by t, "above" only
    the orbits with E > E_c (its curve ends when the last orbit settles: its fit uses the points up to then,
    whatever the window says).  Each fit is the unweighted log fit with E(0) = E0 (:func:`fit_energy_decay`).
    The row in (fit_window, "inside") is ours, the one that fig3.json ``mu`` holds.
    """
    from hhscatter.analysis.dissipative.decay import fit_energy_decay

    paper_mu = study.params.paper_mu
    half = study.params.paper_mu_half_unit
    a_sel = study.params.authors_selection
    a_win = tuple(study.params.authors_window)
    if a_sel not in SELECTIONS:
        raise ValueError(f"[study] authors_selection must be one of {sorted(SELECTIONS)}, got {a_sel!r}")
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
            is_authors = sel == a_sel and w == a_win
            who = (
                "authors' and ours"
                if is_ours and is_authors
                else ("authors'" if is_authors else ("ours" if is_ours else "alternative"))
            )
            ends = f" (its points end at t = {t_last:g}: no orbit is above E_c later)" if t_last < w[1] else ""
            label = f"{sel}, fit {_window_text(w)}"
            err = boot_err[(sel, w)]
            out.append(
                {
                    "selection": sel,
                    "window": list(w),
                    "label": label,
                    "quantity": (
                        f"μ on {_window_text(w)} (log fit, E(0)=E0)"
                        if is_ours
                        else f"μ on {_window_text(w)}, {WHO[sel]}"
                    ),
                    "value": f.mu,
                    "err": err,
                    "fit_err": f.mu_err,
                    "n_points": f.n_points,
                    "t_last": t_last,
                    "ours": is_ours,
                    "authors": is_authors,
                    "convention": (
                        f"{who}: {SELECTIONS[sel]}; unweighted log fit on {_window_text(w)}{ends}; "
                        f"{study.convention_label}"
                    ),
                    "verdict": mu_verdict(f.mu, err, paper_mu, half),
                    "note": (
                        f"bootstrap (orbits) error; fit misfit error {f.mu_err:.2g}; N = {n_orbits}; "
                        f"{abs(f.mu - paper_mu) / err:.1f}σ from {paper_mu:g}"
                    ),
                }
            )
    ours = next(r for r in out if r["ours"])
    ours["verdict"] = verdict_beside_authors(ours["verdict"], [r for r in out if r["authors"] and not r["ours"]])
    return {
        "authors_selection": a_sel,
        "authors_window": list(a_win),
        "selections": SELECTIONS,
        "reading": (
            "the paper's Fig. 3: μ = 0.91 on [0, 200] of ⟨E⟩ 'over an ensemble of trajectories "
            "inside Ω at time t'; selection and window flagged authors=True: [study] "
            "authors_selection, authors_window"
        ),
        "paper_mu": paper_mu,
        "paper_mu_half_unit": half,
        "t_end_above": t_end_above,
        "mu": out,
    }


def _ribbons(study, me) -> dict:
    """The two ribbons of Fig. 3 at [study] ribbon_t: ± 3 SD of the energies (the caption's "3 standard
    deviations", the ensemble's spread) and ± 3 SEM (ours, = 3 SD/√n: how well ⟨E⟩ is known); energies in
    model units.  Also the largest half-width relative to ⟨E⟩ of each over the figure's time axis."""
    t = me["t"].to_numpy()
    i = int(np.argmin(np.abs(t - study.params.ribbon_t)))
    r = me.iloc[i]
    t_max = study.params.plot_t_max
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


def _nearest(grid, times):
    idx = np.clip(np.searchsorted(grid, times), 1, len(grid) - 1)
    left, right = grid[idx - 1], grid[idx]
    return np.where(np.abs(np.asarray(times) - left) <= np.abs(right - np.asarray(times)), left, right)


def plot(study):
    """plot(study) -> None: fig3.png from the derived tables and fig3.json."""
    from .figure import plot_fig3

    me = pd.read_parquet(study.derived("fig3_mean_energy.parquet"))
    tab = pd.read_parquet(study.derived("fig3_mu_windows.parquet"))
    hist = pd.read_parquet(study.derived("fig3_histograms.parquet"))
    numbers = json.loads(study.numbers_path.read_text())
    plot_fig3(me, tab, hist, numbers, study.figure_path, t_max=study.params.plot_t_max)
