"""Paper-comparison rows of the section points against the c-measure (paper Fig. 5 = fig:um_comparison).

Each function turns a record of :mod:`hhscatter.reproduction.cmeasure_comparison` into rows for a study's
comparison table: dicts of the keyword arguments of ``Study.compare`` (quantity, ours, err, paper and verdict,
note, convention, authors). The paper's claims: the points at t* "mostly coincide" with μ_c^{E1}, better than
with μ_c^{E2}; restricting their energy (Fig. 5b) removes most of the dispersion; the agreement holds "up to a
finite spatial scale, which becomes increasingly small as the time for the distributions to relax increases".
A verdict on a distance rests on a paired interval: "agrees" when it excludes the other sign.
"""

from __future__ import annotations

import math

import pandas as pd

from hhscatter.reproduction.verdicts import comparison_row

__all__ = [
    "REFS_QUANTITY",
    "VERDICT_QUANTITY",
    "closer_comparisons",
    "difference_comparisons",
    "interval_verdict",
    "qualify_our_5b",
    "reference_comparisons",
    "scale_comparisons",
]

#: the quantity of a 5b − 5a row ({label}: the construction)
VERDICT_QUANTITY = "Fig. 5b closer to μ_c^0.30 than 5a, paired Δ = d(5b) − d(5a): {label}"
#: the quantity of a row of a set ({s}: 5a or 5b) against the two references
REFS_QUANTITY = "Fig. {s} closer to μ_c^0.30 than to μ_c^0.35, paired Δ = d(μ_c^0.35) − d(μ_c^0.30)"


def interval_verdict(lo: float, hi: float, sign: int) -> str:
    """The verdict of a paired interval [lo, hi] on a difference expected with ``sign`` (+1: > 0, −1: < 0).

    Examples
    --------
    >>> interval_verdict(0.01, 0.05, +1), interval_verdict(0.01, 0.05, -1), interval_verdict(-0.1, 0.05, -1)
    ('agrees', 'differs', 'no significant difference')
    """
    if sign > 0:
        return "agrees" if lo > 0 else ("differs" if hi < 0 else "no significant difference")
    return "agrees" if hi < 0 else ("differs" if lo > 0 else "no significant difference")


def _fmt_iv(iv):
    return f"[{iv[0]:.3f}, {iv[1]:.3f}]"


