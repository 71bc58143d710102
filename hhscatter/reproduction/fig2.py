"""The paper's Fig. 2 in numbers and our numbers set beside them: κ of P(t) and its sticky tail (Fig. 2a), the κ(E)
law (Fig. 2b) under one and under several conventions, and κ from the c-measure (Eq. (eqn:kappa_cmeasure_truetime),
not in the paper).

Each ``*_comparisons`` function returns comparison rows: dicts with the keyword arguments of a study's
``compare`` (quantity, ours, err, paper and unit, verdict, convention, authors, note), so that the rule of each
verdict lives here and the study only records the rows. Units: time in model units, κ in 1/time, energies in model
units; x = E − E_c.

Examples
--------
>>> round(paper_law_kappa(0.30, 1 / 6), 4)  # above E_b = 0.27: c x
0.188
>>> from types import SimpleNamespace as NS
>>> [r["quantity"] for r in pt_comparisons(0.25, NS(kappa=0.2, kappa_err=0.01), NS(tail=None), 1 / 6)]
['kappa(E0=0.25) [Fig. 2a]']
"""

from __future__ import annotations

import pandas as pd

from hhscatter.analysis.stats.verdicts import half_unit
from hhscatter.analysis.survival.kappa_law import PiecewiseKappa
from hhscatter.errors import ConfigError
from hhscatter.model import HenonHeiles
from hhscatter.reproduction.convention_tables import (
    LAW_PARAMETERS,
    convention_rows,
    fit_laws,
    law_spread,
    stable_energies,
)
from hhscatter.reproduction.escape_summaries import kappa_cmeasure_entry, kappa_cmeasure_shifts, tau_star_estimate
from hhscatter.reproduction.verdicts import quoted_verdict, row_verdict

__all__ = [
    "FIG2_CONVENTIONS",
    "LAW_UNITS",
    "PAPER_FIG2",
    "PAPER_KAPPA",
    "FIG2_RULES",
    "cmeasure_comparisons",
    "cmeasure_run_rows",
    "cmeasure_table_rows",
    "convention_analysis",
    "convention_numbers",
    "law_comparisons",
    "paper_law_kappa",
    "pt_comparisons",
    "with_cmeasure_references",
]

#: the paper's Fig. 2 values: the κ(E) law κ = a x² + b x (E < E_b), c x (E ≥ E_b), x = E − E_c, and τ*
PAPER_FIG2 = {"a": 13.63, "b": 0.03, "c": 1.41, "E_b": 0.27, "tau_star": 100.0}

PAPER_KAPPA = PiecewiseKappa(
    E_c=HenonHeiles().critical_energy,
    a2=PAPER_FIG2["a"],
    a1=PAPER_FIG2["b"],
    slope=PAPER_FIG2["c"],
    E_switch=PAPER_FIG2["E_b"],
)
"""κ0(E) with the paper's fitted coefficients (Fig. 2b), for the paper's system (Hénon–Heiles, ω = λ = 1)."""

#: the units of the law's parameters
LAW_UNITS = {"a": "1/(time·energy²)", "b": "1/(time·energy)", "c": "1/(time·energy)", "E_b": "energy"}

#: the conventions of κ(E) (name, IC region, window rule, label): the paper's disk or the authors' square ICs ×
#: our plateau windows or windows fixed by P levels
FIG2_CONVENTIONS = (
    ("disk_plateau", "disk", "plateau", "paper setup (disk r < 0.5), our plateau windows"),
    ("disk_plevel", "disk", "plevel", "paper setup (disk r < 0.5), P-level windows"),
    ("square_plateau", "square", "plateau", "authors' square ICs (goodICs), our plateau windows"),
    ("square_plevel", "square", "plevel", "authors' square ICs (goodICs), P-level windows"),
)

