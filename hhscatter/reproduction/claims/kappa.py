"""Claim 1: κ0(E) per system under several window conventions, the κ(E) law and its exponents."""

from __future__ import annotations

import dataclasses
import math

from hhscatter.analysis.dissipative.transitions import power_law_exponent
from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.survival.escape_rate import escape_rate_from_lifetimes
from hhscatter.analysis.survival.fits import lifetimes_to_arrays
from hhscatter.analysis.survival.kappa_conventions import (
    dead_time_check,
    escape_rate_p_levels,
    plateau_rate,
)
from hhscatter.analysis.survival.kappa_energy import fit_kappa_energy
from hhscatter.reproduction.claims.keys import alt_key, grid_key
from hhscatter.reproduction.claims.records import across, z_verdict

CONVENTIONS = ("plateau", "plevel", "escaping")


HH_PAPER_BREAK = (0.27 - 1 / 6) / (1 / 6)  # the paper's E_b ≈ 0.27 for Hénon–Heiles, as (E_b − E_c)/E_c


def rate_or_reason(lifetimes, min_survivors: float):
    """κ of a lifetimes table by :func:`escape_rate_from_lifetimes` (data-driven plateau windows, no tail search):
    (EscapeRateResult, "") or, where the window rule fails (too few escapes), (None, the rule's message).

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> lt = pd.DataFrame({"t_end": np.arange(1.0, 11.0), "outcome": ["escaped"] * 10})
    >>> res, reason = rate_or_reason(lt, 50.0)
    >>> res is None and reason != ""
    True
    """
    try:
        with counted("claims.kappa.rate_or_reason"):
            return escape_rate_from_lifetimes(lifetimes, detect_tail=False, min_survivors=min_survivors), ""
    except (ValueError, RuntimeError) as exc:  # too few escapes for the window rule: said, not hidden
        return None, str(exc)


def first_escape(observed_t_end) -> float:
    """first_escape(t_end of the orbits that left) -> the first escape time (time units); NaN where none left.

    >>> first_escape([4.0, 1.5, 9.0]), math.isnan(first_escape([]))
    (1.5, True)
    """
    t = [float(x) for x in observed_t_end]
    return min(t) if t else math.nan


def window_rate(lifetimes, p, failure: str):
    """window_rate(lifetimes, p, failure) -> (ConventionRate | None, EscapeRateResult | None, reason).

    κ of :func:`rate_or_reason` with the check for a plateau of censored orbits (``p.max_plateau_bias``) and the
    check that the window neither holds the dead time before the first escape nor spans less than an e-fold of its
    κ (:func:`~hhscatter.analysis.survival.kappa_conventions.dead_time_check`: a prompt burst, or its hand-over to
    the regime, taken for the regime by a small ensemble); where the window rule fails, None and ``failure`` followed by the rule's message: the
    reason of this convention alone.
    """
    t_end, obs = lifetimes_to_arrays(lifetimes)
    res, why = rate_or_reason(lifetimes, p.min_survivors)
    if res is None:
        return None, None, f"{failure}: {why}"
    rate = plateau_rate(res, t_end, obs, max_bias=p.max_plateau_bias)
    if rate.defined and obs.any():
        ok, dead = dead_time_check(res.tau0, first_escape(t_end[obs]), rate.kappa, t_hi=res.t_stop)
        if not ok:
            rate = dataclasses.replace(rate, defined=False, reason=dead)
    return rate, res, ""


