"""Evidence behind the claims' readings: regular orbits counted, long-time escape resolved, where the claims hold.

Pure pieces (frames in, records out) for a study that runs, per system and energy E = r·E_c, a conservative
ensemble to t_max with the section recorded near its end and the shadow runs of the orbits still inside then
(:mod:`hhscatter.analysis.geometry.regularity`):

* :func:`regular_record` — the regular fraction of an ensemble: orbits the shadow indicator calls regular over all
  orbits (those that escaped before the indicator's window are not regular), binomial error;
* :func:`long_time_record` — P(t) at chosen times (Kaplan–Meier, Greenwood errors), the plateau-plus-exponential
  fit of all orbits from t0 (P∞, κ_tail: :func:`hhscatter.analysis.survival.long_time.fit_plateau_exponential`),
  the single-exponential fit and the hazard of the non-regular orbits alone, and the fraction of the orbits still
  inside at t_max that the indicator calls regular (the only ones called "trapped");
* :func:`labelled_selection` and :func:`indicator_record` — the orbits of an ensemble's ambiguous band (and a
  sample either side) that are labelled by a second indicator, the variational FTLE of a longer run, and the
  regular fraction's indicator systematic from the two indicators' disagreements;
* :func:`validity_map` — per (system, E/E_c): the regular fraction beside claim 1's verdict (κ0 defined under the
  paper's convention), claim 2's where measured, and whether one exponential describes the non-regular orbits.

Examples
--------
>>> import numpy as np, pandas as pd
>>> lt = pd.DataFrame({"traj_id": np.arange(4), "t_end": [5.0, 50.0, 100.0, 100.0],
...                    "outcome": ["escaped", "escaped", "censored", "censored"]})
>>> ind = pd.DataFrame({"traj_id": [2, 3], "regular": [True, False], "kind": ["regular", "chaotic"]})
>>> regular_record(lt, ind)["fraction"]
0.25
>>> regular_record(lt, ind.assign(regular=False))["fraction_upper"]     # none regular of 4: a bound, not 0 ± 0
0.527129
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry.regularity import (
    G_MAX,
    indicator_systematic,
    threshold_systematic,
    variational_indicator,
)
from hhscatter.analysis.stats.goodness import TOO_FEW
from hhscatter.analysis.stats.intervals import fraction_with_bound
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.survival.kappa_conventions import dead_time_check
from hhscatter.analysis.survival.long_time import (
    fit_plateau_exponential,
    hazard_profile,
    survival_at,
)

#: P-value below which one exponential is rejected for the non-regular orbits
EXP_REJECT_P = 1e-3


def _finite(x):
    return None if x is None or not math.isfinite(float(x)) else float(x)


def regular_record(lifetimes, indicator, g_max: float = G_MAX) -> dict:
    """regular_record(lifetimes, indicator, g_max=1e4) -> {fraction, err, fraction_upper, fraction_cl, syst,
    by_threshold, n, n_regular, n_chaotic, n_none, n_escaped_before}.

    ``lifetimes``: the ensemble's traj_id, t_end, outcome; ``indicator``: :func:`shadow_indicator`'s frame for the
    orbits still inside at the window's start (traj_id, regular, kind, growth) at threshold ``g_max``. Orbits
    without an indicator row left before the window: not regular. ``n_none``: inside at the window's start but
    crossing the section in neither run (their type undetermined; counted as not regular, and said). The fraction
    by :func:`~hhscatter.analysis.stats.intervals.fraction_with_bound` (no error but a one-sided 95 % bound
    ``fraction_upper`` at a count of 0); ``syst`` the shift under a threshold a decade either side
    (:func:`~hhscatter.analysis.geometry.regularity.threshold_systematic`; ``by_threshold`` the fractions).
    """
    n = len(lifetimes)
    n_reg = int(indicator["regular"].sum())
    b = fraction_with_bound(n_reg, n)
    growth = indicator["growth"] if "growth" in indicator else indicator["regular"].map({True: 0.0, False: np.inf})
    ts = threshold_systematic(n, growth.to_numpy(float), g_max)
    return {
        "fraction": b.value,
        "err": b.err,
        **{f"fraction_{k}": v for k, v in b.record().items() if k in ("upper", "lower", "cl")},
        "syst": ts["syst"],
        "by_threshold": [{"g_max": g, "fraction": f} for g, f in ts["by_threshold"].items()],
        "n": n,
        "n_regular": n_reg,
        "n_chaotic": int((indicator["kind"] == "chaotic").sum()),
        "n_none": int((indicator["kind"] == "none").sum()),
        "n_escaped_before": int(n - len(indicator)),
    }


def labelled_selection(indicator, n: int, band, n_band: int, n_side: int, seed: int):
    """labelled_selection(indicator, n, band, n_band, n_side, seed) -> DataFrame[traj_id, growth, in_band] or None.

    The orbits of an ensemble of ``n`` orbits to label by a second indicator: None where the regular fraction (by
    the shadow indicator's frame ``indicator``: traj_id, regular, growth) is 0 or 1 (no ambiguity to resolve);
    else the orbits whose shadow growth lies in the open ``band`` (lo, hi) — at most ``n_band`` of them, drawn
    without replacement — and ``n_side`` orbits drawn from those below lo and from those at or above hi (an
    infinite growth: one of the pair escaped), all draws from ``seed`` (the same orbits at every run).

    >>> ind = pd.DataFrame({"traj_id": range(6), "regular": [True] * 3 + [False] * 3,
    ...                     "growth": [2.0, 50.0, 3e3, 1e5, 1e9, np.inf]})
    >>> sel = labelled_selection(ind, 10, (10.0, 1e7), 10, 1, 0)
    >>> sel["in_band"].tolist(), len(sel)
    ([False, True, True, True, False], 5)
    """
    n_reg = int(indicator["regular"].sum()) if len(indicator) else 0
    if n_reg == 0 or n_reg == n:
        return None
    lo, hi = (float(x) for x in band)
    g = indicator["growth"].to_numpy(float)
    ids = indicator["traj_id"].to_numpy(np.int64)
    rng = np.random.default_rng(seed)
    inside = (g > lo) & (g < hi)
    below, above = ~np.isnan(g) & (g <= lo), ~np.isnan(g) & (g >= hi)

    def draw(mask, k):
        pick = np.flatnonzero(mask)
        return np.sort(rng.choice(pick, size=min(k, pick.size), replace=False)) if pick.size else pick

    rows = np.concatenate([draw(below, n_side), draw(inside, n_band), draw(above, n_side)])
    rows = np.sort(rows)
    return pd.DataFrame({"traj_id": ids[rows], "growth": g[rows], "in_band": inside[rows]})


def indicator_record(
    n: int, indicator, selection, labelled_lifetimes, t_min: float, *, band, ftle_regular, ftle_chaotic, thresholds
) -> dict:
    """indicator_record(n, indicator, selection, labelled_lifetimes, t_min, band=, ftle_regular=, ftle_chaotic=,
    thresholds=) -> the labelled set's record of one ensemble of ``n`` orbits.

    ``indicator``: the shadow indicator's frame (traj_id, growth); ``selection``: :func:`labelled_selection`'s
    frame; ``labelled_lifetimes``: the lifetimes (with log_stretch) of the selection run again with the tangent
    dynamics to ``t_min`` or beyond. Labels by
    :func:`~hhscatter.analysis.geometry.regularity.variational_indicator`; per shadow threshold of ``thresholds``
    (the first the indicator's own) the confusion against the labels (``confusion``: rows {g_max, regular_regular,
    regular_chaotic, chaotic_regular, chaotic_chaotic, regular_undecided, chaotic_undecided}, shadow verdict first)
    and at the first threshold the systematic
    (:func:`~hhscatter.analysis.geometry.regularity.indicator_systematic`): n_band (the band's orbits in the
    ensemble), n_labelled, n_undecided, the disagreements, shift and syst (fractions of all n orbits).
    """
    lab = variational_indicator(labelled_lifetimes, t_min, ftle_regular=ftle_regular, ftle_chaotic=ftle_chaotic)
    sel = selection.merge(lab[["traj_id", "label", "ftle"]], on="traj_id", how="inner")
    if len(sel) != len(selection):
        raise ValueError(f"the labelled run holds {len(sel)} of the {len(selection)} selected orbits")
    g_all = indicator["growth"].to_numpy(float)
    lo, hi = (float(x) for x in band)
    n_band = int(((g_all > lo) & (g_all < hi)).sum())
    g, label = sel["growth"].to_numpy(float), sel["label"].to_numpy(object)
    confusion = []
    for gm in thresholds:
        reg = g < gm
        row = {"g_max": float(gm)}
        for shadow, s_mask in (("regular", reg), ("chaotic", ~reg)):
            for lb in ("regular", "chaotic", "undecided"):
                row[f"{shadow}_{lb}"] = int((s_mask & (label == lb)).sum())
        confusion.append(row)
    ind = indicator_systematic(n, n_band, g < float(thresholds[0]), label, sel["in_band"].to_numpy(bool))
    return {
        "indicator": "variational FTLE",
        "t_label": float(t_min),
        "ftle_regular": float(ftle_regular),
        "ftle_chaotic": float(ftle_chaotic),
        "band": [lo, hi],
        "n_band": n_band,
        **ind,
        "confusion": confusion,
    }


def total_error(*parts) -> float | None:
    """total_error(stat, syst, …) -> √(Σ parts²), the parts that are None left out (None when all are).

    >>> total_error(0.003, 0.004, None)
    0.005
    """
    xs = [float(x) for x in parts if x is not None]
    return round(math.sqrt(sum(x * x for x in xs)), 12) if xs else None


def long_time_record(lifetimes, regular_ids, times, t0: float, hazard_edges) -> tuple[list, dict]:
    """long_time_record(lifetimes, regular_ids, times, t0, hazard_edges) -> (P rows, fit record).

    P rows: {t, P, P_err} of all orbits at ``times`` (time units). Fit record: the plateau-plus-exponential fit from
    ``t0`` of all orbits (p_inf, kappa_inf, errors, chi2, dof), the censored and regular fractions at t_max, and the
    non-regular orbits alone (all minus ``regular_ids``): single exponential from t0 (kappa_nonregular, χ² of cells
    pooled to expected counts ≥ 5, p-value, ``exponential`` True when p ≥ EXP_REJECT_P, ``exponential_verdict``
    'yes', 'no' or 'too few orbits' when no degree of freedom is left) and their hazard per bin of
    ``hazard_edges`` (a bin with no escape: hazard 0 with its one-sided 95 % bound ``hazard_upper``, no error). A P
    of 0 carries its one-sided 95 % bound ``P_upper`` instead of an error; so does a P∞ of 0
    with no orbit inside at t_max (``P_inf_upper``).
    """
    t = lifetimes["t_end"].to_numpy(float)
    obs = (lifetimes["outcome"].astype(str) != "censored").to_numpy()
    P, Pe = survival_at(t, obs, times)
    rows = [_p_row(float(a), float(b), float(c), t, obs) for a, b, c in zip(times, P, Pe)]
    reg = lifetimes["traj_id"].isin(np.asarray(regular_ids)).to_numpy()
    rec = {
        "t0": float(t0),
        "n": int(t.size),
        "censored_fraction": float((~obs).mean()),
        "regular_fraction_of_censored": float(reg[~obs].mean()) if (~obs).any() else None,
    }
    try:
        f = fit_plateau_exponential(t, obs, t0)
        if f.p_inf == 0 and obs.all():  # no plateau fitted and none inside at t_max: P∞ below the 0-of-N bound
            zero = fraction_with_bound(0, t.size).record("P_inf")
            rec.update({k: v for k, v in zero.items() if k in ("P_inf_upper", "P_inf_cl")})
        rec.update(
            P_inf=f.p_inf,
            P_inf_err=_finite(f.p_inf_err),
            kappa_inf=f.kappa,
            kappa_inf_err=_finite(f.kappa_err),
            chi2=f.chi2,
            dof=f.dof,
            P_t0=f.p_t0,
        )
    except ValueError as exc:
        rec.update(P_inf=None, kappa_inf=None, reason=f"plateau fit: {exc}")
    tn, on = t[~reg], obs[~reg]
    try:
        g = fit_plateau_exponential(tn, on, t0, plateau=False)
        p = None if g.too_few else float(g.p_value)
        rec.update(
            kappa_nonregular=g.kappa,
            kappa_nonregular_err=g.kappa_err,
            chi2_nonregular=_finite(g.chi2),
            dof_nonregular=g.dof,
            p_nonregular=p,
            exponential=None if p is None else bool(p >= EXP_REJECT_P),
            exponential_verdict=TOO_FEW if p is None else ("yes" if p >= EXP_REJECT_P else "no"),
        )
    except ValueError as exc:
        rec.update(kappa_nonregular=None, exponential=None, exponential_verdict=TOO_FEW, reason_nonregular=str(exc))
    h = hazard_profile(tn, on, hazard_edges)
    rec["hazard_nonregular"] = [_hazard_bin(*row) for row in h[list(HAZARD_COLUMNS)].itertuples(index=False)]
    return rows, rec


#: the columns of :func:`~hhscatter.analysis.survival.long_time.hazard_profile` a hazard bin record is made from
HAZARD_COLUMNS = ("t_lo", "t_hi", "hazard", "hazard_err", "events", "hazard_upper")


def _hazard_bin(t_lo, t_hi, hazard, err, events, upper) -> dict:
    """{t_lo, t_hi, hazard, err, events} of one hazard bin; a bin with orbits at risk and no escape gets no error
    but its one-sided 95 % upper bound ``hazard_upper`` (and ``hazard_cl``), never "0 ± 0"."""
    out = {
        "t_lo": float(t_lo),
        "t_hi": float(t_hi),
        "hazard": _finite(hazard),
        "err": _finite(err),
        "events": int(events),
    }
    if _finite(upper) is not None:
        out.update(hazard_upper=float(upper), hazard_cl=0.95)
    return out


def _p_row(t: float, P: float, P_err: float, t_end, observed) -> dict:
    """{t, P, P_err} of one time; where no orbit is left (P = 0) or none has left (P = 1), P's one-sided 95 % bound
    from the orbits not censored before t (:func:`~hhscatter.analysis.stats.intervals.fraction_with_bound`:
    P = k/n exactly when no orbit is censored before t, as in runs censored at t_max only) and no error."""
    if P_err > 0 or P not in (0.0, 1.0):
        return {"t": t, "P": P, "P_err": P_err}
    n = int(((t_end >= t) | observed).sum())
    if n == 0:
        return {"t": t, "P": P, "P_err": None}
    return {"t": t, **fraction_with_bound(0 if P == 0 else n, n).record("P")}


def decay_curves(lifetimes, regular_ids, grid):
    """decay_curves(lifetimes, regular_ids, grid) -> DataFrame[orbits, t, P]: Kaplan–Meier P(t) on ``grid`` (time
    units) of all orbits ('all') and of the orbits not in ``regular_ids`` ('non-regular')."""
    import pandas as pd  # deferred: pandas loads on first use

    t = lifetimes["t_end"].to_numpy(float)
    obs = (lifetimes["outcome"].astype(str) != "censored").to_numpy()
    nonreg = ~lifetimes["traj_id"].isin(np.asarray(regular_ids)).to_numpy()
    out = []
    for what, sel in (("all", np.ones(t.size, bool)), ("non-regular", nonreg)):
        P = survival_at(t[sel], obs[sel], grid)[0] if sel.any() else np.full(len(grid), np.nan)
        out.append(pd.DataFrame({"orbits": what, "t": np.asarray(grid, float), "P": P}))
    return pd.concat(out, ignore_index=True)


def kappa0_rule(max_bias: float, min_survivors: float) -> str:
    """kappa0_rule(max_bias, min_survivors) -> the rule that decides "κ0 defined" in every cell of the validity map,
    in words (the rule :func:`hhscatter.reproduction.claims.kappa.window_rate` applies, with the study's
    ``max_plateau_bias`` and ``min_survivors``; :func:`kappa0_defined_by_rule` applies it to a cell's numbers).

    >>> first = kappa0_rule(0.1, 50).split("; ")[0]
    >>> first.endswith("(f∞/P(t_hi) ≤ 10 %)")
    True
    """
    return (
        f"κ0 defined iff the plateau-window rule finds a window (at least {min_survivors:g} orbits left at its end) "
        f"and the orbits still inside at t_max are at most {100 * max_bias:g} % of P(t) at the window's end "
        f"(f∞/P(t_hi) ≤ {100 * max_bias:g} %); and its window starts less than half an e-fold of its κ before the "
        "first escape, and spans at least one e-fold of its κ or one period 2π (else it holds a prompt burst, or the "
        "burst's hand-over to the regime, not the exponential regime); the regular fraction does not enter the rule"
    )


def kappa0_defined_by_rule(cell: dict, max_bias: float):
    """kappa0_defined_by_rule(cell, max_bias) -> True, False, or None (no κ0 run at the cell's energy): the rule of
    :func:`kappa0_rule` applied to the numbers a validity-map cell records: ``kappa0`` (1/time), ``plateau_bias``
    (None where the window rule found no window), and for the dead-time condition
    (:func:`~hhscatter.analysis.survival.kappa_conventions.dead_time_check`) the window's start and end
    ``kappa0_tau0``, ``kappa0_t_hi`` and the first escape ``kappa0_t_first`` (time units). A record made before the
    cells carried them is judged on the plateau condition alone.

    >>> kappa0_defined_by_rule({"kappa0": Measured(0.02, 0.001).to_dict(), "plateau_bias": 0.84}, 0.1)
    False
    >>> kappa0_defined_by_rule({"kappa0": Measured(0.02, 0.001).to_dict(), "plateau_bias": 0.03}, 0.1)
    True
    >>> burst = {"kappa0": Measured(1.26, 0.29).to_dict(), "plateau_bias": 0.0, "kappa0_tau0": 0.0, "kappa0_t_first": 1.56}
    >>> kappa0_defined_by_rule(burst, 0.1)     # the window starts 2 e-folds of its κ before anyone has left
    False
    """
    if "kappa0" not in cell:
        return None
    k, bias = (cell.get("kappa0") or {}).get("value"), cell.get("plateau_bias")
    if not (k is not None and k > 0 and bias is not None and bias <= max_bias):
        return False
    if "kappa0_tau0" not in cell:
        return True
    return _dead_time(cell, k)[0]


def _dead_time(cell: dict, kappa: float) -> tuple:
    """(ok, reason) of the dead-time conditions on a cell's window and first escape (no window start: ok)."""
    tau0, t_first = _finite(cell.get("kappa0_tau0")), _finite(cell.get("kappa0_t_first"))
    if tau0 is None:
        return True, ""
    t_hi = _finite(cell.get("kappa0_t_hi"))
    return dead_time_check(tau0, math.nan if t_first is None else t_first, kappa, t_hi=t_hi)


def _kappa0_words(row: dict, max_bias: float) -> str:
    """The κ0 verdict of one cell with the numbers that decide it."""
    bias = _finite(row.get("plateau_bias"))
    if bias is None:
        return "ill-defined: " + (row.get("reason") or "no window")
    cmp = "≤" if bias <= max_bias else ">"
    word = "defined" if row["defined"] else "ill-defined"
    pct = 100 * bias
    words = (
        f"{word}: f∞/P(t_hi) = {pct:.3g} % {cmp} {100 * max_bias:g} %"
        if pct < 1000
        else (f"{word}: f∞/P(t_hi) = {pct:.0f} % {cmp} {100 * max_bias:g} %")
    )
    kappa = _finite(row.get("kappa"))
    if bias <= max_bias and kappa is not None and kappa > 0:
        window = {"kappa0_tau0": row.get("tau0"), "kappa0_t_hi": row.get("t_hi"), "kappa0_t_first": row.get("t_first")}
        ok, dead = _dead_time(window, kappa)
        if not ok:
            words += "; " + dead
    return words


def validity_map(
    regular: list, fits: list, kappa: list, claims: list, *, ics: str = "disk", max_bias: float | None = None
) -> list:
    """validity_map(regular, fits, kappa, claims, ics='disk', max_bias=None) -> one record per (system, e_ratio) of
    ``regular``.

    Fields: the regular fraction's count (n_regular of n, regular_fraction ± err, its one-sided bound
    ``regular_fraction_upper`` at a count of 0, the threshold systematic ``regular_syst``, the indicator systematic
    ``regular_syst_indicator`` where a labelled set was run, and ``regular_err_total``, the three in quadrature:
    the error the map's rule uses); claim 1's κ0 under the
    paper's convention (all orbits, plateau windows) from the ``kappa`` records at that E/E_c (the claims' grid, or a
    κ0 run of the map with the claims' scene: ``kappa0_source``): ``kappa0`` (value, err; 1/time), ``kappa0_n``,
    ``trapped_fraction`` (still inside at t_max), ``plateau_bias`` (that fraction over P at the window's end; None
    where no window), ``kappa0_tau0``, ``kappa0_t_hi`` and ``kappa0_t_first`` (the window's start and end and the
    run's first escape, time units: the dead-time conditions), ``kappa0_defined`` (the code's decision; None where no κ0 run is at that energy),
    ``kappa0_reason`` and, with ``max_bias`` (the study's ``max_plateau_bias``), ``kappa0_verdict`` (the decision with
    the numbers that decide it, by :func:`kappa0_rule`); claim2 (claim 2's verdict at that E/E_c, paper's
    convention, where tested); exponential (one exponential describes the non-regular orbits from t0, from ``fits``;
    None with ``exponential_verdict`` 'too few orbits' where the test has no degree of freedom); plateau (P∞ > 3σ,
    from ``fits``).
    """
    out = []
    fit_at = {(f["system"], round(f["e_ratio"], 6)): f for f in fits if f.get("ics") == ics}
    for r in (x for x in regular if x["ics"] == ics):
        key = (r["system"], round(r["e_ratio"], 6))
        k = [
            x
            for x in kappa
            if x.get("system") == r["label"]
            and x.get("convention") == "plateau"
            and abs(x.get("ratio", -1) - r["e_ratio"]) < 1e-9
        ]
        c2 = [
            c
            for c in claims
            if c.get("claim") == "2"
            and c.get("system") == r["label"]
            and f"E/E_c = {r['e_ratio']:g} (all orbits" in c.get("quantity", "")
        ]
        f = fit_at.get(key, {})
        pinf, perr = f.get("P_inf"), f.get("P_inf_err")
        kap = {}
        if k:
            row = k[0]
            kap = {
                "kappa0": Measured.of(
                    _finite(row.get("kappa")), _finite(row.get("kappa_err")), n=row.get("n")
                ).to_dict(),
                "kappa0_n": row.get("n"),
                "kappa0_source": row.get("source", "claims"),
                "trapped_fraction": _finite(row.get("trapped_fraction")),
                "plateau_bias": _finite(row.get("plateau_bias")),
                "kappa0_tau0": _finite(row.get("tau0")),
                "kappa0_t_hi": _finite(row.get("t_hi")),
                "kappa0_t_first": _finite(row.get("t_first")),
                "kappa0_reason": row.get("reason") or "",
            }
            if max_bias is not None and "plateau_bias" in row:
                kap["kappa0_verdict"] = _kappa0_words(row, max_bias)
        out.append(
            {
                "id": r.get("id"),
                "system": r["system"],
                "label": r["label"],
                "e_ratio": r["e_ratio"],
                "ics": ics,
                "n": r.get("n"),
                "n_regular": r.get("n_regular"),
                "regular_fraction": r["fraction"],
                "regular_err": r["err"],
                **({"regular_fraction_upper": r["fraction_upper"]} if r.get("fraction_upper") is not None else {}),
                "regular_syst": r.get("syst"),
                "regular_syst_indicator": r.get("syst_indicator"),
                "regular_err_total": r.get("err_total"),
                "kappa0_defined": bool(k[0]["defined"]) if k else None,
                **kap,
                "claim2": c2[0]["verdict"] if c2 else None,
                "exponential": f.get("exponential"),
                "exponential_verdict": f.get("exponential_verdict"),
                "plateau": None if pinf is None or perr is None else bool(pinf > 3 * perr),
            }
        )
    return out


def first_below(regular: list, level: float = 0.01, *, ics: str = "disk") -> dict:
    """first_below(regular, level=0.01, ics='disk') -> {system: {'from': E/E_c, 'text': …}}: the lowest E/E_c from
    which every measured regular fraction lies below ``level`` ('from' None where the highest measured energy is
    not below it: out of reach, and 'text' says up to where it was measured).

    >>> first_below([{"system": "a", "ics": "disk", "e_ratio": r, "fraction": f}
    ...              for r, f in [(1.1, 0.2), (1.5, 0.004), (2.0, 0.0)]])
    {'a': {'from': 1.5, 'text': 'from 1.5 E_c on'}}
    """
    out = {}
    for s in dict.fromkeys(r["system"] for r in regular):
        rs = sorted((r["e_ratio"], r["fraction"]) for r in regular if r["system"] == s and r["ics"] == ics)
        above = [e for e, f in rs if f >= level]
        tail = [e for e, _ in rs if not above or e > max(above)]
        out[s] = (
            {"from": tail[0], "text": f"from {tail[0]:g} E_c on"}
            if tail
            else {"from": None, "text": f"not reached up to {rs[-1][0]:g} E_c (the highest energy measured)"}
        )
    return out
