"""Claim records and verdicts: ``{claim, quantity, system, value, err, reference, verdict, note}``."""

from __future__ import annotations

import math

import numpy as np

from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.stats.verdicts import Verdict, verdict
from hhscatter.reproduction.model_tables import number_or_none


def z_verdict(value, err, ref, label_ok, label_bad, ref_err=0.0) -> str:
    """z_verdict(value, err, ref, label_ok, label_bad, ref_err=0) -> '<label> (z = …)' by the one rule
    (:data:`hhscatter.reproduction.verdicts.RULE`): |z| ≤ 2 is ``label_ok``, z = (value − ref)/√(err² + ref_err²),
    written as every verdict is (:meth:`~hhscatter.analysis.stats.verdicts.Verdict.text`, minus sign "−"); without a
    value, a reference or our error, "undetermined: <why>".

    Examples
    --------
    >>> z_verdict(1.1, 0.1, 1.0, "agrees", "differs")
    'agrees (z = +1.0)'
    >>> z_verdict(0.5, 0.1, 1.0, "τ2 ∝ 1/γ", "not ∝ 1/γ")
    'not ∝ 1/γ (z = −5.0)'
    >>> z_verdict(0.5, None, 1.0, "agrees", "differs")
    'undetermined: no uncertainty of ours'
    """
    v = verdict(value, err, ref, ref_err or 0.0)
    if v.word not in ("agrees", "differs"):
        return v.text()
    label = label_ok if v.word == "agrees" else label_bad
    return Verdict(label, v.z, v.why).text() if v.z is not None else f"{label} ({v.why})" if v.why else label


class Claims:
    """The list of claim records ``rows``; each record is also passed to ``compare`` (a study's comparison table:
    ``compare(label, value, err, reference, verdict=, note=)``), when given.

    Examples
    --------
    >>> c = Claims()
    >>> c.add("1", "κ0 defined", "barbanis", 1.0, None, "yes")
    >>> c.rows[0]["verdict"]
    'yes'
    """

    def __init__(self, compare=None):
        self.compare, self.rows = compare, []

    def add(self, claim, quantity, system, value, err, verdict, note="", reference=None) -> None:
        """Append one record {claim, quantity, system, value, err, reference, verdict, note}."""
        k = sum(r["claim"] == claim and r["system"] == system for r in self.rows)
        rec = {
            "id": f"{system}-{claim}-{k}",
            "claim": claim,
            "quantity": quantity,
            "system": system,
            **{k: number_or_none(x) for k, x in Measured.of(value, err).to_dict().items()},
            "reference": reference,
            "verdict": verdict,
            "note": note,
        }
        self.rows.append(rec)
        if self.compare is not None:
            self.compare(
                f"[{claim}] {quantity} — {system}", rec["value"], rec["err"], reference, verdict=verdict, note=note
            )


def with_ids(rows: list) -> list:
    """with_ids(claim records) -> the records with ``id`` = '<system>-<claim>-<k>' (k: the record's place among
    that system's records of that claim), as :meth:`Claims.add` gives them: a page names a record by it.

    Examples
    --------
    >>> [r["id"] for r in with_ids([{"claim": "1", "system": "a"}, {"claim": "1", "system": "a"}])]
    ['a-1-0', 'a-1-1']
    """
    seen: dict = {}
    out = []
    for r in rows:
        k = seen.get((r["system"], r["claim"]), 0)
        seen[r["system"], r["claim"]] = k + 1
        out.append({"id": f"{r['system']}-{r['claim']}-{k}", **{a: b for a, b in r.items() if a != "id"}})
    return out


def across(per: dict, key: str):
    """(mean, √(stat² + half range²)) of law parameter ``key`` over the conventions that fitted it."""
    vals = [(v[key]["value"], v[key]["err"]) for v in per.values() if v and v.get(key)]
    if not vals:
        return None, None
    x = np.array([v for v, _ in vals])
    stat = max((e for _, e in vals if e is not None and math.isfinite(e)), default=0.0)
    return float(x.mean()), float(math.hypot(stat, (x.max() - x.min()) / 2))


#: the rules of the claims, as generality.json states them
RULES = {
    "energies": "E = r·E_c on the grid ratios, the same for every system",
    "ics": "uniform in the disk r < radius_frac·r_s, tangential momenta; r_esc the system's default",
    "kappa": "escape_rate (plateau windows) and P-level windows, check of the plateau of censored orbits; law in ε = E/E_c − 1",
    "mu_measured": "fig3's: <E>(t) of orbits not escaped, settled continued; fixed-intercept log fit",
    "mu_predicted": "2<K>/E of the conservative flow (probe drag, c-measure) above E_c, microcanonical "
    "well below; path dE/dt = -gamma mu(E) E fitted like the measured curve",
    "taus": "fig4's: tau0 choose_windows(P_0), tau1 P_g = alpha P_0, tau2 first settling, Eq. (eq:tau2)",
    "kappa_cmeasure": "claim 2: every section crossing of a conservative run (censored orbits dropped) on "
    "[ceil(tau0 + cm_rec_efolds/kappa), cm_t_to - cm_margin], Eq. (eqn:kappa_cmeasure_"
    "truetime), bootstrap over orbits; against kappa0 of the claim-1 run at that E/E_c",
    "cmeasure_distance": "claim 5: first crossing after t* of the dissipative survivors vs the sprinkler "
    "points of mu_c at E(t*) and E0; paired debiased Hellinger, half-samples of orbits",
    "regular_fraction": "shadow FTLE: each orbit and a shadow d0 = ev_delta away on its energy shell, compared at "
    "their first section crossing after ev_t_max - ev_window; regular when the separation grew "
    "less than ev_g_max; orbits that left before: not regular",
    "survival_long": "Kaplan-Meier P(t) (Greenwood errors) of the ev runs to ev_t_max, disk ICs, gamma = 0",
    "long_time": "P(t|t0) = q + (1-q) exp(-kappa (t-t0)) by maximum likelihood on the lifetimes, censored orbits "
    "as censored (no conditioning on escape before t_max); the non-regular orbits alone with q = 0",
}
