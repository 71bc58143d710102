"""The glossary's words for the orbits that stay, in numbers written before the studies used them.

The studies write their rules, reasons and row names as text into the numbers JSON. The orbits still inside at a
run's t_max are *censored* (the glossary's word; *regular* and *chaotic but confined* are what the shadow indicator
calls the survivors it classifies). Records written before the studies said so call them "KAM-trapped",
"trapped" or "KAM-trapped or sticky": :func:`in_glossary_words` gives a record read for a page or the report the
words the studies write now, so that a row keeps one name at every scale (the pages match the paper-scale and the
quick-scale rows by name) and no page says "trapped" for a censored orbit. The benchmarks' summaries are read through
it too (the stress cases' orbits still inside at t = 5000 were "KAM-trapped"). The dissipative mixture's share of
a sub-ensemble that never escapes (it settles) was its "trapped fraction φ" (or "trapped fractions f_ne,k"); it is
read as the glossary names φ and f_ne, the never-escaping share. The neighbour dimension estimator's refusal of a
scaling range ("fewer than 4 neighbour scales in [eps_min, eps_max] = [..]") is read as a point's reason for no d₁,
with units and what the range is (:func:`hhscatter.reproduction.saddle_records.d1_refusal_words`). The JSON keys stay as they are
(``trapped_fraction``, ``n_trapped`` …): readers use them.
"""

from __future__ import annotations

from hhscatter.reproduction.saddle_records import d1_refusal_words

__all__ = ["OLD_PHRASES", "in_glossary_words"]

#: (phrase the studies once wrote, the phrase they write now), longest first where one contains another
OLD_PHRASES: tuple[tuple[str, str], ...] = (
    ("orbits still inside at t_max (KAM-trapped or sticky) are", "censored orbits (still inside at t_max) are"),
    ("orbits censored at t_max (KAM-trapped) removed", "orbits censored at t_max removed"),
    ("KAM-trapped orbits (censored at cm_t_max) dropped", "orbits censored at cm_t_max dropped"),
    ("ill-defined by the trapped plateau", "ill-defined by the plateau of censored orbits"),
    ("trapped-plateau check", "check of the plateau of censored orbits"),
    ("μ_c: KAM-trapped orbits dropped", "μ_c: censored orbits dropped"),
    ("(KAM-trapped orbits dropped)", "(censored orbits dropped)"),
    ("all conservative survivors, trapped kept", "all conservative survivors, censored kept"),
    ("c-measure: trapped orbits dropped", "c-measure: censored orbits dropped"),
    ("(trapped fraction ", "(censored fraction "),
    ("KAM-trapped orbits (E=", "censored orbits (E="),
    ("(one trapped fraction φ)", "(one never-escaping share φ)"),
    ("K trapped fractions f_ne,k", "K never-escaping fractions f_ne,k"),
)


def _reworded(text: str) -> str:
    for old, new in OLD_PHRASES:
        if old in text:
            text = text.replace(old, new)
    return d1_refusal_words(text)  # the neighbour estimator's raw refusal, said as a point's reason for no d₁


def in_glossary_words(doc):
    """in_glossary_words(numbers JSON) -> a copy whose text values say "censored" where an older record wrote
    "KAM-trapped" or "trapped" for an orbit still inside at t_max (:data:`OLD_PHRASES`); keys and numbers unchanged.

    Examples
    --------
    >>> doc = {"kappa": {"reason": "P(t) never falls to 0.001 (trapped fraction 3.17%)", "trapped_fraction": 0.03}}
    >>> in_glossary_words(doc)["kappa"]
    {'reason': 'P(t) never falls to 0.001 (censored fraction 3.17%)', 'trapped_fraction': 0.03}
    """
    if isinstance(doc, str):
        return _reworded(doc)
    if isinstance(doc, dict):
        return {k: in_glossary_words(v) for k, v in doc.items()}
    if isinstance(doc, list):
        return [in_glossary_words(v) for v in doc]
    return doc