#: the rules of Fig. 2's numbers, as its numbers JSON states them
FIG2_RULES = {
    "kappa": "escape_rate: Kaplan-Meier P(t); tau0 and 4 windows by choose_windows (local-slope plateau "
    "covering most e-folds, floor of min_survivors survivors); kappa = mean of the 4 weighted "
    "least-squares fits of log P; err = sqrt(spread^2 + stat^2)",
    "t_max": "choose_t_max on a pilot: t_max = t_half + [ln(n/(2 min_survivors)) + margin_efolds]/kappa_pilot,"
    " clipped to [t_max_min, t_max_cap]",
    "tail": "escaping_tail: orbits censored at t_max removed; detect_power_law_tail after tau0 "
    "with floor tail_min_survivors; tau* = crossing of the exponential and power-law fits",
    "cmeasure": "every section crossing in [t_rec, t_rec + cm_sample_efolds/kappa], t_rec = ceil(tau0 + "
    "cm_rec_efolds/kappa) (kappa, tau0 of the grid run); next crossing or exit seen within "
    "cm_margin; orbits censored at cm_t_max dropped; kappa_from_cmeasure",
}


def _row(quantity, ours, err=None, paper=None, **kw) -> dict:
    return {"quantity": quantity, "ours": ours, "err": err, "paper": paper, **kw}


def paper_law_kappa(energy: float, E_c: float, paper: dict = PAPER_FIG2) -> float:
    """κ (1/time) at ``energy`` of the paper's fitted law of Fig. 2b: a x² + b x below E_b, c x above, x = E − E_c.

    Examples
    --------
    >>> x = 0.25 - 1 / 6
    >>> paper_law_kappa(0.25, 1 / 6) == 13.63 * x**2 + 0.03 * x
    True
    """
    return (
        paper["a"] * (energy - E_c) ** 2 + paper["b"] * (energy - E_c)
        if energy < paper["E_b"]
        else paper["c"] * (energy - E_c)
    )


def pt_comparisons(energy: float, rate, tail, E_c: float, paper: dict = PAPER_FIG2) -> list[dict]:
    """Fig. 2a at one energy against the paper: κ with its Fig. 2b law, τ* with its 100 and z (not in its text).

    Parameters
    ----------
    energy : float
        E0 of the P(t) run (energy units).
    rate
        Its :func:`~hhscatter.analysis.survival.escape_rate.escape_rate` result (``kappa``, ``kappa_err``).
    tail
        Its :func:`~hhscatter.analysis.survival.escape_rate.escaping_tail` result; no τ* or z row without a tail.
    E_c : float
        The critical energy.

    Returns
    -------
    list of dict
        Comparison rows. τ*'s error is the distance of its two definitions (:func:`tau_star_estimate`); its verdict
        agreement within 20 % where that error is undefined.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> rows = pt_comparisons(0.30, NS(kappa=0.19, kappa_err=0.01), NS(tail=None), 1 / 6)
    >>> round(rows[0]["paper"], 4), rows[0]["unit"]
    (0.188, '1/time')
    """
    rows = [
        _row(
            f"kappa(E0={energy:.2f}) [Fig. 2a]",
            rate.kappa,
            rate.kappa_err,
            paper_law_kappa(energy, E_c, paper),
            unit="1/time",
            note="paper value from its fitted law of Fig. 2b (annotations of Fig. 2a not in the text)",
        )
    ]
    if tail.tail is None:
        return rows
    tl = tail.tail
    ts, ts_err, note = tau_star_estimate(tail)
    ref = paper["tau_star"]
    verdict = None if ts_err else ("agrees within 20 %" if abs(ts / ref - 1) <= 0.2 else "differs")
    rows.append(_row(f"tau* (E0={energy:.2f})", ts, ts_err, ref, unit="time", note=note, verdict=verdict))
    rows.append(
        _row(
            f"z (E0={energy:.2f})",
            tl.z,
            tl.z_err,
            None,
            note="power-law exponent of the sticky tail (the paper annotates it in Fig. 2a; no number in the text)",
        )
    )
    return rows


