"""The records of a chaotic-saddle study: per point the error parts and scaling range of d₁, d₀ beside it, the
rows of the Kantz–Grassberger relation κ = λ̄ (1 − d₁) and of the two dimensions, and their summaries with the
statements the page shows.

A point's record is a dict with at least ``id``, ``system``, ``ratio``, ``energy``, ``kappa``/``kappa_err`` and,
where measured, ``lyapunov``, ``d1_section`` (the section's D₁ = 2 d₁), ``d1``, ``predicted`` (λ̄(1 − d₁)),
``d1_implied`` (1 − κ/λ̄), ``z`` and ``verdict`` (:func:`hhscatter.analysis.geometry.saddle.kantz_grassberger`),
``d0`` (1 − α of the exits on lines) and the keys :func:`d1_error_record` adds. Most functions here read those keys
only; :func:`lines_measurement`, :func:`lyapunov_record`, :func:`d0_record`, :func:`mid_lyapunov_record`,
:func:`fluctuation_record` and :func:`hyperbolic_record` run the estimators of
:mod:`hhscatter.analysis.geometry.saddle` on a run's tables and assemble their records.

Units: κ and λ̄ in 1/time, d₀ and d₁ dimensionless (partial dimensions along the unstable direction, the section's
D = 2 d), ε in the section's length units.

Examples
--------
>>> rec = {"id": "hh-1.50", "system": "hh", "ratio": 1.5, "energy": 0.25, "kappa": 0.097, "kappa_err": 0.002,
...        "lyapunov": 0.41, "lyapunov_err": 0.001, "d1": 0.69, "d1_err": 0.02, "predicted": 0.127,
...        "predicted_err": 0.007, "d1_implied": 0.765, "d1_implied_err": 0.005, "z": -4.2,
...        "verdict": "differs (z = −4.2)"}
>>> relation_row(rec)["d1_section_implied"]
{'value': 1.53, 'err': 0.01}
>>> relation_summary([rec, {"id": "hh-3.00", "z": None}])
{'n_points': 2, 'n_checked': 1, 'n_within_2sigma': 0}
"""

from __future__ import annotations

import math
import re

import numpy as np

from hhscatter.analysis.geometry.saddle import (
    dimension_from_uncertainty,
    dimension_order,
    information_dimension_neighbours,
    kantz_grassberger,
    lyapunov_convergence,
    mean_lyapunov,
    neighbour_floor_scan,
    neighbour_scale_bands,
)
from hhscatter.analysis.geometry.saddle_checks import ftle_dimension, interval_lyapunov, low_ftle_share, tmin_trend
from hhscatter.analysis.geometry.uncertainty import uncertainty_exponent, uncertainty_fraction
from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.stats.verdicts import value_err
from hhscatter.errors import ConfigError
from hhscatter.outcomes import LEAVING_OUTCOMES
from hhscatter.reproduction.basin_summary import OUTSIDE, TRAPPED_CODE, outcome_codes

__all__ = [
    "ERR_PARTS",
    "d1_error_record",
    "d1_refusal_words",
    "d1_precision",
    "dimension_row",
    "dimension_summary",
    "floor_scan_record",
    "fluctuation_record",
    "gap_row",
    "hyperbolic_record",
    "sheets_record",
    "gap_summary",
    "d0_record",
    "lines_measurement",
    "long_lived",
    "lyapunov_record",
    "lines_record",
    "lines_row",
    "lines_summary",
    "lyapunov_by_t_min",
    "mid_lyapunov_record",
    "no_lyapunov_words",
    "relation_row",
    "relation_summary",
    "scales_row",
    "scales_summary",
    "with_d0",
    "with_gap",
]

ERR_PARTS = {"fit": "err_fit", "resample": "err_resample", "range": "err_range"}
"""The parts of d₁'s error: record name -> attribute of the dimension's result."""


def d1_error_record(d, extent: float, eps_min: float) -> dict:
    """d1_error_record(d, extent, eps_min) -> the record's keys of d₁'s error.

    ``d`` is the section's information dimension (a
    :class:`~hhscatter.analysis.geometry.saddle.SaddleDimension` with its ``table`` of ε), ``extent`` the saddle
    points' longest side and ``eps_min`` the floor of the scaling range (length units). Keys:
    ``d1_section_err_parts`` (the three parts, section units), ``d1_err_largest`` (the largest finite part),
    ``d1_eps_range_extent`` (the fitted ε range in units of the extent), ``d1_eps_min_extent``, ``d1_range_floor``
    (what ends the range below: ``floor``, the floor eps_min, when the table has ε below it; else ``points``, the
    nearest neighbours' distance, the number of points) and ``d1_rel_err`` (err/value).

    Examples
    --------
    >>> import pandas as pd
    >>> from hhscatter.analysis.geometry.saddle import SaddleDimension
    >>> d = SaddleDimension(value=1.2, err=0.05, err_fit=0.01, err_resample=0.02, err_range=0.045,
    ...                     method="neighbours", eps_range=(0.01, 0.1), n_points=1000, n_groups=100,
    ...                     table=pd.DataFrame({"eps": [0.005, 0.01, 0.1]}))
    >>> r = d1_error_record(d, extent=1.0, eps_min=0.008)
    >>> r["d1_err_largest"], r["d1_range_floor"], round(r["d1_rel_err"], 4)
    ('range', 'floor', 0.0417)
    """
    parts = {k: float(getattr(d, a)) for k, a in ERR_PARTS.items()}
    floor = "floor" if bool(np.any(d.table["eps"].to_numpy() < eps_min)) else "points"
    lo, hi = d.eps_range
    return {"d1_section_err_parts": parts, "d1_err_largest": max(parts, key=lambda k: parts[k] if math.isfinite(parts[k]) else -1.0),
            "d1_eps_range_extent": [lo / extent, hi / extent], "d1_eps_min_extent": eps_min / extent,
            "d1_range_floor": floor, "d1_rel_err": d.err / d.value if d.value else math.nan}  # fmt: skip


def floor_scan_record(scan, scatter: float) -> dict:
    """floor_scan_record(scan, scatter) -> the record's ``d1_floor_scan``: d₁ (partial, D₁/2) at each floor of a
    :func:`~hhscatter.analysis.geometry.saddle.neighbour_floor_scan` of the section points.

    ``scatter`` is the points' estimated distance to the saddle in units of their extent, e^{−λ̄·window[0]·t_min}
    (stated beside the floors, not used by the fit; None where there is no λ̄). Keys: ``floor`` (the rule's, the row with factor 1; a fraction
    of the extent), ``scatter_extent`` and ``rows`` ([{factor, floor, d1: {value, err} or None, eps_range_extent
    (the scales fitted, fractions of the extent) or None, note}]).

    Examples
    --------
    >>> import math, pandas as pd
    >>> scan = pd.DataFrame({"factor": [0.5, 1.0], "floor": [0.004, 0.008], "eps_min": [0.008, 0.016]})
    >>> scan = scan.assign(value=[1.30, 1.24], err=[0.04, 0.06], eps_lo=[0.0081, 0.0162], eps_hi=0.12, note="")
    >>> r = floor_scan_record(scan, 1e-3)
    >>> r["floor"], r["rows"][0]["d1"], [round(v, 4) for v in r["rows"][1]["eps_range_extent"]]
    (0.008, {'value': 0.65, 'err': 0.02}, [0.0081, 0.06])
    """
    rows = []
    for r in scan.itertuples():
        ok = math.isfinite(r.value)
        extent = r.eps_min / r.floor
        rows.append({"factor": float(r.factor), "floor": float(r.floor),
                     "d1": Measured(r.value, r.err).scaled(0.5).to_dict() if ok else None,
                     "eps_range_extent": [r.eps_lo / extent, r.eps_hi / extent] if ok else None, "note": r.note})  # fmt: skip
    ref = next((r["floor"] for r in rows if r["factor"] == 1.0), None)
    return {"floor": ref, "scatter_extent": None if scatter is None else float(scatter), "rows": rows}


def d1_precision(records, target: float = 0.03) -> dict:
    """d1_precision(records, target=0.03) -> how many points have d₁ to ≤ ``target`` (relative 1σ), which part of
    its error is the largest and what ends the scaling range below, with its statement.

    ``records`` are point records with the keys of :func:`d1_error_record` (those without ``d1_rel_err`` have no
    d₁ and are not counted). Keys: target, n_with_d1, n_within, largest_part ({fit, resample, range: count}),
    range_floor ({resolution, points: count}), statement.

    Examples
    --------
    >>> recs = [{"id": "a", "d1_rel_err": 0.02, "d1_err_largest": "resample", "d1_range_floor": "points",
    ...          "d1_eps_range_extent": [0.001, 0.1]},
    ...         {"id": "b", "d1_rel_err": 0.07, "d1_err_largest": "range", "d1_range_floor": "floor",
    ...          "d1_eps_range_extent": [0.03, 0.1]}, {"id": "c"}]
    >>> p = d1_precision(recs)
    >>> p["n_with_d1"], p["n_within"], p["largest_part"], p["range_floor"]
    (2, 1, {'fit': 0, 'resample': 1, 'range': 1}, {'floor': 1, 'points': 1})
    >>> p["statement"].split(";")[0]
    'd₁ to ≤ 3 % (1σ) at 1 of the 2 points with d₁ (a)'
    """
    with_d1 = [r for r in records if r.get("d1_rel_err") is not None]
    ok = [r for r in with_d1 if r["d1_rel_err"] <= target]
    largest = {k: sum(r["d1_err_largest"] == k for r in with_d1) for k in ERR_PARTS}
    floor = {k: sum(r["d1_range_floor"] == k for r in with_d1) for k in ("floor", "points")}
    decades = [math.log10(r["d1_eps_range_extent"][1] / r["d1_eps_range_extent"][0]) for r in with_d1]
    names = {"fit": "the fit's residuals (lacunarity)", "resample": "the bootstrap over orbits",
             "range": "the range part (the slope changes across the scaling range)"}  # fmt: skip
    parts = "; ".join(f"{names[k]} at {v}" for k, v in largest.items() if v)
    span = f"{min(decades):.1f}–{max(decades):.1f}" if decades else "no"
    statement = (f"d₁ to ≤ {100 * target:.0f} % (1σ) at {len(ok)} of the {len(with_d1)} points with d₁"
                 + (f" ({', '.join(r['id'] for r in ok)})" if ok else "")
                 + f"; the largest part of its error: {parts}; the scaling ranges span {span} decades of ε, ended "
                 f"below by the floor (a fixed fraction of the points' extent) at {floor['floor']} points and by the "
                 f"nearest neighbours' distance (the number of points) at {floor['points']}")  # fmt: skip
    return {"target": target, "n_with_d1": len(with_d1), "n_within": len(ok), "largest_part": largest,
            "range_floor": floor, "statement": statement}  # fmt: skip


