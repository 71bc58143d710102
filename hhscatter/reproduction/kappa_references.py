"""The κ references a study reads from the escape-rate study's numbers JSON: κ0(E) of P(t) and κ from the c-measure.

Units: energies in energy units, κ in 1/time.
"""

from __future__ import annotations

__all__ = ["kappa_references"]


def kappa_references(doc: dict) -> tuple[dict, dict]:
    """The κ references of the escape-rate study (fig2) from its numbers JSON ``doc``: ({E: (κ0, err)} of ``kappa_energy``, the P(t) route;
    {E: (κ, err)} of ``cmeasure.*.kappa_cm``, the true-time relation on long-run section crossings).
    KeyError if ``kappa_energy`` is missing.

    Examples
    --------
    >>> from hhscatter.analysis.stats import Measured
    >>> doc = {"kappa_energy": [{"energy": 0.3, "kappa": 0.2, "kappa_err": 0.01}],
    ...        "cmeasure": {"a": {"energy": 0.3, "kappa_cm": Measured(0.19, 0.001).to_dict()}}}
    >>> kappa_references(doc)
    ({0.3: (0.2, 0.01)}, {0.3: (0.19, 0.001)})
    """
    ke = doc.get("kappa_energy")
    if not ke:
        raise KeyError("kappa_energy")
    k0 = {float(r["energy"]): (float(r["kappa"]), float(r["kappa_err"])) for r in ke}
    kcm = {
        float(v["energy"]): (float(v["kappa_cm"]["value"]), float(v["kappa_cm"]["err"]))
        for v in (doc.get("cmeasure") or {}).values()
        if isinstance(v, dict) and "kappa_cm" in v
    }
    return k0, kcm