def law_comparisons(continuous: dict, separate: dict, across: dict, ill, paper: dict = PAPER_FIG2) -> list[dict]:
    """The κ(E) law of Fig. 2b against the paper's a, b, c, E_b: the continuous fit, the law across conventions, the
    points left out as ill-defined, the separate fits.

    Parameters
    ----------
    continuous, separate : dict
        :func:`~hhscatter.analysis.survival.kappa_energy.kappa_law_summary` of the law continuous at E_b and of the
        two laws fitted independently ({name: {"value", "err"}}).
    across : dict
        :func:`~hhscatter.reproduction.convention_tables.law_spread` over the conventions (may be empty).
    ill : DataFrame
        The (energy, convention) rows where κ is ill-defined (the plateau of censored orbits).

    Returns
    -------
    list of dict
        Comparison rows. A "differs" of the continuous fit stands only if it survives the spread across conventions
        (2σ, then the paper's printed precision: 0.27 stands for [0.265, 0.275)).

    Examples
    --------
    >>> import pandas as pd
    >>> from hhscatter.analysis.stats import Measured
    >>> fit = {k: Measured(v, 0.01).to_dict() for k, v in PAPER_FIG2.items()}
    >>> rows = law_comparisons(fit, fit, {}, pd.DataFrame({"energy": [], "convention": []}))
    >>> len(rows), rows[0]["verdict"]
    (9, 'agrees within 2σ')
    """

    def quoted(name, d):
        return quoted_verdict(d[name]["value"], d[name]["err"], paper[name], half_unit(paper[name]))

    rows = []
    for name in LAW_PARAMETERS:
        verdict = quoted(name, continuous)
        if verdict == "differs" and name in across:
            other = quoted(name, across)
            if other != "differs":
                verdict = f"differs in this convention only; across conventions: {other}"
        rows.append(
            _row(
                f"{name} (κ(E) law, continuous fit)",
                continuous[name]["value"],
                continuous[name]["err"],
                paper[name],
                unit=LAW_UNITS[name],
                verdict=verdict,
                note="κ = a x² + b x below E_b, c x above, x = E − E_c, continuous at E_b; "
                "err = max(covariance, bootstrap); all grid energies",
            )
        )
    for name in (n for n in LAW_PARAMETERS if n in across):
        L = across[name]
        rows.append(
            _row(
                f"{name} (κ(E) law across conventions)",
                L["value"],
                L["err"],
                paper[name],
                unit=LAW_UNITS[name],
                verdict=quoted(name, across),
                convention="mean over disk/square ICs × plateau/P-level windows, stable energies only",
                authors=True,
                note=f"err = √(stat² + spread²), spread (half range across conventions) {L['spread']:.3g}; "
                + ", ".join(f"{k} {v:.4g}" for k, v in L["per_convention"].items()),
            )
        )
    rows.append(
        _row(
            "κ(E) points ill-defined by the plateau of censored orbits",
            len(ill),
            convention="all 4 conventions",
            note="; ".join(f"E = {r.energy:g} {r.convention}" for r in ill.itertuples()) or "none",
            verdict="excluded from the law, not returned as κ ≈ 0",
        )
    )
    for name in LAW_PARAMETERS:
        rows.append(
            _row(
                f"{name} (κ(E) law, separate fits)",
                separate[name]["value"],
                separate[name]["err"],
                paper[name],
                verdict=quoted(name, separate),
                note="the two laws fitted independently on either side of the best partition (as the paper)",
            )
        )
    return rows