def with_d0(rec: dict, d0: dict) -> dict:
    """with_d0(rec, d0) -> the record ``rec`` (updated in place) with the keys of ``d0`` and, where d₀ and d₁ are
    both measured, ``d0_ge_d1`` ({z, holds, verdict}: d₀ ≥ d₁ − 2σ, errors in quadrature,
    :func:`~hhscatter.analysis.geometry.saddle.dimension_order`).

    ``d0`` holds the point's d₀ keys (d0, d0_err, …) or a ``note`` saying why there is none, which goes to the
    record's ``notes`` (``d0`` loses its note).

    Examples
    --------
    >>> rec = with_d0({"notes": [], "d1": 0.60, "d1_err": 0.03}, {"d0": 0.64, "d0_err": 0.01})
    >>> rec["d0_ge_d1"]["holds"]
    True
    >>> with_d0({"notes": [], "d1": None}, {"note": "d0: too few ε"})["notes"]
    ['d0: too few ε']
    """
    note = d0.pop("note", None)
    if note:
        rec["notes"].append(note)
    rec.update(d0)
    if rec.get("d0") is not None and rec.get("d1") is not None:
        o = dimension_order(rec["d0"], rec["d0_err"], rec["d1"], rec["d1_err"])
        rec["d0_ge_d1"] = {"z": o.z, "holds": o.holds, "verdict": o.verdict}
    return rec


def relation_row(rec: dict) -> dict:
    """relation_row(rec) -> a record's measured values of the relation as {value, err} pairs (rendered
    ``value ± err``), the ones it has: κ, λ̄, D₁, d₁, λ̄(1 − d₁), d₁ implied and the section's D₁ implied (2×), with
    z and the verdict where checked.

    Examples
    --------
    >>> relation_row({"id": "a", "system": "hh", "ratio": 3.0, "energy": 0.5, "kappa": 0.36, "kappa_err": 0.004})
    {'id': 'a', 'system': 'hh', 'ratio': 3.0, 'energy': 0.5, 'kappa': {'value': 0.36, 'err': 0.004}}
    """
    row = {"id": rec["id"], "system": rec["system"], "ratio": rec["ratio"], "energy": rec["energy"]}
    for name, err in (("kappa", "kappa_err"), ("lyapunov", "lyapunov_err"), ("d1_section", "d1_section_err"),
                      ("d1", "d1_err"), ("predicted", "predicted_err"), ("d1_implied", "d1_implied_err")):  # fmt: skip
        if rec.get(name) is not None and rec.get(err) is not None:
            row[name] = Measured(rec[name], rec[err]).to_dict()
    if rec.get("d1_implied") is not None:
        row["d1_section_implied"] = Measured(rec["d1_implied"], rec["d1_implied_err"]).scaled(2).to_dict()
    if rec.get("verdict") is not None:
        row["z"], row["verdict"] = rec["z"], rec["verdict"]
    return row


def relation_summary(records) -> dict:
    """relation_summary(records) -> {n_points, n_checked, n_within_2sigma}: the points, those where the relation
    was checked (a ``z``) and those within 2σ (|z| ≤ 2).

    Examples
    --------
    >>> relation_summary([{"z": 1.5}, {"z": -2.5}, {"z": None}, {}])
    {'n_points': 4, 'n_checked': 2, 'n_within_2sigma': 1}
    """
    checked = [x for x in records if x.get("z") is not None]
    return {
        "n_points": len(records),
        "n_checked": len(checked),
        "n_within_2sigma": sum(abs(x["z"]) <= 2 for x in checked),
    }


def dimension_row(rec: dict) -> dict:
    """dimension_row(rec) -> a record's d₀ and d₁ (partial, along the unstable direction) and the section's D₀,
    D₁, with the scaling range of d₀ (``"lo – hi (n ε)"``), its fit's p-value and the check d₀ ≥ d₁ − 2σ (or
    "no d₁" / "no d₀").

    Examples
    --------
    >>> dimension_row({"id": "a", "system": "hh", "ratio": 2.0, "d0": 0.6, "d0_err": 0.01, "d0_section": 1.2,
    ...                "d0_section_err": 0.02, "d0_eps_range": [1e-6, 1e-2], "d0_n_eps": 5, "d0_fit_p": 0.4})
    ... # doctest: +NORMALIZE_WHITESPACE
    {'id': 'a', 'system': 'hh', 'ratio': 2.0, 'd0': 0.6, 'd0_err': 0.01, 'd0_section': 1.2, 'd0_section_err': 0.02,
     'd0_eps_range': '1e-06 – 1e-02 (5 ε)', 'd0_fit_p': 0.4, 'check': 'no d₁'}
    """
    row = {"id": rec["id"], "system": rec["system"], "ratio": rec["ratio"]}
    for name in ("d0", "d1", "d0_section", "d1_section"):
        if rec.get(name) is not None:
            row[name], row[name + "_err"] = rec[name], rec[name + "_err"]
    if rec.get("d0_eps_range") is not None:
        lo, hi = rec["d0_eps_range"]
        row["d0_eps_range"] = f"{lo:.0e} – {hi:.0e} ({rec['d0_n_eps']} ε)"
        row["d0_fit_p"] = rec["d0_fit_p"]
    chk = rec.get("d0_ge_d1")
    row["check"] = chk["verdict"] if chk else ("no d₁" if rec.get("d0") is not None else "no d₀")
    return row


def dimension_summary(records) -> dict:
    """dimension_summary(records) -> how many points have d₀, how many both dimensions, and where d₀ ≥ d₁ − 2σ
    holds, with its statement.

    Examples
    --------
    >>> recs = [{"id": "a", "d0": 0.6, "d0_ge_d1": {"holds": True}}, {"id": "b", "d0": 0.5,
    ...         "d0_ge_d1": {"holds": False}}, {"id": "c", "d0": None}]
    >>> s = dimension_summary(recs)
    >>> s["n_d0"], s["n_both"], s["n_holds"], s["statement"][-13:]
    (2, 2, 1, 'it fails at b')
    """
    both = [r for r in records if r.get("d0_ge_d1")]
    held = [r for r in both if r["d0_ge_d1"]["holds"]]
    failed = ", ".join(r["id"] for r in both if not r["d0_ge_d1"]["holds"])
    n_d0 = sum(r.get("d0") is not None for r in records)
    statement = (f"d₀ measured at {n_d0} of {len(records)} points; d₀ ≥ d₁ − 2σ (both partial, errors in "
                 f"quadrature) holds at {len(held)} of the {len(both)} with both dimensions"
                 + (f"; it fails at {failed}" if failed else ""))  # fmt: skip
    return {"n_points": len(records), "n_d0": n_d0, "n_both": len(both), "n_holds": len(held),
            "statement": statement}  # fmt: skip


# ---------------------------------------------------------------------------
# the gap between d₁ and 1 − κ/λ̄: the candidates measured
# ---------------------------------------------------------------------------
def mid_lyapunov_record(lo, hi, t_from: float, t_to: float, *, n_boot: int = 1000) -> dict:
    """mid_lyapunov_record(lo, hi, t_from, t_to, *, n_boot=1000) -> {"lyapunov_mid": {value, err, n_orbits, n_left,
    t_from, t_to}} or {"lyapunov_mid_note": why none}.

    ``lo`` and ``hi`` are the lifetimes tables (``traj_id``, ``outcome``, ``log_stretch``) of the same orbits
    integrated with the tangent dynamics to ``t_from`` and to ``t_to`` (time units): λ̄ between the two times
    (:func:`~hhscatter.analysis.geometry.saddle_checks.interval_lyapunov`) of the orbits still inside at both
    (outcome ``censored``); ``n_left`` counts the others.

    Examples
    --------
    >>> import pandas as pd
    >>> lo = pd.DataFrame({"traj_id": [0, 1, 2], "outcome": ["censored"] * 3, "log_stretch": [2.0, 3.0, 2.5]})
    >>> hi = lo.assign(log_stretch=[6.0, 7.2, 1.0], outcome=["censored", "censored", "escaped"])
    >>> r = mid_lyapunov_record(lo, hi, 10.0, 20.0, n_boot=10)["lyapunov_mid"]
    >>> round(r["value"], 2), r["n_orbits"], r["n_left"]
    (0.41, 2, 1)
    """
    a, b, inside = _inside_at_both(lo, hi)
    if np.count_nonzero(inside) < 2:
        return {"lyapunov_mid_note": f"fewer than 2 orbits still inside at t = {t_to:.6g}"}
    m = interval_lyapunov(a["log_stretch"].to_numpy()[inside], b["log_stretch"].to_numpy()[inside], t_from, t_to,
                          n_boot=n_boot, seed=0)  # fmt: skip
    return {"lyapunov_mid": {**Measured(m.value, m.err).to_dict(), "n_orbits": m.n_orbits,
                             "n_left": int(np.count_nonzero(~inside)), "t_from": float(t_from), "t_to": float(t_to)}}  # fmt: skip