def kappa_rows(runs, label, m):
    """kappa_rows(runs, label, system) -> (rows, fits): one row per (E/E_c, convention) with κ (1/time), its error,
    τ0, window, censored fraction (key ``trapped_fraction``), plateau_bias (the censored fraction over P at the
    window's end, which the plateau
    check holds to ``p.max_plateau_bias``), t_first (the first escape of the ensemble, which the dead-time check
    compares with τ0), defined and the reason of that convention; fits {r: result of all orbits,
    ('escaping', r): result of the escaping orbits}. Conventions: 'plateau' (all orbits), 'plevel' (P-level
    windows), 'escaping' (orbits still inside at t_max dropped) and ``p.alt_region`` (the other ICs)."""
    p = runs.params
    rows, fits = [], {}
    for r in p.ratios:
        lt = runs.lifetimes(grid_key(label, r))
        t_end, obs = lifetimes_to_arrays(lt)
        rates, reasons, trapped, first = {}, {}, {}, {}
        rates["plateau"], fits[r], reasons["plateau"] = window_rate(lt, p, "window rule failed")
        rates["plevel"] = escape_rate_p_levels(
            t_end, obs, p_hi=p.p_levels[0], p_lo=p.p_levels[1], max_bias=p.max_plateau_bias
        )
        # the escaping orbits only (the censored ones dropped: regular, chaotic but confined, or sticky beyond t_max)
        esc = lt[lt["outcome"] != "censored"]
        rates["escaping"], fits["escaping", r], reasons["escaping"] = window_rate(
            esc, p, "window rule failed on the escaping orbits"
        )
        if p.alt_region is not None:
            lt_a = runs.lifetimes(alt_key(label, r, p.alt_region))
            rates[p.alt_region], _, reasons[p.alt_region] = window_rate(
                lt_a, p, f"window rule failed with {p.alt_region} ICs"
            )
            t_a, obs_a = lifetimes_to_arrays(lt_a)
            trapped[p.alt_region] = float((~obs_a).mean())
            first[p.alt_region] = first_escape(t_a[obs_a])
        fits = {k: v for k, v in fits.items() if v is not None}
        for conv, c in rates.items():
            base = {
                "system": label,
                "ratio": r,
                "eps": r - 1.0,
                "energy": r * m.critical_energy,
                "convention": conv,
                "n": int(t_end.size),
                "trapped_fraction": trapped.get(conv, float((~obs).mean())),
                "t_first": first.get(conv, first_escape(t_end[obs])),
            }
            if c is None:
                rows.append(
                    {
                        **base,
                        "kappa": math.nan,
                        "kappa_err": math.nan,
                        "tau0": math.nan,
                        "t_lo": math.nan,
                        "t_hi": math.nan,
                        "plateau_bias": math.nan,
                        "defined": False,
                        "reason": reasons[conv],
                    }
                )
                continue
            rows.append(
                {
                    **base,
                    "kappa": c.kappa,
                    "kappa_err": c.kappa_err,
                    "tau0": c.t_lo,
                    "t_lo": c.t_lo,
                    "t_hi": c.t_hi,
                    "plateau_bias": c.bias_at_end if math.isfinite(c.bias_at_end) else math.nan,
                    "defined": bool(c.defined and c.kappa > 0),
                    "reason": c.reason,
                }
            )
    return rows, fits


def exponents(eps, kappa, err, eps_b):
    """κ ∝ ε^β below and above the break: ((β_low, σ), (β_high, σ)), None where < 2 points."""
    out = []
    for sel in (eps < eps_b, eps >= eps_b):
        p, e = power_law_exponent(eps[sel], kappa[sel], err[sel])
        out.append(None if p is None else (-p, e))
    return out


def fit_law(runs, table):
    """Per convention: the continuous law in ε (fit_kappa_energy with E → r, E_c → 1) and the exponents β."""
    per = {}
    for conv in [*CONVENTIONS, *([runs.params.alt_region] if runs.params.alt_region else [])]:
        d = table[(table["convention"] == conv) & table["defined"]].sort_values("ratio")
        if len(d) < 5:  # a, b and the break need points on both sides
            per[conv] = None
            continue
        with counted("claims.kappa.fit_kappa_energy"):
            f = fit_kappa_energy(
                d["ratio"],
                d["kappa"],
                d["kappa_err"],
                1.0,
                continuous=True,
                n_boot=runs.params.n_boot,
                rng=runs.params.fit_seed,
            )
        eps_b = f.E_b - 1.0
        lo, hi = exponents(d["eps"].to_numpy(), d["kappa"].to_numpy(), d["kappa_err"].to_numpy(), eps_b)
        err = lambda v, e, b: float(max(e, b)) if b is not None and math.isfinite(b) else float(e)
        be = f.boot_err if f.boot_err else (math.nan,) * 4
        per[conv] = {
            "a": Measured.of(f.a, err(f.a, f.a_err, be[0])).to_dict(),
            "b": Measured.of(f.b, err(f.b, f.b_err, be[1])).to_dict(),
            "c": Measured.of(f.c, err(f.c, f.c_err, be[2])).to_dict(),
            "eps_b": Measured.of(eps_b, err(eps_b, f.E_b_err, be[3])).to_dict(),
            "chi2": f.chi2,
            "dof": f.dof,
            "beta_low": None if lo is None else Measured.of(*lo).to_dict(),
            "beta_high": None if hi is None else Measured.of(*hi).to_dict(),
            "n_points": len(d),
        }
    return per


