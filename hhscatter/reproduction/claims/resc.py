"""r_esc sensitivity of claims 1, 3 and 5: κ0 at each radius and its shift, μ measured, μ predicted, the survivors'
own-⟨K⟩ μ and 2⟨K⟩/E at E0 itself, per escape radius, with the same N and rules for each (the default radius and
``resc_values`` in units of each system's saddle distance), and each system's r_esc rule by energy."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.survival.escape_rate import escape_rate
from hhscatter.analysis.survival.fits import lifetimes_to_arrays
from hhscatter.analysis.survival.paired import paired_bootstrap_ratio
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


IC_COLUMNS = ("x0", "y0", "px0", "py0")


def paired_lifetimes(lt_ref, lt_alt, what: str = "the two runs"):
    """paired_lifetimes(lt_ref, lt_alt) -> the two lifetimes tables in one order of ``traj_id`` (row i of both is
    orbit i), after checking they hold the same orbits: the same ``traj_id`` values and, where the tables have
    them, the same initial conditions (``x0, y0, px0, py0``, exactly). ValueError naming ``what`` otherwise.

    Examples
    --------
    >>> a = pd.DataFrame({"traj_id": [1, 0], "x0": [0.2, 0.1], "t_end": [5.0, 3.0]})
    >>> b = pd.DataFrame({"traj_id": [0, 1], "x0": [0.1, 0.2], "t_end": [4.0, 6.0]})
    >>> [x.t_end.tolist() for x in paired_lifetimes(a, b)]
    [[3.0, 5.0], [4.0, 6.0]]
    """
    a = lt_ref.sort_values("traj_id", kind="stable").reset_index(drop=True)
    b = lt_alt.sort_values("traj_id", kind="stable").reset_index(drop=True)
    if len(a) != len(b) or not np.array_equal(a["traj_id"].to_numpy(), b["traj_id"].to_numpy()):
        raise ValueError(f"{what} do not hold the same orbits (traj_id differs): no paired comparison")
    for col in IC_COLUMNS:
        if col in a.columns and col in b.columns and not np.array_equal(a[col].to_numpy(), b[col].to_numpy()):
            raise ValueError(f"{what} hold different initial conditions ({col} differs): no paired comparison")
    return a, b


def _kappa_at(lt, p):
    """κ0 (Measured) of one run by the claims' window rule and plateau check, and the reason where it is
    ill-defined ('' where defined)."""
    c, _, why = window_rate(lt, p, "window rule failed")
    if c is None:
        return None, why
    if not (c.defined and c.kappa > 0):
        return None, c.reason or "κ ≤ 0"
    return Measured.of(c.kappa, c.kappa_err), ""


def _window_kappa(p):
    """κ of the claims' window rule (:func:`rate_or_reason`: plateau windows, ``p.min_survivors``) as a function
    of arrays, for the paired bootstrap."""

    def kappa(t_end, observed):
        return escape_rate(t_end, observed, detect_tail=False, min_survivors=p.min_survivors).kappa

    return kappa


def resc_kappa_rows(runs, systems, *, n_boot: int | None = None, seed: int = 0) -> list:
    """κ0 at the default r_esc and at each other radius of :func:`resc_values`, per system, E/E_c of ``resc_ratios``
    and convention ('plateau': all orbits, the paper's; 'escaping': the orbits escaping at both radii), by the
    claims' window rule and plateau check at each radius; the shift κ0(r_esc)/κ0(default) − 1 with its paired
    error: the runs at both radii hold the same orbits (:func:`paired_lifetimes`), so the error is a bootstrap over
    the orbits drawing them alike at both radii and re-applying the window rule to each
    (:func:`~hhscatter.analysis.survival.paired.paired_bootstrap_ratio`, ``n_boot`` replicates, default
    ``p.resc_boot``; ``seed``); beside it ``shift_err_unpaired`` (the two errors in quadrature, which overstates
    it), the correlation of the two κ0 over the replicates and ``n_boot``; the verdict by the one rule against no
    shift on the paired error (|z| ≤ 2: 'no shift resolved'); "undetermined: …" where κ0 is ill-defined at either
    radius."""
    p = runs.params
    n_boot = p.resc_boot if n_boot is None else n_boot
    kappa_fn = _window_kappa(p)
    out = []
    for label, spec, m in systems:
        Rs = resc_values(p, m)
        for r in p.resc_ratios if len(Rs) > 1 else ():
            E = r * m.critical_energy
            lts = {R: runs.lifetimes(resc_key(label, R, f"r{r:.3f}")) for R in Rs}
            for R in Rs[1:]:
                ref, alt = paired_lifetimes(lts[None], lts[R], f"the r_esc runs of {label} at {r:g} E_c")
                for conv in ("plateau", "escaping"):
                    if conv == "escaping":
                        both = (ref["outcome"] != "censored").to_numpy() & (alt["outcome"] != "censored").to_numpy()
                        ref_c, alt_c = ref[both], alt[both]
                    else:
                        ref_c, alt_c = ref, alt
                    base, why0 = _kappa_at(ref_c, p)
                    k, why = _kappa_at(alt_c, p)
                    row = {
                        "id": f"{label}-{r:g}-r{R:g}-{conv}",
                        "system": spec["name"],
                        "label": label,
                        "e_ratio": float(r),
                        "convention": conv,
                        "r_esc_default": float(m.default_escape_radius(E)),
                        "r_esc": float(R),
                        "r_esc_over_saddle": float(R / m.saddle_radius),
                        "n": int(len(ref_c)),
                        "kappa_default": (base or Measured.of(None, None)).to_dict(),
                        "kappa": (k or Measured.of(None, None)).to_dict(),
                    }
                    if base is None or k is None:
                        where = "; ".join(
                            f"at r_esc = {x:.3g}: {w}" for x, w in ((row["r_esc_default"], why0), (R, why)) if w
                        )
                        row.update(
                            shift=Measured.of(None, None).to_dict(),
                            shift_err_unpaired=None,
                            correlation=None,
                            verdict=f"undetermined: κ0 ill-defined {where}",
                        )
                    else:
                        with counted("claims.resc.paired_bootstrap"):
                            pr = paired_bootstrap_ratio(
                                *lifetimes_to_arrays(ref_c),
                                *lifetimes_to_arrays(alt_c),
                                kappa_fn,
                                n_boot=n_boot,
                                seed=seed,
                            )
                        d = Measured.of(k.value / base.value - 1.0, pr.shift_err)
                        row.update(
                            shift=d.to_dict(),
                            shift_err_unpaired=float(k.ratio(base).err),
                            correlation=_finite(pr.correlation),
                            n_boot=pr.n_boot,
                            verdict=z_verdict(d.value, d.err, 0.0, *SHIFT_WORDS),
                        )
                    out.append(row)
    return out


def _finite(x):
    return float(x) if x is not None and math.isfinite(x) else None


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
