"""Study ``resc``: is the escape criterion r > r_esc sound? (paper App. "Escape Condition").

The paper deems a conservative orbit escaped at its first outward crossing of
r_esc "slightly larger than 1" and states that all values tried gave the same
observations.  This study measures, at E = 0.25, 0.30, 0.35:

1. κ for r_esc ∈ {1.03, 1.1, 1.5, 2.0} on the *same* initial conditions
   (paired), every cell by the same rules.  One common window per energy:
   the median of the four cells' exponential-regime windows found by
   :func:`~hhscatter.analysis.survival.windows.choose_windows` (the paper's rule),
   started no earlier than the time where the r_ref curve has fallen to
   ``p_start`` = 0.1 (the prompt-escape transient, whose hazard peak at
   t ≈ 5 and ringing would otherwise be shifted in and out of the window by
   the flight time).  Reported per cell: κ by the constant-hazard MLE
   (:func:`~hhscatter.analysis.survival.escape_rate.escape_rate_mle`) on that window;
   κ by the paper's mean of 4 least-squares fits with the cell's own windows
   (Fig. 2b caption); and the shift κ(r) − κ(r_ref) from the slope of the
   paired log-survival ratio
   (:func:`~hhscatter.analysis.survival.paired.survival_ratio_slope`), the
   main estimator (the MLE difference is kept as a cross-check: it is
   dominated by the window's first e-fold and so sensitive to the
   period-scale modulation of the hazard).  Delays: the mean flight time
   from r_ref to r on identical trajectories and the delay of P(t).
2. Returns: orbits followed past their escape (the engine's ``follow``
   scene option, table ``crossings``); the fraction
   that comes back inside r < 1 after crossing r_esc outward (Wilson
   intervals) and how fast those escape again; the radial extent of the
   Lyapunov orbit (the exact boundary of Ω) at each energy.
3. Exit channels: fraction of escapes per channel with Wilson intervals
   against the 1/3 of the three-fold symmetry, for all escapes and for
   early (t ≤ τ0) and late (t > τ0) ones.

Outputs (``studies/resc/out/<scale>/``): derived/kappa.parquet,
derived/returns.parquet, derived/channels.parquet, derived/lyapunov.parquet,
resc.json, resc.png.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.scene.schema import Integer, Number, Numbers, StudyParams


class Params(StudyParams):
    """``[study]`` of studies/resc/study.toml."""

    energies: Numbers
    r_esc: Numbers
    r_ref: Number
    r_in: Number = 1.0
    r_far: Number = 10.0
    n_follow: Integer
    z: Number = 1.0
    p_start: Number = 0.1
    n_groups: Integer = 16
    reesc_fast: Number = 10.0
    lyapunov_energies: Numbers = []


# -- keys -------------------------------------------------------------------
def _key(E, r):
    return f"E{E:.2f}_r{r:g}"


def _follow_key(E):
    return f"follow_E{E:.2f}"


def _grid(study):
    return list(study.params.energies), list(study.params.r_esc)


def _follow_radii(study):
    _, radii = _grid(study)
    return tuple(sorted({study.params.r_in, *radii}))


# -- simulate ---------------------------------------------------------------
def _follow_scene(study, E):
    """The first n_follow orbits of the (E, r_ref) ensemble, followed past their escape (scene option
    ``follow``): every crossing of the follow radii, until r_far or t_max."""
    from hhscatter.scene.scene import Follow

    r_ref = study.params.r_ref
    base = study.scene(_key(E, r_ref), energy=E, r_esc=r_ref)
    return study.scene(
        _follow_key(E),
        energy=E,
        r_esc=r_ref,
        n=min(study.params.n_follow, base.n),
        r_far=study.params.r_far,
        follow=Follow(_follow_radii(study)),
    )


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None) -> None: the (E, r_esc) engine runs and the follow runs."""
    energies, radii = _grid(study)
    for E in energies:
        for r in radii:
            study.run(_key(E, r), study.scene(_key(E, r), energy=E, r_esc=r), workers=workers, progress=progress)
        study.run(_follow_key(E), _follow_scene(study, E), workers=workers, progress=progress)