def closer_comparisons(pg: pd.DataFrame, stab: pd.DataFrame, g_main: float, *, mu, mu_err, mu_source, E1, paper):
    """(rows, {"a" | "b": closer}) of the headline γ: t*, the plotted fraction, ⟨E⟩ at the crossings, and which
    c-measure is closer by the sliced Wasserstein distance SW1 in Fig. 5a and 5b.

    ``pg``: per-γ counts (gamma, t_star, t_star_err, N, n_a_all, n_a, mean_E_a, std_E_a); ``stab``: the summary
    of :func:`~hhscatter.reproduction.cmeasure_comparison.distance_tables`; ``paper``: {"t_star",
    "fraction"} the paper's t* ≈ 17 and its plotted fraction ≈ 3e4 of 1e7. Closer to μ_c^{E1}: SW1(E1) +
    2 √(σ1² + σ2²) < SW1(E2).

    Examples
    --------
    >>> pg = pd.DataFrame([{"gamma": 0.01, "t_star": 17.2, "t_star_err": 0.1, "N": 1000, "n_a_all": 3, "n_a": 3,
    ...                     "mean_E_a": 0.30, "std_E_a": 0.01}])
    >>> stab = pd.DataFrame([{"gamma": 0.01, "set": "a", "ref": r, "sw1": v, "sw1_err": 0.001}
    ...                      for r, v in (("E1", 0.02), ("E2", 0.05))])
    >>> rows, closer = closer_comparisons(pg, stab, 0.01, mu=0.9, mu_err=0.01, mu_source="fig3", E1=0.3,
    ...                                   paper={"t_star": 17.0, "fraction": 3e-3})
    >>> closer, rows[1]["verdict"]
    ({'a': True}, 'comparable')
    """

    def srow(g, s, ref):
        r = stab[(stab["gamma"] == g) & (stab["set"] == s) & (stab["ref"] == ref)]
        return r.iloc[0] if len(r) else None

    main = pg[pg["gamma"] == g_main].iloc[0]
    frac_a = float(main["n_a_all"]) / float(main["N"])
    paper_frac = paper["fraction"]
    rows = [
        comparison_row(
            "t* (E2=0.35 → E1=0.30, γ=0.01)",
            float(main["t_star"]),
            float(main["t_star_err"]),
            paper["t_star"],
            note=f"t* = ln(E2/E1)/(μγ) with μ = {mu:.4g} ± {mu_err:.2g} from {mu_source}; "
            "paper gives t* ≈ 17 (its μ = 0.91 gives 16.94)",
        ),
        comparison_row(
            "fraction of N plotted in Fig. 5a",
            frac_a,
            math.sqrt(frac_a * (1 - frac_a) / float(main["N"])),
            paper_frac,
            verdict="differs" if abs(frac_a - 3e-3) > 0.5 * 3e-3 else "comparable",
            note="paper: ≈3e4 of N = 1e7 plotted; the fraction depends on the initial ensemble "
            "(ours: uniform disk r < 0.5, tangential velocities), so only the order matters",
        ),
        comparison_row(
            "⟨E⟩ of the Fig. 5a crossings",
            float(main["mean_E_a"]),
            float(main["std_E_a"]) / math.sqrt(max(float(main["n_a"]), 1.0)),
            E1,
            note=f"spread (std) {float(main['std_E_a']):.4f}; the paper's premise is ⟨E⟩ ≈ E1 at t*",
        ),
    ]
    closer_by_set = {}
    for s in ("a", "b"):
        r1, r2 = srow(g_main, s, "E1"), srow(g_main, s, "E2")
        if r1 is None or r2 is None:
            continue
        closer = r1["sw1"] + 2 * math.hypot(r1["sw1_err"], r2["sw1_err"]) < r2["sw1"]
        closer_by_set[s] = bool(closer)
        rows.append(
            comparison_row(
                f"Fig. 5{s}: SW1(diss, μ_c^0.30) < SW1(diss, μ_c^0.35)",
                f"{r1['sw1']:.4f}±{r1['sw1_err']:.4f} vs {r2['sw1']:.4f}±{r2['sw1_err']:.4f}",
                None,
                "μ_c^{E1} better than μ_c^{E2}",
                verdict="agrees" if closer else "differs",
                note="sliced Wasserstein W1 (units of x, y), bootstrap 1σ",
            )
        )
    return rows, closer_by_set


def difference_comparisons(record: dict, conventions: dict, like_for_like: str = "cut_offsets") -> list:
    """One row per construction of a 5b − 5a record: is 5b closer to μ_c^{E1} than 5a (paired Δ < 0)?

    ``record``: {"rows" (of :func:`~hhscatter.reproduction.cmeasure_comparison.paired_differences`),
    "level", "n_boot"}; ``conventions`` {construction: its convention, None for ours}. A "differs" of our
    construction ("ours") that the authors' construction ``like_for_like`` does not show is qualified as ours
    only. Rows with a ``note`` (sets too small) give none.

    Examples
    --------
    >>> row = {"construction": "ours", "label": "ours", "delta": 0.05, "delta_interval": [0.01, 0.09],
    ...        "d_5a": 0.2, "d_5b": 0.25, "box": 0.05, "offsets": 16, "offset_spread_of_delta": 0.01}
    >>> out = difference_comparisons({"rows": [row], "level": 0.95, "n_boot": 100}, {"ours": None})
    >>> out[0]["verdict"], out[0]["authors"]
    ('differs', False)
    """
    verdict_of = lambda r: interval_verdict(*r["delta_interval"], sign=-1)  # noqa: E731
    like = {r["construction"]: r for r in record["rows"] if "delta" in r}.get(like_for_like)
    out = []
    for r in record["rows"]:
        if "delta" not in r:
            continue
        lo, hi = r["delta_interval"]
        v = verdict_of(r)
        if r["construction"] == "ours" and v == "differs" and like is not None and verdict_of(like) != "differs":
            v = f"differs in our convention only; in the authors' construction, like for like: {verdict_of(like)}"
        out.append(
            comparison_row(
                VERDICT_QUANTITY.format(label=r["label"]),
                f"{r['delta']:+.3f} [{lo:+.3f}, {hi:+.3f}]",
                None,
                "Δ < 0 (the energy filter tightens the agreement)",
                verdict=v,
                authors=r["construction"] != "ours",
                convention=conventions[r["construction"]],
                note=f"d(5a) {r['d_5a']:.3f}, d(5b) {r['d_5b']:.3f} (debiased Hellinger, ε = {r['box']:g}, "
                f"{r['offsets']} grid placements; spread of Δ over placements {r['offset_spread_of_delta']:.3f}); "
                f"{int(record['level'] * 100)} % interval from {record['n_boot']} paired half-samples "
                "over orbits",
            )
        )
    return out