def cmeasure_table_rows(
    sections, lifetimes, window, shifts, kappa: float, reference, *, energy, E_c, min_survivors, n_boot, seed
) -> list[dict]:
    """κ from the c-measure of one energy's section run, one row per start shift, beside κ from P(t): of the Fig. 2b
    run at that energy (``reference``) and of the section run itself.

    Parameters
    ----------
    sections, lifetimes : DataFrame
        The section run's crossings (traj_id, t) and lifetimes (traj_id, outcome, t_end).
    window : (float, float, float)
        (t_rec, t_sample_end, t_record_end) of :func:`~hhscatter.reproduction.escape_summaries.cmeasure_windows`.
    shifts : sequence of float
        Later starts of the window, in e-folds of ``kappa`` (0: the window itself).
    kappa : float
        κ (1/time) that set the window; ``reference``: the escape-rate result of the Fig. 2b run.
    energy, E_c : float
        The run's energy and the critical energy; min_survivors the window rule's survivor floor.

    Returns
    -------
    list of dict
        The rows of :func:`~hhscatter.reproduction.escape_summaries.kappa_cmeasure_shifts` with energy, x = E − E_c,
        kappa_pt_grid(_err), kappa_pt_same_run(_err) and n_trapped_dropped (orbits censored at t_max).
    """
    from hhscatter.analysis.survival.escape_rate import escape_rate  # deferred: scipy loads on first use
    from hhscatter.analysis.survival.fits import observed_from_outcome  # deferred: as above

    t_rec, t_samp, t_rec_end = window
    own = escape_rate(
        lifetimes["t_end"].to_numpy(),
        observed_from_outcome(lifetimes["outcome"]),
        detect_tail=False,
        min_survivors=min_survivors,
    )
    rows = kappa_cmeasure_shifts(
        sections, lifetimes, t_rec, t_samp - t_rec, shifts, kappa, t_rec_end, n_boot=n_boot, seed=seed
    )
    n_trapped = int((lifetimes["outcome"] == "censored").sum())
    return [
        {
            "energy": energy,
            "x": energy - E_c,
            **row,
            "kappa_pt_grid": reference.kappa,
            "kappa_pt_grid_err": reference.kappa_err,
            "kappa_pt_same_run": own.kappa,
            "kappa_pt_same_run_err": own.kappa_err,
            "n_trapped_dropped": n_trapped,
        }
        for row in rows
    ]


def cmeasure_comparisons(table) -> tuple[list[dict], dict]:
    """κ from the c-measure at the unshifted window of each energy against κ from P(t) of Fig. 2b (not in the paper).

    Parameters
    ----------
    table : DataFrame
        The rows of :func:`~hhscatter.reproduction.escape_summaries.kappa_cmeasure_shifts` completed with the P(t)
        references and :func:`~hhscatter.reproduction.escape_summaries.kappa_cmeasure_z` (columns energy,
        shift_efolds, kappa_cm, kappa_cm_err, kappa_pt_grid, kappa_pt_grid_err, z_vs_grid, ...).

    Returns
    -------
    (rows, entries)
        Comparison rows against κ from P(t) (its 1σ: another measurement, verdicts by the one rule) and
        {energy: numbers entry} with the later starts beside
        (:func:`~hhscatter.reproduction.escape_summaries.kappa_cmeasure_entry`).
    """
    rows, entries = [], {}
    for _, row in table[table["shift_efolds"] == 0.0].iterrows():
        z = row["z_vs_grid"]
        out = _row(
            f"κ from the c-measure (E={row['energy']:.2f})",
            row["kappa_cm"],
            row["kappa_cm_err"],
            row["kappa_pt_grid"],
            paper_err=row["kappa_pt_grid_err"],
            reference="propagated",
            unit="1/time",
            note=f"∫e^(κT)dμ_c = 1 + μ_c(ℰ) vs κ from P(t) of Fig. 2b {row['kappa_pt_grid']:.4f} ± "
            f"{row['kappa_pt_grid_err']:.4f} (z = {z:+.2f}); not in the paper",
        )
        rows.append({**out, "verdict": row_verdict({**out, "reference_kind": out["reference"]})})
        later = table[(table["energy"] == row["energy"]) & (table["shift_efolds"] > 0)]
        entries[row["energy"]] = kappa_cmeasure_entry(row, later)
    return rows, entries


#: the quantity of a row of κ from the c-measure (its energy in the parentheses)
_CM_QUANTITY = "κ from the c-measure (E="