# -- analyze ----------------------------------------------------------------
def _lifetimes(study, E, r):
    """(traj_id, t_end, observed, exit_channel) arrays of run (E, r), sorted by traj_id (channel −1: none).

    Read as Arrow columns into numpy (no pandas frame, no Python object per orbit): 1e7 orbits per run at
    paper scale, 4 runs per energy held at once.
    """
    from hhscatter.analysis.survival.fits import observed_from_outcome
    from hhscatter.data.read import read_by_orbit

    c = read_by_orbit(study.raw(_key(E, r)), ["outcome", "t_end", "exit_channel"])
    obs = observed_from_outcome(c["outcome"])
    ch = np.where(obs, c["exit_channel"], -1).astype(np.int8)
    return c["traj_id"], c["t_end"], obs, ch


def analyze(study):
    """analyze(study) -> None: derived tables and resc.json (see the module docstring).

    Steps per energy: the paired runs (:func:`_paired_runs`), the common κ
    window (:func:`_common_window`), the follow runs' returns
    (:func:`_follow_returns`), then per r_esc the κ row (:func:`_kappa_row`),
    the returns row (:func:`_returns_row`) and the exit channels
    (:func:`_channel_rows`); then the numbers and the comparison
    (:func:`_numbers_and_comparison`).
    """
    energies, radii = _grid(study)
    r_ref = study.params.r_ref
    if r_ref not in radii:
        raise ValueError(f"[study] r_ref = {r_ref} must be one of r_esc = {radii}")
    lyap = _lyapunov_table(study, energies)
    lyap_at = {row.energy: row for row in lyap.itertuples()}

    k_rows, ret_rows, ch_rows = [], [], []
    for E in energies:
        arrs, chans = _paired_runs(study, E, radii, r_ref)
        grid, own, win = _common_window(study, arrs, radii, r_ref)
        ends, rs, recross = _follow_returns(study, E, radii)
        for r in radii:
            k_row, ps = _kappa_row(study, E, r, r_ref, arrs, own, win, rs, ends)
            k_rows.append(k_row)
            ret_rows.append(_returns_row(study, E, r, rs[r], recross[r], win, ps, lyap_at[E], ends))
            ch_rows.extend(_channel_rows(study, E, r, chans[r], arrs[r][0], win))
        del arrs, chans, own, ends, rs, recross  # 4 runs of 1e7 orbits: free them before the next energy's
    kap = pd.DataFrame(k_rows)
    ret = pd.DataFrame(ret_rows)
    chan = pd.DataFrame(ch_rows)
    study.write_table(kap, "kappa.parquet")
    study.write_table(ret, "returns.parquet")
    study.write_table(chan, "channels.parquet")
    study.write_table(lyap, "lyapunov.parquet")
    study.write_numbers(_numbers_and_comparison(study, energies, radii, r_ref, kap, ret, chan, lyap))


def _lyapunov_table(study, energies) -> pd.DataFrame:
    """The Lyapunov orbit of the exits (the exact boundary of Ω) at every energy of the study and of
    ``lyapunov_energies``: radial extent r_min, r_max, y on the axis, period."""
    from hhscatter.analysis.geometry.channels import lyapunov_orbit

    rows = []
    for E in sorted({*study.params.lyapunov_energies, *energies}):
        L = lyapunov_orbit(E)
        rows.append({"energy": E, "r_min": L.r_min, "r_max": L.r_max, "y_axis": L.y_axis, "period": L.period})
    return pd.DataFrame(rows)


def _paired_runs(study, E, radii, r_ref):
    """({r: (t_end, observed)}, {r: exit channel}) of the runs at energy E, which must hold the same orbits."""
    arrs, chans = {}, {}
    ids_ref = None
    for r in sorted(radii, key=lambda v: v != r_ref):
        ids, t_, o_, chans[r] = _lifetimes(study, E, r)
        arrs[r] = (t_, o_)
        if ids_ref is None:
            ids_ref = ids
        elif not np.array_equal(ids, ids_ref):
            raise ValueError(f"E={E}: runs r_esc={r} and {r_ref} do not hold the same orbits")
    return arrs, chans


