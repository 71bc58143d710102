"""The records a basin study publishes: outcome codes, one record per (E0, γ), the energy scan's trends.

The measures themselves are in :mod:`hhscatter.analysis.geometry.basins` (fractions, entropies, Wada),
:mod:`hhscatter.analysis.geometry.uncertainty` (f(ε), α, the cut-off) and
:mod:`hhscatter.analysis.geometry.cutoff` (the decision rate λ and the predicted cut-off); this module turns
their results into the JSON records of a basin study and computes the summaries that combine several of
them. Pure functions: tables and result objects in, dicts and DataFrames out.

Outcome codes of a basin map: 0 … n−1 the exit channel, :data:`SETTLED_CODE` settled (drag),
:data:`TRAPPED_CODE` alive at t_max (or stopped), :data:`OUTSIDE` a forbidden cell (V ≥ E0).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry.basins import basin_entropy, basin_entropy_table, basin_fractions, wada_merging
from hhscatter.analysis.geometry.channels import channel_fractions
from hhscatter.analysis.geometry.cutoff import cutoff_comparison, decision_rate, stretch_tail
from hhscatter.analysis.geometry.uncertainty import (
    local_exponent,
    slim_fractal,
    uncertainty_cutoff,
    uncertainty_exponent,
    uncertainty_fraction,
    weighted_line,
)
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.stats.verdicts import verdict

__all__ = [
    "entropy_by_box_at",
    "CODES",
    "CODE_NAMES",
    "OUTSIDE",
    "SETTLED_CODE",
    "TRAPPED_CODE",
    "cutoff_records",
    "cutoff_summary",
    "rate_table",
    "saddle_cutoff_records",
    "saddle_cutoff_summary",
    "stretch_record",
    "stretch_summary",
    "stretch_table",
    "tangent_lambda",
    "energy_trend",
    "entropy_exponents",
    "SCAN_COLUMNS",
    "comparison_rows",
    "kantz_grassberger",
    "map_measures",
    "outcome_codes",
    "point_record",
    "point_table",
    "rate_record",
    "scan_row",
    "smooth_chi2",
    "uncertainty_fits",
    "uncertainty_row",
    "wada_record",
    "zoom_centre",
    "zoom_extent",
]

SETTLED_CODE, TRAPPED_CODE, OUTSIDE = 3, 4, -1
CODES = (0, 1, 2, SETTLED_CODE, TRAPPED_CODE)
CODE_NAMES = ("exit 0", "exit 1", "exit 2", "settled", "trapped")


def outcome_codes(lt: pd.DataFrame) -> np.ndarray:
    """Outcome code of each orbit of a lifetimes table, in traj_id order (int8).

    ``lt`` has columns traj_id, outcome ("escaped", "settled", …) and exit_channel. Escaped orbits get
    their channel, settled ones :data:`SETTLED_CODE`, the rest (alive at t_max, stopped)
    :data:`TRAPPED_CODE`.

    Examples
    --------
    >>> lt = pd.DataFrame({"traj_id": [1, 0, 2], "outcome": ["settled", "escaped", "censored"],
    ...                    "exit_channel": [None, 2, None]})
    >>> outcome_codes(lt).tolist()
    [2, 3, 4]
    """
    lt = lt.sort_values("traj_id")
    oc = lt["outcome"].astype(str).to_numpy()
    ch = lt["exit_channel"].to_numpy(dtype=float, na_value=-1)
    code = np.full(len(lt), TRAPPED_CODE, dtype=np.int8)
    esc = oc == "escaped"
    code[esc] = ch[esc].astype(np.int8)
    code[oc == "settled"] = SETTLED_CODE
    return code


def zoom_extent(extent, centre, factor):
    """The window (x0, x1, y0, y1) of a zoom by ``factor`` into the map over ``extent`` around ``centre`` (x, y):
    the same aspect, sides divided by ``factor`` (position units).

    Examples
    --------
    >>> zoom_extent((-1, 1, -1, 1), (0.5, 0.0), 10)
    (0.4, 0.6, -0.1, 0.1)
    """
    x0, x1, y0, y1 = extent
    hx, hy = (x1 - x0) / (2 * factor), (y1 - y0) / (2 * factor)
    return (centre[0] - hx, centre[0] + hx, centre[1] - hy, centre[1] + hy)


def zoom_centre(labels, extent, box=5, clearance=0):
    """Centre (x, y) of the most mixed box of a basin map, away from its edge and from forbidden cells.

    The most mixed box has the highest Gibbs entropy (first in row-major order on ties).
    ``clearance`` (cells): only boxes whose centre lies at least this far (Euclidean, in cells) from every
    forbidden cell and from the map's edge are eligible, so that a zoom window of half-width ``clearance``
    cells around the centre is wholly allowed (an unconstrained choice sits at the edge of the allowed region, where
    the zooms show mostly forbidden cells). ``extent`` = (x0, x1, y0, y1) in position units.

    Examples
    --------
    >>> lab = np.zeros((20, 20), int); lab[:, 12:] = 1; lab[12:, 12:] = 2
    >>> zoom_centre(lab, (0, 1, 0, 1))
    (0.625, 0.625)
    """
    from scipy import ndimage  # deferred: scipy loads on first use

    ent = basin_entropy(labels, box, outside=OUTSIDE)  # box_entropy: the wholly valid boxes, row-major
    nr, nc = labels.shape[0] // box, labels.shape[1] // box
    blocks = labels[: nr * box, : nc * box].reshape(nr, box, nc, box).transpose(0, 2, 1, 3).reshape(nr, nc, -1)
    valid = (blocks != OUTSIDE).all(axis=-1)
    grid = np.full((nr, nc), np.nan)
    grid[valid] = ent.box_entropy
    grid[[0, -1], :] = np.nan
    grid[:, [0, -1]] = np.nan
    if clearance > 0:
        # distance of every cell to the nearest forbidden cell or to the map's edge (padded as forbidden)
        dist = ndimage.distance_transform_edt(np.pad(labels != OUTSIDE, 1))[1:-1, 1:-1]
        centres = dist[box // 2 :: box, box // 2 :: box][:nr, :nc]
        grid[centres < clearance] = np.nan
        if np.all(np.isnan(grid)):
            raise ValueError(f"zoom_centre: no mixed box lies {clearance} cells inside the allowed region")
    i, j = np.unravel_index(np.nanargmax(grid), grid.shape)
    x0, x1, y0, y1 = extent
    return (
        float(x0 + (j + 0.5) * box * (x1 - x0) / labels.shape[1]),
        float(y0 + (i + 0.5) * box * (y1 - y0) / labels.shape[0]),
    )


def uncertainty_row(codes, t_end, energy, gamma, eps):
    """One f(ε) row from the codes of m reference ICs followed by their m shifted copies.

    Returns (row dict: energy, gamma, eps, f, f_lo, f_hi, k, n, t_decide_median; the decision times of the
    pairs whose outcome differs, i.e. the time until the first orbit of the pair leaves).
    """
    codes, t_end = np.asarray(codes), np.asarray(t_end, dtype=float)
    m = len(codes) // 2
    uf = uncertainty_fraction(codes[:m], codes[m:])
    changed = codes[:m] != codes[m:]
    t_dec = np.minimum(t_end[:m], t_end[m:])[changed]
    row = {
        "energy": energy,
        "gamma": gamma,
        "eps": eps,
        "f": uf.f,
        "f_lo": uf.lo,
        "f_hi": uf.hi,
        "k": uf.k,
        "n": uf.n,
        "t_decide_median": float(np.median(t_dec)) if t_dec.size else math.nan,
    }
    return row, t_dec


def uncertainty_fits(unc, min_count):
    """The power law f(ε) ∝ ε^α and its cut-off, fitted over the resolved ε (≥ ``min_count`` changed pairs).

    Returns (resolved mask, UncertaintyExponent or None below 3 resolved ε, UncertaintyCutoff or None
    below 5).
    """
    ok = unc["k"] >= min_count
    fit = cut = None
    if ok.sum() >= 3:
        rng = (float(unc.loc[ok, "eps"].min()), float(unc.loc[ok, "eps"].max()))
        fit = uncertainty_exponent(unc["eps"], unc["f"], unc["n"], eps_range=rng)
        if ok.sum() >= 5:
            cut = uncertainty_cutoff(unc["eps"], unc["f"], unc["n"], eps_range=rng)
    return ok, fit, cut


def wada_record(w, basins):
    """The JSON record of a :class:`~hhscatter.analysis.geometry.basins.WadaTest` (None → None)."""
    if w is None:
        return None
    return {
        "verdict": bool(w.wada),
        "basins": [CODE_NAMES[c] for c in basins],
        "W_at_r": float(w.wada_fraction[min(w.r_wada, len(w.wada_fraction) - 1)]),
        "r": int(w.r_wada),
        "hausdorff_slope": float(w.hausdorff_slope),
    }


def rate_record(eps, times):
    """λ from the pairs' decision times (:func:`~hhscatter.analysis.geometry.cutoff.decision_rate`) as a
    record {value, err, t0, chi2, dof}, or None when it cannot be measured."""
    try:
        r = decision_rate(eps, times)
    except ValueError:
        return None
    return {**Measured(r.lam, r.lam_err).to_dict(), "t0": r.t0, "chi2": r.chi2, "dof": r.dof}


def point_record(E, g, hb, ec, ent, unc, loc, m):
    """The JSON record of one (E0, γ) at the headline box ``hb`` (cells).

    ``m`` holds the measures: fr (BasinFractions), present (codes in the Wada test), wada, chans (channel
    fractions), exits, wada_x, slim, rate, ok, fit, cut (:func:`uncertainty_fits`); ``ent`` the entropy
    table over box sides, ``unc`` the f(ε) table, ``loc`` the local exponents. τ2 = ln(E0/E_c)/γ is
    Eq. (eq:tau2) with μ = 1 (∞ at γ = 0).
    """
    fr, wada, fit, cut = m["fr"], m["wada"], m["fit"], m["cut"]
    head = ent.set_index("box").loc[hb] if hb in set(ent["box"]) else None
    tau2 = math.log(E / ec) / g if g > 0 else math.inf
    smallest = unc.loc[m["ok"]].tail(1)
    return {
        "energy": E,
        "gamma": g,
        "fractions": {
            name: Measured.of(f, 0.5 * (hi - lo)).to_dict()
            for name, f, lo, hi in zip(CODE_NAMES, fr.frac, fr.lo, fr.hi)
        },
        "n_cells": int(fr.n),
        "channel_symmetry_p": float(m["chans"].p_value),
        "channel_shares_r_sym": [float(v) for v in m["chans"].frac],
        "S_b": Measured.of(head.S_b, head.S_b_err).to_dict() if head is not None else None,
        "S_bb": Measured.of(head.S_bb, head.S_bb_err).to_dict() if head is not None else None,
        "log2_fractal": bool(head.log2_fractal) if head is not None else None,
        "box_headline": hb,
        "wada": {
            "verdict": bool(wada.wada),
            "basins": [CODE_NAMES[c] for c in m["present"]],
            "W_at_r": float(wada.wada_fraction[min(wada.r_wada, len(wada.wada_fraction) - 1)]),
            "r": int(wada.r_wada),
            "hausdorff_slope": float(wada.hausdorff_slope),
        },
        "wada_exits": wada_record(m["wada_x"], m["exits"]),
        "local_d": [
            {"eps_mid": float(r.eps_mid), "d": float(r.d), "d_err": float(r.d_err)}
            for r in loc.itertuples()
            if np.isfinite(r.d)
        ],
        "slim_fractal": m["slim"],
        "lyapunov_decision": m["rate"],
        "alpha": Measured.of(fit.alpha, fit.alpha_err).to_dict() if fit else None,
        "d": Measured.of(fit.d, fit.d_err).to_dict() if fit else None,
        "alpha_fit_range": list(fit.eps_range) if fit else None,
        "alpha_fit_p": float(fit.p_value) if fit else None,
        "cutoff": (
            {
                "detected": bool(cut.detected),
                "eps_c": float(cut.eps_c),
                "eps_c_lo": float(cut.eps_c_lo),
                "eps_c_hi": float(cut.eps_c_hi),
                "delta_aic": float(cut.delta_aic),
            }
            if cut
            else None
        ),
        "tau2_mu1": tau2,
        "t_decide_median_smallest_eps": (float(smallest["t_decide_median"].iloc[0]) if len(smallest) else None),
        "smallest_resolved_eps": float(smallest["eps"].iloc[0]) if len(smallest) else None,
    }


def kantz_grassberger(scan: pd.DataFrame, kappa_rows) -> pd.DataFrame:
    """``scan`` with columns kappa, lam_kg, lam_kg_err: λ_KG = κ(E)/α(E) beside the decision rate.

    For a hyperbolic saddle the uncertainty exponent of the section is α = κ/λ (Kantz & Grassberger,
    Physica D 17, 75 (1985)); ``kappa_rows`` are records {energy, kappa, kappa_err} of κ(E), interpolated
    linearly in E (NaN outside their energies). ``scan`` has columns energy, alpha, alpha_err.
    """
    if scan.empty:
        return scan.assign(kappa=[], lam_kg=[], lam_kg_err=[])
    k = pd.DataFrame(kappa_rows).sort_values("energy")
    inside = (scan.energy >= k.energy.min()) & (scan.energy <= k.energy.max())
    kap = np.where(inside, np.interp(scan.energy, k.energy, k.kappa), np.nan)
    kap_err = np.where(inside, np.interp(scan.energy, k.energy, k.kappa_err), np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        lam = kap / scan.alpha
        err = np.abs(lam) * np.hypot(kap_err / kap, scan.alpha_err / scan.alpha)
    return scan.assign(kappa=kap, lam_kg=lam, lam_kg_err=err)


def smooth_chi2(E, y, err):
    """χ²/dof of a quadratic in E through (E, y ± err): ≈ 1 for a smooth curve, ≫ 1 when y fluctuates.

    Returns {chi2_dof, n}; chi2_dof is NaN below 5 usable points.

    Examples
    --------
    >>> E = np.linspace(0, 1, 6)
    >>> round(smooth_chi2(E, 1 + E ** 2, np.full(6, 0.1))["chi2_dof"], 12)
    0.0
    """
    ok = np.isfinite(y) & np.isfinite(err) & (err > 0)
    E, y, err = np.asarray(E)[ok], np.asarray(y)[ok], np.asarray(err)[ok]
    if E.size < 5:
        return {"chi2_dof": math.nan, "n": int(E.size)}
    c = np.polyfit(E, y, 2, w=1.0 / err)
    chi2 = float(np.sum(((y - np.polyval(c, E)) / err) ** 2))
    return {"chi2_dof": chi2 / (E.size - 3), "n": int(E.size)}


def energy_trend(scan, E_b, smooth_threshold=2.0):
    """Nieto et al. 2020 (S_b fluctuates while KAM islands remain, smooth once hyperbolic) and Daza et al.
    2016 (α rises with E) on the γ = 0 energy scan, each side of the break energy E_b of κ(E).

    ``scan`` has columns energy, above_E_b, S_b(_err), S_bb(_err), trapped, wada_exits, log2_fractal,
    alpha(_err). Returns None for an empty scan.
    """
    if scan.empty:
        return None
    lo, hi = scan[~scan.above_E_b], scan[scan.above_E_b]
    out = {"E_b": E_b}
    for name, part in (("below_E_b", lo), ("above_E_b", hi)):
        out[name] = {
            "S_b": smooth_chi2(part.energy, part.S_b, part.S_b_err),
            "S_bb": smooth_chi2(part.energy, part.S_bb, part.S_bb_err),
            "trapped_max": float(part.trapped.max()) if len(part) else math.nan,
            "wada_exits_all": bool(part.wada_exits.all()) if len(part) else None,
            "log2_all": bool(part.log2_fractal.all()) if len(part) else None,
        }
    # where the change happens: the lowest scan energy E* from which on S_b(E) is smooth (a quadratic with
    # χ²/dof < smooth_threshold on every energy ≥ E*, at least 5 of them), to be set beside E_b
    for q in ("S_b", "S_bb"):
        e_star = math.nan
        for E in sorted(scan.energy)[::-1]:
            part = scan[scan.energy >= E]
            c = smooth_chi2(part.energy, part[q], part[q + "_err"])
            if c["n"] >= 5 and not c["chi2_dof"] < smooth_threshold:
                break
            if c["n"] >= 5:
                e_star = float(E)
        out[f"E_smooth_{q}"] = e_star
    # the censored orbits (still inside at t_max at γ = 0, not classified): the lowest energy from which none remain
    srt = scan.sort_values("energy")
    trapped = srt.trapped.to_numpy() > 0
    out["E_no_trapped"] = (
        float(srt.energy.iloc[np.flatnonzero(trapped).max() + 1])
        if trapped.any() and not trapped[-1]
        else (float(srt.energy.iloc[0]) if not trapped.any() else math.nan)
    )
    ok = np.isfinite(scan.alpha) & (scan.alpha_err > 0)
    if ok.sum() >= 3:
        _, slope, cov, _, _ = weighted_line(scan.energy[ok], scan.alpha[ok], scan.alpha_err[ok])
        out["alpha_slope"] = Measured(slope, float(math.sqrt(cov[1, 1]))).to_dict()
    return out


def cutoff_records(per, scan, mu, mu_err, ec):
    """Records of the measured and predicted cut-off ε_c, one per (E0, γ > 0) of ``per`` (point records).

    The prediction (:func:`~hhscatter.analysis.geometry.cutoff.cutoff_comparison`) uses λ(E) of the γ = 0
    ``scan`` (columns energy, lam, lam_err, lam_kg): the decision rate, with Kantz–Grassberger's κ/α as the
    systematic in the predicted interval, and μ ± its error. Each record: E0, gamma, eps_c, eps_c_err,
    eps_c_interval, detected, eps_c_predicted, eps_c_predicted_interval (statistical and systematic),
    eps_c_predicted_kantz_grassberger, tau2, smallest_resolved_eps, log10_ratio (NaN when not detected),
    factor, gap_decades, z, intervals_overlap, statement.
    """
    lam_E = scan[np.isfinite(scan.lam)] if len(scan) else scan
    out = []
    if len(lam_E) == 0:
        return out
    kg = lam_E["lam_kg"].to_numpy(dtype=float) if "lam_kg" in lam_E else None
    for p in per:
        if p["gamma"] <= 0:
            continue
        E0, g, c = p["energy"], p["gamma"], p["cutoff"]
        det = bool(c and c["detected"])
        cmp = cutoff_comparison(
            E0,
            g,
            ec,
            mu,
            mu_err,
            lam_E.energy,
            lam_E.lam,
            lam_E.lam_err,
            lam_alt=kg,
            measured=c["eps_c"] if det else None,
            measured_lo=c["eps_c_lo"] if c else None,
            measured_hi=c["eps_c_hi"] if c else None,
        )
        rec = {
            "E0": E0,
            "gamma": g,
            "eps_c": c["eps_c"] if det else None,
            "eps_c_err": 0.5 * (c["eps_c_hi"] - c["eps_c_lo"]) if det else None,
            "eps_c_interval": [c["eps_c_lo"], c["eps_c_hi"]] if c else None,
            "detected": det,
            "eps_c_predicted": cmp.predicted,
            "eps_c_predicted_interval": [cmp.predicted_lo, cmp.predicted_hi],
            "eps_c_predicted_kantz_grassberger": cmp.predicted_alt if math.isfinite(cmp.predicted_alt) else None,
            "tau2": math.log(E0 / ec) / (mu * g),
            "smallest_resolved_eps": p["smallest_resolved_eps"],
            "log10_ratio": cmp.log10_ratio if det else None,
            "factor": cmp.factor if det else None,
            "gap_decades": cmp.gap_decades,
            "z": cmp.z if det else None,
            "intervals_overlap": cmp.overlap,
            "statement": cmp.statement,
        }
        out.append(rec)
    return out


def cutoff_summary(records) -> dict:
    """How far prediction and measurement differ over the resolved cut-offs of :func:`cutoff_records`.

    Returns {n_resolved, n_overlap, factor_min, factor_max, mean_log10_ratio, n_below, statement}
    (factors and means over the detected cut-offs; NaN when none is).

    Examples
    --------
    >>> cutoff_summary([{"detected": True, "log10_ratio": -0.3, "factor": 2.0, "intervals_overlap": False},
    ...                 {"detected": False}])["n_resolved"]
    1
    """
    det = [r for r in records if r.get("detected")]
    if not det:
        return {
            "n_resolved": 0,
            "n_overlap": 0,
            "factor_min": math.nan,
            "factor_max": math.nan,
            "mean_log10_ratio": math.nan,
            "n_below": 0,
            "statement": "no cut-off is resolved at these (E0, γ)",
        }
    lr = np.array([r["log10_ratio"] for r in det])
    fac = np.array([r["factor"] for r in det])
    n_ov = sum(bool(r["intervals_overlap"]) for r in det)
    n_below = int(np.count_nonzero(lr < 0))
    words = (
        f"over the {len(det)} resolved cut-offs the prediction is off by a factor {fac.min():.2g} to "
        f"{fac.max():.2g} (measured below it in {n_below} of {len(det)}; geometric mean factor "
        f"{10 ** abs(lr.mean()):.2g}); the 1σ intervals, the predicted one with the λ(E) systematic, "
        f"overlap in {n_ov} of {len(det)}"
    )
    return {
        "n_resolved": len(det),
        "n_overlap": int(n_ov),
        "factor_min": float(fac.min()),
        "factor_max": float(fac.max()),
        "mean_log10_ratio": float(lr.mean()),
        "n_below": n_below,
        "statement": words,
    }


def entropy_exponents(records, min_cells: int = 5) -> list:
    """The exponent of S_b(s) ∝ s^α over the fixed box sides s, per map and grid.

    ``records`` are rows of :func:`~hhscatter.analysis.geometry.basins.entropy_by_box` with E0, gamma and
    map; for a fractal boundary the basin entropy grows as the box side to the power of the uncertainty
    exponent (Daza et al., Sci. Rep. 6, 31416 (2016)), for a smooth one linearly. Weighted least squares of
    ln S_b against ln s (errors σ(S_b)/S_b, widened by √(χ²/dof)) over the sides of at least ``min_cells`` cells
    (a box of 2 cells cannot hold the mixing a fractal boundary puts in it); only groups with ≥ 3 such sides.
    Returns records {E0, gamma, map, grid, alpha, alpha_err, sides}.

    Examples
    --------
    >>> recs = [{"E0": 0.25, "gamma": 0.0, "map": "map", "grid": 2000, "box_side": s, "box_cells": int(s * 1000),
    ...          "S_b": 0.5 * s ** 0.3, "S_b_err": 1e-3} for s in (0.01, 0.02, 0.05)]
    >>> round(entropy_exponents(recs)[0]["alpha"], 6)
    0.3
    """
    if not records:
        return []
    t = pd.DataFrame(records)
    out = []
    for (E0, g, which, grid), part in t.groupby(["E0", "gamma", "map", "grid"], sort=True):
        part = part[(part.S_b > 0) & (part.S_b_err > 0) & (part.box_cells >= min_cells)].sort_values("box_side")
        if len(part) < 3:
            continue
        _, slope, cov, _, _ = weighted_line(np.log(part.box_side), np.log(part.S_b), part.S_b_err / part.S_b)
        out.append(
            {
                "E0": float(E0),
                "gamma": float(g),
                "map": which,
                "grid": int(grid),
                "alpha": float(slope),
                "alpha_err": float(math.sqrt(cov[1, 1])),
                "sides": [float(v) for v in part.box_side],
            }
        )
    return out


def entropy_by_box_at(records, sides=(0.025, 0.05)) -> list:
    """The rows of :func:`~hhscatter.analysis.geometry.basins.entropy_by_box` (with E0, gamma, map) at the box
    ``sides`` (position units, matched to 1e-9), sorted by E0, γ, side and grid: the like-for-like table of the
    page (the same physical box on every grid).

    Examples
    --------
    >>> recs = [{"E0": 0.25, "gamma": 0.0, "map": m, "grid": n, "box_side": s, "S_b": 0.4}
    ...         for m, n in (("map", 2000), ("scan", 400)) for s in (0.01, 0.025, 0.05)]
    >>> [(r["grid"], r["box_side"]) for r in entropy_by_box_at(recs)]
    [(400, 0.025), (2000, 0.025), (400, 0.05), (2000, 0.05)]
    """
    keep = [r for r in records if any(abs(r["box_side"] - s) < 1e-9 for s in sides)]
    return sorted(keep, key=lambda r: (r["E0"], r["gamma"], r["box_side"], r["grid"]))


def comparison_rows(per, hb) -> list[dict]:
    """The comparison rows of the basin records ``per`` (:func:`point_record`), for a study's ``compare``: the
    uncertainty exponent α, the boundary basin entropy S_bb at the headline box ``hb`` (against ln 2, sufficient
    for a fractal boundary) and, for γ > 0, the cut-off ε_c of the power law f(ε) that the paper expects.

    Each row holds quantity, ours, err and note (α and S_bb dimensionless, ε_c in position units); a record
    without α, S_bb or a cut-off gives no such row.

    Examples
    --------
    >>> rec = {"energy": 0.25, "gamma": 0.01, "alpha": Measured(0.31, 0.02).to_dict(), "alpha_fit_range": [1e-6, 1e-3],
    ...        "d": {"value": 1.69}, "S_bb": None, "cutoff": {"detected": False, "eps_c_hi": 2e-6}}
    >>> [(r["quantity"], r["ours"]) for r in comparison_rows([rec], 10)]
    [('uncertainty exponent α (E0=0.25, γ=0.01)', 0.31), ('cut-off ε_c of the power law f(ε) (E0=0.25, γ=0.01)', None)]
    """
    rows = []
    for p in per:
        tag = f"E0={p['energy']:g}, γ={p['gamma']:g}"
        if p["alpha"]:
            rows.append(
                {
                    "quantity": f"uncertainty exponent α ({tag})",
                    "ours": p["alpha"]["value"],
                    "err": p["alpha"]["err"],
                    "note": f"f(ε) ∝ ε^α on ε ∈ [{p['alpha_fit_range'][0]:.0e}, {p['alpha_fit_range'][1]:.0e}];"
                    f" d = 2 − α = {p['d']['value']:.3f}",
                }
            )
        if p["S_bb"]:
            rows.append(
                {
                    "quantity": f"boundary basin entropy S_bb ({tag}, box {hb})",
                    "ours": p["S_bb"]["value"],
                    "err": p["S_bb"]["err"],
                    "note": "S_bb > ln 2 is sufficient for a fractal boundary: "
                    + ("yes" if p["log2_fractal"] else "not shown"),
                }
            )
        if p["cutoff"] is not None and p["gamma"] > 0:
            c = p["cutoff"]
            rows.append(
                {
                    "quantity": f"cut-off ε_c of the power law f(ε) ({tag})",
                    "ours": c["eps_c"] if c["detected"] else None,
                    "err": None,
                    "note": (
                        f"detected, 1σ [{c['eps_c_lo']:.2g}, {c['eps_c_hi']:.2g}]"
                        if c["detected"]
                        else f"none seen: ε_c < {c['eps_c_hi']:.2g}"
                    )
                    + " (paper: expected for γ > 0)",
                }
            )
    return rows


def point_table(per) -> list:
    """One flat record per (E0, γ) of the point records ``per`` (:func:`point_record`), for a page's table:
    E0, gamma, d (± d_err) of the one-law fit and its p, the local dimension at the coarsest and finest
    resolved resolution, its slope per decade (± err) and the slim-fractal verdict, S_bb (± err) at the headline
    box, and the Wada fraction with settled a basin and of the exits alone (settled masked)."""
    out = []
    for p in per:
        s, w, wx = p.get("slim_fractal") or {}, p["wada"], p.get("wada_exits")
        out.append(
            {
                "E0": p["energy"],
                "gamma": p["gamma"],
                "d": p["d"]["value"] if p["d"] else None,
                "d_err": p["d"]["err"] if p["d"] else None,
                "fit_p": (p.get("alpha_fit_p") if p.get("alpha_fit_p") != 0 else "< 1e-300 (underflow)"),
                "d_coarse": s.get("d_coarse"),
                "d_coarse_err": s.get("d_coarse_err"),
                "d_fine": s.get("d_fine"),
                "d_fine_err": s.get("d_fine_err"),
                "slope": s.get("slope"),
                "slope_err": s.get("slope_err"),
                "slim": "yes" if s.get("slim") else "no",
                "S_bb": p["S_bb"]["value"] if p["S_bb"] else None,
                "S_bb_err": p["S_bb"]["err"] if p["S_bb"] else None,
                "box_cells": p.get("box_headline"),
                "wada_all": f"{'yes' if w['verdict'] else 'no'} (W = {w['W_at_r']:.3f})",
                "wada_exits": (
                    f"{'yes' if wx['verdict'] else 'no'} (W = {wx['W_at_r']:.3f})"
                    if wx
                    else "— (fewer than 3 exit basins)"
                ),
            }
        )
    return out


def map_measures(
    img,
    r,
    unc: pd.DataFrame,
    eps,
    times,
    E: float,
    g: float,
    boxes,
    *,
    wada_min_share: float,
    wada_r: int,
    symmetry_radius: float,
    fit_min_count: int,
):
    """map_measures(img, r, unc, eps, times, E, g, boxes, ...) -> (entropy table, local-exponent table, measures).

    The measures of one basin map (labels :data:`CODES`, :data:`OUTSIDE` for forbidden cells) at (E0, γ) =
    (``E``, ``g``): the basins' fractions, the basin entropy per box size ``boxes`` (cells), the Wada test of the
    basins holding at least ``wada_min_share`` of the allowed cells and of the exits alone (three exits present;
    ``wada_r`` cells), the exits' shares on the cells with ``r`` < ``symmetry_radius`` (``r``: each cell's distance
    from the origin, position units; the potential is three-fold symmetric, a square map is not), the local
    uncertainty exponent and the slim-fractal test of the f(ε) table ``unc``, its power-law and cut-off fits
    (:func:`uncertainty_fits`) and, at γ = 0, the decision rate of the pairs' decision ``times`` per ε
    (:func:`rate_record`).

    Returns the entropy table and the local-exponent table (with columns energy, gamma) and a dict: fr, present,
    wada, chans, exits, wada_x, slim, rate, ok, fit, cut.

    Examples
    --------
    >>> img = np.repeat(np.array([[0, 1, 2, 3]]), 4, axis=0)
    >>> eps = np.geomspace(1e-2, 1e-5, 6)
    >>> unc = pd.DataFrame({"eps": eps, "k": np.round(1e5 * 0.5 * eps**0.4).astype(int), "n": 100_000})
    >>> unc["f"] = unc["k"] / unc["n"]
    >>> ent, loc, m = map_measures(img, np.zeros((4, 4)), unc, eps, None, 0.3, 0.01, [2], wada_min_share=0.1,
    ...                           wada_r=1, symmetry_radius=1.0, fit_min_count=10)
    >>> [float(f) for f in m["fr"].frac[:4]], m["present"], m["exits"], round(m["fit"].alpha, 2), m["rate"]
    ([0.25, 0.25, 0.25, 0.25], [0, 1, 2, 3], [0, 1, 2], 0.4, None)
    """
    fr = basin_fractions(img, basins=list(CODES), outside=OUTSIDE)
    ent = basin_entropy_table(img, boxes, outside=OUTSIDE).assign(energy=E, gamma=g)
    present = [c for c, share in zip(CODES, fr.frac) if share >= wada_min_share]
    wada = wada_merging(img, basins=present, outside=OUTSIDE, r_wada=wada_r)
    chans = channel_fractions(img[(img >= 0) & (img <= 2) & (r < symmetry_radius)])
    # like-for-like with the literature (Seoane, Aguirre, Sanjuán & Lai 2006): the exit basins alone,
    # settled (and trapped) cells masked as outside
    exits = [c for c in present if c in (0, 1, 2)]
    wada_x = wada_merging(img, basins=exits, outside=OUTSIDE, r_wada=wada_r) if len(exits) >= 3 else None
    loc = local_exponent(unc["eps"], unc["k"], unc["n"]).assign(energy=E, gamma=g)
    slim = slim_fractal(loc)
    rate = rate_record(eps, times) if g == 0 else None
    ok, fit, cut = uncertainty_fits(unc, fit_min_count)
    measures = {
        "fr": fr,
        "present": present,
        "wada": wada,
        "chans": chans,
        "exits": exits,
        "wada_x": wada_x,
        "slim": slim,
        "rate": rate,
        "ok": ok,
        "fit": fit,
        "cut": cut,
    }
    return ent, loc, measures


#: the columns of a basin study's energy scan table (one row per E0 of :func:`scan_row`)
SCAN_COLUMNS = [
    "energy",
    "above_E_b",
    "S_b",
    "S_b_err",
    "S_bb",
    "S_bb_err",
    "log2_fractal",
    "trapped",
    "wada_exits",
    "W_exits",
    "alpha",
    "alpha_err",
    "alpha_p",
    "lam",
    "lam_err",
]


def scan_row(
    img, unc: pd.DataFrame, eps, times, E: float, E_b: float, boxes, hb, *, wada_min_share, wada_r, fit_min_count
):
    """scan_row(img, unc, eps, times, E, E_b, boxes, hb, ...) -> one row of the γ = 0 energy scan (:data:`SCAN_COLUMNS`).

    At E0 = ``E``: the basin entropies S_b, S_bb (with errors, bits) at the box size ``hb`` (cells; the largest
    of ``boxes`` when ``hb`` is not one of them), whether the map is above E_b, the trapped share, the Wada test of
    the exits holding at least ``wada_min_share`` of the allowed cells (three present; ``wada_r`` cells), the
    uncertainty exponent α of the f(ε) table ``unc`` (:func:`uncertainty_fits`) and the decision rate λ
    (1/time) of the decision ``times`` per ε (:func:`rate_record`). NaN where a measure is undefined.

    Examples
    --------
    >>> img = np.repeat(np.array([[0, 1, 2, 4]]), 4, axis=0)
    >>> eps = np.geomspace(1e-2, 1e-5, 6)
    >>> unc = pd.DataFrame({"eps": eps, "k": np.round(1e5 * 0.5 * eps**0.4).astype(int), "n": 100_000})
    >>> unc["f"] = unc["k"] / unc["n"]
    >>> row = scan_row(img, unc, eps, [np.array([1.0, 2.0])] * 6, 0.2, 0.25, [2], 2, wada_min_share=0.1,
    ...                wada_r=1, fit_min_count=10)
    >>> row["above_E_b"], row["trapped"], round(row["alpha"], 2), list(row) == SCAN_COLUMNS
    (False, 0.25, 0.4, True)
    """
    fr = basin_fractions(img, basins=list(CODES), outside=OUTSIDE)
    ent = basin_entropy_table(img, boxes, outside=OUTSIDE).set_index("box")
    exits = [c for c in (0, 1, 2) if fr.frac[c] >= wada_min_share]
    w = wada_merging(img, basins=exits, outside=OUTSIDE, r_wada=wada_r) if len(exits) >= 3 else None
    _, fit, _ = uncertainty_fits(unc, fit_min_count)
    rate = rate_record(eps, times)
    h = ent.loc[hb] if hb in ent.index else ent.iloc[-1]
    return {
        "energy": E,
        "above_E_b": bool(E > E_b),
        "S_b": float(h.S_b),
        "S_b_err": float(h.S_b_err),
        "S_bb": float(h.S_bb),
        "S_bb_err": float(h.S_bb_err),
        "log2_fractal": bool(h.log2_fractal),
        "trapped": float(fr.frac[TRAPPED_CODE]),
        "wada_exits": bool(w.wada) if w else False,
        "W_exits": float(w.wada_fraction[w.r_wada]) if w else math.nan,
        "alpha": fit.alpha if fit else math.nan,
        "alpha_err": fit.alpha_err if fit else math.nan,
        "alpha_p": fit.p_value if fit else math.nan,
        "lam": rate["value"] if rate else math.nan,
        "lam_err": rate["err"] if rate else math.nan,
    }


# ---------------------------------------------------------------------------
# the cut-off with the saddle's own λ̄ and the deciding orbits' own energy decay
# ---------------------------------------------------------------------------
#: intervals of measured and predicted ε_c closer than this factor count as "within a factor 1.5"
WITHIN_FACTOR = 1.5


def tangent_lambda(records, system: str) -> pd.DataFrame:
    """λ̄(E) of a saddle study's records for one system: DataFrame(energy, lam, lam_err) sorted by energy.

    ``records`` are dicts with system, energy, lyapunov and lyapunov_err (1/time); records without λ̄ are
    left out.

    Examples
    --------
    >>> recs = [{"system": "a", "energy": 0.3, "lyapunov": 0.5, "lyapunov_err": 0.01},
    ...         {"system": "a", "energy": 0.2, "lyapunov": None, "lyapunov_err": None},
    ...         {"system": "b", "energy": 0.2, "lyapunov": 0.4, "lyapunov_err": 0.01}]
    >>> tangent_lambda(recs, "a").to_dict(orient="records")
    [{'energy': 0.3, 'lam': 0.5, 'lam_err': 0.01}]
    """
    rows = [
        {"energy": float(r["energy"]), "lam": float(r["lyapunov"]), "lam_err": float(r["lyapunov_err"])}
        for r in records
        if r.get("system") == system and r.get("lyapunov") is not None and r.get("lyapunov_err") is not None
    ]
    return pd.DataFrame(rows, columns=["energy", "lam", "lam_err"]).sort_values("energy", ignore_index=True)


def rate_table(scan: pd.DataFrame, tangent: pd.DataFrame) -> list:
    """The three estimates of the saddle's λ at each energy of ``tangent`` that the γ = 0 scan also has.

    ``scan`` has columns energy, lam, lam_err (the decision rate of the pairs), lam_kg, lam_kg_err (κ/α);
    ``tangent`` those of :func:`tangent_lambda` (λ̄ of the tangent dynamics). Each row: E0, decision,
    tangent, kappa_over_alpha (each with its ``_err``), decision_over_tangent (with its error) and the verdicts
    of the decision rate and of κ/α against λ̄ by the 2σ rule (both errors).

    Examples
    --------
    >>> scan = pd.DataFrame({"energy": [0.2, 0.3], "lam": [0.3, 0.4], "lam_err": [0.01, 0.01],
    ...                      "lam_kg": [0.5, 0.6], "lam_kg_err": [0.05, 0.05]})
    >>> r = rate_table(scan, pd.DataFrame({"energy": [0.3], "lam": [0.6], "lam_err": [0.01]}))[0]
    >>> r["E0"], round(r["decision_over_tangent"], 3), r["decision_vs_tangent"], r["kappa_over_alpha_vs_tangent"]
    (0.3, 0.667, 'differs (z = −14.1)', 'agrees (z = +0.0)')
    """
    out = []
    for t in tangent.itertuples():
        hit = scan[np.isclose(scan["energy"].to_numpy(dtype=float), t.energy, rtol=0, atol=1e-9)]
        if hit.empty:
            continue
        s = hit.iloc[0]
        dec, kg = Measured(float(s["lam"]), float(s["lam_err"])), Measured(float(s["lam_kg"]), float(s["lam_kg_err"]))
        tan = Measured(float(t.lam), float(t.lam_err))
        ratio = dec / tan
        out.append(
            {
                "E0": float(t.energy),
                "decision": dec.value,
                "decision_err": dec.err,
                "tangent": tan.value,
                "tangent_err": tan.err,
                "kappa_over_alpha": kg.value,
                "kappa_over_alpha_err": kg.err,
                "decision_over_tangent": ratio.value,
                "decision_over_tangent_err": ratio.err,
                "decision_vs_tangent": verdict(dec.value, dec.err, tan.value, tan.err).text(),
                "kappa_over_alpha_vs_tangent": verdict(kg.value, kg.err, tan.value, tan.err).text(),
            }
        )
    return out


def _log_verdict(c) -> str:
    """The 2σ rule on log10 ε_c: measured against predicted, each with its interval's half-width on the facing
    side (NaN when no cut-off is resolved)."""
    if not math.isfinite(c.measured) or not c.predicted > 0:
        return "no verdict: no cut-off resolved"
    up = c.measured > c.predicted
    lg = math.log10
    sm = lg(c.measured) - lg(c.measured_lo) if up else lg(c.measured_hi) - lg(c.measured)
    sp = lg(c.predicted_hi) - lg(c.predicted) if up else lg(c.predicted) - lg(c.predicted_lo)
    return verdict(lg(c.measured), sm, lg(c.predicted), sp).text()


def saddle_cutoff_records(per, tangent: pd.DataFrame, mu, mu_err, ec) -> list:
    """The cut-off ε_c predicted with the saddle's own λ̄(E) (tangent dynamics) and, beside it, with the energy
    decay of the orbits that decide the outcome, against the measured one; one record per (E0, γ > 0) of ``per``.

    ``per`` are point records with energy, gamma, cutoff (detected, eps_c, eps_c_lo, eps_c_hi) and mu_own
    ({value, err}: μ of the orbits of the pairs that changed outcome at the smallest resolved ε,
    :func:`~hhscatter.analysis.dissipative.decay.orbit_decay_exponent`; None where not measured). ``tangent``:
    :func:`tangent_lambda` (λ̄ interpolated linearly in E, held constant beyond its energies). μ ± ``mu_err``:
    the ensemble's decay exponent. Each prediction (:func:`~hhscatter.analysis.geometry.cutoff.cutoff_comparison`)
    has its interval over λ̄ ± σ and μ ± σ; ``within_1p5``: the measured and the predicted intervals come within a
    factor 1.5 of each other; ``verdict``: the 2σ rule on log10 ε_c with both intervals' half-widths.
    """
    out = []
    if tangent.empty:
        return out
    En, lam, lam_err = (tangent[c].to_numpy(dtype=float) for c in ("energy", "lam", "lam_err"))
    for p in per:
        if p["gamma"] <= 0:
            continue
        E0, g, c = p["energy"], p["gamma"], p["cutoff"]
        det = bool(c and c["detected"])
        meas = {"measured": c["eps_c"] if det else None, "measured_lo": c["eps_c_lo"] if c else None,
                "measured_hi": c["eps_c_hi"] if c else None}  # fmt: skip
        rec = {"E0": E0, "gamma": g, "eps_c": c["eps_c"] if det else None,
               "eps_c_interval": [c["eps_c_lo"], c["eps_c_hi"]] if c else None, "detected": det}  # fmt: skip
        own = p.get("mu_own")
        variants = [("tangent", mu, mu_err)]
        if own is not None:
            rec["mu_own"], rec["mu_own_err"] = own["value"], own["err"]
            variants.append(("tangent_own", own["value"], own["err"]))
        for name, m, me in variants:
            cmp = cutoff_comparison(E0, g, ec, m, me, En, lam, lam_err, **meas)
            within = det and cmp.gap_decades <= math.log10(WITHIN_FACTOR) + 1e-12
            rec.update(
                {
                    f"eps_c_{name}": cmp.predicted,
                    f"eps_c_{name}_interval": [cmp.predicted_lo, cmp.predicted_hi],
                    f"factor_{name}": cmp.factor if det else None,
                    f"log10_ratio_{name}": cmp.log10_ratio if det else None,
                    f"overlap_{name}": bool(det and cmp.overlap),
                    f"within_1p5_{name}": bool(within),
                    f"verdict_{name}": _log_verdict(cmp),
                }
            )
        out.append(rec)
    return out


def saddle_cutoff_summary(records, rates, mu) -> dict:
    """How close each prediction of :func:`saddle_cutoff_records` comes over the resolved cut-offs, and, where one
    is not within a factor 1.5, the measured reasons: λ̄ against the decision rate (``rates``, rows of
    :func:`rate_table`) and the deciding orbits' μ against the ensemble's ``mu``. Returns {n_resolved, per
    variant n_within, n_overlap, factor_min, factor_max, n_below, and statement}.

    Examples
    --------
    >>> recs = [{"detected": True, "factor_tangent": 1.2, "log10_ratio_tangent": -0.08, "within_1p5_tangent": True,
    ...          "overlap_tangent": True}]
    >>> saddle_cutoff_summary(recs, [], 0.9)["tangent"]["n_within"]
    1
    """
    det = [r for r in records if r.get("detected")]
    out = {"n_resolved": len(det)}
    words = []
    names = {"tangent": "with λ̄ of the tangent dynamics and the ensemble's μ",
             "tangent_own": "with λ̄ and the deciding orbits' own μ"}  # fmt: skip
    for name, label in names.items():
        rs = [r for r in det if r.get(f"factor_{name}") is not None]
        if not rs:
            continue
        fac = np.array([r[f"factor_{name}"] for r in rs])
        n_w = sum(bool(r[f"within_1p5_{name}"]) for r in rs)
        n_o = sum(bool(r[f"overlap_{name}"]) for r in rs)
        n_b = sum(r[f"log10_ratio_{name}"] < 0 for r in rs)
        out[name] = {"n": len(rs), "n_within": n_w, "n_overlap": n_o, "factor_min": float(fac.min()),
                     "factor_max": float(fac.max()), "n_below": int(n_b)}  # fmt: skip
        words.append(
            f"{label}: off by a factor {fac.min():.2g} to {fac.max():.2g} (measured below it in {n_b} of {len(rs)}), "
            f"within a factor {WITHIN_FACTOR:g} in {n_w} of {len(rs)}, intervals overlapping in {n_o} of {len(rs)}"
        )
    if not words:
        out["statement"] = "no cut-off is resolved at these (E0, γ), or no λ̄ of the tangent dynamics is given"
        return out
    best = max(v["n_within"] for k, v in out.items() if k in names)
    if best < len(det):
        why = []
        if rates:
            q = np.array([r["decision_over_tangent"] for r in rates])
            why.append(
                f"the decision rate is {q.min():.2g}–{q.max():.2g} times λ̄ at the {len(rates)} energies both have "
                "(a prediction's ln(1/ε_c) scales with λ)"
            )
        own = [r["mu_own"] for r in det if r.get("mu_own") is not None]
        if own:
            why.append(
                f"the orbits that decide at the smallest resolved ε decay with μ = {min(own):.2g}–{max(own):.2g} "
                f"against the ensemble's μ = {mu:.2g}"
            )
        words.append("not every cut-off comes within a factor 1.5; measured: " + "; ".join(why) if why else "")
    out["statement"] = "; ".join(w for w in words if w)
    return out


def _share(t, i) -> dict:
    """{share, lo, hi, k} of entry ``i`` of a :class:`~hhscatter.analysis.geometry.cutoff.StretchTail`."""
    return {"share": float(t.share[i]), "lo": float(t.lo[i]), "hi": float(t.hi[i]), "k": int(t.k[i])}


def stretch_record(point: dict, unc: pd.DataFrame, stretch, cut: dict | None, *, min_count: int) -> dict:
    """Where f(ε) and the measured cut-off lie in the distribution of each orbit's own stretch Λ, for one (E0, γ).

    ``point``: the point's record (energy, gamma, cutoff); ``unc``: its f(ε) rows (eps, f, k, n); ``stretch``:
    Λ of every reference orbit of its uncertainty runs
    (:func:`~hhscatter.analysis.geometry.cutoff.orbit_stretch`); ``cut``: its record of
    :func:`saddle_cutoff_records` (None at γ = 0). Returns energy, gamma, n_orbits, ``rows`` (per ε: S(ln 1/ε)
    with its Wilson bounds and f/S, None where S has no orbit) and the ε with at least ``min_count`` changed pairs;
    ``at_cutoff`` (S at ln(1/ε_c), and at both ends of ε_c's interval), ``at_mean_history`` and ``at_own_history``
    (S at the Λ of the two predictions of ``cut``, with that Λ), each None when not defined.

    Examples
    --------
    >>> unc = pd.DataFrame({"eps": [0.1, 0.01], "f": [0.3, 0.2], "k": [300, 200], "n": [1000, 1000]})
    >>> r = stretch_record({"energy": 0.3, "gamma": 0.0, "cutoff": None}, unc, [1.0, 3.0, 5.0, 6.0], None, min_count=10)
    >>> [(row["S"], round(row["f_over_S"], 6)) for row in r["rows"]]    # Λ > ln 10 = 2.3: 3 of 4; > ln 100: 2 of 4
    [(0.75, 0.4), (0.5, 0.4)]
    """
    unc = unc.sort_values("eps", ascending=False)
    eps = unc["eps"].to_numpy(dtype=float)
    c = point.get("cutoff")
    at_cut = [c["eps_c"], c["eps_c_hi"], c["eps_c_lo"]] if c and c.get("detected") else []
    hist = {key: (cut or {}).get(name) for key, name in (("at_mean_history", "eps_c_tangent"),
                                                          ("at_own_history", "eps_c_tangent_own"))}  # fmt: skip
    hist = {key: e for key, e in hist.items() if e is not None and e > 0}
    t = stretch_tail(stretch, [*eps, *at_cut, *hist.values()])  # one sort of the stretches for every ε asked
    rows = []
    for i, (e, f, k) in enumerate(zip(eps, unc["f"].to_numpy(dtype=float), unc["k"].to_numpy())):
        S = float(t.share[i])
        rows.append({"eps": float(e), "f": float(f), "S": S, "S_lo": float(t.lo[i]), "S_hi": float(t.hi[i]),
                     "f_over_S": float(f / S) if t.k[i] > 0 else None, "resolved": bool(k >= min_count)})  # fmt: skip
    out = {"energy": point["energy"], "gamma": point["gamma"], "n_orbits": t.n, "rows": rows,
           "at_cutoff": None, "at_mean_history": None, "at_own_history": None}  # fmt: skip
    i = eps.size
    if at_cut:
        out["at_cutoff"] = {"ln_inv_eps_c": math.log(1.0 / c["eps_c"]), **_share(t, i),
                            "share_range": [float(t.share[i + 1]), float(t.share[i + 2])]}  # fmt: skip
        i += 3
    for key, e in hist.items():
        out[key] = {"stretch": math.log(1.0 / e), **_share(t, i)}
        i += 1
    return out


def stretch_summary(records) -> dict:
    """The statement of :func:`stretch_record` over the points: f/S over the resolved ε without drag, and the
    share of orbits beyond the measured cut-off's ln(1/ε_c) against those beyond the two predictions' Λ.

    Examples
    --------
    >>> rec = {"gamma": 0.0, "rows": [{"eps": 0.1, "f_over_S": 0.7, "resolved": True},
    ...                              {"eps": 1e-4, "f_over_S": 0.74, "resolved": True}], "at_cutoff": None}
    >>> stretch_summary([rec])["conservative"]["f_over_S"]
    [0.7, 0.74]
    """
    out = {}
    words = []
    cons = [r["f_over_S"] for p in records if p["gamma"] == 0 for r in p["rows"]
            if r["resolved"] and r["f_over_S"] is not None]  # fmt: skip
    if cons:
        e = [r["eps"] for p in records if p["gamma"] == 0 for r in p["rows"] if r["resolved"] and r["f_over_S"]]
        out["conservative"] = {"f_over_S": [float(min(cons)), float(max(cons))], "eps": [min(e), max(e)]}
        words.append(
            f"without drag f(ε)/S(ln 1/ε) = {min(cons):.2g}–{max(cons):.2g} over ε = {max(e):.0e} to {min(e):.0e} "
            "(S: the share of orbits whose own stretch Λ exceeds ln(1/ε))"
        )
    det = [p for p in records if p.get("at_cutoff")]
    if det:
        sh = np.array([p["at_cutoff"]["share"] for p in det])
        out["at_cutoff"] = [float(sh.min()), float(sh.max())]
        w = f"the measured cut-off lies where S = {sh.min():.2g} to {sh.max():.2g} at the {len(det)} resolved cut-offs"
        for key, label in (("at_mean_history", "the mean energy history's Λ"),
                           ("at_own_history", "the deciding orbits' own-μ history's Λ")):  # fmt: skip
            v = np.array([p[key]["share"] for p in det if p.get(key)])
            if v.size:
                out[key] = [float(v.min()), float(v.max())]
                w += f"; {label} at S = {v.min():.2g} to {v.max():.2g}"
        words.append(w)
    out["statement"] = "; ".join(words) if words else "no point with a stretch distribution"
    return out


def stretch_table(records) -> list:
    """One flat row per resolved cut-off of :func:`stretch_record`'s records (the page's table): E0, γ, ln(1/ε_c),
    S there and over ε_c's interval, and Λ and S of the two predictions' histories (None where not defined).

    Examples
    --------
    >>> rec = {"energy": 0.3, "gamma": 0.02, "at_cutoff": {"ln_inv_eps_c": 10.8, "share": 0.02,
    ...        "share_range": [0.019, 0.021]}, "at_mean_history": {"stretch": 10.1, "share": 0.1},
    ...        "at_own_history": None}
    >>> stretch_table([rec])[0]["S_mean_history"]
    0.1
    """
    out = []
    for p in records:
        c = p.get("at_cutoff")
        if not c:
            continue
        mh, oh = p.get("at_mean_history") or {}, p.get("at_own_history") or {}
        out.append({"E0": p["energy"], "gamma": p["gamma"], "ln_inv_eps_c": c["ln_inv_eps_c"], "S_cutoff": c["share"],
                    "S_cutoff_range": c["share_range"], "stretch_mean_history": mh.get("stretch"),
                    "S_mean_history": mh.get("share"), "stretch_own_history": oh.get("stretch"),
                    "S_own_history": oh.get("share")})  # fmt: skip
    return out