def lyapunov_by_t_min(tangent, t_mins, kappa: float, *, n_boot: int = 1000) -> list:
    """lyapunov_by_t_min(tangent, t_mins, kappa, *, n_boot=1000) -> rows {t_min_kappa, n_orbits, value, err}: λ̄ =
    ΣΛ/ΣT (:func:`~hhscatter.analysis.geometry.saddle.mean_lyapunov`) of the orbits of ``tangent`` (``t_end``,
    ``log_stretch``) with t_end ≥ t_min, for each t_min of ``t_mins`` (time units) with at least 2 orbits.

    Examples
    --------
    >>> import pandas as pd
    >>> tg = pd.DataFrame({"t_end": [10.0, 20.0, 40.0], "log_stretch": [3.0, 8.0, 18.0]})
    >>> [(r["t_min_kappa"], r["n_orbits"], round(r["value"], 3)) for r in lyapunov_by_t_min(tg, [10, 20, 40], 0.1, n_boot=5)]
    [(1.0, 3, 0.414), (2.0, 2, 0.433)]
    """
    rows = []
    for t in t_mins:
        sel = tangent[tangent["t_end"].to_numpy() >= t]
        if len(sel) >= 2:
            m = mean_lyapunov(sel["log_stretch"], sel["t_end"], n_boot=n_boot, seed=0)
            rows.append({"t_min_kappa": float(t) * kappa, "n_orbits": m.n_orbits, **Measured(m.value, m.err).to_dict()})
    return rows


def _trend(rows, name):
    """The t_min trend (:func:`~hhscatter.analysis.geometry.saddle_checks.tmin_trend`) of rows {t_min_kappa, name:
    {value, err}} with a value, as a dict, or a note."""
    ok = [r for r in rows if r.get(name) is not None and r[name]["err"] > 0]
    if len(ok) < 3:
        return {
            "note": f"a trend needs at least 3 t_min with a value, got {len(ok)}",
            "t_min_kappa": [r["t_min_kappa"] for r in ok],
        }
    try:
        tr = tmin_trend([r["t_min_kappa"] for r in ok], [r[name]["value"] for r in ok], [r[name]["err"] for r in ok])
    except ConfigError as exc:
        return {"note": str(exc), "t_min_kappa": [r["t_min_kappa"] for r in ok]}
    return {"t_min_kappa": [r["t_min_kappa"] for r in ok], "last": Measured(tr.last, tr.last_err).to_dict(),
            "extrapolated": Measured(tr.extrapolated, tr.extrapolated_err).to_dict(),
            "slope": Measured(tr.slope, tr.slope_err).to_dict(), "step_z": tr.step_z, "bound": tr.bound,
            "converged": tr.converged}  # fmt: skip


def _inside_at_both(lo, hi):
    """(a, b, inside): ``lo`` and ``hi`` indexed by traj_id in lo's order and the mask of the orbits censored (still
    inside) in both."""
    a, b = (d.set_index("traj_id") for d in (lo, hi))
    b = b.reindex(a.index)
    inside = (a["outcome"].astype(object) == "censored").to_numpy() & (
        b["outcome"].astype(object) == "censored"
    ).to_numpy()
    return a, b, inside


def fluctuation_record(tangent, kappa: float, kappa_err: float, mid=None, *, n_boot: int = 1000) -> dict:
    """fluctuation_record(tangent, kappa, kappa_err, mid=None, *, n_boot=1000) -> {"ftle_fluctuation": {...}} or
    {"ftle_fluctuation_note": why none}.

    d₂ implied by κ (and its error, 1/time) and the selected orbits' log-stretches (the partition form of
    :func:`~hhscatter.analysis.geometry.saddle_checks.ftle_dimension`, q = 2) and its distance from 1 − κ/λ̄ with
    the same λ̄ = ΣΛ/ΣT, the fluctuations' part (``shift``). ``mid`` = (lo, hi, t_from, t_to): the lifetimes tables
    (``traj_id``, ``outcome``, ``log_stretch``) of the same orbits run to t_from and to t_to (time units); the
    stretch between the two times of the orbits inside at both is the one on the saddle, and gives ``shift`` (with
    ``d2``, ``diffusion`` and ``shift_cumulant``, the Gaussian form). ``tangent`` (``log_stretch``, ``t_end`` over
    the whole lives) gives ``shift_whole_life``: its scatter includes the way in and out, so it bounds the
    fluctuations' part from above; without ``mid`` it is ``shift``. D = Σ(Λ − λ̄T)²/ΣT in 1/time.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> rng = np.random.default_rng(0)
    >>> T = rng.uniform(50.0, 150.0, 2000)
    >>> tg = pd.DataFrame({"t_end": T, "log_stretch": 0.5 * T + np.sqrt(0.1 * T) * rng.normal(size=T.size)})
    >>> r = fluctuation_record(tg, 0.15, 0.001, n_boot=20)["ftle_fluctuation"]
    >>> round(r["shift"]["value"], 3), round(r["shift_cumulant"]["value"], 3), round(r["diffusion"]["value"], 2)
    (-0.009, -0.01, 0.1)
    """

    def fit(L, T):
        out = {}
        for form in ("partition", "cumulant"):
            try:
                out[form] = ftle_dimension(L, T, kappa, kappa_err, q=2.0, form=form, n_boot=n_boot, seed=0)
            except ConfigError as exc:
                out[form] = f"{form} form: {exc}"
        return out["partition"], out["cumulant"]

    def shift(r):
        return r if isinstance(r, str) else Measured(r.shift, r.shift_err).to_dict()

    whole = fit(tangent["log_stretch"].to_numpy(), tangent["t_end"].to_numpy())[0]
    source = "whole life"
    if mid is None:
        e, c = fit(tangent["log_stretch"].to_numpy(), tangent["t_end"].to_numpy())
    else:
        lo, hi, t_from, t_to = mid
        a, b, inside = _inside_at_both(lo, hi)
        if np.count_nonzero(inside) < 2:
            return {"ftle_fluctuation_note": f"fewer than 2 orbits still inside at t = {t_to:.6g}"}
        dL = b["log_stretch"].to_numpy()[inside] - a["log_stretch"].to_numpy()[inside]
        e, c = fit(dL, np.full(dL.size, float(t_to) - float(t_from)))
        source = f"mid-life, t = {t_from:.6g} to {t_to:.6g}"
    if isinstance(e, str):
        return {"ftle_fluctuation_note": e}
    return {"ftle_fluctuation": {"q": e.q, "stretch": source, "d2": Measured(e.value, e.err).to_dict(),
                                 "shift": shift(e), "shift_cumulant": shift(c), "shift_whole_life": shift(whole),
                                 "diffusion": Measured(e.diffusion, e.diffusion_err).to_dict(),
                                 "n_orbits": e.n_orbits}}  # fmt: skip


def sheets_record(points, force, *, floor: float, k_max: int, n_boot: int, min_boxes: float = 8.0) -> dict:
    """sheets_record(points, force, *, floor, k_max, n_boot, min_boxes=8) -> dict.

    The section ṙ = 0, φ̇ > 0 one sheet at a time and in a second chart. ``points`` holds section points
    (``traj_id``, ``x``, ``y``, ``px``, ``py``; positions in length units, momenta per unit mass) of a conservative
    flow with the force ``force(x, y) -> (F_x, F_y)``. The section is the union of two sheets that meet where the
    flow grazes it: the radial maxima (r̈ < 0) and the radial minima (r̈ > 0), with r̈ = (p² + r·F)/r at ṙ = 0.
    Each sheet's D₁ is measured by the neighbour estimator in two charts, the positions (x, y) and the canonical
    pair (φ, p_φ) (p_φ = x p_y − y p_x; the return map preserves dφ ∧ dp_φ), each axis scaled to the unit
    interval, fitted from ``floor`` up to 1/``min_boxes``. Returns ``sheets``: per sheet (``r_max``, ``r_min``) its
    number of points and d₁ = D₁/2 in each chart (``xy``, ``canonical``), or its ``note`` where the estimator
    refuses; and, where both sheets have one, ``d1_sheets`` and ``d1_chart``: the mean of the two sheets' d₁ in
    (x, y) and in (φ, p_φ), errors in quadrature (the gap candidates "sheets" and "chart").

    Examples
    --------
    Points filling a square of positions and a range of tangential speeds under a harmonic force (r̈ < 0 where
    the speed is below r): each sheet fills an area in both charts, d₁ = 1 up to the square's edges.

    >>> import numpy as np, pandas as pd
    >>> rng = np.random.default_rng(0)
    >>> x, y, v = 2 + rng.random(8000), rng.random(8000) - 0.5, 4 * rng.random(8000)
    >>> phi = np.arctan2(y, x)
    >>> pts = pd.DataFrame({"traj_id": np.arange(8000), "x": x, "y": y, "px": -v * np.sin(phi), "py": v * np.cos(phi)})
    >>> rec = sheets_record(pts, lambda x, y: (-x, -y), floor=1 / 128, k_max=8, n_boot=10)
    >>> rec["sheets"]["r_max"]["n_points"] == int((v < np.hypot(x, y)).sum())
    True
    >>> bool(abs(rec["d1_sheets"]["value"] - 1) < 0.05), bool(abs(rec["d1_chart"]["value"] - 1) < 0.05)
    (True, True)
    """
    check.table(points, "points", ("traj_id", "x", "y", "px", "py"))
    check.function(force, "force")
    floor, k_max = check.number(floor, "floor", positive=True), check.count(k_max, "k_max", 1)
    n_boot, min_boxes = check.count(n_boot, "n_boot", 0), check.number(min_boxes, "min_boxes", positive=True)
    x, y, px, py = (points[c].to_numpy(dtype=float) for c in ("x", "y", "px", "py"))
    g = points["traj_id"].to_numpy()
    fx, fy = force(x, y)
    r = np.hypot(x, y)
    rdd = (px**2 + py**2 + x * np.asarray(fx) + y * np.asarray(fy)) / r
    charts = {"xy": (x, y), "canonical": (np.arctan2(y, x), x * py - y * px)}
    out, means = {}, {}
    for sheet, at in (("r_max", rdd < 0), ("r_min", rdd > 0)):
        row = {"n_points": int(np.count_nonzero(at))}
        for chart, (a, b) in charts.items():
            P = np.column_stack([a[at], b[at]])
            try:
                if len(P) < 2:
                    raise ConfigError(f"the sheet holds {len(P)} point(s)")
                span = np.ptp(P, axis=0)
                if not np.all(span > 0):
                    raise ConfigError("the sheet's points span no area")
                d = information_dimension_neighbours((P - P.min(axis=0)) / span, g[at], k_max=k_max,
                                                     eps_max=1.0 / min_boxes, floor=floor, n_boot=n_boot, seed=0)  # fmt: skip
            except ConfigError as exc:
                row[f"{chart}_note"] = str(exc)
                continue
            half = Measured(d.value, d.err).scaled(0.5)
            row[chart] = half.to_dict()
            means.setdefault(chart, []).append(half)
        out[sheet] = row
    rec = {"sheets": out}
    for chart, key in (("xy", "d1_sheets"), ("canonical", "d1_chart")):
        if len(means.get(chart, [])) == 2:
            rec[key] = means[chart][0].sum(means[chart][1]).scaled(0.5).to_dict()
    return rec