def _common_window(study, arrs, radii, r_ref):
    """(grid, {r: EscapeRateResult or None}, window) of one energy.

    (a) the paper's rule (mean of 4 LSQ fits) with each cell's own windows;
    (b) one common window for the paired estimators: the median of the cells'
    own windows (robust to one cell's plateau search picking an outlying τ0),
    started no earlier than where the reference P(t) has fallen to p_start: a
    prompt-escape transient inside the window (hazard peak at t ≈ 5, ringing
    for a few periods) would be shifted in or out by the flight time and
    masquerade as a κ shift.
    """
    import warnings

    from hhscatter.analysis.survival.escape_rate import escape_rate
    from hhscatter.analysis.survival.fits import survival_curve

    t_ref, _ = arrs[r_ref]
    n_tot = t_ref.size
    t_hi = float(np.quantile(t_ref, 1 - 10 / n_tot)) if n_tot > 20 else float(t_ref.max())
    grid = np.linspace(0.0, t_hi, 20001)
    curves = {r: survival_curve(*arrs[r], grid) for r in radii}
    own = {}
    for r in radii:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                own[r] = escape_rate(*arrs[r], grid, detect_tail=False)
        except ValueError:
            own[r] = None
    p_start = study.params.p_start
    below = np.flatnonzero(curves[r_ref].P <= p_start)
    t_p = float(grid[below[0]]) if below.size else 0.0
    tau0s = [own[r].tau0 for r in radii if own[r] is not None]
    stops = [own[r].t_stop for r in radii if own[r] is not None]
    win = (max(t_p, float(np.median(tau0s)) if tau0s else 0.0), float(np.median(stops)) if stops else t_hi)
    if not win[1] > win[0]:
        win = (t_p, t_hi)
    return grid, own, win


def _follow_returns(study, E, radii):
    """(follow-run lifetimes, {r: return statistics back inside r_in}, {r: back inside r itself}) at energy E:
    returns and flight times on identical trajectories (the follow runs' ``crossings``)."""
    from hhscatter.analysis.geometry.channels import return_statistics
    from hhscatter.data.read import read_crossings, read_lifetimes

    r_in = study.params.r_in
    fdir = study.raw(_follow_key(E))
    cross = read_crossings(fdir).sort_values(["traj_id", "t"], kind="stable")
    ends = read_lifetimes(fdir, columns=["traj_id", "outcome", "t_end", "e0", "e_end"]).sort_values("traj_id")
    # a followed orbit that never escapes is censored at t_max (its t_end)
    ends["energy_error"] = (ends["e_end"] - ends["e0"]).abs()
    nf = len(ends)
    cols = (cross.traj_id.to_numpy(), cross.t.to_numpy(), cross.radius.to_numpy(), cross.direction.to_numpy())
    rs = {r: return_statistics(*cols, nf, r, r_in) for r in radii}
    # broader: back inside r_esc itself (not necessarily inside r_in) after the first escape
    recross = {r: return_statistics(*cols, nf, r, r)["returned"] for r in radii}
    return ends, rs, recross


def _kappa_row(study, E, r, r_ref, arrs, own, win, rs, ends):
    """(row of kappa.parquet, PairedShift) of cell (E, r): κ by the MLE on the common window, its shift from
    r_ref (paired log-survival-ratio slope; on the follow runs too), the paper's LSQ κ, delays and flight
    times."""
    from hhscatter.analysis.survival.escape_rate import escape_rate_mle
    from hhscatter.analysis.survival.paired import paired_mle_shift, survival_ratio_slope

    t_ref, obs_ref = arrs[r_ref]
    n_tot = t_ref.size
    t_alt, obs_alt = arrs[r]
    res = own[r]
    if res is not None:
        k_lsq, k_lsq_err, tau0, t_stop = res.kappa, res.kappa_err, res.tau0, res.t_stop
    else:
        k_lsq = k_lsq_err = tau0 = t_stop = math.nan
    ps = paired_mle_shift(t_ref, obs_ref, t_alt, obs_alt, *win)
    mle = escape_rate_mle(t_alt, obs_alt, *win)
    rsl = survival_ratio_slope(t_ref, obs_ref, t_alt, obs_alt, win, n_groups=study.params.n_groups)
    # delay of P(t) at the window start: log(P_alt/P_ref)(t_lo)/κ_ref (the flight time, plus the
    # premature escapes of r_ref accumulated up to t_lo)
    tshift = rsl.offset / ps.kappa_ref if r != r_ref else 0.0
    both = obs_alt & obs_ref
    dt = t_alt[both] - t_ref[both]
    s_ref, s = rs[r_ref], rs[r]
    ok = np.isfinite(s["t_esc"]) & np.isfinite(s_ref["t_esc"])
    flight = s["t_esc"][ok] - s_ref["t_esc"][ok]
    # the same shift on the follow runs: both criteria on one and the same trajectory
    # (no divergence of the paired runs), smaller sample
    fol = math.nan, math.nan
    if r != r_ref:
        tf_ref = np.where(np.isfinite(s_ref["t_esc"]), s_ref["t_esc"], ends.t_end.to_numpy())
        tf_alt = np.where(np.isfinite(s["t_esc"]), s["t_esc"], ends.t_end.to_numpy())
        try:
            rf = survival_ratio_slope(
                tf_ref,
                np.isfinite(s_ref["t_esc"]),
                tf_alt,
                np.isfinite(s["t_esc"]),
                win,
                n_groups=study.params.n_groups,
            )
            fol = rf.shift, rf.shift_err
        except ValueError:
            pass
    row = {
        "energy": E,
        "r_esc": r,
        "n": n_tot,
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
        "flight_mean": float(flight.mean()) if flight.size else math.nan,
        "flight_err": float(flight.std(ddof=1) / math.sqrt(flight.size)) if flight.size > 1 else math.nan,
        "flight_median": float(np.median(flight)) if flight.size else math.nan,
        "dt_end_mean": float(dt.mean()) if dt.size else math.nan,
        "dt_end_err": float(dt.std(ddof=1) / math.sqrt(dt.size)) if dt.size > 1 else math.nan,
    }
    return row, ps