def reference_comparisons(record: dict, authors_convention: str) -> list:
    """One row per construction and set: closer to μ_c^{E1} than to μ_c^{E2} (paired Δ > 0)?

    ``record``: {"rows" (of :func:`~hhscatter.reproduction.cmeasure_comparison.paired_reference_distances`),
    "E1", "E2", "box", "offsets", "level", "n_boot"}; rows of a construction other than "ours" are the authors'
    (convention ``authors_convention``). Rows with a ``note`` give none.

    Examples
    --------
    >>> iv = lambda v: {"value": v, "interval": [v - 0.01, v + 0.01]}
    >>> row = {"construction": "ours", "label": "ours", "set": "5a", "d_E1": iv(0.1), "d_E2": iv(0.2),
    ...        "delta": iv(0.1), "n_set": 10, "n_E1": 20, "n_E2": 20}
    >>> rec = {"rows": [row], "E1": 0.3, "E2": 0.35, "box": 0.05, "offsets": 16, "level": 0.95, "n_boot": 100}
    >>> reference_comparisons(rec, "authors'")[0]["verdict"]
    'agrees'
    """
    E1, E2 = record["E1"], record["E2"]
    out = []
    for r in record["rows"]:
        if "delta" not in r:
            continue
        d, (lo, hi) = r["delta"]["value"], r["delta"]["interval"]
        ours = r["construction"] == "ours"
        out.append(
            comparison_row(
                REFS_QUANTITY.format(s=r["set"]) + f": {r['label']}",
                f"{d:+.3f} [{lo:+.3f}, {hi:+.3f}]",
                None,
                "Δ > 0 (closer to μ_c^{E1})",
                verdict=interval_verdict(lo, hi, sign=+1),
                authors=not ours,
                convention=None if ours else authors_convention,
                note=f"d to μ_c^{E1:g} {r['d_E1']['value']:.3f} {_fmt_iv(r['d_E1']['interval'])}, to "
                f"μ_c^{E2:g} {r['d_E2']['value']:.3f} {_fmt_iv(r['d_E2']['interval'])} (debiased "
                f"Hellinger, ε = {record['box']:g}, {record['offsets']} grid placements; "
                f"{int(record['level'] * 100)} % intervals from {record['n_boot']} paired half-samples over "
                f"orbits; {r['n_set']} / {r['n_E1']} / {r['n_E2']} points)",
            )
        )
    return out


