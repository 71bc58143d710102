"""r_esc sensitivity of claims 1, 3 and 5: κ0 at each radius and its shift, μ measured, μ predicted, the survivors'
own-⟨K⟩ μ and 2⟨K⟩/E at E0 itself, per escape radius, with the same N and rules for each (the default radius and
``resc_values`` in units of each system's saddle distance), and each system's r_esc rule by energy."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.stats.measured import Measured
from hhscatter.reproduction.claims.kappa import rate_or_reason, window_rate
from hhscatter.reproduction.claims.keys import resc_key
from hhscatter.reproduction.claims.mu import (
    mu_conservative,
    mu_measured,
    mu_of_E,
    mu_predicted,
    mu_windows,
)
from hhscatter.reproduction.claims.records import z_verdict


def resc_values(p, m) -> list:
    """[None (the default), *the radii f·r_s of ``p.resc_values`` (factors f of the system's saddle distance r_s)
    valid for this system (beyond its saddle, not its default radius at E0)] (length).

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> from hhscatter.model.builtins import contopoulos, henon_heiles
    >>> p = NS(resc_values=[1.03, 0.9], e0_ratio=1.8)
    >>> resc_values(p, henon_heiles()), resc_values(p, contopoulos(eps=0.25))
    ([None, 1.03], [None, 2.06])
    """
    r_s = m.saddle_radius
    default = m.default_escape_radius(p.e0_ratio * m.critical_energy)
    radii = (float(f) * r_s for f in p.resc_values)
    return [None, *(R for R in radii if R > r_s and not math.isclose(R, default))]


def r_esc_rule(m, ratios) -> dict:
    """r_esc_rule(system, ratios) -> {rule, saddle_radius, by_ratio: [{e_ratio, r_esc, from}]}: the escape radius a
    scene without one uses at E = r·E_c for each r of ``ratios`` (the system's ``default_escape_radius``, length),
    and which term sets it ('1.5 r_s' or 'R(E)', the no-return radius; '1.5' for a fixed radius).

    Examples
    --------
    >>> from hhscatter.model.builtins import contopoulos
    >>> [(x["e_ratio"], round(x["r_esc"], 3), x["from"]) for x in
    ...  r_esc_rule(contopoulos(eps=0.25), [1.05, 3.5])["by_ratio"]]
    [(1.05, 3.0, '1.5 r_s'), (3.5, 3.742, 'R(E)')]
    """
    r_s = m.saddle_radius
    rows = []
    for r in sorted(float(x) for x in ratios):
        E = r * m.critical_energy
        R = float(m.default_escape_radius(E))
        no_return = float(m.no_return_radius(E))
        src = "R(E)" if R > 1.5 * r_s + 1e-12 and math.isclose(R, no_return) else "1.5 r_s"
        rows.append({"e_ratio": r, "r_esc": R, "from": src, "no_return_radius": no_return})
    grows = len({round(x["r_esc"], 12) for x in rows}) > 1
    if grows:
        k = next(x for x in rows if x["from"] == "R(E)")
        rule = (
            f"max(1.5 r_s, R(E)) = {rows[0]['r_esc']:.3g} up to {rows[rows.index(k) - 1]['e_ratio']:g} E_c, then R(E), "
            f"growing with E ({k['r_esc']:.3g} at {k['e_ratio']:g} E_c, {rows[-1]['r_esc']:.3g} at "
            f"{rows[-1]['e_ratio']:g} E_c)"
        )
    else:
        inside = [x for x in rows if x["no_return_radius"] > x["r_esc"] + 1e-12]
        rule = f"{rows[0]['r_esc']:.3g} at every E" + (
            f" (inside the no-return radius R(E) from {inside[0]['e_ratio']:g} E_c on: R = "
            f"{inside[-1]['no_return_radius']:.3g} at {inside[-1]['e_ratio']:g} E_c)"
            if inside
            else ""
        )
    return {"rule": rule, "saddle_radius": r_s, "by_ratio": rows}


#: the verdict words of κ0's shift with r_esc (the one rule: |z| ≤ 2 against no shift)
SHIFT_WORDS = ("no shift resolved", "shifts")


def _kappa_at(lt, p, convention: str):
    """κ0 (Measured) of one run under one convention ('plateau': all orbits; 'escaping': censored dropped) and the
    reason where it is ill-defined ('' where defined)."""
    if convention == "escaping":
        lt = lt[lt["outcome"] != "censored"]
    c, _, why = window_rate(lt, p, "window rule failed")
    if c is None:
        return None, why
    if not (c.defined and c.kappa > 0):
        return None, c.reason or "κ ≤ 0"
    return Measured.of(c.kappa, c.kappa_err), ""


def resc_kappa_rows(runs, systems) -> list:
    """κ0 at the default r_esc and at each other radius of :func:`resc_values`, per system, E/E_c of ``resc_ratios``
    and convention ('plateau': all orbits, the paper's; 'escaping': the orbits still inside at t_max dropped), the same
    N and rules at each radius; the shift κ0(r_esc)/κ0(default) − 1 with its error (the two runs' errors in
    quadrature: they share their initial conditions, so this overstates the error of the difference) and its
    verdict by the one rule against no shift (|z| ≤ 2: 'no shift resolved'); "undetermined: …" where κ0 is
    ill-defined at either radius."""
    p = runs.params
    out = []
    for label, spec, m in systems:
        Rs = resc_values(p, m)
        for r in p.resc_ratios if len(Rs) > 1 else ():
            E = r * m.critical_energy
            lts = {R: runs.lifetimes(resc_key(label, R, f"r{r:.3f}")) for R in Rs}
            for conv in ("plateau", "escaping"):
                base, why0 = _kappa_at(lts[None], p, conv)
                for R in Rs[1:]:
                    k, why = _kappa_at(lts[R], p, conv)
                    row = {
                        "id": f"{label}-{r:g}-r{R:g}-{conv}",
                        "system": spec["name"],
                        "label": label,
                        "e_ratio": float(r),
                        "convention": conv,
                        "r_esc_default": float(m.default_escape_radius(E)),
                        "r_esc": float(R),
                        "r_esc_over_saddle": float(R / m.saddle_radius),
                        "n": int(len(lts[R])),
                        "kappa_default": (base or Measured.of(None, None)).to_dict(),
                        "kappa": (k or Measured.of(None, None)).to_dict(),
                    }
                    if base is None or k is None:
                        where = "; ".join(
                            f"at r_esc = {x:.3g}: {w}" for x, w in ((row["r_esc_default"], why0), (R, why)) if w
                        )
                        row.update(shift={"value": None, "err": None}, verdict=f"undetermined: κ0 ill-defined {where}")
                    else:
                        d = k.ratio(base).difference(1.0)
                        row.update(shift=d.to_dict(), verdict=z_verdict(d.value, d.err, 0.0, *SHIFT_WORDS))
                    out.append(row)
    return out


def resc_rows(runs, systems) -> list:
    """μ measured, μ predicted (c-measure), the survivors' own-⟨K⟩ μ and 2⟨K⟩/E at E0 itself, per r_esc (the
    default and resc_values), the same N and rules for each: the r_esc sensitivity of claims 3 and 5."""
    p = runs.params
    out = []
    for label, spec, m in systems:
        Rs = resc_values(p, m)
        if len(Rs) < 2:
            continue
        ec = m.critical_energy
        E0 = p.e0_ratio * ec
        for R in Rs:
            fits = {}
            for r in p.resc_ratios:
                lt = runs.lifetimes(resc_key(label, R, f"r{r:.3f}"))
                res, _ = rate_or_reason(lt[lt["outcome"] != "censored"], p.min_survivors)
                if res is not None:  # too few escapes: no κ, τ0 for the probe window at this energy
                    fits["escaping", r] = res
            keys = {r: resc_key(label, R, f"probe_r{r:.3f}") for r in p.resc_ratios}
            mdf = pd.DataFrame(mu_conservative(runs, label, m, fits, keys=keys))
            meas, _, (own, _) = mu_measured(
                runs, label, m, E0, key=resc_key(label, R, f"g{p.mu_gamma:g}"), n=p.resc_diss_n
            )
            pred, _, _ = mu_predicted(runs, mdf, ec, E0)
            c = mdf[(mdf["kind"] == "c-measure") & np.isclose(mdf["ratio"], p.e0_ratio)]
            r_esc = float(m.default_escape_radius(E0)) if R is None else float(R)
            for wname, w in mu_windows(runs).items():
                (v, e), (pv, pe) = own[wname], pred["c-measure", wname]
                out.append(
                    {
                        "id": f"{label}-r{r_esc:g}-{wname}",
                        "system": spec["name"],
                        "label": label,
                        "r_esc": r_esc,
                        "default": R is None,
                        "window": list(w),
                        "mu_measured": Measured.of(*meas[wname]).to_dict(),
                        "mu_predicted": Measured.of(pv, pe).to_dict(),
                        "mu_own_K": Measured.of(v, e).to_dict(),
                        "moment_test": (Measured.of(v, e) - Measured.of(pv, pe)).to_dict(),
                        "kinetic_at_E0": Measured.of(
                            *(c[["mu", "mu_err"]].iloc[0] if len(c) else (None, None))
                        ).to_dict(),
                        "kinetic_at_E0_interpolated_without_E0": float(
                            mu_of_E(mdf[~np.isclose(mdf["ratio"], p.e0_ratio)], ec)(E0)
                        ),
                        "n_diss": p.resc_diss_n,
                        "n_probe": p.resc_probe_n,
                    }
                )
    return out
