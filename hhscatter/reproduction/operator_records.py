"""The transfer operator's κ beside the escape rate of P(t), and its dissipative survival beside a simulated one.

:func:`kappa_records` turns the operator's results per energy
(:func:`~hhscatter.analysis.geometry.ulam_convergence.energy_results`) into the records of κ, of its convergence
and of the mixed phase space, with the comparison rows of the extrapolated κ against the reference κ0
(:func:`kappa_comparisons`); :func:`probe_islands` marks the KAM boxes that probe orbits found;
:func:`dissipative_comparison` predicts P(t) and the first crossing after t* of a dissipative ensemble with the
operator on (box × energy bin) and sets them beside the simulated ensemble; :func:`cost_rows` sets the orbit-time
of the operator's κ beside that of P(t)'s. Nothing here reads a file. Units: κ in 1/time, times in time units, energies in energy units, box sides in the section's
units.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import distance as dist
from hhscatter.analysis.geometry import ulam
from hhscatter.analysis.geometry import ulam_convergence as uc
from hhscatter.analysis.stats.verdicts import verdict
from hhscatter.analysis.survival.escape_rate import escape_rate
from hhscatter.analysis.survival.fits import observed_from_outcome
from hhscatter.outcomes import CENSORED, OUTCOMES

__all__ = ["cost_rows", "dissipative_comparison", "kappa_comparisons", "kappa_records", "probe_islands"]


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
        results, records (one :func:`~hhscatter.analysis.geometry.ulam_convergence.kappa_record` per grid
        energy), convergence (:func:`~hhscatter.analysis.geometry.ulam_convergence.convergence_record` with the
        cut boxes), mixed (the islands and largest classes per energy), rows (κ per partition), grids (the
        extrapolation grids and their bootstrap replicates, column kind) and kappa0.
    """
    out = {"results": results, "records": [], "convergence": [], "mixed": [], "rows": [], "grids": [], "kappa0": kappa0}
    for E, res in results.items():
        k0, kc = kappa0.get(E), kappa_cm.get(E)
        rec = uc.kappa_record(E, res, samples, box, k0, kc)
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
    reference. The row is :func:`~hhscatter.analysis.geometry.ulam.cost_row`'s.

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
        rows.append(ulam.cost_row(E, pt, rec, kappa0, target_rel))
    return rows