def _returns_row(study, E, r, s, recrossed, win, ps, lyapE, ends) -> dict:
    """Row of returns.parquet of cell (E, r): the fraction of escapes that come back inside r_in (all, and after
    the window start) with Wilson intervals, how fast they escape again, the Lyapunov orbit's extent."""
    from hhscatter.analysis.stats.intervals import wilson_interval

    z = study.params.z
    fast = study.params.reesc_fast
    nf = len(ends)
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
        "upper95": float(wilson_interval(n_ret, n_esc, 1.96)[2]),
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
        "kappa_ref": ps.kappa_ref,
        "n_fast": n_fast,
        "frac_fast": float(pf),
        "frac_fast_lo": float(flo),
        "frac_fast_hi": float(fhi),
        "lyap_r_min": lyapE.r_min,
        "lyap_r_max": lyapE.r_max,
        "energy_error_max": float(ends.energy_error.max()),
        "n_censored_follow": int((ends.outcome == "censored").sum()),
    }


def _channel_rows(study, E, r, ch, t_alt, win) -> list:
    """Rows of channels.parquet of cell (E, r): escape fractions per exit channel with Wilson intervals and the
    χ² test of equal thirds, for all escapes and for those before / after the window start."""
    from hhscatter.analysis.geometry.channels import channel_fractions

    z = study.params.z
    n_tot = t_alt.size
    rows = []
    for subset, m in (("all", np.ones(n_tot, bool)), ("early", t_alt <= win[0]), ("late", t_alt > win[0])):
        cf = channel_fractions(ch[m], 3, z)
        for k in range(3):
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