def claim1(claims, label, per, table):
    allk = table[table["convention"] == "plateau"]
    bad = allk[~allk["defined"]]
    claims.add(
        "1",
        "κ0 well defined (all orbits, plateau windows) at every E/E_c",
        label,
        float(allk["defined"].mean()),
        None,
        "yes"
        if bad.empty
        else "no: ill-defined at E/E_c = "
        + ", ".join(f"{r:g}" for r in bad["ratio"])
        + f" (orbits still inside at t_max up to {bad['trapped_fraction'].max():.0%})",
        "value: fraction of the grid energies where κ0 is defined; the paper's convention (all orbits)",
    )
    alt = table[~table["convention"].isin(CONVENTIONS)]
    if len(alt):
        name = alt["convention"].iloc[0]
        bad_a = alt[~alt["defined"]]
        claims.add(
            "1",
            f"κ0 well defined with {name} ICs (all orbits, plateau windows)",
            label,
            float(alt["defined"].mean()),
            None,
            "yes"
            if bad_a.empty
            else "no: ill-defined at E/E_c = "
            + ", ".join(f"{r:g}" for r in bad_a["ratio"])
            + (
                f" (orbits still inside at t_max up to {bad_a['trapped_fraction'].max():.0%})"
                if bad_a["trapped_fraction"].notna().any()
                else ""
            ),
            "the same grid, N and t_max with ICs uniform in that region, random momentum directions",
        )
    fitted = [k for k, v in per.items() if v]
    prim = per.get("plateau") or per.get("escaping") or per.get("plevel")
    if prim is None:
        claims.add(
            "1",
            "κ0(E) law fitted",
            label,
            None,
            None,
            "undetermined",
            "fewer than 5 defined κ0 points in every window convention",
        )
        return
    lo, hi = prim.get("beta_low"), prim.get("beta_high")
    b_lo = across({k: v and {"x": v["beta_low"]} for k, v in per.items()}, "x")
    b_hi = across({k: v and {"x": v["beta_high"]} for k, v in per.items()}, "x")
    eb = across(per, "eps_b")
    if lo:
        claims.add(
            "1",
            "exponent β below the break (κ0 ∝ ε^β)",
            label,
            b_lo[0],
            b_lo[1],
            z_verdict(b_lo[0], b_lo[1], 2.0, "quadratic", "not quadratic"),
            "ε = (E − E_c)/E_c; mean over the conventions fitted (" + ", ".join(fitted) + "), err √(stat² + spread²)",
            2.0,
        )
    if hi:
        claims.add(
            "1",
            "exponent β above the break",
            label,
            b_hi[0],
            b_hi[1],
            z_verdict(b_hi[0], b_hi[1], 1.0, "linear", "not linear"),
            "as above",
            1.0,
        )
    claims.add(
        "1",
        "break ε_b = (E_b − E_c)/E_c",
        label,
        eb[0],
        eb[1],
        z_verdict(eb[0], eb[1], HH_PAPER_BREAK, "same as the paper's HH break", "differs from the paper's HH break"),
        "continuous law a ε² + b ε, c ε; the paper's E_b ≈ 0.27 for HH is ε_b = 0.62",
        HH_PAPER_BREAK,
    )
    bl = across(per, "b")
    if bl[0] is not None:
        claims.add(
            "1",
            "linear term b of the law at threshold (κ0 ≈ b ε)",
            label,
            bl[0],
            bl[1],
            z_verdict(bl[0], bl[1], 0.0, "quadratic onset (b = 0)", "linear onset (b ≠ 0)"),
            "reduced units (κ in well frequencies, ε = E/E_c − 1); the paper's HH b = 0.03 is 0.005 here",
            0.0,
        )
    chi = prim["chi2"] / max(prim["dof"], 1)
    claims.add(
        "1",
        f"law family fits (χ²/dof, {'plateau' if per.get('plateau') else 'escaping'} convention)",
        label,
        chi,
        None,
        "fits" if chi <= 3 else "poor fit (χ²/dof > 3)",
        f"{prim['n_points']} points, dof {prim['dof']}",
    )
