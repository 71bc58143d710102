"""The transfer operator's κ beside the escape rate of P(t), and its dissipative survival beside a simulated one.

:func:`kappa_records` turns the operator's results per energy
(:func:`~hhscatter.analysis.geometry.ulam_convergence.energy_results`) into the records of κ, of its convergence
and of the mixed phase space, with the comparison rows of the extrapolated κ against the reference κ0
(:func:`kappa_comparisons`); :func:`probe_islands` marks the KAM boxes that probe orbits found;
:func:`dissipative_comparison` predicts P(t) and the first crossing after t* of a dissipative ensemble with the
operator on (box × energy bin) and sets them beside the simulated ensemble; :func:`cost_rows` sets the orbit-time
of the operator's κ beside that of P(t)'s. :func:`kappa_record` (one energy's κ with its box bias and the references),
:func:`convergence_summary` (κ∞ against the references in one sentence) and :func:`cost_row` (one energy's cost)
are their pieces. Nothing here reads a file. Units: κ in 1/time, times in time units, energies in energy units, box sides in the section's
units.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import _checks, ulam
from hhscatter.analysis.geometry import distance as dist
from hhscatter.analysis.geometry import ulam_convergence as uc
from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.verdicts import verdict
from hhscatter.analysis.survival.escape_rate import escape_rate
from hhscatter.analysis.survival.fits import observed_from_outcome
from hhscatter.errors import ConfigError
from hhscatter.outcomes import CENSORED, OUTCOMES

__all__ = [
    "convergence_summary",
    "cost_row",
    "cost_rows",
    "dissipative_comparison",
    "kappa_comparisons",
    "kappa_record",
    "kappa_records",
    "probe_islands",
]


def kappa_records(results: dict, kappa0: dict, kappa_cm: dict, *, samples, box, grid_energies, verdicts: bool) -> dict:
    """The records of κ from the operator's results at every energy.

    Parameters
    ----------
    results : dict
        {E: :func:`~hhscatter.analysis.geometry.ulam_convergence.energy_results` with ``islands`` and ``cut_boxes``}.
    kappa0, kappa_cm : dict
        {E: (κ, err)} of the references (κ0 of P(t), κ from long-run crossings); an energy may lack them.
    samples, box : int, float
        Samples per finest box and the finest box side.
    grid_energies : sequence of float
        The energies of the κ grid: their records and convergence are kept; any other energy is mixed phase space
        (its record goes to ``mixed`` with a note).
    verdicts : bool
        Whether the convergence records keep their verdicts (False at a smoke-test scale).

    Returns
    -------
    dict
        results, records (one :func:`kappa_record` per grid
        energy), convergence (:func:`~hhscatter.analysis.geometry.ulam_convergence.convergence_record` with the
        cut boxes), mixed (the islands and largest classes per energy), rows (κ per partition), grids (the
        extrapolation grids and their bootstrap replicates, column kind) and kappa0.
    """
    out = {"results": results, "records": [], "convergence": [], "mixed": [], "rows": [], "grids": [], "kappa0": kappa0}
    for E, res in results.items():
        k0, kc = kappa0.get(E), kappa_cm.get(E)
        rec = kappa_record(E, res, samples, box, k0, kc)
        out["rows"].extend(res["rows"])
        out["mixed"].append({"energy": E, **res["islands"], "largest_classes": res["largest_classes"]})
        if any(np.isclose(E, e) for e in grid_energies):
            out["records"].append(rec)
            refs = {"kappa0": k0, "kappa_cm": kc}
            conv = uc.convergence_record(E, res["grid"], res["boot_grid"], res["kappa"], refs)
            if not verdicts:
                conv = {k: v for k, v in conv.items() if not k.startswith("verdict_")}
            out["convergence"].append({**conv, **res["cut_boxes"]})
            out["grids"] += [
                res["grid"].assign(energy=E, kind="estimate"),
                res["boot_grid"].assign(energy=E, kind="bootstrap"),
            ]
        else:
            out["mixed"][-1]["record"] = {**rec, "note": "mixed phase space (below the κ grid)"}
    return out


def kappa_record(E, res, samples, box, kappa0=None, kappa_cm=None):
    """The record of κ at one energy from the results ``res`` of the finest partition.

    ``res`` holds rows (κ per box side, ``vary`` = "box"), boot (bootstrap replicates), kappa, kappa_map,
    info, sub, cost. κ on the finest boxes; the linear discretisation bias from a straight line κ(b) through
    the three finest box sides (κ at b → 0); err = √(σ_boot² + bias²). The references ``kappa0`` (fig2's κ0,
    the P(t) route) and ``kappa_cm`` (κ from long-run crossings), each (value, err) or None, are recorded as
    fig2_kappa, fig2_err, fig2_kappa_cm, fig2_kappa_cm_err, with z_vs_fig2 against κ0 (both errors). Units: κ
    and its errors in 1/time, box sides in the section's units.

    Examples
    --------
    16 boxes, each sending a quarter of its samples out, a quarter back into itself and half to the next box
    (T = 2): κ = ln(4/3)/2 at every partition, so no box bias.

    >>> cell, rank = np.repeat(np.arange(16), 16), np.tile(np.arange(16), 16)
    >>> nxt = np.where(rank % 4 == 1, cell, (cell + 1) % 16)
    >>> tab = pd.DataFrame({"cell": cell, "rank": rank, "w": 1.0, "censored": False, "ret": rank % 4 > 0,
    ...     "T": 2.0, "t_end": 2.0, "x1": -0.75 + 0.5 * (nxt % 4), "y1": -0.75 + 0.5 * (nxt // 4), "e1": 0.3})
    >>> res = uc.energy_results(tab, (-1, 1, -1, 1), 0.5, [1, 2], [4, 16], 16, 3, 2, 1, 0.3)
    >>> rec = kappa_record(0.3, res, 16, 0.5, kappa0=(0.1438, 0.0001))
    >>> round(rec["kappa"], 6), abs(rec["discretisation_bias"]) < 1e-9, rec["fig2_kappa"], rec["fig2_kappa_cm"]
    (0.143841, True, 0.1438, None)
    """
    check.number(E, "E")
    _checks.mapping(res, "res", ("rows", "boot", "kappa", "kappa_map", "info", "sub", "cost"))
    _checks.whole(samples, "samples")
    check.number(box, "box", positive=True)
    _checks.reference(kappa0, "kappa0")
    _checks.reference(kappa_cm, "kappa_cm")
    rows = pd.DataFrame([r for r in res["rows"] if r["vary"] == "box"]).sort_values("box")
    fit = rows.head(3)
    slope, k_inf = (
        np.polyfit(fit["box"].to_numpy(), fit["kappa"].to_numpy(), 1) if len(fit) >= 2 else (0.0, res["kappa"])
    )
    boot = res["boot"]
    stat = float(np.std(boot, ddof=1)) if boot.size > 1 else math.nan
    bias = float(k_inf - res["kappa"])
    rec = {
        "energy": E,
        "kappa": res["kappa"],
        "err": float(math.hypot(stat, bias)),
        "boxes": int(res["sub"].n_states),
        "samples": samples,
        "box": box,
        "kappa_stat_err": stat,
        "discretisation_bias": bias,
        "kappa_extrapolated": float(k_inf),
        "bias_slope": float(slope),
        "kappa_map_per_return": res["kappa_map"],
        "mean_return_time": res["cost"]["mean_return_time"],
        "orbit_time": res["cost"]["orbit_time"],
        "orbits": res["cost"]["orbits"],
        "censored": res["cost"]["censored"],
        **{f"class_{k}": v for k, v in res["info"].items()},
        "fig2_kappa": kappa0[0] if kappa0 else None,
        "fig2_err": kappa0[1] if kappa0 else None,
        "fig2_kappa_cm": kappa_cm[0] if kappa_cm else None,
        "fig2_kappa_cm_err": kappa_cm[1] if kappa_cm else None,
    }
    if kappa0:
        rec["z_vs_fig2"] = (rec["kappa"] - kappa0[0]) / math.hypot(rec["err"], kappa0[1])
    return rec


def convergence_summary(records, *, z_agree: float = 2.0) -> dict:
    """How the extrapolated κ∞ compares with the references, in words and numbers.

    ``records``: :func:`~hhscatter.analysis.geometry.ulam_convergence.convergence_record` per energy. For each reference (kappa0, kappa_cm): the energies where |z| ≤ ``z_agree`` (both errors), the largest
    |κ∞/κ_ref − 1| and the mean residual; ``statement`` says it in one sentence per reference.

    Examples
    --------
    >>> recs = [{"energy": 0.3, "kappa_inf": 0.2, "z_kappa0": 0.5, "residual_kappa0": 0.01}]
    >>> convergence_summary(recs)["kappa0"]["agree"]
    [0.3]
    """
    if isinstance(records, (str, bytes)) or not isinstance(records, (list, tuple)):
        raise ConfigError(f"records must be a list of records (mappings), got {type(records).__name__}")
    for r in records:
        _checks.mapping(r, "records", ("energy",))
    check.number(z_agree, "z_agree", positive=True)
    out, words = {}, []
    names = {"kappa0": "fig2's κ0 from P(t)", "kappa_cm": "fig2's κ from long-run crossings"}
    for ref, label in names.items():
        rs = [r for r in records if r.get("kappa_inf") is not None and r.get(f"z_{ref}") is not None]
        if not rs:
            continue
        agree = [r["energy"] for r in rs if abs(r[f"z_{ref}"]) <= z_agree]
        res = np.array([r[f"residual_{ref}"] for r in rs])
        out[ref] = {
            "energies": [r["energy"] for r in rs],
            "agree": agree,
            "max_abs_residual": float(np.max(np.abs(res))),
            "mean_residual": float(res.mean()),
        }
        words.append(
            f"against {label}, κ∞ agrees within {z_agree:g}σ (both errors) at {len(agree)} of {len(rs)} "
            f"energies; |κ∞/κ_ref − 1| ≤ {100 * np.max(np.abs(res)):.2g} %, mean {100 * res.mean():+.2g} %"
        )
    out["statement"] = "; ".join(words) if words else "no reference to compare with"
    return out


def kappa_comparisons(convergence: list, box: float) -> list[dict]:
    """Comparison rows of the extrapolated κ against κ0, one per convergence record that has both.

    Each row holds the keyword arguments of a study's ``compare`` (quantity, ours, err, paper, verdict, note)
    and ``paper_err``, the reference's own error, which the comparison rule takes too.

    Examples
    --------
    >>> rows = kappa_comparisons([{"energy": 0.3, "kappa_inf": 0.2, "err": 0.01, "kappa0": 0.21,
    ...     "kappa0_err": 0.005, "kappa_finest": 0.19}, {"energy": 0.35, "kappa_inf": None}], 0.01)
    >>> [(r["quantity"], r["paper_err"]) for r in rows]
    [("κ_Ulam(0.3) extrapolated vs fig2's κ0", 0.005)]
    """
    rows = []
    for r in convergence:
        if r.get("kappa0") is not None and r.get("kappa_inf") is not None:
            rows.append(
                {
                    "quantity": f"κ_Ulam({r['energy']:g}) extrapolated vs fig2's κ0",
                    "ours": r["kappa_inf"],
                    "err": r["err"],
                    "paper": r["kappa0"],
                    "verdict": verdict(r["kappa_inf"], r["err"], r["kappa0"], r["kappa0_err"]).text(),
                    "note": f"fig2 ± {r['kappa0_err']:.2g}; finest boxes {box:g}: κ = {r['kappa_finest']:.4g}",
                    "paper_err": r["kappa0_err"],
                }
            )
    return rows


def dissipative_comparison(tab, lifetimes, sections, *, extent, box, edges, radius, dt, t_horizon, t_star,
                           max_return_time, boxes, n_splits, seed, box_headline, energy, gamma):  # fmt: skip
    """P(t) and the first crossing after t* of a dissipative ensemble: the operator's prediction and the simulation.

    ``tab``: the one-return samples of the run with drag, with an energy bin ``ebin`` over ``edges``
    (:func:`~hhscatter.analysis.geometry.ulam.one_return_samples`); the operator on (box of side ``box`` × energy
    bin), started from the disk of ``radius``, on a grid of step ``dt`` to ``t_horizon``
    (:func:`~hhscatter.analysis.geometry.ulam.dissipative_operator`). ``lifetimes`` (traj_id, outcome, t_end) and
    ``sections`` (traj_id, t, x, y, energy) of the simulated ensemble: its empirical P(t) on the operator's grid
    and its first crossings after ``t_star``, compared with the operator's by the debiased Hellinger distance over
    ``boxes`` (:func:`~hhscatter.analysis.geometry.ulam.t_star_distance`).

    Returns
    -------
    (dict, DataFrame, DataFrame, DataFrame)
        The numbers (:func:`~hhscatter.analysis.geometry.ulam.dissipative_record`), the P(t) curves (t, sim,
        operator, reduced), the points after t* (x, y, energy, w, set) and the distances per box side.
    """
    op = ulam.dissipative_operator(
        tab, extent, box, edges, dt=dt, t_horizon=t_horizon, t_star=t_star, max_return_time=max_return_time,
        radius=radius,
    )  # fmt: skip
    leaving = observed_from_outcome(lifetimes["outcome"])
    P_sim = ulam.empirical_survival(lifetimes["t_end"].to_numpy(), leaving, op["grid"])
    sim_pts = dist.first_crossings(sections, t_star)
    dtab, j = ulam.t_star_distance(op["pred"], dist.points(sim_pts), boxes, extent, n_splits, seed, box_headline)
    t_sim = float(lifetimes["t_end"].sum())
    numbers = ulam.dissipative_record(
        op, edges, P_sim, len(lifetimes), sim_pts, t_sim, dtab, j, energy=energy, gamma=gamma, dt=dt, t_star=t_star
    )
    curves = pd.DataFrame({"t": op["grid"], "sim": P_sim, "operator": op["P"], "reduced": op["P_reduced"]})
    pts = pd.concat(
        [op["pred"].assign(set="operator"), sim_pts[["x", "y", "energy"]].assign(w=1.0, set="sim")],
        ignore_index=True,
    )
    return numbers, curves, pts, dtab


def probe_islands(cells, outcomes, tr, ids, keep, sub) -> dict:
    """Mixed phase space from KAM probes: one probe orbit per finest box, trapped where it is still inside at its end.

    ``cells`` are the probes' finest boxes and ``outcomes`` their outcome names, in the same order; a probe whose
    outcome is ``censored`` marks its box trapped. The trapped boxes are set against the operator on the states
    ``ids`` of ``tr`` (saddle class ``keep``, its matrix ``sub``) by
    :func:`~hhscatter.analysis.geometry.ulam.islands_record`.

    Returns
    -------
    dict
        probes (their number) and the fields of :func:`~hhscatter.analysis.geometry.ulam.islands_record`.

    Examples
    --------
    Two boxes (ids 5 and 9) that send half their samples to each other and lose the other half; the probe of box 9
    stayed inside:

    >>> import numpy as np
    >>> from hhscatter.analysis.geometry import transfer as tf
    >>> tr = tf.Transitions(np.array([0, 0, 1, 1]), np.array([1, -1, 0, -1]), np.ones(4), 2, np.ones(4))
    >>> keep, sub = ulam.saddle_kappa(tr)[3:]
    >>> rec = probe_islands([5, 9], ["escaped", "censored"], tr, np.array([5, 9]), keep, sub)
    >>> rec["probes"], rec["trapped_boxes"], rec["trapped_share_of_saddle_class"]
    (2, 1, 0.5)
    """
    cells = np.asarray(cells)
    trapped = cells[np.asarray(outcomes).astype(str) == OUTCOMES[CENSORED]]
    return {"probes": int(len(cells)), **ulam.islands_record(trapped, tr, ids, keep, sub)}


def cost_rows(lifetimes: dict, records: list, kappa0: dict, target_rel: float) -> list[dict]:
    """Orbit-time of each route to κ at the relative error ``target_rel``, one row per energy.

    ``lifetimes``: {E: DataFrame(outcome, t_end)} of a plain P(t) run at each energy; its κ is the escape rate
    of :func:`~hhscatter.analysis.survival.escape_rate.escape_rate` (no tail detection, windows kept where at
    least 100 orbits survive), its cost the summed orbit time (time units). ``records``: the operator's κ records
    (dicts with ``energy``; an energy without one gets the P(t) route only); ``kappa0``: {E: (κ0, err)} of the
    reference. The row is :func:`cost_row`'s.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> t = np.random.default_rng(1).exponential(1 / 0.05, 5000)
    >>> (row,) = cost_rows({0.3: pd.DataFrame({"outcome": "escaped", "t_end": t})}, [], {}, 0.01)
    >>> row["pt_orbits"], bool(abs(row["pt_kappa"] - 0.05) < 3 * row["pt_err"]), "op_kappa" in row
    (5000, True, False)
    """
    rows = []
    for E, lt in lifetimes.items():
        r = escape_rate(
            lt["t_end"].to_numpy(), observed_from_outcome(lt["outcome"]), detect_tail=False, min_survivors=100.0
        )
        pt = {"kappa": r.kappa, "kappa_err": r.kappa_err, "orbits": len(lt), "orbit_time": float(lt["t_end"].sum())}
        rec = next((x for x in records if np.isclose(x["energy"], E)), None)
        rows.append(cost_row(E, pt, rec, kappa0, target_rel))
    return rows


def cost_row(E, pt, rec, kappa0, target):
    """Orbit-time of each route for κ at the relative error ``target``.

    ``pt``: the P(t) route's result {kappa, kappa_err, orbits, orbit_time}; ``rec``: the operator's κ record
    at E (or None); ``kappa0``: {E: (κ0, err)} of the reference. The P(t) route scales as 1/√N; the
    operator's is a lower bound: its bias ∝ box side (cost ∝ 1/b² at fixed samples per box) and its
    statistics ∝ 1/√(samples) — optimistic, since finer boxes raise the per-sample noise. Units: κ in 1/time,
    orbit-times in time units.

    Examples
    --------
    P(t) gave κ to 2 % in 10⁵ time units of orbits: 1 % takes four times as much.

    >>> pt = {"kappa": 0.05, "kappa_err": 0.001, "orbits": 5000, "orbit_time": 1e5}
    >>> row = cost_row(0.3, pt, None, {0.3: (0.049, 0.0005)}, 0.01)
    >>> row["pt_orbit_time_1pct"], row["fig2_kappa"], "op_kappa" in row
    (400000.0, 0.049, False)
    """
    check.number(E, "E")
    _checks.mapping(pt, "pt", ("kappa", "kappa_err", "orbits", "orbit_time"))
    if rec is not None:
        _checks.mapping(rec, "rec", ("kappa", "kappa_stat_err", "discretisation_bias", "err", "orbit_time"))
    _checks.mapping(kappa0, "kappa0")
    check.number(target, "target", positive=True)
    rel = float(pt["kappa_err"] / pt["kappa"])
    ot = float(pt["orbit_time"])
    k0 = kappa0.get(E, (math.nan, math.nan))
    row = {
        "energy": E,
        "pt_kappa": float(pt["kappa"]),
        "pt_err": float(pt["kappa_err"]),
        "pt_rel": rel,
        "pt_orbits": int(pt["orbits"]),
        "pt_orbit_time": ot,
        "pt_orbit_time_1pct": ot * (rel / target) ** 2,
        "fig2_kappa": k0[0],
        "fig2_err": k0[1],
    }
    if rec is not None:
        k = rec["kappa"]
        st_rel = rec["kappa_stat_err"] / k
        b_rel = abs(rec["discretisation_bias"]) / k
        share = target / math.sqrt(2)  # half of the budget (in quadrature) to each part
        f_bias = max(1.0, (b_rel / share) ** 2)
        f_stat = max(1.0, (st_rel / share) ** 2)
        row.update(
            {
                "op_kappa": k,
                "op_err": rec["err"],
                "op_rel": rec["err"] / k,
                "op_stat_rel": st_rel,
                "op_bias_rel": b_rel,
                "op_orbit_time": rec["orbit_time"],
                "op_orbit_time_1pct": rec["orbit_time"] * max(f_bias, f_stat),
                "pt_rel_at_op_cost": rel * math.sqrt(ot / rec["orbit_time"]),
            }
        )
    return row
