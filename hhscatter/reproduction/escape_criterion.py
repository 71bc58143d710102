"""Is the escape criterion r > r_esc sound? (paper App. "Escape Condition"): κ under several r_esc on the same
orbits, the returns after an escape, the exit channels, and the default r_esc these measurements recommend.

The paper deems a conservative orbit escaped at its first outward crossing of r_esc "slightly larger than 1" and
states that all values tried gave the same observations. Per energy the runs at every r_esc hold the same orbits
(paired); one common window serves the paired estimators (:func:`common_window`); per r_esc a κ row
(:func:`kappa_row`: the constant-hazard MLE on the window, the shift from r_ref by the slope of the paired
log-survival ratio, the paper's mean of 4 least-squares fits with the cell's own windows, delays and flight times),
a returns row (:func:`returns_row`, from runs followed past their escape) and the exit channels
(:func:`channel_rows`); then the numbers and the comparison rows (:func:`criterion_numbers`).

Units: time in time units, κ in 1/time, radii in length units, energies in energy units.

Examples
--------
>>> rng = np.random.default_rng(0)
>>> t = rng.exponential(10.0, 4000)
>>> arrs = {1.5: (t, np.ones(t.size, bool)), 2.0: (t + 0.5, np.ones(t.size, bool))}
>>> grid, own, win = common_window(arrs, [1.5, 2.0], 1.5, 0.1)
>>> row, shift = kappa_row(0.3, 2.0, 1.5, arrs, own, win, n_groups=8)
>>> abs(row["kappa_shift"]) < 3 * row["kappa_shift_err"]  # a constant delay leaves κ unchanged
True
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.stats.intervals import fraction_with_bound, wilson_interval
from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.survival.escape_rate import escape_rate, escape_rate_mle
from hhscatter.analysis.survival.fits import survival_curve
from hhscatter.analysis.survival.paired import paired_mle_shift, survival_ratio_slope

__all__ = [
    "channel_rows",
    "common_window",
    "criterion_numbers",
    "follow_returns",
    "kappa_row",
    "lyapunov_table",
    "paired_runs",
    "recommend_r_esc",
    "return_quantity",
    "returns_row",
    "with_return_counts",
]


def common_window(arrs: dict, radii, r_ref: float, p_start: float):
    """The window rule of one energy: (grid, {r: EscapeRateResult or None}, window).

    (a) The paper's rule (mean of 4 least-squares fits) with each cell's own windows; None where it fails.
    (b) One common window for the paired estimators: the median of the cells' own windows (robust to one cell's
    plateau search picking an outlying τ0), started no earlier than where the reference P(t) has fallen to
    ``p_start``: a prompt-escape transient inside the window (hazard peak at t ≈ 5, ringing for a few periods)
    would be shifted in or out by the flight time and masquerade as a κ shift.

    Parameters
    ----------
    arrs : dict
        {r_esc: (t_end, observed)} of the runs at one energy, the same orbits in the same order.
    radii : sequence of float
        The r_esc values; ``r_ref`` the reference among them.
    p_start : float
        The reference P(t) at which the window may start at the earliest.

    Returns
    -------
    (ndarray, dict, (float, float))
        The P(t) grid (20001 times up to the reference run's quantile 1 − 10/N), the cells' own results and the
        common window (t_lo, t_hi).
    """
    t_ref, _ = arrs[r_ref]
    n_tot = t_ref.size
    t_hi = float(np.quantile(t_ref, 1 - 10 / n_tot)) if n_tot > 20 else float(t_ref.max())
    grid = np.linspace(0.0, t_hi, 20001)
    curves = {r: survival_curve(*arrs[r], grid) for r in radii}
    own = {}
    for r in radii:
        try:
            with counted("survival.escape_criterion.escape_rate"):
                own[r] = escape_rate(*arrs[r], grid, detect_tail=False)
        except ValueError:
            own[r] = None
    below = np.flatnonzero(curves[r_ref].P <= p_start)
    t_p = float(grid[below[0]]) if below.size else 0.0
    tau0s = [own[r].tau0 for r in radii if own[r] is not None]
    stops = [own[r].t_stop for r in radii if own[r] is not None]
    win = (max(t_p, float(np.median(tau0s)) if tau0s else 0.0), float(np.median(stops)) if stops else t_hi)
    if not win[1] > win[0]:
        win = (t_p, t_hi)
    return grid, own, win


def _mean_err(x):
    return (
        float(x.mean()) if x.size else math.nan,
        float(x.std(ddof=1) / math.sqrt(x.size)) if x.size > 1 else math.nan,
    )


def _follow_shift(s_ref, s, t_end, win, n_groups):
    """The κ shift of the paired ratio slope on the follow runs: both criteria on one and the same trajectory (no
    divergence of the paired runs), a smaller sample; (NaN, NaN) where the slope cannot be fitted."""
    tf_ref = np.where(np.isfinite(s_ref["t_esc"]), s_ref["t_esc"], t_end)
    tf_alt = np.where(np.isfinite(s["t_esc"]), s["t_esc"], t_end)
    try:
        rf = survival_ratio_slope(
            tf_ref, np.isfinite(s_ref["t_esc"]), tf_alt, np.isfinite(s["t_esc"]), win, n_groups=n_groups
        )
    except ValueError:
        return math.nan, math.nan
    return rf.shift, rf.shift_err


def kappa_row(E, r, r_ref, arrs, own, win, returns=None, follow_t_end=None, *, n_groups: int = 16):
    """(row of the κ table, PairedShift) of cell (E, r).

    κ by the constant-hazard MLE on the common window ``win``; its shift from r_ref by the slope of the paired
    log-survival ratio (:func:`~hhscatter.analysis.survival.paired.survival_ratio_slope`, the main estimator; the
    MLE difference beside it); the paper's κ (mean of 4 least-squares fits, Fig. 2b caption) with the cell's own
    windows (``own`` of :func:`common_window`); the delay of P(t) at the window start, log(P_r/P_ref)(t_lo)/κ_ref;
    the mean difference of t_end of the orbits escaping under both. With ``returns`` ({r: return statistics of
    :func:`~hhscatter.analysis.geometry.channels.return_statistics`}) and ``follow_t_end`` (the follow runs'
    t_end): the flight time from r_ref to r on identical trajectories and the shift on them.
    """
    t_ref, obs_ref = arrs[r_ref]
    t_alt, obs_alt = arrs[r]
    res = own[r]
    if res is not None:
        k_lsq, k_lsq_err, tau0, t_stop = res.kappa, res.kappa_err, res.tau0, res.t_stop
    else:
        k_lsq = k_lsq_err = tau0 = t_stop = math.nan
    ps = paired_mle_shift(t_ref, obs_ref, t_alt, obs_alt, *win)
    mle = escape_rate_mle(t_alt, obs_alt, *win)
    rsl = survival_ratio_slope(t_ref, obs_ref, t_alt, obs_alt, win, n_groups=n_groups)
    # delay of P(t) at the window start (the flight time, plus the premature escapes of r_ref up to t_lo)
    tshift = rsl.offset / ps.kappa_ref if r != r_ref else 0.0
    both = obs_alt & obs_ref
    flight, fol = np.array([]), (math.nan, math.nan)
    if returns is not None:
        s_ref, s = returns[r_ref], returns[r]
        ok = np.isfinite(s["t_esc"]) & np.isfinite(s_ref["t_esc"])
        flight = s["t_esc"][ok] - s_ref["t_esc"][ok]
        if r != r_ref:
            fol = _follow_shift(s_ref, s, follow_t_end, win, n_groups)
    f_mean, f_err = _mean_err(flight)
    dt_mean, dt_err = _mean_err(t_alt[both] - t_ref[both])
    row = {
        "energy": E,
        "r_esc": r,
        "n": t_ref.size,
        "n_escaped": int(obs_alt.sum()),
        "kappa": ps.kappa_alt,
        "kappa_err": ps.kappa_alt_err,
        "n_events": mle.n_events,
        "t_start": win[0],
        "t_stop": win[1],
        "kappa_shift": rsl.shift if r != r_ref else 0.0,
        "kappa_shift_err": rsl.shift_err if r != r_ref else 0.0,
        "kappa_shift_follow": fol[0],
        "kappa_shift_follow_err": fol[1],
        "mle_shift": ps.shift,
        "mle_shift_err": ps.shift_err,
        "mle_shift_err_unpaired": ps.shift_err_unpaired,
        "mle_correlation": ps.correlation,
        "kappa_lsq": k_lsq,
        "kappa_lsq_err": k_lsq_err,
        "tau0_own": tau0,
        "t_stop_own": t_stop,
        "time_shift": tshift,
        "flight_mean": f_mean,
        "flight_err": f_err,
        "flight_median": float(np.median(flight)) if flight.size else math.nan,
        "dt_end_mean": dt_mean,
        "dt_end_err": dt_err,
    }
    return row, ps


def returns_row(E, r, s, recrossed, win, kappa_ref, lyapunov, follow, *, z: float = 1.0, fast: float = 10.0) -> dict:
    """Row of the returns table of cell (E, r): the fraction of escapes that come back inside r_in (all, and after
    the window start) with Wilson intervals at ``z`` σ (and, for a count of 0, its one-sided 95 % upper bound
    ``upper95``, by :func:`~hhscatter.analysis.stats.intervals.fraction_with_bound`), how long the returned orbits stay
    and the fraction of them escaping again within ``fast``, the Lyapunov orbit's extent.

    ``s``: :func:`~hhscatter.analysis.geometry.channels.return_statistics` back inside r_in; ``recrossed``: the
    orbits back inside r itself; ``kappa_ref``: κ of r_ref on the window; ``lyapunov``: a row with r_min, r_max;
    ``follow``: the follow runs' lifetimes (outcome, energy_error).

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> s = {"t_esc": np.array([5.0, 20.0, np.nan]), "returned": np.array([True, False, False]),
    ...      "t_return": np.array([6.0, np.nan, np.nan]), "t_reesc": np.array([9.0, np.nan, np.nan])}
    >>> follow = pd.DataFrame({"outcome": ["escaped", "escaped", "censored"], "energy_error": [0.0, 1e-12, 0.0]})
    >>> row = returns_row(0.3, 1.5, s, np.array([True, False, False]), (10.0, 50.0), 0.1, NS(r_min=1.1, r_max=1.3),
    ...                   follow)
    >>> row["n_escaped"], row["n_returned"], row["n_escaped_late"], row["stay_median"], row["n_fast"]
    (2, 1, 1, 3.0, 1)
    """
    nf = len(follow)
    esc = np.isfinite(s["t_esc"])
    late = esc & (s["t_esc"] > win[0])
    n_esc, n_ret = int(esc.sum()), int(s["returned"].sum())
    n_late, n_ret_late = int(late.sum()), int((s["returned"] & late).sum())
    p, lo, hi = wilson_interval(n_ret, n_esc, z)
    pl, lol, hil = wilson_interval(n_ret_late, n_late, z) if n_late else (math.nan,) * 3
    stay = s["t_reesc"][s["returned"]] - s["t_return"][s["returned"]]
    n_re = int(np.isfinite(stay).sum())
    n_fast = int(np.count_nonzero(stay <= fast))
    pf, flo, fhi = wilson_interval(n_fast, n_ret, z) if n_ret else (math.nan,) * 3
    return {
        "energy": E,
        "r_esc": r,
        "n_followed": nf,
        "n_escaped": n_esc,
        "n_returned": n_ret,
        "frac": float(p),
        "lo": float(lo),
        "hi": float(hi),
        # a count of 0: the one-sided 95 % bound the tables print (NaN for a count above 0)
        "upper95": float(fraction_with_bound(0, n_esc).upper) if n_ret == 0 and n_esc else math.nan,
        "n_recrossed": int(recrossed.sum()),
        "t_late": win[0],
        "n_escaped_late": n_late,
        "n_returned_late": n_ret_late,
        "frac_late": float(pl),
        "lo_late": float(lol),
        "hi_late": float(hil),
        "n_reescaped": n_re,
        "stay_median": float(np.nanmedian(stay)) if n_re else math.nan,
        "stay_mean": float(np.nanmean(stay)) if n_re else math.nan,
        "kappa_ref": kappa_ref,
        "n_fast": n_fast,
        "frac_fast": float(pf),
        "frac_fast_lo": float(flo),
        "frac_fast_hi": float(fhi),
        "lyap_r_min": lyapunov.r_min,
        "lyap_r_max": lyapunov.r_max,
        "energy_error_max": float(follow.energy_error.max()),
        "n_censored_follow": int((follow.outcome == "censored").sum()),
    }


def channel_rows(E, r, channel, t_end, win, *, z: float = 1.0, n_channels: int = 3) -> list[dict]:
    """Rows of the channels table of cell (E, r): the escape fraction per exit channel with Wilson intervals and the
    χ² test of equal shares, for all escapes and for those before ("early") and after ("late") the window start.

    ``channel``: the exit channel per orbit (−1: not escaped); ``t_end``: the orbits' end times.

    Examples
    --------
    >>> rows = channel_rows(0.3, 1.5, np.array([0, 1, 2, 0, -1]), np.array([1.0, 2.0, 30.0, 40.0, 50.0]), (10.0, 60.0))
    >>> [(r["subset"], r["count"]) for r in rows if r["channel"] == 0]
    [('all', 2), ('early', 1), ('late', 1)]
    """
    from hhscatter.analysis.geometry.channels import channel_fractions  # deferred: scipy loads on first use

    n_tot = t_end.size
    rows = []
    for subset, m in (("all", np.ones(n_tot, bool)), ("early", t_end <= win[0]), ("late", t_end > win[0])):
        cf = channel_fractions(channel[m], n_channels, z)
        for k in range(n_channels):
            rows.append(
                {
                    "energy": E,
                    "r_esc": r,
                    "subset": subset,
                    "channel": k,
                    "count": int(cf.counts[k]),
                    "n": cf.n,
                    "frac": float(cf.frac[k]),
                    "lo": float(cf.lo[k]),
                    "hi": float(cf.hi[k]),
                    "chi2": cf.chi2,
                    "p_value": cf.p_value,
                }
            )
    return rows


def lyapunov_table(energies, system) -> pd.DataFrame:
    """lyapunov_table(energies, system) -> one row per energy (sorted, once each) over all exits of ``system``.

    The exits' Lyapunov orbits are the exact boundary of Ω (paper Sec. II, "Scattering dynamics";
    :func:`~hhscatter.analysis.geometry.channels.lyapunov_orbit`); the row gives their radial extent together:
    ``r_min`` the smallest and ``r_max`` the largest r = √(x² + y²) on any of them (length), ``period`` the
    longest of their periods (time; under Hénon–Heiles' three-fold symmetry all three are equal) and
    ``n_exits``. Energies at or below an exit's saddle energy are refused by ``lyapunov_orbit`` (ValueError).

    Examples
    --------
    >>> from hhscatter.model import HenonHeiles
    >>> t = lyapunov_table([0.3, 0.2, 0.3], HenonHeiles())
    >>> t.energy.tolist(), t.n_exits.tolist(), round(float(t.r_max.iloc[1]), 4)
    ([0.2, 0.3], [3, 3], 1.0858)
    """
    from hhscatter.analysis.geometry.channels import lyapunov_orbit  # deferred: scipy loads on first use

    rows = []
    for E in sorted(set(energies)):
        orbits = [lyapunov_orbit(E, system, exit=k) for k in range(len(system.exits))]
        rows.append(
            {
                "energy": E,
                "r_min": min(L.r_min for L in orbits),
                "r_max": max(L.r_max for L in orbits),
                "period": max(L.period for L in orbits),
                "n_exits": len(orbits),
            }
        )
    return pd.DataFrame(rows)


def recommend_r_esc(returns: pd.DataFrame, lyapunov: pd.DataFrame, r_ref: float) -> dict:
    """The default r_esc the measurements recommend: the smallest tested radius beyond every Lyapunov orbit of the
    energies considered (the exact no-return boundary of Ω) with no measured return at any energy; the largest
    tested one if none qualifies.

    Returns ``recommended`` (that radius, length), ``authors`` (``r_ref``: the reference radius the shifts are
    measured from, the authors' value in the study, not the tool's default), the largest Lyapunov-orbit extent
    and its energy, and the ``rule`` in words.

    Examples
    --------
    >>> ret = pd.DataFrame({"r_esc": [1.03, 1.03, 1.5, 1.5], "n_returned": [3, 0, 0, 0]})
    >>> pick = recommend_r_esc(ret, pd.DataFrame({"energy": [0.3], "r_max": [1.2]}), 1.03)
    >>> pick["recommended"], pick["authors"]
    (1.5, 1.03)
    """
    radii = sorted(returns.r_esc.unique())
    r_lyap = float(lyapunov.r_max.max())
    ok = [r for r in radii if r > r_lyap and returns[returns.r_esc == r].n_returned.sum() == 0]
    choice = ok[0] if ok else radii[-1]
    return {
        "recommended": float(choice),
        "authors": float(r_ref),
        "lyapunov_r_max_at_max_energy": float(lyapunov.r_max.max()),
        "lyapunov_energy_max": float(lyapunov.energy.max()),
        "rule": "smallest tested r_esc with zero measured returns at every energy; it must exceed the radial "
        "extent r_max of the Lyapunov orbit (the exact boundary of Ω) at the highest energy used",
    }


def _kappa_numbers(kap, r_ref):
    numbers, rows = {}, []
    for row in kap.itertuples():
        numbers.setdefault(f"E={row.energy:.2f}", {})[f"r_esc={row.r_esc:g}"] = {
            "kappa": Measured(row.kappa, row.kappa_err).to_dict(),
            "shift_vs_ref": Measured(row.kappa_shift, row.kappa_shift_err).to_dict(),
            "mle_difference_vs_ref": Measured(row.mle_shift, row.mle_shift_err).to_dict(),
            "shift_vs_ref_follow_runs": Measured(row.kappa_shift_follow, row.kappa_shift_follow_err).to_dict(),
            "kappa_lsq": Measured(row.kappa_lsq, row.kappa_lsq_err).to_dict(),
            "window": [row.t_start, row.t_stop],
            "delay_of_P": row.time_shift,
            "flight_time_from_ref": Measured(row.flight_mean, row.flight_err).to_dict(),
            "mean_t_end_difference": Measured(row.dt_end_mean, row.dt_end_err).to_dict(),
        }
        if row.r_esc != r_ref:
            rows.append(
                {
                    "quantity": f"κ(E={row.energy:.2f}, r_esc={row.r_esc:g}) − κ(r_esc={r_ref:g})",
                    "ours": row.kappa_shift,
                    "err": row.kappa_shift_err,
                    "paper": 0.0,
                    "unit": "1/time",
                    "note": "paper App. 'Escape Condition': any r_esc slightly above 1 gives the same "
                    "observations (paired slope of log P(t) ratio on a common window)",
                }
            )
    return numbers, rows


def _returns_numbers(ret, r_in, fast):
    numbers, rows = {}, []
    for row in ret.itertuples():
        numbers.setdefault(f"E={row.energy:.2f}", {})[f"r_esc={row.r_esc:g}"] = {
            "n_escaped": row.n_escaped,
            "n_returned": row.n_returned,
            "n_back_inside_r_esc": row.n_recrossed,
            # each fraction states its number of trials n: a count of 0 is read as its one-sided bound
            "fraction": {"value": row.frac, "lo": row.lo, "hi": row.hi, "upper95": row.upper95, "n": row.n_escaped},
            "returned_then_reescaped": row.n_reescaped,
            "stay_median": row.stay_median,
            "stay_mean": row.stay_mean,
            "one_over_kappa_ref": 1.0 / row.kappa_ref,
            "fraction_reescaping_within_reesc_fast": {
                "value": row.frac_fast,
                "lo": row.frac_fast_lo,
                "hi": row.frac_fast_hi,
                "n": row.n_returned,
            },
            # the same for a typical survivor of the exponential regime: 1 − e^{−κ t_fast}
            "typical_survivor_fraction_within_reesc_fast": 1.0 - math.exp(-row.kappa_ref * fast),
            "reesc_fast": fast,
            "fraction_late": {
                "value": row.frac_late,
                "lo": row.lo_late,
                "hi": row.hi_late,
                "t_late": row.t_late,
                "n": getattr(row, "n_escaped_late", None),
            },
        }
        counted = row.n_returned == 0
        rows.append(
            {
                "quantity": return_quantity(r_in, row.r_esc, row.energy),
                "ours": row.frac,
                # a count of 0 has no σ: the row states its one-sided 95 % bound from n (verdicts.row_bound)
                "err": None if counted else 0.5 * (row.hi - row.lo),
                "paper": 0.0,
                "n": int(row.n_escaped),
                "note": "paper: crossing r_esc slightly above 1 means the orbit has left Ω for good; "
                + (
                    "no return among n escaped orbits: the one-sided 95 % bound"
                    if counted
                    else "err = half the Wilson ±1σ interval"
                ),
            }
        )
    return numbers, rows


def return_quantity(r_in: float, r: float, E: float) -> str:
    """The quantity of the returns row of cell (E, r) in the paper comparison.

    >>> return_quantity(1.0, 1.5, 0.3)
    'fraction returning inside r<1 after crossing r_esc=1.5 (E=0.30)'
    """
    return f"fraction returning inside r<{r_in:g} after crossing r_esc={r:g} (E={E:.2f})"


def with_return_counts(numbers: dict) -> dict:
    """with_return_counts(numbers JSON) -> the same numbers with each returns row of its ``paper_comparison`` and
    each fraction of its ``returns`` record given its number of trials ``n`` where it does not state it (a record
    written before they carried their count), so that a count of 0 is read as its one-sided bound
    (:func:`hhscatter.reproduction.verdicts.row_bound`), never "0 [0, hi]". Numbers of any other study come back
    unchanged.

    The counts come from the record itself: ``n_escaped`` for ``fraction``, ``n_returned`` for the fraction
    re-escaping fast; for ``fraction_late``, whose count of escapes after the window start older records do not
    state, from its Wilson interval at the study's ``z``: at 0 of n the upper end is z²/(n + z²).

    Examples
    --------
    >>> doc = {"config": {"study": {"r_in": 1.0}}, "returns": {"E=0.30": {"r_esc=1.5": {"n_escaped": 60000}}},
    ...        "paper_comparison": [{"quantity": return_quantity(1.0, 1.5, 0.3), "ours": 0.0, "paper": 0.0}]}
    >>> with_return_counts(doc)["paper_comparison"][0]["n"]
    60000
    >>> cell = {"n_escaped": 60000, "n_returned": 0, "fraction": {"value": 0.0, "lo": 0.0, "hi": 1 / 60001},
    ...         "fraction_late": {"value": 0.0, "lo": 0.0, "hi": 1 / 6394}}
    >>> doc = {"config": {"study": {"r_in": 1.0, "z": 1.0}}, "returns": {"E=0.30": {"r_esc=1.5": cell}}}
    >>> out = with_return_counts(doc)["returns"]["E=0.30"]["r_esc=1.5"]
    >>> out["fraction"]["n"], out["fraction_late"]["n"]
    (60000, 6393)
    """
    returns = numbers.get("returns")
    study = (numbers.get("config") or {}).get("study") or {}
    r_in = study.get("r_in")
    if not isinstance(returns, dict) or not isinstance(r_in, (int, float)):
        return numbers
    z = study.get("z", 1.0)
    counts, cells_out = {}, {}
    for e_key, cells in returns.items():
        cells_out[e_key] = cells
        if not isinstance(cells, dict):
            continue
        filled_cells = {}
        for r_key, cell in cells.items():
            filled_cells[r_key] = _cell_with_counts(cell, z) if isinstance(cell, dict) else cell
            try:
                E, r = float(e_key.partition("=")[2]), float(r_key.partition("=")[2])
            except ValueError:
                continue
            if isinstance(cell, dict) and isinstance(cell.get("n_escaped"), int):
                counts[return_quantity(r_in, r, E)] = cell["n_escaped"]
        cells_out[e_key] = filled_cells
    out = {**numbers, "returns": cells_out}
    rows = numbers.get("paper_comparison")
    if rows:
        out["paper_comparison"] = [
            {**row, "n": counts[row.get("quantity")]} if row.get("quantity") in counts and "n" not in row else row
            for row in rows
        ]
    return out


def _cell_with_counts(cell: dict, z) -> dict:
    """One cell of a ``returns`` record with ``n`` in each of its fractions (see :func:`with_return_counts`)."""
    out = dict(cell)
    sources = {"fraction": cell.get("n_escaped"), "fraction_reescaping_within_reesc_fast": cell.get("n_returned")}
    for key, n in sources.items():
        frac = cell.get(key)
        if isinstance(frac, dict) and "n" not in frac and isinstance(n, int) and not isinstance(n, bool):
            out[key] = {**frac, "n": n}
    late = cell.get("fraction_late")
    hi = late.get("hi") if isinstance(late, dict) else None
    if (
        isinstance(late, dict)
        and "n" not in late
        and late.get("value") == 0
        and isinstance(hi, (int, float))
        and 0 < hi < 1
        and isinstance(z, (int, float))
        and z > 0
    ):
        out["fraction_late"] = {**late, "n": int(round(z * z * (1.0 - hi) / hi))}
    return out


def criterion_numbers(energies, radii, r_ref, kap, ret, chan, lyap, *, r_in: float, fast: float):
    """The numbers of the escape-criterion study and its comparison rows (the keyword arguments of a study's
    ``compare``): κ shifts against 0, the fraction of returns against 0, the channel fractions against 1/3 (the
    three-fold symmetry of V and of the disk ICs), and the recommended default r_esc (:func:`recommend_r_esc`).

    ``kap``, ``ret``, ``chan``, ``lyap``: the tables of :func:`kappa_row`, :func:`returns_row`, :func:`channel_rows`
    and :func:`lyapunov_table`; ``r_in``: the radius a return must reach; ``fast``: the re-escape time of the fast
    fraction.

    Returns
    -------
    (dict, list of dict)
        The numbers (energies, r_esc, r_ref, kappa, returns, channels, lyapunov, default_r_esc) and the rows.
    """
    kappa, rows = _kappa_numbers(kap, r_ref)
    returns, ret_rows = _returns_numbers(ret, r_in, fast)
    rows += ret_rows
    channels = {}
    for row in chan.itertuples():
        channels.setdefault(f"E={row.energy:.2f}", {}).setdefault(f"r_esc={row.r_esc:g}", {}).setdefault(
            row.subset, {"n": row.n, "chi2_p_value": row.p_value}
        )[f"channel {row.channel}"] = {"value": row.frac, "lo": row.lo, "hi": row.hi}
    sym = chan[(chan.subset == "all") & (chan.r_esc == r_ref)]
    # under exact symmetry each row lies beyond 2σ with probability erfc(√2) ≈ 0.046: the family's expectation
    by_chance = len(sym) * math.erfc(math.sqrt(2.0))
    for row in sym.itertuples():
        rows.append(
            {
                "quantity": f"escape fraction through channel {row.channel} (E={row.energy:.2f}, r_esc={r_ref:g})",
                "ours": row.frac,
                "err": 0.5 * (row.hi - row.lo),
                "paper": 1.0 / 3.0,
                "note": "three-fold symmetry of V and of the disk ICs (rotation by 120° maps the IC ensemble onto "
                f"itself); the three fractions at this E together: χ² p = {row.p_value:.2g}; under exact symmetry "
                f"{by_chance:.1f} of these {len(sym)} rows lie beyond 2σ by chance",
            }
        )
    numbers = {
        "energies": energies,
        "r_esc": radii,
        "r_ref": r_ref,
        "kappa": kappa,
        "returns": returns,
        "channels": channels,
        "lyapunov": {
            f"E={row.energy:.2f}": {"r_min": row.r_min, "r_max": row.r_max, "period": row.period}
            for row in lyap.itertuples()
        },
        "default_r_esc": recommend_r_esc(ret, lyap, r_ref),
    }
    return numbers, rows


def paired_runs(read, radii, r_ref: float, E: float):
    """({r: (t_end, observed)}, {r: exit channel}) of the runs at energy ``E``, which must hold the same orbits.

    ``read(r)`` gives the run at r_esc = r as arrays (traj_id, t_end, observed, exit channel) sorted by traj_id;
    the runs are read one at a time, r_ref first, and every one's traj_id must equal r_ref's, else ValueError.

    Examples
    --------
    >>> runs = {1.5: (np.arange(3), np.ones(3), np.ones(3, bool), np.zeros(3)), 2.0: (np.arange(3),) + (None,) * 3}
    >>> arrs, chans = paired_runs(runs.get, [2.0, 1.5], 1.5, 0.3)
    >>> list(arrs), list(chans)
    ([1.5, 2.0], [1.5, 2.0])
    """
    arrs, chans = {}, {}
    ids_ref = None
    for r in sorted(radii, key=lambda v: v != r_ref):
        ids, t_, o_, chans[r] = read(r)
        arrs[r] = (t_, o_)
        if ids_ref is None:
            ids_ref = ids
        elif not np.array_equal(ids, ids_ref):
            raise ValueError(f"E={E}: runs r_esc={r} and {r_ref} do not hold the same orbits")
    return arrs, chans


def follow_returns(crossings: pd.DataFrame, lifetimes: pd.DataFrame, radii, r_in: float):
    """(lifetimes, {r: returns back inside r_in}, {r: back inside r itself}) of runs followed past their escape.

    ``crossings``: the follow run's crossings (traj_id, t, radius, direction), with the exact radii r_in and
    every r of ``radii``; ``lifetimes``: its traj_id, outcome, t_end, e0, e_end (an orbit that never escapes is
    censored at t_max, its t_end). Per r: :func:`~hhscatter.analysis.geometry.channels.return_statistics` with
    r_esc = r back inside ``r_in``, and whether the orbit comes back inside r itself after its first escape.
    The lifetimes come back sorted by traj_id with ``energy_error`` = |e_end − e0| (energy units).

    Examples
    --------
    >>> cross = pd.DataFrame({"traj_id": [0, 0, 0], "t": [1.0, 2.0, 3.0], "radius": [1.5, 1.0, 1.5],
    ...                       "direction": [1, -1, 1]})
    >>> ends = pd.DataFrame({"traj_id": [0], "outcome": ["escaped"], "t_end": [3.0], "e0": [0.3], "e_end": [0.3]})
    >>> ends, rs, back = follow_returns(cross, ends, [1.5], 1.0)
    >>> bool(rs[1.5]["returned"][0]), float(rs[1.5]["t_reesc"][0]), bool(back[1.5][0])
    (True, 3.0, False)
    """
    from hhscatter.analysis.geometry.channels import return_statistics  # deferred: geometry loads on first use

    cross = crossings.sort_values(["traj_id", "t"], kind="stable")
    ends = lifetimes.sort_values("traj_id")
    ends["energy_error"] = (ends["e_end"] - ends["e0"]).abs()
    nf = len(ends)
    cols = (cross.traj_id.to_numpy(), cross.t.to_numpy(), cross.radius.to_numpy(), cross.direction.to_numpy())
    rs = {r: return_statistics(*cols, nf, r, r_in) for r in radii}
    # broader: back inside r_esc itself (not necessarily inside r_in) after the first escape
    recross = {r: return_statistics(*cols, nf, r, r)["returned"] for r in radii}
    return ends, rs, recross