def hyperbolic_record(tangent, points, d1_of, d1_all, thresholds=(0.25, 0.5, 0.75), *, n_boot: int = 1000) -> dict:
    """hyperbolic_record(tangent, points, d1_of, d1_all, thresholds=(0.25, 0.5, 0.75), *, n_boot=1000) ->
    {"hyperbolic": {...}} or {"hyperbolic_note": why none}.

    The selected orbits whose finite-time exponent Λ/T lies below a fraction of λ̄
    (:func:`~hhscatter.analysis.geometry.saddle_checks.low_ftle_share`), at each of ``thresholds`` (the middle one
    the stated rule, the others its systematic), and the relation's inputs from the other orbits, the hyperbolic
    part, at the middle threshold. ``tangent`` holds the orbits' ``traj_id``, ``log_stretch`` and ``t_end`` (time
    units), ``points`` the saddle points (``traj_id`` and coordinates) of the same orbits, ``d1_of`` a function of
    a subset of ``points`` returning its section dimension (a
    :class:`~hhscatter.analysis.geometry.saddle.SaddleDimension`, the estimator of the whole set) and ``d1_all``
    that dimension on all of ``points`` (used where no orbit is left out). Keys: ``shares`` ([{threshold, share:
    {value, err}, n_low}]), ``threshold``, ``n_low``, ``lyapunov_shift`` (λ̄ = ΣΛ/ΣT of the hyperbolic part minus
    that of all, 1/time, its bootstrap error), ``d1`` (partial, D₁/2, of the hyperbolic part's points), ``n_orbits``.

    Examples
    --------
    >>> import dataclasses, pandas as pd
    >>> from hhscatter.analysis.geometry.saddle import SaddleDimension
    >>> tg = pd.DataFrame({"traj_id": [1, 2, 3, 4], "t_end": [100.0] * 4, "log_stretch": [2.0, 40.0, 42.0, 38.0]})
    >>> pts = pd.DataFrame({"traj_id": [1, 2, 3, 4], "x": [0.0, 0.1, 0.2, 0.3]})
    >>> d = SaddleDimension(value=1.2, err=0.02, err_fit=0.0, err_resample=0.0, err_range=0.0, method="",
    ...                     eps_range=(0.01, 0.1), n_points=4, n_groups=4, table=None)
    >>> h = hyperbolic_record(tg, pts, lambda p: dataclasses.replace(d, value=len(p) / 2.5), d, n_boot=10)
    >>> h = h["hyperbolic"]   # orbit 1 stretches at 0.02 against λ̄ = 0.305: left out at every threshold
    >>> [s["n_low"] for s in h["shares"]], round(h["lyapunov_shift"]["value"], 3), h["d1"]["value"]
    ([1, 1, 1], 0.095, 0.6)
    """
    L, T = tangent["log_stretch"].to_numpy(), tangent["t_end"].to_numpy()
    ths = sorted(float(t) for t in thresholds)
    if not ths:
        raise ConfigError("thresholds must name at least one fraction of λ̄")
    try:
        res = [low_ftle_share(L, T, threshold=t, n_boot=n_boot, seed=0) for t in ths]
    except ConfigError as exc:
        return {"hyperbolic_note": str(exc)}
    mid = res[len(res) // 2]
    if mid.rest is None:
        return {"hyperbolic_note": f"fewer than 2 orbits with Λ/T ≥ {mid.threshold:g}·λ̄"}
    low_ids = tangent["traj_id"].to_numpy()[~mid.hyperbolic]
    if low_ids.size:
        try:
            d = d1_of(points[~points["traj_id"].isin(low_ids)])
        except ConfigError as exc:
            return {"hyperbolic_note": f"d1 of the hyperbolic part: {exc}"}
    else:
        d = d1_all
    return {"hyperbolic": {"shares": [{"threshold": r.threshold, "share": Measured(r.share, r.share_err).to_dict(),
                                       "n_low": r.n_low} for r in res],
                           "threshold": mid.threshold, "n_low": mid.n_low, "n_orbits": mid.n_orbits,
                           "lyapunov_shift": Measured(mid.rest.value - mid.lyapunov, mid.rest.err).to_dict(),
                           "d1": Measured(d.value, d.err).scaled(0.5).to_dict()}}  # fmt: skip


def _fit_cells(r) -> dict:
    """A row of :func:`~hhscatter.analysis.geometry.saddle.neighbour_floor_scan` or
    :func:`~hhscatter.analysis.geometry.saddle.neighbour_scale_bands` (value, err, eps_lo, eps_hi, note) as a record's
    cells: d1 ({value, err}) and eps_range, None where the estimator refused the row, and its note."""
    ok = math.isfinite(r.value)
    return {"d1": Measured(r.value, r.err).to_dict() if ok else None,
            "eps_range": [float(r.eps_lo), float(r.eps_hi)] if ok else None, "note": r.note}  # fmt: skip


def lines_record(by_t_min, chosen: float, scan, kg, *, n_lines: int, scatter: float) -> dict:
    """lines_record(by_t_min, chosen, scan, kg, *, n_lines, scatter) -> the record's keys of d₁ on lines.

    d₁ measured on lines of initial conditions: the orbits of a line that leave after t_min start within
    ~e^{−λ̄ t_min} of the saddle's stable manifold, and the measure they carry along the line (Lebesgue, normalised
    over the survivors) tends to the stable manifold's natural measure, whose information dimension along the
    line is the partial d₁ of the relation: the weight of a surviving interval of length ε_i is ε_i e^{κt}, so its
    information over the scale ln(1/ε) ≈ λ̄t is (λ̄ − κ)t/(λ̄t) = 1 − κ/λ̄ (Kantz and Grassberger 1985). No section
    points, no doubling of a section dimension: an independent measurement of the same d₁.

    ``by_t_min`` is a list of (t_min·κ, number of survivors, SaddleDimension or the refusal's text), ``chosen`` the
    t_min·κ of the rule (one of them), ``scan`` the :func:`~hhscatter.analysis.geometry.saddle.neighbour_floor_scan`
    of the chosen survivors, ``kg`` the :class:`~hhscatter.analysis.geometry.saddle.KantzGrassberger` of κ, λ̄ and
    that d₁ (or None), ``scatter`` e^{−λ̄ t_min}: the survivors' distance from the stable manifold in units of a
    line's extent (stated, not used; None where λ̄ ≤ 0). Keys: ``d1_lines`` ({value, err}, None where refused) and
    ``d1_lines_detail`` (t_min_kappa, n_points, n_lines, eps_range, scatter_extent, floor_scan rows, by_t_min rows,
    and the relation with this d₁: predicted, z, verdict).

    Examples
    --------
    >>> import pandas as pd
    >>> from hhscatter.analysis.geometry.saddle import kantz_grassberger
    >>> class D: value, err, eps_range = 0.77, 0.005, (1e-4, 0.02)
    >>> scan = pd.DataFrame({"factor": [1.0], "floor": [1e-4], "eps_min": [1e-4]})
    >>> scan = scan.assign(value=[0.77], err=[0.005], eps_lo=[1e-4], eps_hi=[0.02], note=[""])
    >>> kg = kantz_grassberger(0.0953, 0.0004, 0.412, 0.0017, 0.77, 0.005)
    >>> r = lines_record([(5.0, 5000, D), (6.0, 1650, "too few")], 5.0, scan, kg, n_lines=16, scatter=1e-9)
    >>> r["d1_lines"], r["d1_lines_detail"]["verdict"], r["d1_lines_detail"]["by_t_min"][1]["d1"]
    ({'value': 0.77, 'err': 0.005}, 'agrees (z = +0.3)', None)
    """
    rows, chosen_row = [], None
    for c, n, d in by_t_min:
        ok = not isinstance(d, str)
        row = {"t_min_kappa": float(c), "n_points": int(n), "d1": Measured(d.value, d.err).to_dict() if ok else None,
               "eps_range": list(d.eps_range) if ok else None, "note": "" if ok else str(d)}  # fmt: skip
        rows.append(row)
        if c == chosen:
            chosen_row = row
    if chosen_row is None:
        raise ConfigError(f"chosen t_min·κ {chosen!r} is not among the t_min of by_t_min")
    scan_rows = [{"factor": float(r.factor), "floor": float(r.floor), **_fit_cells(r)} for r in scan.itertuples()]
    detail = {"t_min_kappa": float(chosen), "n_points": chosen_row["n_points"], "n_lines": int(n_lines),
              "eps_range": chosen_row["eps_range"], "scatter_extent": None if scatter is None else float(scatter),
              "floor_scan": scan_rows,
              "by_t_min": rows}  # fmt: skip
    if kg is not None:
        detail.update({"predicted": Measured(kg.predicted, kg.predicted_err).to_dict(), "z": kg.z,
                       "verdict": kg.verdict})  # fmt: skip
    return {"d1_lines": chosen_row["d1"], "d1_lines_detail": detail}


def long_lived(lifetimes, t_min: float):
    """long_lived(lifetimes, t_min) -> the rows of ``lifetimes`` (``outcome``, ``t_end``) of the orbits that left
    (escaped or settled) at t_end ≥ ``t_min`` (time units): the orbits that stayed near the saddle; an orbit still
    inside at the end of its run (censored) is not one of them.

    Examples
    --------
    >>> import pandas as pd
    >>> lt = pd.DataFrame({"traj_id": [0, 1, 2, 3], "outcome": ["escaped", "censored", "settled", "escaped"],
    ...                    "t_end": [5.0, 50.0, 20.0, 30.0]})
    >>> long_lived(lt, 10.0)["traj_id"].tolist()
    [2, 3]
    """
    check.table(lifetimes, "lifetimes", ("outcome", "t_end"), min_rows=0)
    t_min = check.number(t_min, "t_min")
    left = lifetimes["outcome"].astype(object).isin(LEAVING_OUTCOMES).to_numpy()
    return lifetimes[left & (lifetimes["t_end"].to_numpy() >= t_min)]


def lines_measurement(
    rows,
    kappa,
    kappa_err,
    lam,
    lam_err,
    *,
    efolds,
    checks,
    floor,
    factors,
    k_max,
    n_boot,
    t_max,
    n_lines,
    bands=(),
    section_band=None,
) -> dict:
    """lines_measurement(rows, κ, σ_κ, λ̄, σ_λ, *, efolds, checks, floor, factors, k_max, n_boot, t_max, n_lines,
    bands=(), section_band=None) -> dict.

    d₁ on lines: ``rows`` holds one row per initial condition of the lines (``x`` its position along its line,
    ``line``, ``outcome``, ``t_end``); the orbits that left at t_end ≥ c/κ, for c of ``efolds`` and ``checks``, are
    the survivors whose positions sample the stable manifold's measure, one block a line
    (:func:`~hhscatter.analysis.geometry.saddle.information_dimension_neighbours` with ``floor`` of a line's
    extent); at ``efolds`` its floor scan (× ``factors``) and the relation κ = λ̄(1 − d₁) with it. A t_min not
    before the lines' ``t_max`` is refused; no λ̄ (None) or λ̄ ≤ 0 gives no relation. ``bands`` ((lo, hi) pairs,
    fractions of a line's extent): the local slope band by band
    (:func:`~hhscatter.analysis.geometry.saddle.neighbour_scale_bands`) at every t_min, in ``d1_lines_detail.bands``;
    ``section_band`` (lo, hi): d₁ on lines over the section's own range of scales (the same fractions of the
    extent as its rule), at ``efolds``, in ``d1_lines_detail.at_section_scales``. Returns :func:`lines_record`'s
    keys, or ``{"notes_lines": why}`` where d₁ at ``efolds`` is refused.
    """

    def args(c):
        sel = long_lived(rows, c / kappa)
        return {"points": sel["x"].to_numpy(), "blocks": sel["line"].to_numpy(), "k_max": k_max, "n_boot": n_boot,
                "seed": 0}, len(sel)  # fmt: skip

    by, chosen_args = [], None
    for c in sorted({efolds, *checks}):
        a, n = args(c)
        if c == efolds:
            chosen_args = a
        try:
            if c / kappa >= t_max:
                raise ConfigError(f"t_min = {c / kappa:.4g} is not before the lines' t_max {t_max:.4g}")
            by.append((c, n, information_dimension_neighbours(**a, floor=floor)))
        except ConfigError as exc:
            by.append((c, n, str(exc)))
    chosen = next(d for c, _n, d in by if c == efolds)
    if isinstance(chosen, str):
        return {"notes_lines": f"d1 on lines: {chosen}"}
    scan = neighbour_floor_scan(**chosen_args, floor=floor, factors=factors)
    try:
        kg = kantz_grassberger(kappa, kappa_err, lam, lam_err, chosen.value, chosen.err)
    except ConfigError:  # λ̄ ≤ 0: no relation to check (the record's own note says why)
        kg = None
    scatter = math.exp(-lam * efolds / kappa) if lam is not None and lam > 0 else None
    out = lines_record(by, efolds, scan, kg, n_lines=n_lines, scatter=scatter)

    def band_rows(a, bs, c):
        tab = neighbour_scale_bands(a["points"], blocks=a["blocks"], bands=bs, k_max=k_max, n_boot=n_boot, seed=0)
        return [{"t_min_kappa": float(c), "lo": float(r.lo), "hi": float(r.hi), **_fit_cells(r)}
                for r in tab.itertuples()]  # fmt: skip

    detail = out["d1_lines_detail"]
    if bands:
        detail["bands"] = []
        for c, _n, d in by:
            if isinstance(d, str):  # refused at this t_min: no bands either
                continue
            detail["bands"].extend(band_rows(args(c)[0], list(bands), c))
    if section_band is not None:
        detail["at_section_scales"] = band_rows(chosen_args, [tuple(section_band)], efolds)[0]
    return out


def lyapunov_record(lt, *, n_bins: int, n_boot: int):
    """lyapunov_record(lt, *, n_bins, n_boot) -> (the record's λ̄: value, error, rule, the FTLE quantiles and the 1/T
    extrapolation, the rows of ``lt`` with their FTLE), or None with fewer than 2 orbits.

    ``lt``: the selected orbits of a tangent run (``log_stretch`` Λ, ``t_end`` T). λ̄ = ΣΛ/ΣT
    (:func:`~hhscatter.analysis.geometry.saddle.mean_lyapunov`); λ̄(T) = λ∞ + Λ₀/T over ``n_bins`` bins of T
    (:func:`~hhscatter.analysis.geometry.saddle.lyapunov_convergence`, its bins in ``by_T``: mean T, orbits, λ̄ and
    its error), λ∞ taken where the drift Λ₀ is resolved (|Λ₀| > 2σ). An offset of Λ per orbit (the way in to the
    saddle and out) leaves λ∞ the saddle's positive exponent; where the drift is resolved and λ∞ is not above 0 by
    2σ, λ̄(T) is not of that form (it falls with T more than an offset allows, or the lifetimes span too little to
    tell), and the record has no λ̄: ``value`` and ``err`` None, ``rule`` "none (…)".

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> T = np.repeat([100.0, 120.0, 140.0, 160.0, 180.0], 50)
    >>> lam, _ = lyapunov_record(pd.DataFrame({"log_stretch": 0.2 * T + 3.0, "t_end": T}), n_bins=5, n_boot=20)
    >>> round(lam["value"], 6), lam["rule"]                # an offset Λ₀ = 3: λ∞ = 0.2
    (0.2, 'extrapolated (1/T drift resolved)')
    >>> lam, _ = lyapunov_record(pd.DataFrame({"log_stretch": 20.0 - 0.05 * T, "t_end": T}), n_bins=5, n_boot=20)
    >>> lam["value"], lam["rule"][:4], round(lam["extrapolated"], 6)   # Λ/T falls to 0.06: λ∞ = −0.05
    (None, 'none', -0.05)
    """
    L, T = lt["log_stretch"].to_numpy(), lt["t_end"].to_numpy()
    if L.size < 2:
        return None
    mean = mean_lyapunov(L, T, n_boot=n_boot, seed=0)
    out = {"mean": mean.value, "mean_err": mean.err, "n_orbits": mean.n_orbits, "ftle_std": mean.ftle_std,
           "ftle_q05": mean.ftle_quantiles[0.05], "ftle_q50": mean.ftle_quantiles[0.5],
           "ftle_q95": mean.ftle_quantiles[0.95], **Measured(mean.value, mean.err).to_dict(), "rule": "mean"}  # fmt: skip
    try:
        c = lyapunov_convergence(L, T, n_bins=n_bins, n_boot=n_boot, seed=0)
    except ConfigError as exc:
        out["convergence"] = str(exc)
        return out, lt.assign(ftle=mean.ftle)
    out.update({"extrapolated": c.extrapolated, "extrapolated_err": c.extrapolated_err, "slope": c.slope,
                "slope_err": c.slope_err, "converged": c.converged,
                "by_T": [{"T": float(r.T), "n_orbits": int(r.n_orbits), **Measured(r.value, r.err).to_dict()}
                         for r in c.table.itertuples()]})  # fmt: skip
    lam_inf = Measured(c.extrapolated, c.extrapolated_err, "1/T extrapolation", mean.n_orbits)
    out.update({"lambda_mean": Measured(mean.value, mean.err, "mean", mean.n_orbits).to_dict(),
                "lambda_inf": lam_inf.to_dict(),
                "b": Measured(c.slope, c.slope_err, "1/T slope", mean.n_orbits).to_dict()})  # fmt: skip
    if not c.converged:
        if c.extrapolated > 2.0 * c.extrapolated_err:
            out.update({**lam_inf.to_dict(), "rule": "extrapolated (1/T drift resolved)"})
        else:
            # no value and no error: not a measurement, so no Measured
            out.update({**dict.fromkeys(("value", "err")), "rule": "none (1/T drift resolved, λ∞ not above 0 by 2σ)"})
    return out, lt.assign(ftle=mean.ftle)


def no_lyapunov_words(lam: dict) -> str:
    """no_lyapunov_words(lam) -> a point's note where :func:`lyapunov_record` gives no λ̄: the 1/T extrapolation,
    λ̄(T) in the first and last bins of T and ΣΛ/ΣT, and that the relation is not checked (1/time; T in time units).

    Examples
    --------
    >>> lam = {"extrapolated": -0.02, "extrapolated_err": 0.005, "mean": 0.057, "mean_err": 0.001, "n_orbits": 1160,
    ...        "by_T": [{"T": 385.0, **Measured(0.074, 0.002).to_dict()}, {"T": 562.0, **Measured(0.044, 0.001).to_dict()}]}
    >>> print(no_lyapunov_words(lam))  # doctest: +NORMALIZE_WHITESPACE
    λ̄: none; λ̄(T) = λ∞ + Λ₀/T extrapolates to λ∞ = −0.0200 ± 0.0050, not above 0 by 2σ; λ̄(T) = 0.0740 ± 0.0020
    at T = 385 to 0.0440 ± 0.0010 at T = 562 (ΣΛ/ΣT = 0.0570 ± 0.0010 over 1160 orbits); the relation is not checked
    """
    for key in ("extrapolated", "extrapolated_err", "mean", "mean_err", "n_orbits", "by_T"):
        if key not in lam:
            raise ConfigError(f"lam: no key {key!r} (a record of lyapunov_record with its 1/T extrapolation)")
    if len(lam["by_T"]) < 2:
        raise ConfigError(f"lam['by_T'] must hold at least 2 bins of T, got {len(lam['by_T'])}")
    a, b = lam["by_T"][0], lam["by_T"][-1]
    return (
        f"λ̄: none; λ̄(T) = λ∞ + Λ₀/T extrapolates to λ∞ = {value_err(lam['extrapolated'], lam['extrapolated_err'])}, "
        f"not above 0 by 2σ; λ̄(T) = {value_err(a['value'], a['err'])} at T = {a['T']:.0f} to "
        f"{value_err(b['value'], b['err'])} at T = {b['T']:.0f} (ΣΛ/ΣT = {value_err(lam['mean'], lam['mean_err'])} "
        f"over {int(lam['n_orbits'])} orbits); the relation is not checked"
    )


def d0_record(layout, lifetimes, *, min_count: int) -> dict:
    """d0_record(layout, lifetimes, *, min_count) -> d₀ = 1 − α of a lines run: the record's keys (d0, d0_err, the
    section's D₀, the scaling range, the fit's χ² and p, the f(ε) rows) or a note.

    ``layout`` (sorted by traj_id) gives each orbit's ``eps``, ``pair`` and ``moved``; ``lifetimes`` the run's
    lifetimes in the same order (outcome and exit channel). A pair is uncertain when its exits differ; a pair
    with an orbit still inside at t_max is left out; α by binomial maximum likelihood over the ε with ≥
    ``min_count`` uncertain pairs (and not all).
    """
    import pandas as pd  # deferred: pandas loads on first use

    codes = outcome_codes(lifetimes)
    codes[codes == TRAPPED_CODE] = OUTSIDE  # an orbit still inside at t_max: its pair is left out
    rows = []
    for e, g in layout.assign(code=codes).groupby("eps", sort=False):
        ref, moved = (g[g["moved"] == m].sort_values("pair")["code"].to_numpy() for m in (False, True))
        u = uncertainty_fraction(ref, moved, outside=OUTSIDE)
        rows.append({"eps": float(e), "f": u.f, "k": u.k, "n": u.n, "n_excluded": u.n_excluded})
    tab = pd.DataFrame(rows).sort_values("eps", ascending=False)
    ok = (tab["k"] >= min_count) & (tab["k"] < tab["n"])
    out = {"d0_uncertainty": tab.to_dict(orient="records")}
    if ok.sum() < 3:
        return {**out, "note": f"d0: fewer than 3 values of ε with ≥ {min_count} uncertain pairs"}
    rng = (float(tab.loc[ok, "eps"].min()), float(tab.loc[ok, "eps"].max()))
    try:
        d = dimension_from_uncertainty(tab["eps"], tab["f"], tab["n"], eps_range=rng)
        u = uncertainty_exponent(tab["eps"], tab["f"], tab["n"], eps_range=rng, dim=1.0)
    except (ValueError, ConfigError) as exc:
        return {**out, "note": f"d0: {exc}"}
    return {**out, "d0": d.value, "d0_err": d.err, "d0_section": 2 * d.value, "d0_section_err": 2 * d.err,
            "d0_eps_range": list(d.eps_range), "d0_n_eps": u.n_points, "d0_fit_chi2": u.chi2,
            "d0_fit_dof": u.dof, "d0_fit_p": u.p_value}  # fmt: skip


def lines_row(rec: dict) -> dict:
    """lines_row(rec) -> a record's d₁ on the section (D₁/2), d₁ on lines, 1 − κ/λ̄ and the relation with d₁ on lines
    (the table beside the section's), the ones it has.

    Examples
    --------
    >>> lines_row({"id": "a", "system": "hh", "ratio": 1.5, "d1": 0.70, "d1_err": 0.005,
    ...            "d1_implied": 0.769, "d1_implied_err": 0.001, "d1_lines": Measured(0.77, 0.005).to_dict(),
    ...            "d1_lines_detail": {"n_points": 5000, "eps_range": [1e-4, 0.02], "z": -0.3,
    ...                                "verdict": "agrees (z = −0.3)"}})  # doctest: +NORMALIZE_WHITESPACE
    {'id': 'a', 'system': 'hh', 'ratio': 1.5, 'd1': {'value': 0.7, 'err': 0.005},
     'd1_implied': {'value': 0.769, 'err': 0.001}, 'd1_lines': {'value': 0.77, 'err': 0.005}, 'n_points': 5000,
     'eps_range': [0.0001, 0.02], 'z': -0.3, 'verdict': 'agrees (z = −0.3)'}
    """
    row = {"id": rec["id"], "system": rec["system"], "ratio": rec["ratio"]}
    for name in ("d1", "d1_implied"):
        if rec.get(name) is not None and rec.get(name + "_err") is not None:
            row[name] = Measured(rec[name], rec[name + "_err"]).to_dict()
    if rec.get("d1_lines"):
        det = rec["d1_lines_detail"]
        row.update({"d1_lines": rec["d1_lines"], "n_points": det["n_points"], "eps_range": det["eps_range"]})
        if "z" in det:
            row.update({"z": det["z"], "verdict": det["verdict"]})
    return row


def _by(gaps) -> str:
    """ ", by a" or ", by a–b" of sorted gaps."""
    return (
        f", by {gaps[0]:.3f}"
        if len(gaps) == 1 or f"{gaps[0]:.3f}" == f"{gaps[-1]:.3f}"
        else (f", by {gaps[0]:.3f}–{gaps[-1]:.3f}")
    )


def lines_summary(records) -> dict:
    """lines_summary(records) -> the relation with d₁ on lines (checked, within 2σ, per system) and d₁ on the section
    against d₁ on lines (z of their difference, both errors; where it exceeds 2 and by how much), with the statement.

    Examples
    --------
    >>> recs = [{"id": "a", "system": "hh", "d1": 0.70, "d1_err": 0.005, "d1_lines": Measured(0.77, 0.005).to_dict(),
    ...          "d1_lines_detail": {"z": -0.3}},
    ...         {"id": "b", "system": "hh", "d1": 0.61, "d1_err": 0.007, "d1_lines": Measured(0.64, 0.009).to_dict(),
    ...          "d1_lines_detail": {"z": 2.4}}, {"id": "c", "system": "hh"}]
    >>> s = lines_summary(recs)
    >>> s["n_checked"], s["n_within_2sigma"], s["section_below_at"]
    (2, 1, ['a', 'b'])
    >>> print(s["statement"])
    With d₁ on lines, κ = λ̄(1 − d₁) holds within 2σ at 1 of the 2 points checked (hh: 1 of 2); the section points' d₁ lies more than 2σ below d₁ on lines at 2 of 2, by 0.030–0.070
    """
    checked = [r for r in records if r.get("d1_lines") and "z" in r.get("d1_lines_detail", {})]
    within = [r for r in checked if abs(r["d1_lines_detail"]["z"]) <= 2]
    by_system = {}
    for r in checked:
        s = by_system.setdefault(r["system"], {"n_checked": 0, "n_within_2sigma": 0})
        s["n_checked"] += 1
        s["n_within_2sigma"] += abs(r["d1_lines_detail"]["z"]) <= 2
    both = [r for r in records if r.get("d1_lines") and r.get("d1") is not None and r.get("d1_err") is not None]
    diffs = []
    for r in both:
        diff = Measured(r["d1"], r["d1_err"]).difference(Measured(r["d1_lines"]["value"], r["d1_lines"]["err"]))
        diffs.append(
            (r["id"], diff.value, diff.value / diff.err if diff.err > 0 else math.copysign(math.inf, diff.value))
        )
    below = [(i, v) for i, v, z in diffs if z < -2]
    above = [i for i, _v, z in diffs if z > 2]
    statement = (f"With d₁ on lines, κ = λ̄(1 − d₁) holds within 2σ at {len(within)} of the {len(checked)} points "
                 f"checked" + (" (" + ", ".join(f"{k}: {v['n_within_2sigma']} of {v['n_checked']}"
                                                for k, v in by_system.items()) + ")" if by_system else "")
                 + f"; the section points' d₁ lies more than 2σ below d₁ on lines at {len(below)} of {len(both)}"
                 + (_by(sorted(-v for _i, v in below)) if below else "")
                 + (f", more than 2σ above at {len(above)}" if above else ""))  # fmt: skip
    return {"n_checked": len(checked), "n_within_2sigma": len(within), "by_system": by_system,
            "section_minus_lines": [{"id": i, "value": v, "z": z} for i, v, z in diffs],
            "section_below_at": [i for i, _v in below], "section_above_at": above, "statement": statement}  # fmt: skip


def _lowest_band(det: dict, c: float):
    """The row of ``det["bands"]`` with the smallest scales at t_min·κ = c that has a d₁, or None."""
    rows = [r for r in det.get("bands", []) if r["t_min_kappa"] == c and r["d1"]]
    return min(rows, key=lambda r: r["lo"]) if rows else None


def _z(a: dict, b: dict) -> float:
    """z of a − b, {value, err} each, errors in quadrature."""
    diff = Measured(a["value"], a["err"]).difference(Measured(b["value"], b["err"]))
    return diff.value / diff.err if diff.err > 0 else math.copysign(math.inf, diff.value) if diff.value else 0.0


def scales_row(rec: dict) -> dict:
    """scales_row(rec) -> a record's d₁ across scales: the section's d₁ (D₁/2), d₁ on lines over the section's band
    of scales and per band (``band_<lo>``: the bands of ``d1_lines_detail.bands`` at the rule's t_min, lo as a
    fraction of a line's extent), 1 − κ/λ̄, and the z of: the lines over the section's band against the section
    (``z_section``), the lowest band against the section's band on lines (``z_rise``), the lowest band against
    1 − κ/λ̄ (``z_implied``) and the lowest band at the latest t_min against the rule's (``z_t_min``); the scales
    fitted, fractions of the extent: ``section_eps`` (the section's fit) and ``lowest_eps`` (the lowest band's).

    Examples
    --------
    >>> m = lambda v, e: Measured(v, e).to_dict()
    >>> det = {"t_min_kappa": 6.0, "at_section_scales": {"lo": 0.002, "hi": 0.125, "d1": m(0.72, 0.01)},
    ...        "bands": [{"t_min_kappa": 6.0, "lo": 1e-4, "hi": 1e-3, "d1": m(0.77, 0.015)},
    ...                  {"t_min_kappa": 6.0, "lo": 1e-3, "hi": 1e-2, "d1": m(0.75, 0.01)},
    ...                  {"t_min_kappa": 7.0, "lo": 1e-4, "hi": 1e-3, "d1": m(0.77, 0.02)}]}
    >>> r = scales_row({"id": "a", "system": "hh", "ratio": 1.5, "d1": 0.70, "d1_err": 0.005, "d1_implied": 0.769,
    ...                 "d1_implied_err": 0.001, "d1_lines_detail": det})
    >>> r["band_0.0001"] == m(0.77, 0.015), round(r["z_rise"], 2), round(r["z_implied"], 2), r["z_t_min"]
    (True, 2.77, 0.07, 0.0)
    """
    row = {"id": rec["id"], "system": rec["system"], "ratio": rec["ratio"]}
    if rec.get("d1") is not None:
        row["d1"] = Measured(rec["d1"], rec["d1_err"]).to_dict()
    det = rec.get("d1_lines_detail") or {}
    sec = (det.get("at_section_scales") or {}).get("d1")
    if sec:
        row["d1_section_scales"] = sec
        if "d1" in row:
            row["z_section"] = _z(sec, row["d1"])
    c = det.get("t_min_kappa")
    for r in det.get("bands", []):
        if r["t_min_kappa"] == c and r["d1"]:
            row[f"band_{r['lo']:g}"] = r["d1"]
    low = _lowest_band(det, c) if c is not None else None
    if rec.get("d1_implied") is not None:
        row["d1_implied"] = Measured(rec["d1_implied"], rec["d1_implied_err"]).to_dict()
    if rec.get("d1_eps_range_extent"):  # the scales the section's fit reached, fractions of its points' extent
        row["section_eps"] = rec["d1_eps_range_extent"]
    if low:
        row["lowest_band"], row["lowest_eps"] = [low["lo"], low["hi"]], low.get("eps_range")
        if sec:
            row["z_rise"] = _z(low["d1"], sec)
        if "d1_implied" in row:
            row["z_implied"] = _z(low["d1"], row["d1_implied"])
        later = [r for r in det.get("bands", []) if r["t_min_kappa"] > c and r["lo"] == low["lo"] and r["d1"]]
        if later:
            row["z_t_min"] = _z(max(later, key=lambda r: r["t_min_kappa"])["d1"], low["d1"])
    return row


def scales_summary(records) -> dict:
    """scales_summary(records) -> how d₁ on lines changes with the scale, over the points with its bands: where the
    lowest band lies above the section's band (with the one-sided sign test over the points: each an independent
    run, the chance of so many above if either side were as likely), where by more than 2σ (the slope rises
    towards the small scales) and where it lies more than 2σ below; where d₁ on lines over the section's band meets the section's d₁ within 2σ; where the lowest
    band meets 1 − κ/λ̄ within 2σ; and where the lowest band moves beyond 2σ from the rule's t_min to the latest
    (the survivors' scatter about the manifold reaching into it), with the statement.

    Examples
    --------
    >>> rows = [{"id": "a", "z_rise": 2.8, "z_section": 1.0, "z_implied": 0.1, "z_t_min": 0.0},
    ...         {"id": "b", "z_rise": 0.5, "z_section": -0.4, "z_implied": 3.1, "z_t_min": -2.5}, {"id": "c"}]
    >>> s = scales_summary(rows)
    >>> s["rise_at"], s["section_agrees_at"], s["implied_agrees_at"], s["t_min_moves_at"]
    (['a'], ['a', 'b'], ['a'], ['b'])
    >>> s["above_at"], s["p_sign"]                     # 2 of 2 above: (1/2)² one-sided
    (['a', 'b'], 0.25)
    """

    def where(key, test):
        return [r["id"] for r in records if r.get(key) is not None and test(r[key])]

    has = [r["id"] for r in records if r.get("z_rise") is not None]
    rise, fall = where("z_rise", lambda z: z > 2), where("z_rise", lambda z: z < -2)
    above = where("z_rise", lambda z: z > 0)
    # one-sided sign test over the points (independent runs): P(≥ len(above) of len(has) above | each side ½)
    p_sign = sum(math.comb(len(has), k) for k in range(len(above), len(has) + 1)) / 2.0 ** len(has) if has else None
    sec_n, sec_ok = where("z_section", lambda z: True), where("z_section", lambda z: abs(z) <= 2)
    imp_n, imp_ok = where("z_implied", lambda z: True), where("z_implied", lambda z: abs(z) <= 2)
    t_n, moves = where("z_t_min", lambda z: True), where("z_t_min", lambda z: abs(z) > 2)

    def ids(xs):
        return f" ({', '.join(xs)})" if xs else ""

    statement = (f"On lines, d₁ over the smallest scales lies above d₁ over the section's band of scales at {len(above)} "
                 f"of {len(has)} points" + (f" (one-sided sign test p = {p_sign:.2g})" if has else "")
                 + f", by more than 2σ at {len(rise)}{ids(rise)}" + (f", more than 2σ below it at {len(fall)}{ids(fall)}" if fall else "")
                 + f"; over the section's band, d₁ on lines meets the section's d₁ within 2σ at {len(sec_ok)} of "
                 f"{len(sec_n)}; over the smallest scales it meets 1 − κ/λ̄ within 2σ at {len(imp_ok)} of {len(imp_n)}"
                 f"{ids(imp_ok)}, and it moves beyond 2σ from the rule's t_min to the latest at {len(moves)} of "
                 f"{len(t_n)}{ids(moves)}")  # fmt: skip
    return {"n_points": len(has), "above_at": above, "p_sign": p_sign, "rise_at": rise, "fall_at": fall, "n_section": len(sec_n),
            "section_agrees_at": sec_ok, "n_implied": len(imp_n), "implied_agrees_at": imp_ok, "n_t_min": len(t_n),
            "t_min_moves_at": moves, "statement": statement}  # fmt: skip


CANDIDATES = {
    "lines": "d₁ on lines of initial conditions (the measure of the survivors along the stable direction)",
    "small_scales": "d₁ on lines over the smallest band of scales alone (the slope's small-scale end)",
    "estimator": "d₁ by a second estimator (fixed-radius mass) on the same points",
    "selection": "d₁ and λ̄ extrapolated in 1/t_min (the selection's convergence)",
    "mid_life": "λ̄ of the mid-life only (window·t_min), without the way in and out",
    "fluctuation": "1 − κ/λ̄ moved to the d₂ that κ and the mid-life exponents' fluctuations imply",
    "hyperbolic": "d₁ and λ̄ of the hyperbolic part (the orbits with finite-time exponent not near 0)",
    "sheets": "d₁ of the section's two sheets (radial maxima, radial minima) one at a time, their mean",
    "chart": "d₁ of the two sheets in the canonical chart (φ, p_φ), their mean",
}
"""The candidate reasons for a gap between d₁ and 1 − κ/λ̄ that :func:`with_gap` measures: name -> what it is."""


def with_gap(rec: dict) -> dict:
    """with_gap(rec) -> the record ``rec`` (updated in place) with ``d1_trend`` and ``lyapunov_trend`` (the t_min
    trends of ``d1_trend_by_t_min``, partial d₁ = D₁/2, and of ``lyapunov_by_t_min``) and, where the relation was
    checked, ``gap``: the gap d₁(implied) − d₁ = 1 − κ/λ̄ − d₁ and, per candidate of :data:`CANDIDATES` measured
    at the point, the gap left when its alternative replaces d₁ or λ̄ (``left``, errors in quadrature, the
    alternatives' correlation with the originals ignored: an upper bound on its error), ``z`` = left/err, the
    share of the gap it explains (1 − left/gap), ``closes`` (|z| ≤ 2 left and a share ≥ 1/2: the candidate
    accounts for the gap) and ``within_by_error`` (|z| ≤ 2 left with a share < 1/2: consistent only because the
    candidate's own error is larger, not an explanation).

    Examples
    --------
    >>> rec = {"kappa": 0.1, "kappa_err": 0.0, "lyapunov": 0.4, "lyapunov_err": 0.0, "d1": 0.70, "d1_err": 0.01,
    ...        "d1_implied": 0.75, "d1_implied_err": 0.0, "z": -5.0, "d1_radius": Measured(0.74, 0.01).to_dict()}
    >>> g = with_gap(rec)["gap"]
    >>> round(g["gap"]["value"], 3), round(g["estimator"]["share"], 3), g["estimator"]["closes"]
    (0.05, 0.8, True)
    """
    rec["d1_trend"] = _trend([{"t_min_kappa": r["t_min_kappa"], "d1": None if r["d1_section"] is None else
                               Measured(r["d1_section"]["value"], r["d1_section"]["err"]).scaled(0.5).to_dict()}
                              for r in rec.get("d1_trend_by_t_min", [])], "d1")  # fmt: skip
    rec["lyapunov_trend"] = _trend([{"t_min_kappa": r["t_min_kappa"], "lam": Measured(r["value"], r["err"]).to_dict()}
                                    for r in rec.get("lyapunov_by_t_min", [])], "lam")  # fmt: skip
    if rec.get("z") is None:
        return rec
    kappa = Measured(rec["kappa"], rec["kappa_err"])
    d1, implied = Measured(rec["d1"], rec["d1_err"]), Measured(rec["d1_implied"], rec["d1_implied_err"])

    def implied_by(lam):  # 1 − κ/λ̄ with another λ̄
        r = kappa.ratio(Measured(lam["value"], lam["err"]))
        return Measured(1.0 - r.value, r.err)

    gap = implied.difference(d1)
    alt = {}
    if rec.get("d1_lines"):
        alt["lines"] = (implied, Measured(rec["d1_lines"]["value"], rec["d1_lines"]["err"]))
        det = rec.get("d1_lines_detail") or {}
        low = _lowest_band(det, det.get("t_min_kappa"))
        if low:
            alt["small_scales"] = (implied, Measured(low["d1"]["value"], low["d1"]["err"]))
    if rec.get("d1_radius"):
        alt["estimator"] = (implied, Measured(rec["d1_radius"]["value"], rec["d1_radius"]["err"]))
    if "extrapolated" in rec["d1_trend"] and "extrapolated" in rec["lyapunov_trend"]:
        d1x = rec["d1_trend"]["extrapolated"]
        alt["selection"] = (implied_by(rec["lyapunov_trend"]["extrapolated"]), Measured(d1x["value"], d1x["err"]))
    if rec.get("lyapunov_mid"):
        alt["mid_life"] = (implied_by(rec["lyapunov_mid"]), d1)
    if rec.get("ftle_fluctuation"):
        sh = rec["ftle_fluctuation"]["shift"]
        alt["fluctuation"] = (Measured(implied.value + sh["value"], math.hypot(implied.err, sh["err"])), d1)
    for name, key in (("sheets", "d1_sheets"), ("chart", "d1_chart")):
        if rec.get(key):
            alt[name] = (implied, Measured(rec[key]["value"], rec[key]["err"]))
    if rec.get("hyperbolic"):
        h = rec["hyperbolic"]
        lam_h = Measured(rec["lyapunov"] + h["lyapunov_shift"]["value"], h["lyapunov_shift"]["err"]).to_dict()
        alt["hyperbolic"] = (implied_by(lam_h), Measured(h["d1"]["value"], h["d1"]["err"]))
    out = {"gap": gap.to_dict(), "z": rec["z"]}
    for name, (imp, d) in alt.items():
        left = imp.difference(d)
        z = left.value / left.err if left.err > 0 else math.copysign(math.inf, left.value)
        share = 1.0 - left.value / gap.value if gap.value else math.nan
        out[name] = {"d1": d.to_dict(), "d1_implied": imp.to_dict(), "left": left.to_dict(), "z": z,
                     "share": share, "closes": abs(z) <= 2 and share >= 0.5, "within_by_error": abs(z) <= 2 and not share >= 0.5}  # fmt: skip
    rec["gap"] = out
    return rec


def gap_row(rec: dict) -> dict:
    """gap_row(rec) -> a record's gap d₁(implied) − d₁ and, per candidate measured, the gap it leaves and the share
    it explains (the table of the candidates), or only the point's names where the relation was not checked.

    Examples
    --------
    >>> gap_row({"id": "a", "system": "hh", "ratio": 1.5, "gap": {"gap": Measured(0.05, 0.01).to_dict(), "z": -5.0,
    ...          "estimator": {"left": Measured(0.01, 0.014).to_dict(), "z": 0.7, "share": 0.8, "closes": True}}})
    ... # doctest: +NORMALIZE_WHITESPACE
    {'id': 'a', 'system': 'hh', 'ratio': 1.5, 'gap': {'value': 0.05, 'err': 0.01}, 'z': -5.0,
     'left_estimator': {'value': 0.01, 'err': 0.014}, 'share_estimator': 0.8}
    """
    row = {"id": rec["id"], "system": rec["system"], "ratio": rec["ratio"]}
    g = rec.get("gap")
    if not g:
        return row
    row.update({"gap": g["gap"], "z": g["z"]})
    for name in CANDIDATES:
        if name in g:
            row[f"left_{name}"], row[f"share_{name}"] = g[name]["left"], g[name]["share"]
    return row


def gap_summary(records) -> dict:
    """gap_summary(records) -> where d₁ and 1 − κ/λ̄ differ by more than 2σ and, per candidate, at how many of those
    points it closes the gap (|z| ≤ 2 left and at least half of it explained), at how many it is consistent only by
    its larger error, and its median share of the gap, with the statement of the measured reason ("not explained"
    where no candidate closes it).

    Examples
    --------
    >>> recs = [{"id": "a", "gap": {"gap": Measured(0.05, 0.01).to_dict(), "z": -5.0,
    ...          "estimator": {"closes": False, "share": 0.1}, "mid_life": {"closes": False, "share": -0.2}}},
    ...         {"id": "b", "gap": {"gap": Measured(0.0, 0.01).to_dict(), "z": 0.1}}, {"id": "c"}]
    >>> s = gap_summary(recs)
    >>> s["n_gap"], s["candidates"]["estimator"]["n_closes"], s["not_explained"]
    (1, 0, ['a'])
    """
    gaps = [r for r in records if r.get("gap") and abs(r["gap"]["z"]) > 2]
    cands, parts = {}, []
    for name, what in CANDIDATES.items():
        at = [r for r in gaps if name in r["gap"]]
        closes = [r["id"] for r in at if r["gap"][name]["closes"]]
        by_error = [r["id"] for r in at if r["gap"][name].get("within_by_error")]
        shares = [r["gap"][name]["share"] for r in at if math.isfinite(r["gap"][name]["share"])]
        med = float(np.median(shares)) if shares else None
        cands[name] = {"what": what, "n_measured": len(at), "n_closes": len(closes), "closes_at": closes,
                       "n_within_by_error": len(by_error), "within_by_error_at": by_error, "median_share": med}  # fmt: skip
        if at:
            parts.append(f"{what}: closes it at {len(closes)} of {len(at)}" + (f" ({', '.join(closes)})" if closes
                         else "") + (f", consistent only by its larger error at {len(by_error)}" if by_error else "")
                         + (f", median share of the gap {100 * med:.0f} %" if med is not None else ""))  # fmt: skip
    unexplained = [r["id"] for r in gaps if not any(r["gap"].get(n, {}).get("closes") for n in CANDIDATES)]
    statement = (f"d₁ and 1 − κ/λ̄ differ by more than 2σ at {len(gaps)} of the {sum(bool(r.get('gap')) for r in records)}"
                 f" points with both" + (f" ({', '.join(r['id'] for r in gaps)})" if gaps else "")
                 + ("; " + "; ".join(parts) if parts else "")
                 + (f"; not explained by any at {len(unexplained)} ({', '.join(unexplained)})" if unexplained else ""))  # fmt: skip
    return {"n_gap": len(gaps), "gap_at": [r["id"] for r in gaps], "candidates": cands, "not_explained": unexplained,
            "statement": statement}  # fmt: skip


#: the neighbour estimator's refusal of a scaling range with fewer than 4 of its scales
_FEW_SCALES = re.compile(
    r"points: fewer than 4 neighbour scales in \[eps_min, eps_max\] = \[(?P<lo>[^,\]]+), (?P<hi>[^\]]+)\] "
    r"\(the k-th neighbours of (?P<n>\d+) points lie at (?P<a>\S+) … (?P<b>[^)]+)\): give more points or widen the range"
)


def d1_refusal_words(text: str) -> str:
    """d1_refusal_words(text) -> ``text`` with the neighbour estimator's refusal "fewer than 4 neighbour scales in
    [eps_min, eps_max] = [..]" said as a point's reason for no d₁: the range of scales the fit may use (position
    units, from the range's floor to the largest scale), where the section points' k-th neighbour
    distances lie, or a range whose lower end lies above its upper end. Any other text is returned unchanged.

    Examples
    --------
    >>> d1_refusal_words("d1: points: fewer than 4 neighbour scales in [eps_min, eps_max] = [0.0913179, 0.294261] "
    ...                  "(the k-th neighbours of 3749 points lie at 0.00184 … 0.11): give more points or widen the range")
    "d1: no scaling range for d₁: the fit's scales run from the range's floor, eps_min = 0.0913, to \
the largest scale, eps_max = 0.294 (position units), and hold fewer than 4 of the k-th neighbour distances of the \
3749 section points, which lie at 0.00184 … 0.11"
    >>> d1_refusal_words("d1: points: fewer than 4 neighbour scales in [eps_min, eps_max] = [220.287, 0.493901] "
    ...                  "(the k-th neighbours of 35172 points lie at 0.000499 … 0.13): give more points or widen the range")
    "d1: no scaling range for d₁: the range's floor, eps_min = 220, lies above the largest scale, \
eps_max = 0.494 (position units)"
    >>> d1_refusal_words("d1: something else")
    'd1: something else'
    """
    if not isinstance(text, str):
        raise ConfigError(f"text must be a string, got {type(text).__name__}")

    def said(m: re.Match) -> str:
        lo, hi = float(m["lo"]), float(m["hi"])
        head = "no scaling range for d₁: "
        if not lo < hi:
            return head + (
                f"the range's floor, eps_min = {lo:.3g}, lies above the largest scale, "
                f"eps_max = {hi:.3g} (position units)"
            )
        return head + (
            f"the fit's scales run from the range's floor, eps_min = {lo:.3g}, to the largest scale, "
            f"eps_max = {hi:.3g} (position units), and hold fewer than 4 of the k-th neighbour distances of the "
            f"{m['n']} section points, which lie at {m['a']} … {m['b']}"
        )

    return _FEW_SCALES.sub(said, text)