def with_cmeasure_references(numbers: dict) -> dict:
    """with_cmeasure_references(numbers JSON) -> the same numbers with each row "κ from the c-measure (E=…)" of its
    ``paper_comparison`` given its reference, κ from P(t) with its 1σ (``paper``, ``paper_err``, ``reference_kind``
    "propagated"), from the ``cmeasure`` record of that energy where the row does not state it (a record written
    before the rows carried it, whose verdict was not in the one rule's words), so that its verdict comes from
    :func:`~hhscatter.reproduction.verdicts.row_verdict`. Numbers of any other study come back unchanged.

    Examples
    --------
    >>> from hhscatter.analysis.stats.measured import Measured
    >>> doc = {"cmeasure": {"cm_E0.27": {"energy": 0.27, "kappa_pt_grid": Measured(0.145, 0.002).to_dict()}},
    ...        "paper_comparison": [{"quantity": "κ from the c-measure (E=0.27)", "ours": 0.146, "err": 0.001,
    ...                              "paper": None, "verdict": "consistent with P(t) (|z| ≤ 2)"}]}
    >>> row = with_cmeasure_references(doc)["paper_comparison"][0]
    >>> row["paper"], row["paper_err"], row_verdict(row)
    (0.145, 0.002, 'agrees (z = +0.4)')
    """
    if not isinstance(numbers, dict):
        raise ConfigError(f"numbers must be a study's numbers JSON (a dict), got {type(numbers).__name__}")
    records, rows = numbers.get("cmeasure"), numbers.get("paper_comparison")
    if not isinstance(records, dict) or not isinstance(rows, list):
        return numbers
    refs = {}
    for rec in records.values():
        ref = rec.get("kappa_pt_grid") if isinstance(rec, dict) else None
        if isinstance(ref, dict) and isinstance(rec.get("energy"), (int, float)):
            refs[f"{_CM_QUANTITY}{rec['energy']:.2f})"] = ref
    out = []
    for row in rows:
        ref = refs.get(row.get("quantity")) if isinstance(row, dict) else None
        if ref is not None and row.get("paper") is None:
            row = {**row, "paper": ref["value"], "paper_err": ref["err"], "reference_kind": "propagated"}
            row["verdict"] = row_verdict(row)
        out.append(row)
    return {**numbers, "paper_comparison": out}


def convention_numbers(table, stability, fit_info: dict, law: dict, *, p_levels, max_bias, rel_tol) -> dict:
    """The numbers of κ(E) under the :data:`FIG2_CONVENTIONS`: the rules, the stable and unstable energies, the points
    ill-defined by the plateau of censored orbits (with their reasons), the law per convention and across them.

    ``table``: one row per (energy, convention) with defined and reason; ``stability``:
    :func:`~hhscatter.reproduction.convention_tables.stable_energies`; ``fit_info`` and ``law``: the second
    result of :func:`~hhscatter.reproduction.convention_tables.fit_laws` and its
    :func:`~hhscatter.reproduction.convention_tables.law_spread`.

    Examples
    --------
    >>> import pandas as pd
    >>> t = pd.DataFrame({"energy": [0.2], "convention": ["disk_plateau"], "defined": [False], "reason": ["plateau"]})
    >>> s = pd.DataFrame({"energy": [0.2], "stable": [False]})
    >>> convention_numbers(t, s, {}, {}, p_levels=[0.5, 0.01], max_bias=0.1, rel_tol=0.1)["ill_defined"]
    [{'energy': 0.2, 'convention': 'disk_plateau', 'reason': 'plateau'}]
    """
    stable = stability.loc[stability["stable"], "energy"]
    return {
        "conventions": {name: label for name, _, _, label in FIG2_CONVENTIONS},
        "p_levels": list(p_levels),
        "max_plateau_bias": max_bias,
        "stable_rel_tol": rel_tol,
        "stable_energies": sorted(float(e) for e in set(stable)),
        "unstable_energies": sorted(float(e) for e in stability.loc[~stability["stable"], "energy"]),
        "ill_defined": [
            {"energy": r.energy, "convention": r.convention, "reason": r.reason}
            for r in table[~table["defined"]].itertuples()
        ],
        "fits": fit_info,
        "law": law,
    }


