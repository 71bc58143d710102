"""The records of a chaotic-saddle study: per point the error parts and scaling range of d₁, d₀ beside it, the
rows of the Kantz–Grassberger relation κ = λ̄ (1 − d₁) and of the two dimensions, and their summaries with the
statements the page shows.

A point's record is a dict with at least ``id``, ``system``, ``ratio``, ``energy``, ``kappa``/``kappa_err`` and,
where measured, ``lyapunov``, ``d1_section`` (the section's D₁ = 2 d₁), ``d1``, ``predicted`` (λ̄(1 − d₁)),
``d1_implied`` (1 − κ/λ̄), ``z`` and ``verdict`` (:func:`hhscatter.analysis.geometry.saddle.kantz_grassberger`),
``d0`` (1 − α of the exits on lines) and the keys :func:`d1_error_record` adds. The functions here read those keys
only; they run no estimator but :func:`hhscatter.analysis.geometry.saddle.dimension_order` (in :func:`with_d0`).

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

import numpy as np

from hhscatter.analysis.geometry.saddle import dimension_order
from hhscatter.analysis.stats.measured import Measured

__all__ = [
    "ERR_PARTS",
    "d1_error_record",
    "d1_precision",
    "dimension_row",
    "dimension_summary",
    "relation_row",
    "relation_summary",
    "with_d0",
]

ERR_PARTS = {"fit": "err_fit", "resample": "err_resample", "range": "err_range"}
"""The parts of d₁'s error: record name -> attribute of the dimension's result."""


def d1_error_record(d, extent: float, eps_min: float) -> dict:
    """d1_error_record(d, extent, eps_min) -> the record's keys of d₁'s error.

    ``d`` is the section's information dimension (a
    :class:`~hhscatter.analysis.geometry.saddle.SaddleDimension` with its ``table`` of ε), ``extent`` the saddle
    points' longest side and ``eps_min`` their distance to the saddle, extent·e^{−λ̄·window[0]·t_min} (length
    units). Keys: ``d1_section_err_parts`` (the three parts, section units), ``d1_err_largest`` (the largest finite
    part), ``d1_eps_range_extent`` (the fitted ε range in units of the extent), ``d1_eps_min_extent``,
    ``d1_range_floor`` (what ends the range below: ``resolution``, the points' distance to the saddle, when the
    table has ε below eps_min; else ``points``, the nearest neighbours' distance, the number of points) and
    ``d1_rel_err`` (err/value).

    Examples
    --------
    >>> import pandas as pd
    >>> from hhscatter.analysis.geometry.saddle import SaddleDimension
    >>> d = SaddleDimension(value=1.2, err=0.05, err_fit=0.01, err_resample=0.02, err_range=0.045,
    ...                     method="neighbours", eps_range=(0.01, 0.1), n_points=1000, n_groups=100,
    ...                     table=pd.DataFrame({"eps": [0.005, 0.01, 0.1]}))
    >>> r = d1_error_record(d, extent=1.0, eps_min=0.008)
    >>> r["d1_err_largest"], r["d1_range_floor"], round(r["d1_rel_err"], 4)
    ('range', 'resolution', 0.0417)
    """
    parts = {k: float(getattr(d, a)) for k, a in ERR_PARTS.items()}
    floor = "resolution" if bool(np.any(d.table["eps"].to_numpy() < eps_min)) else "points"
    lo, hi = d.eps_range
    return {"d1_section_err_parts": parts, "d1_err_largest": max(parts, key=lambda k: parts[k] if math.isfinite(parts[k]) else -1.0),
            "d1_eps_range_extent": [lo / extent, hi / extent], "d1_eps_min_extent": eps_min / extent,
            "d1_range_floor": floor, "d1_rel_err": d.err / d.value if d.value else math.nan}  # fmt: skip


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
    ...         {"id": "b", "d1_rel_err": 0.07, "d1_err_largest": "range", "d1_range_floor": "resolution",
    ...          "d1_eps_range_extent": [0.03, 0.1]}, {"id": "c"}]
    >>> p = d1_precision(recs)
    >>> p["n_with_d1"], p["n_within"], p["largest_part"], p["range_floor"]
    (2, 1, {'fit': 0, 'resample': 1, 'range': 1}, {'resolution': 1, 'points': 1})
    >>> p["statement"].split(";")[0]
    'd₁ to ≤ 3 % (1σ) at 1 of the 2 points with d₁ (a)'
    """
    with_d1 = [r for r in records if r.get("d1_rel_err") is not None]
    ok = [r for r in with_d1 if r["d1_rel_err"] <= target]
    largest = {k: sum(r["d1_err_largest"] == k for r in with_d1) for k in ERR_PARTS}
    floor = {k: sum(r["d1_range_floor"] == k for r in with_d1) for k in ("resolution", "points")}
    decades = [math.log10(r["d1_eps_range_extent"][1] / r["d1_eps_range_extent"][0]) for r in with_d1]
    names = {"fit": "the fit's residuals (lacunarity)", "resample": "the bootstrap over orbits",
             "range": "the range part (the slope changes across the scaling range)"}  # fmt: skip
    parts = "; ".join(f"{names[k]} at {v}" for k, v in largest.items() if v)
    span = f"{min(decades):.1f}–{max(decades):.1f}" if decades else "no"
    statement = (f"d₁ to ≤ {100 * target:.0f} % (1σ) at {len(ok)} of the {len(with_d1)} points with d₁"
                 + (f" ({', '.join(r['id'] for r in ok)})" if ok else "")
                 + f"; the largest part of its error: {parts}; the scaling ranges span {span} decades of ε, ended "
                 f"below by the points' distance to the saddle at {floor['resolution']} points and by the "
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