def scale_comparisons(record) -> list:
    """Rows of panel (d): ε*_δ shrinks with t*, and d at the headline box decreases with t* (paired steps).

    ``record``: of :func:`~hhscatter.reproduction.cmeasure_comparison.paired_scale_curves` (none without
    its curves). ε*_δ shrinks ("agrees") when it does in at least ``level`` of the replicates; d decreases when
    every step's interval lies below 0, "differs" when one lies above.

    Examples
    --------
    >>> c = lambda t, e: {"t_star": t, "eps_delta": e, "eps_delta_interval": [e, e], "d": [0.2, 0.1]}
    >>> rec = {"curves": [c(8.5, 0.1), c(17.0, 0.05)], "level": 0.95, "eps_shrink_share": 0.97, "n_boot": 100,
    ...        "delta": 0.1, "box_headline": 0.05, "boxes": [0.1, 0.05], "offsets": 16,
    ...        "steps": [{"value": -0.02, "interval": [-0.03, -0.01]}]}
    >>> [r["verdict"] for r in scale_comparisons(rec)]
    ['agrees', 'agrees']
    """
    if not record or "curves" not in record:
        return []
    fmt = lambda e: f"{e:.3g}" if e is not None else "none"  # noqa: E731
    cur, level = record["curves"], int(record["level"] * 100)
    share = record["eps_shrink_share"]
    steps = record["steps"]
    all_down = all(s["interval"][1] < 0 for s in steps)
    any_up = any(s["interval"][0] > 0 for s in steps)
    jh = record["boxes"].index(record["box_headline"])
    return [
        comparison_row(
            f"agreement scale ε*_δ of Fig. 5a vs μ_c^0.30 shrinks with relaxation time t* (debiased H ≤ δ = "
            f"{record['delta']:g}, paired half-samples)",
            "; ".join(
                f"t*={c['t_star']:.1f}: {fmt(c['eps_delta'])} [{fmt(c['eps_delta_interval'][0])}, "
                f"{fmt(c['eps_delta_interval'][1])}]"
                for c in cur
            ),
            None,
            "finite scale, smaller for longer relaxation",
            verdict="agrees" if share >= record["level"] else "not shown",
            note=f"ε*_δ of the mean curve with its {level} % interval over {record['n_boot']} paired half-samples "
            f"(orbits of every γ's run and of the reference); it shrinks in {share:.0%} of them",
        ),
        comparison_row(
            f"debiased Hellinger(ε={record['box_headline']:g}) of Fig. 5a to μ_c^0.30 decreases with t* "
            "(paired differences between consecutive t*)",
            ", ".join(f"t*={c['t_star']:.1f}: {c['d'][jh]:.3f}" for c in cur)
            + "; steps "
            + ", ".join(f"{s['value']:+.3f} [{s['interval'][0]:+.3f}, {s['interval'][1]:+.3f}]" for s in steps),
            None,
            "convergence to μ_c^{E(t)} with relaxation time",
            verdict="agrees" if all_down else ("differs" if any_up else "not shown"),
            note=f"{level} % intervals of d(t*_(i+1)) − d(t*_i) from {record['n_boot']} paired half-samples; "
            f"{record['offsets']} grid placements",
        ),
    ]


def qualify_our_5b(rows: list, like_for_like_label: str) -> None:
    """Qualify, in place, a "differs" of our Fig. 5b that the authors' own construction of 5b does not show.

    Our 5b (our 5a filtered to the energy band) is checked against the authors' rows (``authors`` true): 5b
    against the two references (:data:`REFS_QUANTITY`) and 5b against 5a in the construction labelled
    ``like_for_like_label`` (:data:`VERDICT_QUANTITY`). Where that row's verdict is not "differs", ours becomes
    "differs in our convention only; under the authors' construction of 5b: <its verdict>".

    Examples
    --------
    >>> rows = [{"quantity": "Fig. 5b: SW1", "verdict": "differs"},
    ...         {"quantity": REFS_QUANTITY.format(s="5b") + ": theirs", "verdict": "agrees", "authors": True}]
    >>> qualify_our_5b(rows, "like for like"); rows[0]["verdict"]
    "differs in our convention only; under the authors' construction of 5b: agrees"
    """
    auth = [r for r in rows if r.get("authors")]
    auth_b = next((r for r in auth if r["quantity"].startswith(REFS_QUANTITY.format(s="5b"))), None)
    auth_ab = next((r for r in auth if r["quantity"] == VERDICT_QUANTITY.format(label=like_for_like_label)), None)
    for r in rows:
        if r.get("authors") or r.get("verdict") != "differs" or not r["quantity"].startswith("Fig. 5b"):
            continue
        ref = auth_ab if "than 5a" in r["quantity"] else auth_b
        if ref is not None and ref.get("verdict") != "differs":
            r["verdict"] = f"differs in our convention only; under the authors' construction of 5b: {ref['verdict']}"