def convention_analysis(runs: dict, *, E_c, p_levels, max_bias, rel_tol, n_boot, seed, min_survivors):
    """κ(E) under the :data:`FIG2_CONVENTIONS`: the table, the stable energies and the numbers of every convention.

    Parameters
    ----------
    runs : dict
        {energy: {region ("disk", "square"): (lifetimes, rate)}}: each run's lifetimes (t_end, outcome) and its
        escape-rate result (None: fitted here with ``min_survivors``, no tail detection).
    E_c : float
        The critical energy (x = E − E_c).
    p_levels : (float, float)
        The P levels (p_hi, p_lo) of the windows fixed by P; ``max_bias`` the largest bias of the slope at the
        window end from the plateau of censored orbits (beyond: κ ill-defined); ``rel_tol`` the relative spread of the
        conventions' κ within which an energy is stable.
    n_boot, seed : int
        The bootstrap of the law fits (:func:`~hhscatter.reproduction.convention_tables.fit_laws`).

    Returns
    -------
    (DataFrame, DataFrame, dict)
        One row per (energy, convention) (energy, x, convention, region, the columns of
        :func:`~hhscatter.reproduction.convention_tables.convention_rows`, stable); the stability per energy
        (:func:`~hhscatter.reproduction.convention_tables.stable_energies`); :func:`convention_numbers`.
    """
    from hhscatter.analysis.survival.escape_rate import escape_rate_from_lifetimes  # deferred: scipy on first use
    from hhscatter.analysis.survival.fits import lifetimes_to_arrays  # deferred: as above

    rows = []
    for energy, by_region in runs.items():
        for region, (lt, res) in by_region.items():
            if res is None:
                res = escape_rate_from_lifetimes(lt, detect_tail=False, min_survivors=min_survivors)
            t_end, obs = lifetimes_to_arrays(lt)
            for row in convention_rows(t_end, obs, res, p_hi=p_levels[0], p_lo=p_levels[1], max_bias=max_bias):
                rows.append(
                    {"energy": energy, "x": energy - E_c, "convention": f"{region}_{row['windows']}", "region": region}
                    | row
                )
    table = pd.DataFrame(rows)
    stab = stable_energies(table, rel_tol=rel_tol)
    table = table.merge(stab[["energy", "stable"]], on="energy", how="left")
    stable = set(stab.loc[stab["stable"], "energy"])
    names = [name for name, *_ in FIG2_CONVENTIONS]
    fits, fit_info = fit_laws(table, names, stable, E_c, n_boot=n_boot, seed=seed)
    law = law_spread(fits) if fits else {}
    numbers = convention_numbers(table, stab, fit_info, law, p_levels=p_levels, max_bias=max_bias, rel_tol=rel_tol)
    return table, stab, numbers


def cmeasure_run_rows(
    sections, lifetimes, choice: dict, section_window: dict, grid_rates: dict, *, label: str, **kw
) -> list[dict]:
    """κ from the c-measure of one section run per start shift, beside κ from P(t) (:func:`cmeasure_table_rows`).

    ``choice``: the run's recorded window (t_rec, t_sample_end, t_record_end in time units, and the κ in 1/time
    that set it); ``section_window``: the run's ``[sections]`` (t_from, t_to), which must be that window, else
    RuntimeError naming the run ``label`` (it was made for another choice); ``grid_rates``: {energy: escape-rate result} of the
    Fig. 2b runs, the one nearest ``kw["energy"]`` the reference; ``kw``: ``shifts`` and the keyword arguments of
    :func:`cmeasure_table_rows`.
    """
    t_rec, t_samp, t_rec_end = choice["t_rec"], choice["t_sample_end"], choice["t_record_end"]
    win = section_window
    if abs(float(win["t_from"]) - t_rec) > 1e-9 or abs(float(win["t_to"]) - t_rec_end) > 1e-6:
        raise RuntimeError(
            f"{label}: raw run's section window {win} is not the recorded choice "
            f"[{t_rec}, {t_rec_end}]; re-run the simulate stage"
        )
    energy = kw["energy"]
    reference = grid_rates[min(grid_rates, key=lambda e: abs(e - energy))]
    shifts = kw.pop("shifts")
    return cmeasure_table_rows(
        sections, lifetimes, (t_rec, t_samp, t_rec_end), shifts, choice["kappa"], reference, **kw
    )