def _numbers_and_comparison(study, energies, radii, r_ref, kap, ret, chan, lyap) -> dict:
    """resc.json's numbers from the tables, the paper comparison (κ shifts, returns, channels), the default
    r_esc recommended."""
    r_in = study.params.r_in
    fast = study.params.reesc_fast
    numbers = {
        "energies": energies,
        "r_esc": radii,
        "r_ref": r_ref,
        "kappa": {},
        "returns": {},
        "channels": {},
        "lyapunov": {},
    }
    for row in kap.itertuples():
        key = f"E={row.energy:.2f}"
        numbers["kappa"].setdefault(key, {})[f"r_esc={row.r_esc:g}"] = {
            "kappa": {"value": row.kappa, "err": row.kappa_err},
            "shift_vs_ref": {"value": row.kappa_shift, "err": row.kappa_shift_err},
            "mle_difference_vs_ref": {"value": row.mle_shift, "err": row.mle_shift_err},
            "shift_vs_ref_follow_runs": {"value": row.kappa_shift_follow, "err": row.kappa_shift_follow_err},
            "kappa_lsq": {"value": row.kappa_lsq, "err": row.kappa_lsq_err},
            "window": [row.t_start, row.t_stop],
            "delay_of_P": row.time_shift,
            "flight_time_from_ref": {"value": row.flight_mean, "err": row.flight_err},
            "mean_t_end_difference": {"value": row.dt_end_mean, "err": row.dt_end_err},
        }
        if row.r_esc != r_ref:
            study.compare(
                f"κ(E={row.energy:.2f}, r_esc={row.r_esc:g}) − κ(r_esc={r_ref:g})",
                row.kappa_shift,
                row.kappa_shift_err,
                0.0,
                unit="1/time",
                note="paper App. 'Escape Condition': any r_esc slightly above 1 gives the same "
                "observations (paired slope of log P(t) ratio on a common window)",
            )
    for row in ret.itertuples():
        numbers["returns"].setdefault(f"E={row.energy:.2f}", {})[f"r_esc={row.r_esc:g}"] = {
            "n_escaped": row.n_escaped,
            "n_returned": row.n_returned,
            "n_back_inside_r_esc": row.n_recrossed,
            "fraction": {"value": row.frac, "lo": row.lo, "hi": row.hi, "upper95": row.upper95},
            "returned_then_reescaped": row.n_reescaped,
            "stay_median": row.stay_median,
            "stay_mean": row.stay_mean,
            "one_over_kappa_ref": 1.0 / row.kappa_ref,
            "fraction_reescaping_within_reesc_fast": {
                "value": row.frac_fast,
                "lo": row.frac_fast_lo,
                "hi": row.frac_fast_hi,
            },
            # the same for a typical survivor of the exponential regime: 1 − e^{−κ t_fast}
            "typical_survivor_fraction_within_reesc_fast": 1.0 - math.exp(-row.kappa_ref * fast),
            "reesc_fast": fast,
            "fraction_late": {"value": row.frac_late, "lo": row.lo_late, "hi": row.hi_late, "t_late": row.t_late},
        }
        study.compare(
            f"fraction returning inside r<{r_in:g} after crossing r_esc={row.r_esc:g} (E={row.energy:.2f})",
            row.frac,
            0.5 * (row.hi - row.lo),
            0.0,
            note="paper: crossing r_esc slightly above 1 means the orbit has left Ω for good; "
            "err = half the Wilson ±1σ interval",
        )
    for row in chan.itertuples():
        numbers["channels"].setdefault(f"E={row.energy:.2f}", {}).setdefault(f"r_esc={row.r_esc:g}", {}).setdefault(
            row.subset, {"n": row.n, "chi2_p_value": row.p_value}
        )[f"channel {row.channel}"] = {"value": row.frac, "lo": row.lo, "hi": row.hi}
    for row in chan[(chan.subset == "all") & (chan.r_esc == r_ref)].itertuples():
        study.compare(
            f"escape fraction through channel {row.channel} (E={row.energy:.2f}, r_esc={r_ref:g})",
            row.frac,
            0.5 * (row.hi - row.lo),
            1.0 / 3.0,
            note="three-fold symmetry of V and of the disk ICs (rotation by 120° maps the IC ensemble onto itself)",
        )
    for row in lyap.itertuples():
        numbers["lyapunov"][f"E={row.energy:.2f}"] = {"r_min": row.r_min, "r_max": row.r_max, "period": row.period}
    numbers["default_r_esc"] = _recommend(kap, ret, lyap, r_ref)
    return numbers


def _recommend(kap, ret, lyap, r_ref):
    """Default r_esc: the smallest tested radius beyond every Lyapunov orbit of the energies considered
    (the exact no-return boundary of Ω) with no measured return at any energy."""
    radii = sorted(ret.r_esc.unique())
    r_lyap = float(lyap.r_max.max())
    ok = [r for r in radii if r > r_lyap and ret[ret.r_esc == r].n_returned.sum() == 0]
    choice = ok[0] if ok else radii[-1]
    return {
        "recommended": float(choice),
        "current": float(r_ref),
        "lyapunov_r_max_at_max_energy": float(lyap.r_max.max()),
        "lyapunov_energy_max": float(lyap.energy.max()),
        "rule": "smallest tested r_esc with zero measured returns at every energy; it must exceed the radial "
        "extent r_max of the Lyapunov orbit (the exact boundary of Ω) at the highest energy used",
    }


# -- plot -------------------------------------------------------------------
def plot(study):
    """plot(study) -> None: resc.png from the derived tables."""
    from .figure import plot_resc

    d = study.out / "derived"
    plot_resc(
        kappa=pd.read_parquet(d / "kappa.parquet"),
        returns=pd.read_parquet(d / "returns.parquet"),
        channels=pd.read_parquet(d / "channels.parquet"),
        lyapunov=pd.read_parquet(d / "lyapunov.parquet"),
        path=study.figure_path,
        r_ref=study.params.r_ref,
        scale=study.scale,
    )
