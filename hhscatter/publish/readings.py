"""Readings in prose, generated from the committed study JSON like the numbers: the words around the numbers.

A comparative or qualitative statement on a results page (agrees, approaches, monotone, within a factor, holds,
never, always, the best or worst case) is not typed: the page names a reading, ``[[reading:name]]``, and the docs
build replaces it with the sentence a function writes after testing its condition with the uncertainties (a
trend by a weighted fit and its σ, "within a factor" from the intervals, "holds" from the verdicts, "closer" from
the distance's interval). Where the data do not support a reading, the sentence says what is measured, no more.

The building blocks are pure functions of numbers (:func:`trend`, :func:`trend_words`, :func:`factor_words`,
:func:`closer_words`, :func:`pass_fail_words`); :data:`READINGS` maps each name a page may use to the function that
writes it from the studies' numbers. :func:`hhscatter.publish.numbers.typed_readings` lists the reading words a page
types by hand; the docs tests fail on any, as they fail on a typed number.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable

import numpy as np

from hhscatter.analysis.stats.least_squares import weighted_least_squares
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.stats.verdicts import half_unit, signed, verdict, verdict_class
from hhscatter.publish.formatting import format_bound, format_value_err, typographic_minus
from hhscatter.reproduction.verdicts import claim_verdict

__all__ = [
    "READINGS",
    "closer_words",
    "factor_words",
    "interval_side",
    "pass_fail_words",
    "reading",
    "trend",
    "trend_words",
]

#: the p-value below which a goodness-of-fit test rejects
P_LEVEL = 0.05
#: a difference or slope is "resolved" when it lies this many σ from zero (the verdict rule's 2σ)
Z_RESOLVED = 2.0


def _ve(value, err) -> str:
    return typographic_minus(format_value_err(float(value), float(err)))


def _hazard_text(b: dict) -> str:
    """A hazard bin as pages write it: its value ± error, or, with no escape in the bin, its one-sided bound."""
    if b.get("hazard_upper") is not None:
        return typographic_minus(format_bound(b["hazard_upper"], cl=b.get("hazard_cl", 0.95)))
    return _ve(b["hazard"], b["err"])


def _int(n) -> str:
    """A count with thin-space thousands (as the rendered numbers write them)."""
    return f"{int(n):,}".replace(",", "\u2009")


def trend(x, y, err) -> dict:
    """trend(x, y, 1σ of y) -> {slope, err, z, chi2, dof}: the weighted straight-line fit y = a + s·x (weights 1/σ²).

    Examples
    --------
    >>> t = trend([3, 4, 5, 6], [0.874, 0.932, 0.909, 0.972], [0.030, 0.030, 0.030, 0.031])
    >>> round(t["slope"], 4), round(t["err"], 4), round(t["z"], 1)
    (0.0269, 0.0136, 2.0)
    """
    x, y, e = (np.asarray(v, dtype=float) for v in (x, y, err))
    if x.size < 3:
        raise ValueError(f"a trend needs at least 3 points, got {x.size}")
    fit = weighted_least_squares(np.column_stack([np.ones_like(x), x]), y, 1.0 / e**2)
    s, se = float(fit.coef[1]), float(math.sqrt(fit.cov[1, 1]))
    return {"slope": s, "err": se, "z": s / se, "chi2": fit.chi2, "dof": fit.dof}


def trend_words(t: dict, y_name: str, x_name: str, unit: str = "") -> str:
    """trend_words(trend, what, against what) -> "rises with X (slope s ± σ per unit, z = …)" when |z| > 2, "falls
    …" likewise, else "shows no trend resolved at 2σ (slope …)".

    Examples
    --------
    >>> trend_words({"slope": 0.0286, "err": 0.0135, "z": 2.12}, "the ratio", "ΔE/T")
    'the ratio rises with ΔE/T (weighted slope 0.029 ± 0.013, z = +2.1)'
    >>> trend_words({"slope": 0.01, "err": 0.02, "z": 0.5}, "the ratio", "ΔE/T")
    'the ratio shows no trend in ΔE/T resolved at 2σ (weighted slope 0.010 ± 0.020, z = +0.5)'
    """
    per = f" per {unit}" if unit else ""
    fit = f"weighted slope {_ve(t['slope'], t['err'])}{per}, z = {signed(t['z'])}"
    if abs(t["z"]) > Z_RESOLVED:
        return f"{y_name} {'rises' if t['slope'] > 0 else 'falls'} with {x_name} ({fit})"
    return f"{y_name} shows no trend in {x_name} resolved at 2σ ({fit})"


def factor_words(factor_min: float, factor_max: float, n_overlap: int, n: int, what: str = "the prediction") -> str:
    """factor_words(smallest factor, largest factor, intervals overlapping, cases) -> how far apart two sets of
    numbers are, from their ratios and their intervals: "within a factor F" only when every ratio is within it.

    Examples
    --------
    >>> factor_words(1.08, 6.63, 1, 5)
    'the prediction is off by a factor 1.1 to 6.6 over the 5 cases; their 1σ intervals overlap in 1 of 5'
    >>> factor_words(1.02, 1.4, 5, 5)
    'the prediction is within a factor 1.4 in all 5 cases, and their 1σ intervals overlap in every one'
    """
    if n_overlap == n and factor_max <= 2:
        return (
            f"{what} is within a factor {factor_max:.2g} in all {n} cases, and their 1σ intervals overlap in every one"
        )
    return (
        f"{what} is off by a factor {factor_min:.2g} to {factor_max:.2g} over the {n} cases; their 1σ intervals "
        f"overlap in {n_overlap} of {n}"
    )


def closer_words(d_a, e_a, d_b, e_b, a: str, b: str, distance: str) -> str:
    """closer_words(d to a, 1σ, d to b, 1σ, a, b, distance) -> which reference is closer by this distance, by the
    verdict rule (|Δd| > 2σ, both errors): "closer to a by SW1 (… vs …, z = …)" or "as close to a as to b".

    Examples
    --------
    >>> closer_words(0.0288, 0.0015, 0.0206, 0.0010, "μ_c^0.30", "μ_c^0.35", "SW1")
    'closer to μ_c^0.35 by SW1 (0.0288 ± 0.0015 to μ_c^0.30 vs 0.0206 ± 0.0010, z = +4.5)'
    """
    v = verdict(d_a, e_a, d_b, e_b)
    pair = f"{_ve(d_a, e_a)} to {a} vs {_ve(d_b, e_b)}"
    if v.z is None or v.word == "agrees":
        return f"as close to {a} as to {b} by {distance} ({pair}{'' if v.z is None else f', z = {signed(v.z)}'})"
    return f"closer to {a if v.z < 0 else b} by {distance} ({pair}, z = {signed(v.z)})"


def pass_fail_words(cells: list[tuple[str, bool | None]], holds: str, fails: str, untested: str = "not tested") -> str:
    """pass_fail_words([(cell, passed: True / False / None)], holds, fails, untested='not tested') -> "fails at …;
    holds at …; not tested at …": never an "always" or a "never" unless every cell was tested and says so.

    Examples
    --------
    >>> pass_fail_words([("1.05", False), ("1.9", True), ("2.6", None)], "one exponential", "not one exponential")
    'not one exponential at 1.05; one exponential at 1.9; not tested at 2.6'
    >>> pass_fail_words([("a", False), ("b", False)], "holds", "fails")
    'fails at every tested cell (a, b)'
    """
    groups: dict = {False: [], True: [], None: []}
    for cell, ok in cells:
        groups[ok].append(cell)
    if groups[False] and not groups[True] and not groups[None]:
        return f"{fails} at every tested cell ({', '.join(groups[False])})"
    if groups[True] and not groups[False] and not groups[None]:
        return f"{holds} at every tested cell ({', '.join(groups[True])})"
    out = []
    if groups[False]:
        out.append(f"{fails} at {', '.join(groups[False])}")
    if groups[True]:
        out.append(f"{holds} at {', '.join(groups[True])}")
    if groups[None]:
        out.append(f"{untested} at {', '.join(groups[None])}")
    return "; ".join(out)


# -- the named readings -----------------------------------------------------------------------------------------
Loader = Callable[[str, str | None], dict]


def _basins_cutoff(get: Loader) -> str:
    s = get("basins", None)["cutoff_summary"]
    words = factor_words(s["factor_min"], s["factor_max"], s["n_overlap"], s["n_resolved"])
    return f"{words} (the measured cut-off lies below the prediction in {s['n_below']} of {s['n_resolved']})"


def _basins_energy_scan(get: Loader) -> str:
    """The energy scan at γ = 0: the exits' Wada test and S_bb against ln 2 energy by energy (S_bb above ln 2 by more
    than 2σ), α's trend with E (the study's weighted slope) and S_b's (a weighted straight line here)."""
    doc = get("basins", None)
    scan = sorted(doc["energy_scan"], key=lambda r: r["energy"])
    span = f"E = {scan[0]['energy']:g} to {scan[-1]['energy']:g}"

    def every(cells, holds, fails):
        if all(ok for _, ok in cells):
            return f"{holds} at all {len(cells)} scan energies ({span})"
        return pass_fail_words(cells, holds, fails)

    wada = every([(f"{r['energy']:g}", bool(r["wada_exits"])) for r in scan], "Wada", "not Wada")
    ln2 = math.log(2)
    fractal = every(
        [(f"{r['energy']:g}", r["S_bb"] - ln2 > Z_RESOLVED * r["S_bb_err"]) for r in scan],
        "S_bb above ln 2 by more than 2σ",
        "S_bb not above ln 2 by 2σ",
    )
    a = doc["energy_trend"]["alpha_slope"]
    alpha = trend_words({"slope": a["value"], "err": a["err"], "z": a["value"] / a["err"]}, "α", "E", "unit energy")
    s_b = trend_words(
        trend([r["energy"] for r in scan], [r["S_b"] for r in scan], [r["S_b_err"] for r in scan]),
        "S_b",
        "E",
        "unit energy",
    )
    return f"the exit basins are {wada}; {fractal}; {alpha}; {s_b}"


def _basins_smooth_order(get: Loader) -> str:
    """Where S_b(E) turns smooth (E*, a scan energy) against the scan energy from which no orbit is left censored
    at t_max (the same grid: above, at or below it) and against fig2's break energy E_b (below or above it where
    E* lies beyond E_b's 2σ interval, else at it within 2σ)."""
    d = get("basins", None)
    t, eb = d["energy_trend"], d["E_b"]
    e_s, e_n = t["E_smooth_S_b"], t["E_no_trapped"]
    if e_s is None or e_n is None or eb is None:
        return "S_b(E) has no smooth part or every scan energy keeps censored orbits: no order to state"
    ebv, ebe = (eb["value"], eb["err"]) if isinstance(eb, dict) else (float(eb), 0.0)
    censored = "the energy from which no orbit is left censored at t_max"
    first = (
        f"above {censored} ({e_n:g})"
        if e_s > e_n
        else (f"at {censored} ({e_n:g})" if e_s == e_n else f"below {censored} ({e_n:g})")
    )
    if e_s < ebv - Z_RESOLVED * ebe:
        second = f"below fig2's break energy E_b = {_ve(ebv, ebe)} by more than 2σ"
    elif e_s > ebv + Z_RESOLVED * ebe:
        second = f"above fig2's break energy E_b = {_ve(ebv, ebe)} by more than 2σ"
    else:
        second = f"at fig2's break energy E_b = {_ve(ebv, ebe)} within 2σ"
    return f"{first} and {second}"


def _basins_kantz_grassberger(get: Loader) -> str:
    """κ/α (Kantz–Grassberger: α = κ/λ on a hyperbolic saddle) against the decision rate λ, energy by energy of the
    scan: within 2σ (their errors combined) or more than 2σ apart; energies without κ/α are left out."""
    scan = sorted(get("basins", None)["energy_scan"], key=lambda r: r["energy"])
    cells = []
    for r in scan:
        kg, lam = r.get("lam_kg"), r.get("lam")
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in (kg, lam)):
            continue
        sigma = math.hypot(r.get("lam_kg_err") or 0.0, r.get("lam_err") or 0.0)
        cells.append((f"E = {r['energy']:g}", abs(kg - lam) <= Z_RESOLVED * sigma if sigma > 0 else None))
    return pass_fail_words(cells, "κ/α lies within 2σ of λ", "κ/α and λ are more than 2σ apart", "no error")


def _fig5_premise(get: Loader) -> str:
    d = get("fig5", None)
    g = d["gamma_main"]
    rows = {(r["set"], r["ref"]): r for r in d["distances"] if r["gamma"] == g}
    paired = {r["set"]: r for r in d["refs_paired"]["rows"] if r["construction"] == "ours"}
    parts, closer = [], {}
    for s in ("a", "b"):
        p = paired[f"5{s}"]["delta"]
        lo, hi = p["interval"]
        by_h = "μ_c^0.30" if lo > 0 else "μ_c^0.35" if hi < 0 else None
        hel = (
            f"closer to {by_h} by the debiased Hellinger distance (Δ = d(μ_c^0.35) − d(μ_c^0.30) = "
            f"{signed(p['value'], '+.3f')}, 95 % [{signed(lo, '+.3f')}, {signed(hi, '+.3f')}])"
            if by_h
            else "as close to either by the debiased Hellinger distance (its 95 % interval of Δ holds 0)"
        )
        r1, r2 = rows[s, "E1"], rows[s, "E2"]
        sw = closer_words(r1["sw1"], r1["sw1_err"], r2["sw1"], r2["sw1_err"], "μ_c^0.30", "μ_c^0.35", "SW1")
        by_s = "μ_c^0.30" if "closer to μ_c^0.30" in sw else "μ_c^0.35" if "closer to μ_c^0.35" in sw else None
        closer[s] = {by_h, by_s}
        parts.append(f"5{s} lies {hel} and {sw}")
    same = [s for s in ("a", "b") if closer[s] == {"μ_c^0.30"}]
    if len(same) == 2:
        tail = "the paper's premise for Fig. 5 (the points are distributed like μ_c^0.30) holds for both sets by both distances"
    elif same:
        other = "b" if same == ["a"] else "a"
        tail = (
            f"the paper's premise for Fig. 5 (the points are distributed like μ_c^0.30) holds for 5{same[0]} by both "
            f"distances; for 5{other} it depends on the distance"
        )
    else:
        tail = "the paper's premise for Fig. 5 (the points are distributed like μ_c^0.30) depends on the distance"
    return f"At γ = {g:g}, " + "; ".join(parts) + f": {tail}"


def _generality_b_onset(get: Loader) -> str:
    d = get("generality", None)
    rec = next(c for c in d["claims"] if c["id"] == "henon_heiles-1-5")
    v = claim_verdict(rec, d.get("scale"))
    cls = verdict_class(v)
    z = re.search(r"\(z = [^)]*\)", v)
    if cls == "ok":
        return f"consistent with a quadratic onset, b = 0 {z.group(0) if z else ''}".strip()
    if cls == "bad":
        return f"a linear onset, b resolved from 0 {z.group(0) if z else ''}".strip()
    return f"not judged against b = 0 ({v})"


def _generality_law_slope(get: Loader) -> str:
    """The law a ε² + b ε of the first system's κ0 over each convention's fitted range (its lowest defined ε to its
    break ε_b): the linear term over the quadratic one, b/(a ε), and the local slope d ln κ0/d ln ε =
    (2aε + b)/(aε + b) at both ends, and whether the claims' β below the break lies in the range of those slopes
    (its 2σ interval overlapping it)."""
    d = get("generality", None)
    system = next(iter(d["systems"]))
    beta = next((c for c in d["claims"] if c["id"] == f"{system}-1-2"), None)
    parts, slopes = [], []
    for conv, law in d["systems"][system]["kappa_law"].items():
        if not law or not law.get("a") or not law.get("b") or not law.get("eps_b"):
            continue
        a, b, eps_b = law["a"]["value"], law["b"]["value"], law["eps_b"]["value"]
        eps = [r["eps"] for r in d["kappa"] if r["system"] == system and r["convention"] == conv and r["defined"]]
        if not eps or a <= 0 or min(eps) >= eps_b:
            continue
        ends = (min(eps), eps_b)
        s = [(2 * a * e + b) / (a * e + b) for e in ends]
        slopes += s
        parts.append(
            f"{conv} (ε {ends[0]:.2f} to {ends[1]:.2f}): b/(a ε) {b / (a * ends[0]):.2g} → {b / (a * ends[1]):.2g},"
            f" slope {s[0]:.2f} → {s[1]:.2f}"
        )
    if not parts:
        return "no convention has a law a ε² + b ε with a > 0 below its break"
    lo, hi = min(slopes), max(slopes)
    out = (
        "per convention, the linear term over the quadratic one and the law's local slope d ln κ0/d ln ε = "
        f"(2aε + b)/(aε + b) from the lowest fitted ε to the break: {'; '.join(parts)}"
    )
    if not beta or beta.get("value") is None or not beta.get("err"):
        return out
    v, e = beta["value"], beta["err"]
    if v + Z_RESOLVED * e < lo:
        side = f"lies below these slopes ({lo:.2f} to {hi:.2f}) by more than 2σ"
    elif v - Z_RESOLVED * e > hi:
        side = f"lies above these slopes ({lo:.2f} to {hi:.2f}) by more than 2σ"
    elif lo <= v <= hi:
        side = f"lies inside the range of these slopes ({lo:.2f} to {hi:.2f}): the two fits do not contradict"
    else:
        side = f"lies within 2σ of the range of these slopes ({lo:.2f} to {hi:.2f}): the two fits do not contradict"
    return f"{out}. The power law's β = {_ve(v, e)} {side}"


def _generality_escape_excess(get: Loader) -> str:
    """κγ(t)/κ0(E(t)) at the smallest γ per system (claim 7), with the verdict of the one rule: more or fewer escapes
    than κ0 at the mean energy predicts only where the ratio differs from 1; the mechanism (a convex κ0 averaged
    over the energy spread exceeds κ0 at the mean energy) stated only for an excess; the undetermined named."""
    d = get("generality", None)
    said, undetermined = [], []
    for system in d["systems"]:
        rec = next((c for c in d["claims"] if c["id"] == f"{system}-7-0"), None)
        name = _SYSTEM_NAMES.get(system, system)
        if rec is None:
            continue
        if rec.get("value") is None or not rec.get("err"):
            undetermined.append(name)
            continue
        v = claim_verdict(rec, d.get("scale"))
        text = f"{name} escapes {_ve(rec['value'], rec['err'])} times as often as κ0 at E0 e^(−μγt) predicts ({v})"
        if verdict_class(v) == "bad" and rec["value"] > 1:
            text += ": more often, as the energy spread makes the mean of a convex κ0(E_i) exceed κ0 at the mean energy"
        elif verdict_class(v) == "bad":
            text += ": less often than κ0 at the mean energy predicts"
        said.append(text)
    if undetermined:
        said.append(
            f"undetermined for {' and '.join(undetermined)} (τ0 comes after E(t) has reached the lowest energy with "
            "a defined κ0; the claims' table gives the times)"
        )
    return "; ".join(said)


def _generality_mu_gap(get: Loader) -> str:
    """The share of the gap between the paper's μ and the measured μ on fig3's window that the prediction from the
    conservative ⟨K⟩ covers, (μ_pred − μ_paper)/(μ_meas − μ_paper), its error propagated from the three (the paper's
    μ carries half a unit of its last printed digit), worded by its 2σ interval against 1/2 and 1."""
    d = get("generality", None)
    system = next(iter(d["systems"]))
    win = d["systems"][system]["mu_by_window"]["paper"]
    ref = next(c for c in d["claims"] if c["id"] == f"{system}-3-0")["reference"]
    p, dp = win["predicted_c_measure"]["value"], win["predicted_c_measure"]["err"]
    m, dm = win["measured"]["value"], win["measured"]["err"]
    dr = half_unit(ref)
    gap = m - ref
    f = (p - ref) / gap
    err = math.hypot(dp / gap, f * dm / gap, (p - m) / gap**2 * dr)
    lo_w, hi_w = win["window"]
    head = (
        f"on [{lo_w:g}, {hi_w:g}] the prediction from the conservative ⟨K⟩ covers {_ve(f, err)} of the gap between "
        f"the paper's {ref:g} (± {dr:g}, half its last digit) and the measured μ"
    )
    if abs(f - 1) <= Z_RESOLVED * err:
        return f"{head}: all of it within 2σ"
    if f - Z_RESOLVED * err > 1:
        return f"{head}: more than the gap, by more than 2σ"
    if f - Z_RESOLVED * err > 0.5:
        return f"{head}: more than half of it, by more than 2σ"
    if f + Z_RESOLVED * err < 0:
        return f"{head}: none of it (the prediction lies on the other side of the paper's value by more than 2σ)"
    if f + Z_RESOLVED * err < 0.5:
        return f"{head}: less than half of it, by more than 2σ"
    return f"{head}: a share not resolved from one half at 2σ"


def _b_relation(get: Loader) -> str:
    f2, g = get("fig2", None), get("generality", None)
    e_c = float(f2["E_c"])
    b = f2["kappa_fit"]["b"]
    rec = next(c for c in g["claims"] if c["id"] == "henon_heiles-1-5")
    brk = next(c for c in g["claims"] if c["id"] == "henon_heiles-1-4")  # generality's break ε_b
    e_b = f2["kappa_fit"]["E_b"]
    b_red, e_red = b["value"] * e_c, b["err"] * e_c
    v = verdict(rec["value"], rec["err"], b_red, e_red)
    f2_n = f2["config"]["study"]["grid_n"]
    f2_e = f2["config"]["study"]["grid_energies"]
    g_st = g["config"]["study"]
    ratio = rec["err"] / e_red
    z_f2, z_g = b["value"] / b["err"], rec["value"] / rec["err"]
    agree = "agree" if v.word == "agrees" else "differ"

    def resolves(who: str, z: float) -> str:
        if abs(z) > Z_RESOLVED:
            return f"{who} resolves b from 0 ({abs(z):.0f}σ)"
        return f"{who} does not resolve b from 0 ({abs(z):.1f}σ)"

    return (
        (
            f"fig2's linear term b = {_ve(b['value'], b['err'])} is fitted to κ (1/time) against E − E_c below "
            f"its break E_b = {_ve(e_b['value'], e_b['err'])} (ε_b = {(e_b['value'] - e_c) / e_c:.2f}), of "
            f"{len(f2_e)} energies from {min(f2_e):g} to {max(f2_e):g} (r_esc {f2['config']['scene']['r_esc']:g}, "
            f"{_int(f2_n)} orbits each, t_max up to {f2['config']['scene']['t_max']:g}); in generality's reduced units "
            f"(κ in well frequencies, which for Hénon–Heiles (ω = 1) is 1/time, against ε = E/E_c − 1) it is "
            f"b·E_c = {_ve(b_red, e_red)}. Generality's b = {_ve(rec['value'], rec['err'])}, fitted below its break "
            f"ε_b = {_ve(brk['value'], brk['err'])}, is the mean over its "
            f"window and IC conventions on {len(g_st['ratios'])} energies from {min(g_st['ratios']):g} to "
            f"{max(g_st['ratios']):g} E_c (r_esc the system's default, {_int(g_st['grid_n'])} orbits each, t_max "
            f"{g['config']['scene']['t_max']:g}), its error widened by their spread. The two {agree} "
            f"(z = {signed(v.z)}); generality's error is {ratio:.2g} times fig2's: {resolves('fig2', z_f2)}, "
            f"{resolves('generality', z_g)}"
        )
        .replace(",", "\u2009")
        .replace("\u2009 ", ", ")
    )


def _generality_one_exponential(get: Loader) -> str:
    d = get("generality", None)
    pooled = any("exponential_verdict" in f for f in d["long_time"])  # cells pooled to expected counts ≥ 5
    out = []
    for label in d.get("systems") or {}:
        cells = [
            (f"{f['e_ratio']:g}", None if f.get("p_nonregular") is None else f["p_nonregular"] >= P_LEVEL)
            for f in d["long_time"]
            if f["label"] == label and "disk" in f["ics"]
        ]
        untested = "too few orbits for the test" if pooled else "not tested"
        out.append(f"{label}: " + pass_fail_words(cells, f"p ≥ {P_LEVEL:g}", f"p < {P_LEVEL:g}", untested))
    caveat = (
        "Its cells are pooled until each expects at least 5 orbits (the orbits still inside at t_max join the last "
        "escape cell where they expect fewer), so no handful of orbits in a nearly empty cell decides it; where no "
        "degree of freedom is left it gives no verdict"
        if pooled
        else "What it measures is the fit of one exponential, not its cause: its last cell, the orbits still inside "
        "at t_max, can have an expected count far below 5, where a handful of orbits drives χ²"
    )
    return (
        "The χ² test of one exponential from t0 on the non-regular orbits gives, by E/E_c, "
        + "; ".join(out)
        + ". "
        + caveat
    )


def constancy_words(values, errs, what: str) -> str:
    """constancy_words(values, 1σ, what) -> whether numbers are one constant within their errors: the weighted mean,
    χ² about it and its p-value; "constant within its errors" only when p ≥ 0.05.

    Examples
    --------
    >>> constancy_words([0.00309, 0.00333, 0.00319], [6.9e-5, 6.5e-5, 7.1e-5], "the hazard")
    'the hazard is not one constant within its errors (weighted mean 0.00321 ± 0.00004, χ² = 6.5 for 2 dof, p = 0.039)'
    """
    from scipy.stats import chi2 as chi2_dist  # deferred: scipy is loaded on first use

    v, e = np.asarray(values, dtype=float), np.asarray(errs, dtype=float)
    w = 1.0 / e**2
    mean, mean_err = float(np.sum(w * v) / np.sum(w)), float(1.0 / math.sqrt(np.sum(w)))
    chi2, dof = float(np.sum(w * (v - mean) ** 2)), v.size - 1
    pv = float(chi2_dist.sf(chi2, dof)) if dof > 0 else float("nan")
    head = f"{what} is constant within its errors" if pv >= P_LEVEL else f"{what} is not one constant within its errors"
    return f"{head} (weighted mean {_ve(mean, mean_err)}, χ² = {chi2:.1f} for {dof} dof, p = {pv:.2g})"


def _generality_hh_1_05(get: Loader) -> str:
    d = get("generality", None)
    k = next(
        r for r in d["kappa"] if r["system"] == "henon_heiles" and r["ratio"] == 1.05 and r["convention"] == "plateau"
    )
    vm = next(v for v in d["validity_map"] if v["id"] == "henon_heiles-1.05-disk")
    lt = next(f for f in d["long_time"] if f["id"] == "henon_heiles-1.05-disk")
    t_max = d["config"]["scene"]["t_max"]
    bins = lt["hazard_nonregular"]
    before = [b for b in bins if b["t_hi"] <= t_max and b["err"] is not None]
    empty = [b for b in bins if b["t_hi"] <= t_max and b.get("hazard_upper") is not None]
    after = [b for b in bins if b["t_lo"] >= t_max and (b["err"] is not None or b.get("hazard_upper") is not None)]
    state = "defined" if k["defined"] else "ill-defined"
    out = (
        f"κ0 is {state} under the plateau rule at t_max = {t_max:g}: with κ ≈ {k['kappa']:.2g} the run covers "
        f"κ·t_max = {k['kappa'] * t_max:.1f} e-folds, and {100 * k['trapped_fraction']:.1f} % of its orbits are still "
        f"inside at t_max (the rule: {k['reason'] or 'met'}). Its regular fraction is "
        f"{100 * vm['regular_fraction']:.2g} %: the orbits left inside are chaotic by the indicator. In the long run "
        f"({_int(lt['n'])} orbits to t = {max(b['t_hi'] for b in bins):g}) "
        + constancy_words(
            [b["hazard"] for b in before],
            [b["err"] for b in before],
            f"the non-regular orbits' hazard from t = {before[0]['t_lo']:g} to {t_max:g}",
        )
    )
    if empty:
        out += " (no escape in " + ", ".join(f"[{b['t_lo']:g}, {b['t_hi']:g}]: {_hazard_text(b)}" for b in empty) + ")"
    if after:
        mean = np.average([b["hazard"] for b in before], weights=[1 / b["err"] ** 2 for b in before])
        zs = ", ".join(
            f"[{b['t_lo']:g}, {b['t_hi']:g}]: {_hazard_text(b)}"
            + (f" (z = {signed((b['hazard'] - mean) / b['err'])})" if b["err"] is not None else "")
            for b in after
        )
        out += f"; after t_max it is {zs} against that mean"
    return out


def _noise_kramers(get: Loader) -> str:
    d = get("noise", None)
    rows = sorted(d["kramers"], key=lambda r: r["barrier_over_T"])
    x = [r["barrier_over_T"] for r in rows]
    y = [r["ratio"] for r in rows]
    e = [r["ratio_err"] for r in rows]
    below = [r for r in rows if verdict(r["ratio"], r["ratio_err"], 1.0).word == "differs" and r["ratio"] < 1]
    within = [r for r in rows if verdict(r["ratio"], r["ratio_err"], 1.0).word == "agrees"]
    t = trend(x, y, e)
    where = ", ".join(f"{r['barrier_over_T']:g}" for r in below)
    near = ", ".join(f"{r['barrier_over_T']:g}" for r in within)
    head = f"the ratio lies below 1 by more than 2σ at ΔE/T = {where}" if below else "no ratio lies below 1 by 2σ"
    head += f" and within 2σ of 1 at {near}" if near else ""
    return f"{head}; {trend_words(t, 'it', 'ΔE/T')}"


def _fig5_tightening(get: Loader) -> str:
    d = get("fig5", None)
    rows = [r for r in d["verdict_5b"]["rows"] if r["construction"] != "old"]  # like for like: every set cut alike
    below = [r for r in rows if r["delta_interval"][1] < 0]
    above = [r for r in rows if r["delta_interval"][0] > 0]
    zero = len(rows) - len(below) - len(above)
    big = max(abs(r["delta"]) for r in rows)
    return (
        f"of the {len(rows)} like-for-like constructions, the tightening the paper reports (Δ < 0, its 95 % "
        f"interval below 0) is seen in {len(below)}, the opposite (interval above 0) in {len(above)}, and the "
        f"interval holds 0 in {zero}; |Δ| ≤ {big:.3f} in all of them"
    )


def _fig5_shrink(get: Loader) -> str:
    pd_ = get("fig5", None)["panel_d"]
    steps = pd_["steps"]
    down = [st for st in steps if st["interval"][1] < 0]
    share = pd_["eps_shrink_share"]
    level = pd_["level"]
    every = len(down) == len(steps)
    head = (
        f"d at the headline box falls at {'every one' if every else f'{len(down)}'} of the {len(steps)} steps "
        f"of t* (95 % intervals below 0), and ε*_δ shrinks with t* in {100 * share:.0f} % of the half-samples"
    )
    if every and share >= level:
        return head + ": the paper's statement is borne out within these intervals"
    return head + f": below the {100 * level:.0f} % level, so the statement is not established here"


def _operator_residuals(get: Loader) -> str:
    rows = [r for r in get("operator", None)["kappa_convergence"] if r.get("residual_kappa0_err") is not None]
    within = [r for r in rows if abs(r["residual_kappa0"]) <= Z_RESOLVED * r["residual_kappa0_err"]]
    errs = [100 * r["residual_kappa0_err"] for r in within]
    return (
        f"the residuals κ∞/κ0 − 1 lie within 2σ of zero at {len(within)} of {len(rows)} energies, with 1σ errors "
        f"of {min(errs):.0f} to {max(errs):.0f} % there"
    )


def _regular_side(v: dict, level: float = 0.01) -> str:
    """'below', 'above' (at or above) or 'near' ``level``: a cell's regular fraction with its total error (stat ⊕
    threshold ⊕ indicator; a count of 0 by its one-sided bound), 'near' where the error reaches across the level."""
    f = v["regular_fraction"]
    if v.get("regular_fraction_upper") is not None:
        return "below" if v["regular_fraction_upper"] < level else "near"
    err = v.get("regular_err_total")
    if err is None:
        err = math.hypot(v.get("regular_err") or 0.0, v.get("regular_syst") or 0.0)
    return "below" if f + err < level else ("above" if f - err >= level else "near")


def _generality_regular_majority(get: Loader) -> str:
    """Per system, the energies (disk ICs) at which more than half of the orbits are regular by the indicator: the
    regular fraction 2σ of its total error (stat ⊕ threshold ⊕ indicator) above 1/2; those within 2σ of 1/2
    named apart; a count of 0 is below."""
    d = get("generality", None)
    above, near, none = [], [], []
    by: dict[str, dict[str, list[str]]] = {}
    for v in d["validity_map"]:
        system, ratio, ic = v["id"].rsplit("-", 2)
        if ic != "disk":
            continue
        side = by.setdefault(system, {"above": [], "near": []})
        if v.get("regular_fraction_upper") is not None:
            continue
        f, err = v["regular_fraction"], v.get("regular_err_total")
        if err is None:
            err = math.hypot(v.get("regular_err") or 0.0, v.get("regular_syst") or 0.0)
        if f - Z_RESOLVED * err > 0.5:
            side["above"].append(ratio)
        elif f + Z_RESOLVED * err >= 0.5:
            side["near"].append(ratio)
    for system, side in by.items():
        name = _SYSTEM_NAMES.get(system, system)
        if side["above"]:
            above.append(f"{name} at {', '.join(side['above'])} E_c")
        if side["near"]:
            near.append(f"{name} at {', '.join(side['near'])} E_c")
        if not side["above"] and not side["near"]:
            none.append(name)
    parts = []
    if above:
        parts.append(
            "more than half of the orbits are regular by the indicator (the fraction 2σ of its total error above "
            f"one half) for {'; '.join(above)}"
        )
    if near:
        parts.append(f"about half, within 2σ of one half, for {'; '.join(near)}")
    if none:
        parts.append(f"less than half at every energy for {' and '.join(none)}")
    return "; ".join(parts)


def _generality_validity(get: Loader) -> str:
    d = get("generality", None)
    cells = [v for v in d["validity_map"] if v["kappa0_defined"] is not None]

    def name(v):
        return f"{v['label']} {v['e_ratio']:g}"

    side = {id(v): _regular_side(v) for v in cells}
    low = [v for v in cells if side[id(v)] == "below"]
    high = [v for v in cells if side[id(v)] == "above"]
    near = [name(v) for v in cells if side[id(v)] == "near"]
    low_ill = [name(v) for v in low if not v["kappa0_defined"]]
    high_def = [name(v) for v in high if v["kappa0_defined"]]
    out = (
        f"of the {len(cells)} cells of the map with a κ0 verdict, {len(low)} have a regular fraction below 1 % "
        "with its total error; "
        f"κ0 is defined at {len(low) - len(low_ill)} of them"
        + (f" and ill-defined at {', '.join(low_ill)}" if low_ill else "")
        + f". Of the {len(high)} cells at or above 1 % with it, κ0 is defined at {len(high_def)}"
        + (f" ({', '.join(high_def)})" if high_def else "")
        + (f"; the total error reaches across 1 % at {', '.join(near)}" if near else "")
    )
    both: dict[str, list[str]] = {}
    for v in low:
        if v["kappa0_defined"]:
            both.setdefault(v["label"], []).append(f"{v['e_ratio']:g}")
    where = "; ".join(f"{k} at {', '.join(x)} E_c" for k, x in both.items())
    return out + f". Both conditions are met for {where}" if where else out


def _pc(x: float) -> str:
    """A fraction in per cent with two significant digits (0 as 0)."""
    return "0 %" if x == 0 else f"{100 * x:.2g} %"


def _generality_indicator_systematic(get: Loader) -> str:
    """The labelled sets in one sentence (each cell's counts are in the evidence's table of labelled sets): how
    many cells and orbits, how many undecided and how many disagreements in the bands, in how many cells the
    indicator systematic is the larger of the two systematics and where it is largest; the largest total error."""
    d = get("generality", None)
    cells = [r for r in d["regular_fraction"] if r.get("labelled")]
    if not cells:
        return "No cell of this record has a labelled set (every regular fraction is 0 or 1)"
    n_lab = sum(r["labelled"]["n_labelled"] for r in cells)
    n_und = sum(r["labelled"]["n_undecided"] for r in cells)
    to_c = sum(r["labelled"]["disagree_to_chaotic"] for r in cells)
    to_r = sum(r["labelled"]["disagree_to_regular"] for r in cells)
    larger = [r for r in cells if r["syst_indicator"] > r["syst"]]
    top = max(cells, key=lambda r: r["syst_indicator"])
    worst = max(cells, key=lambda r: r["err_total"] or 0.0)
    return (
        f"The labelled sets: {len(cells)} cells, {_int(n_lab)} orbits, {_int(n_und)} of them undecided; in the bands"
        f" {to_c} orbits are regular by the shadow and chaotic by the FTLE and {to_r} the reverse (each "
        "cell in the table of labelled sets below). The indicator systematic is the larger of the two in "
        f"{len(larger)} of {len(cells)} cells and largest at {top['label']} {top['e_ratio']:g} E_c "
        f"({_pc(top['syst_indicator'])}, threshold systematic {_pc(top['syst'])}); the largest total error is at "
        f"{worst['label']} {worst['e_ratio']:g} E_c, {_pc(worst['fraction'])} ± {_pc(worst['err_total'])} "
        "(stat ⊕ threshold ⊕ indicator)"
    )


def _generality_resc_rule(get: Loader) -> str:
    from hhscatter.model.spec import system_from_spec  # deferred: the model is loaded for this reading only

    d = get("generality", None)
    ratios = sorted({v["e_ratio"] for v in d["validity_map"]} | set(d["config"]["study"]["ratios"]))
    out = []
    for label, info in (d.get("systems") or {}).items():
        m = system_from_spec(info["spec"])
        e_c = m.critical_energy
        r = [m.default_escape_radius(x * e_c) for x in ratios]
        if max(r) - min(r) < 1e-12:
            out.append(f"{label} {r[0]:.3g} at every energy")
        else:
            k = next(i for i, y in enumerate(r) if y > r[0] + 1e-12)
            out.append(
                f"{label} {r[0]:.3g} up to {ratios[k - 1]:g} E_c, then growing ({r[k]:.3g} at {ratios[k]:g} E_c, "
                f"{r[-1]:.3g} at {ratios[-1]:g} E_c)"
            )
    return "the escape radius is each system's default (`default_escape_radius` of its model, by energy): " + "; ".join(
        out
    )


def _generality_claims_by_system(get: Loader) -> str:
    d = get("generality", None)
    out = []
    for label in d.get("systems") or {}:
        n = {"ok": 0, "bad": 0, "meh": 0}
        for c in d["claims"]:
            if c["system"] == label:
                cls = verdict_class(claim_verdict(c, d.get("scale")))
                n[cls if cls in n else "meh"] += 1
        out.append(f"{label} {n['ok']} agree, {n['bad']} differ, {n['meh']} qualitative or without a verdict")
    return "of the claims' records, by the verdicts' classes: " + "; ".join(out)


def _operator_convergence(get: Loader) -> str:
    rows = get("operator", None)["kappa_convergence"]
    out = []
    for key, what in (
        ("verdict_kappa0", "fig2's κ0 from P(t)"),
        ("verdict_kappa_cm", "fig2's κ from long-run crossings"),
    ):
        cells = [(f"{r['energy']:g}", verdict_class(r[key]) == "ok") for r in rows if r.get(key)]
        ok = [c for c, passed in cells if passed]
        miss = [c for c, passed in cells if not passed]
        out.append(
            f"κ∞ agrees with {what} within 2σ (both errors) at {len(ok)} of {len(cells)} energies"
            + (f" (not at E = {', '.join(miss)})" if miss else "")
        )
    return "; ".join(out)


#: the energy of the operator study where κ does not converge with the box side (mixed phase space)
OPERATOR_MIXED_ENERGY = 0.20


def _operator_mixed_refinement(get: Loader) -> str:
    """Ulam's κ on the finest boxes of each scale at :data:`OPERATOR_MIXED_ENERGY` against fig2's κ0 of that scale
    (2σ, both errors), and its change from the coarser finest side to the finer one."""
    rows = []
    for scale in ("quick", "paper"):
        row = next(r for r in get("operator", scale)["kappa_ulam"] if abs(r["energy"] - OPERATOR_MIXED_ENERGY) < 1e-9)
        rows.append((scale, row))
    rows.sort(key=lambda sr: -sr[1]["box"])  # the coarser side first
    parts, z = [], []
    for scale, r in rows:
        k, k0 = Measured(r["kappa"], r["err"]).to_dict(), Measured(r["fig2_kappa"], r["fig2_err"]).to_dict()
        z.append((k["value"] - k0["value"]) / math.hypot(k["err"], k0["err"]))
        side = _side(k, k0, "fig2's κ0")
        parts.append(f"{_ve(k['value'], k['err'])} on boxes of side {r['box']:g} ({scale} scale), {side}")
    (_, a), (_, b) = rows
    moved, z_move = _move(Measured(a["kappa"], a["err"]).to_dict(), Measured(b["kappa"], b["err"]).to_dict())
    change = (
        f"{'falls' if z_move < 0 else 'rises'} from side {a['box']:g} to {b['box']:g}"
        if abs(z_move) > Z_RESOLVED
        else f"does not change resolved at 2σ from side {a['box']:g} to {b['box']:g}"
    )
    crosses = min(abs(x) for x in z) > Z_RESOLVED and z[0] * z[1] < 0
    return (
        f"Ulam's κ on the finest boxes at E = {OPERATOR_MIXED_ENERGY:.2f} is "
        + "; ".join(parts)
        + f": it {change} ({moved})"
        + (", from one side of fig2's κ0 to the other" if crosses else "")
    )


def _noise_turnover(get: Loader) -> str:
    rows = sorted(get("noise", None)["turnover"], key=lambda r: r["gamma"])

    def z1(r):
        return verdict(r["ratio"], r["ratio_err"], 1.0)

    below = [f"{r['gamma']:g}" for r in rows if z1(r).word == "differs" and r["ratio"] < 1]
    near = [f"{r['gamma']:g}" for r in rows if z1(r).word == "agrees"]
    steps = []
    for a, b in zip(rows, rows[1:]):
        v = verdict(b["ratio"], b["ratio_err"], a["ratio"], a["ratio_err"])
        steps.append((f"{a['gamma']:g} → {b['gamma']:g}", v))
    up = [s for s, v in steps if v.word == "differs" and v.z > 0]
    down = [s for s, v in steps if v.word == "differs" and v.z < 0]
    flat = [s for s, v in steps if v.word != "differs"]
    parts = [f"below 1 by more than 2σ at γ = {', '.join(below)}" if below else "below 1 by 2σ nowhere"]
    if near:
        parts.append(f"within 2σ of 1 at γ = {', '.join(near)}")
    trend_bits = []
    if up:
        trend_bits.append(f"rises by more than 2σ at {len(up)} of the {len(steps)} steps in γ ({'; '.join(up)})")
    if down:
        trend_bits.append(f"falls by more than 2σ at {'; '.join(down)}")
    if flat:
        trend_bits.append(f"shows no resolved change at {'; '.join(flat)}")
    low = rows[0]
    return (
        f"the ratio lies {' and '.join(parts)}; from step to step it "
        + ", ".join(trend_bits)
        + f"; at γ = {low['gamma']:g} the rate is {_ve(low['ratio'], low['ratio_err'])} of Kramers–Langer's"
    )


def _noise_turnover_theory(get: Loader) -> str:
    d = get("noise", None)
    rows = sorted((r for r in d["turnover"] if "ratio_mm" in r), key=lambda r: r["gamma"])
    if not rows:
        return "the turnover theory's ratios are not in this scale's numbers"
    rng = d["conventions"].get("theory_range", "its range")
    inside = [r for r in rows if r["theory_assumptions_hold"]]
    outside = [r for r in rows if not r["theory_assumptions_hold"]]

    def cells(rs):
        groups = {"within 2σ of 1": [], "below 1 by more than 2σ": [], "above 1 by more than 2σ": []}
        for r in rs:
            v = verdict(r["ratio_mm"], r["ratio_mm_err"], 1.0)
            key = (
                "within 2σ of 1"
                if v.word != "differs"
                else "below 1 by more than 2σ"
                if v.z < 0
                else "above 1 by more than 2σ"
            )
            groups[key].append(f"{r['gamma']:g}")
        return "; ".join(f"{k} at γ = {', '.join(g)}" for k, g in groups.items() if g)

    out = []
    if inside:
        dev = max(abs(r["ratio_mm"] - 1) for r in inside)
        gammas = ", ".join(f"{r['gamma']:g}" for r in inside)
        out.append(
            f"where {rng} (γ = {gammas}) the rate over Υ(δ) k_KL is {cells(inside)}, |ratio − 1| at most {dev:.1%}"
        )
    else:
        out.append(f"no turnover point lies where {rng}")
    if outside:
        out.append(f"outside that range {cells(outside)}")
    return "; ".join(out)


#: the turnover theory is read as holding to this relative tolerance (a 2σ interval inside 1 ± this)
TURNOVER_TOLERANCE = 0.15


def _tolerance_class(ratio: float, err: float, tol: float) -> str:
    """ "within" when the 2σ interval of ``ratio`` lies inside 1 ± tol, "beyond" when it lies outside, else
    "undecided"."""
    d = abs(ratio - 1.0)
    return "within" if d + Z_RESOLVED * err <= tol else "beyond" if d - Z_RESOLVED * err > tol else "undecided"


def _tolerance_words(rows: list[dict], key: str, tol: float) -> str:
    """Where the ratios ``key`` of rows sorted by γ lie within 1 ± tol, from their 2σ intervals: the widest run of
    consecutive γ that do, and the γ that do not or are undecided, with their ratios."""
    cls = [_tolerance_class(r[key], r[f"{key}_err"], tol) for r in rows]
    best, run = (0, 0), None
    for i, c in enumerate(cls + ["end"]):
        if c == "within" and run is None:
            run = i
        elif c != "within" and run is not None:
            best = max(best, (i - run, run), key=lambda x: x[0])
            run = None
    n, start = best
    if n == 0:
        out = f"within {100 * tol:g} % at no γ"
    elif n == 1:
        out = f"within {100 * tol:g} % at γ = {rows[start]['gamma']:g} only"
    else:
        out = f"within {100 * tol:g} % from γ = {rows[start]['gamma']:g} to {rows[start + n - 1]['gamma']:g}"
    rest = []
    for word, what in (("beyond", f"beyond {100 * tol:g} %"), ("undecided", f"undecided at {100 * tol:g} %")):
        cells = [
            f"{r['gamma']:g} ({_ve(r[key], r[f'{key}_err'])})"
            for i, (r, c) in enumerate(zip(rows, cls))
            if c == word and not start <= i < start + n
        ]
        if cells:
            rest.append(f"{what} at γ = {', '.join(cells)}")
    stray = [
        f"{r['gamma']:g}" for i, (r, c) in enumerate(zip(rows, cls)) if c == "within" and not start <= i < start + n
    ]
    if stray:
        rest.append(f"within {100 * tol:g} % also at γ = {', '.join(stray)}")
    return out + (f"; {'; '.join(rest)}" if rest else "")


def _noise_turnover_barriers(get: Loader) -> str:
    d = get("noise", None)
    series = [
        sorted((r for r in d.get(k) or [] if "ratio_mm" in r), key=lambda r: r["gamma"])
        for k in ("turnover", "turnover_high")
    ]
    series = [s for s in series if s]
    if len(series) < 2:
        return "the turnover at a second barrier is not in this scale's numbers"
    tol = TURNOVER_TOLERANCE
    cells = []
    for rows in series:
        inside = [r for r in rows if r["theory_assumptions_hold"]]
        where = f" (the theory's range: γ ≤ {inside[-1]['gamma']:g})" if inside else ""
        cells.append(
            f"at ΔE/T = {rows[0]['barrier_over_T']:.3g} the rate over Υ(δ) k_KL is "
            f"{_tolerance_words(rows, 'ratio_mm', tol)}{where}"
        )
    (lo, hi) = series
    common = sorted({r["gamma"] for r in lo} & {r["gamma"] for r in hi})
    out = (
        f"by the 2σ intervals (within {100 * tol:g} %: inside [{1 - tol:.2f}, {1 + tol:.2f}]; beyond: outside it; "
        f"undecided: across its edge), {'; '.join(cells)}"
    )
    if common:
        g = common[0]
        a = next(r for r in lo if r["gamma"] == g)
        b = next(r for r in hi if r["gamma"] == g)
        ea, eb = a["ratio_mm"] - 1, b["ratio_mm"] - 1
        sa, sb = a["ratio_mm_err"], b["ratio_mm_err"]
        ba, bb = a["barrier_over_T"], b["barrier_over_T"]
        change = verdict(eb, sb, ea, sa)
        scaled, scaled_err = ea * ba / bb, sa * ba / bb
        prop = verdict(eb, sb, scaled, scaled_err)
        out += (
            f". At the lowest γ = {g:g} the excess over the theory is {_ve(100 * ea, 100 * sa)} % at ΔE/T = {ba:.3g} "
            f"and {_ve(100 * eb, 100 * sb)} % at {bb:.3g}: "
            + (
                f"{'it grows' if change.z > 0 else 'it shrinks'} by "
                if change.word == "differs"
                else "a change not resolved at 2σ, "
            )
            + f"{_ve(100 * abs(eb - ea), 100 * math.hypot(sa, sb))} points (z = {signed(change.z)}); an "
            f"excess ∝ T/ΔE would be {_ve(100 * scaled, 100 * scaled_err)} % at {bb:.3g}, which the measured one "
            f"{'agrees with' if prop.word == 'agrees' else 'differs from'} (z = {signed(prop.z)})"
        )
    return out


def _noise_saddles_turnover(get: Loader) -> str:
    d = get("noise", None).get("two_saddles_turnover") or {}
    rows = sorted((r for r in d.get("records") or [] if "ratio_mm" in r), key=lambda r: r["gamma"])
    if not rows:
        return "the two-saddle system's turnover is not in this scale's numbers"
    lo, hi = rows[0], rows[-1]
    tol = TURNOVER_TOLERANCE
    higher = max(range(len(lo["saddles"])), key=lambda i: lo["saddles"][i]["barrier"])
    share = [r["saddles"][higher]["melnikov_meshkov"] / r["melnikov_meshkov"] for r in rows]
    return (
        f"at ΔE/T = {d['barrier_over_T']:.3g} of the lowest saddle, from γ = {lo['gamma']:g} to {hi['gamma']:g}, the "
        f"rate over the sum Σ_s Υ(δ_s) k_KL,s is {_tolerance_words(rows, 'ratio_mm', tol)}. At γ = {hi['gamma']:g} "
        f"the rate over the Kramers–Langer sum is {_ve(hi['ratio'], hi['ratio_err'])}, which "
        f"{_against(hi['ratio'], hi['ratio_err'], 1.0, '1')}; at γ = {lo['gamma']:g} it is "
        f"{_ve(lo['ratio'], lo['ratio_err'])} of the Kramers–Langer sum and {_ve(lo['ratio_ed'], lo['ratio_ed_err'])} "
        f"of the energy-diffusion limit Σ_s δ_s k_TST,s. The higher saddle's share of the theory's sum is "
        f"{share[0]:.3f} at γ = {lo['gamma']:g} and {share[-1]:.3f} at {hi['gamma']:g} (its δ_s = "
        f"{lo['saddles'][higher]['delta']:.3g} at γ = {lo['gamma']:g}, the lower saddle's "
        f"{min(s['delta'] for s in lo['saddles']):.3g})"
    )


#: the theories of the low-γ turnover points: (the ratio's key, its name in the reading)
_LOW_GAMMA_THEORIES = (
    ("ratio_shell", "the shells' energy diffusion with the flux over the dividing lines above E_b"),
    ("ratio_shell_absorbing", "the shells' energy diffusion absorbing at E_b"),
    ("ratio_shell_turnover", "Υ(δ_shell) k_KL"),
    ("ratio_mm", "Υ(δ) k_KL with the line orbit's action"),
)


def _noise_low_gamma_theory(get: Loader) -> str:
    d = get("noise", None)
    g_max = (d.get("conventions") or {}).get("energy_diffusion_gamma_max")
    series = [
        (f"Hénon–Heiles at ΔE/T = {rows[0]['barrier_over_T']:.3g}" if rows else "", rows)
        for rows in (d.get("turnover") or [], d.get("turnover_high") or [])
    ]
    two = d.get("two_saddles_turnover") or {}
    if two.get("records"):
        series.append((f"the two-saddle system at ΔE/T = {two['barrier_over_T']:.3g}", two["records"]))
    points = [
        (label, r)
        for label, rows in series
        for r in sorted(rows, key=lambda r: r["gamma"])
        if g_max is not None and r["gamma"] <= g_max and "ratio_shell" in r
    ]
    if not points:
        return f"no turnover point at γ ≤ {g_max:g} is in this scale's numbers" if g_max else "not in these numbers"
    labels = dict.fromkeys(lb for lb, _ in points)
    where = "; ".join(f"{lb}, γ = " + ", ".join(f"{r['gamma']:g}" for b, r in points if b == lb) for lb in labels)
    n = len(points)
    out, summary = [], []
    for key, name in _LOW_GAMMA_THEORIES:
        vals = [(label, r, verdict(r[key], r[f"{key}_err"], 1.0)) for label, r in points]
        agree = sum(v.word != "differs" for _, _, v in vals)
        dev = max(abs(r[key] - 1) for _, r, _ in vals)
        cells = ", ".join(f"{_ve(r[key], r[f'{key}_err'])}" for _, r, _ in vals)
        out.append(f"over {name}: {cells} (within 2σ of 1 at {agree} of {n}; |ratio − 1| at most {dev:.1%})")
        summary.append((key, name, agree, dev, [r[key] for _, r, _ in vals]))
    text = f"at γ ≤ {g_max:g} ({n} points, in this order: {where}) the measured rate " + "; ".join(out)
    groups = {}
    for label, r in points:
        groups.setdefault(label.split(" at ΔE/T")[0], []).append(r)
    verdicts = []
    for system, rows in groups.items():
        count = f"{len(rows)} point{'s' if len(rows) > 1 else ''}"
        agree, closest = [], None
        for key, name in _LOW_GAMMA_THEORIES:
            ok = [verdict(r[key], r[f"{key}_err"], 1.0).word != "differs" for r in rows]
            dev = max(abs(r[key] - 1) for r in rows)
            if all(ok):
                agree.append(name)
            if closest is None or dev < closest[1]:
                closest = (name, dev, sum(ok))
        if agree:
            verdicts.append(f"on {system} ({count}) they agree at 2σ with {' and '.join(agree)}")
        else:
            verdicts.append(
                f"on {system} ({count}) no theory agrees at 2σ at every point; the closest is "
                f"{closest[0]}, within {closest[1]:.1%} of every point (within 2σ at {closest[2]} of {len(rows)})"
            )
    text += ". By system, " + "; ".join(verdicts)
    flux = next(x for x in summary if x[0] == "ratio_shell")
    absorbing = next(x for x in summary if x[0] == "ratio_shell_absorbing")
    if all(v < 1 for v in absorbing[4]) and flux[3] < absorbing[3]:
        text += (
            f". The absorbing closure's rate is {1 / max(absorbing[4]):.2f} to {1 / min(absorbing[4]):.2f} times the "
            "measured one: an orbit whose energy reaches E_b has not escaped yet; with the microcanonical flux over "
            "the saddles above E_b as the closure the largest deviation falls to "
            + " and ".join(
                f"{max(abs(r['ratio_shell'] - 1) for r in rows):.1%} on {system}" for system, rows in groups.items()
            )
        )
    if two.get("separable") and any(lb.startswith("the two-saddle") for lb, _ in points):
        text += (
            ". The two-saddle potential is separable (∂²V/∂x∂y = 0): each degree of freedom keeps its own energy, "
            "the orbits do not explore the energy shell that the shells' theory averages over, and each line "
            "orbit's δ_s is the exact one of its own degree of freedom"
        )
    return text


def _noise_no_drag(get: Loader) -> str:
    rows = [r for r in get("noise", None)["no_drag"] if r["sigma"] > 0]
    out = []
    for s in sorted({r["sigma"] for r in rows}):
        cells = []
        for r in sorted((r for r in rows if r["sigma"] == s), key=lambda r: r["energy"]):
            v = verdict(r["kappa_over_kappa0"], r["kappa_over_kappa0_err"], 1.0)
            word = (
                "below κ0" if v.word == "differs" and v.z < 0 else "above κ0" if v.word == "differs" else "κ0 within 2σ"
            )
            cells.append(f"{word} at E0 = {r['energy']:g} (z = {signed(v.z)})")
        out.append(f"σ = {s:g}: " + ", ".join(cells))
    return "the rate over the window is " + "; ".join(out)


def _against(value, err, ref, ref_name: str) -> str:
    """ "agrees with NAME (z = …)" or "differs from NAME (z = …)" by the 2σ rule."""
    v = verdict(value, err, ref)
    if ref == 0:
        return f"{'lies within 2σ of 0' if v.word == 'agrees' else 'is resolved from 0'} (z = {signed(v.z)})"
    return f"{'agrees with' if v.word == 'agrees' else 'differs from'} {ref_name} (z = {signed(v.z)})"


def _noise_finite_barrier(get: Loader) -> str:
    d = get("noise", None)
    f = d.get("finite_barrier")
    if f is None:
        return "the finite-barrier fit is not in this scale's numbers"
    a, c, c1 = f["intercept"], f["slope"], f["slope_intercept_one"]
    c_tst = f["transition_state_slope"]
    lo, hi = f["T_over_barrier_range"]
    out = (
        f"the weighted fit of k/k_KL against T/ΔE ({lo:.3g} to {hi:.3g}) gives the intercept "
        f"{_ve(a['value'], a['err'])}, which {_against(a['value'], a['err'], 1.0, '1')}, and the slope "
        f"c = {_ve(c['value'], c['err'])} (χ² = {f['chi2']:.1f} for {f['dof']} dof, p = {f['p_value']:.2g}); with "
        f"the intercept fixed at 1, c = {_ve(c1['value'], c1['err'])}. The transition-state part of the first "
        f"correction is c_TST = {signed(c_tst, '+.3f')}: the free slope {_against(c['value'], c['err'], c_tst, 'it')} "
        f"and {_against(c['value'], c['err'], 0.0, '0')}; the slope at intercept 1 "
        f"{_against(c1['value'], c1['err'], c_tst, 'it')} and {_against(c1['value'], c1['err'], 0.0, '0')}"
    )
    if f["p_value"] < P_LEVEL:
        out += (
            f". The ratios scatter about the line by more than their errors (p < {P_LEVEL:g}): the slopes' errors "
            f"are then understated by about √(χ²/dof) = {math.sqrt(f['chi2'] / f['dof']):.2g}"
        )
    return out


def _unsigned_zero(text: str) -> str:
    """A rendered value that rounds to zero without its sign ("−0 ± 5" → "0 ± 5")."""
    return re.sub(r"^[−-](0(?:\.0+)?)(?![\d.])", r"\1", text)


def _noise_absorbing_radius(get: Loader) -> str:
    d = get("noise", None)
    rows = d.get("absorbing_radius") or []
    if not rows:
        return "the rates at a second absorbing radius are not in this scale's numbers"
    cells = []
    for r in sorted(rows, key=lambda r: r["barrier_over_T"]):
        q = r["rate_ratio"]
        v = verdict(q["value"], q["err"], 1.0)
        word = (
            "no shift resolved at 2σ"
            if v.word == "agrees"
            else f"the larger radius {'lowers' if v.z < 0 else 'raises'} the rate"
        )
        cells.append(
            f"at ΔE/T = {r['barrier_over_T']:g} the rate at r_esc = {r['r_esc']:g} is {_ve(q['value'], q['err'])} "
            f"of that at {r['r_esc_default']:g} (shift {_unsigned_zero(_ve(100 * (q['value'] - 1), 100 * q['err']))} %, z = "
            f"{signed(v.z)}: {word})"
        )
    return "; ".join(cells)


def _noise_two_saddles(get: Loader) -> str:
    d = get("noise", None).get("two_saddles") or {}
    recs = sorted(d.get("records") or [], key=lambda r: r["barrier_over_T"])
    if not recs:
        return "the two-saddle system is not in this scale's numbers"
    cells = []
    for r in recs:
        low = min(r["exit_shares"], key=lambda e: e["barrier"])
        high = max(r["exit_shares"], key=lambda e: e["barrier"])
        measured = (
            _ve(high["measured"], high["measured_err"])
            if high["measured_err"] is not None
            else format_bound(high["measured_upper95"], high["measured_lower95"])
        )
        share = (
            f"the higher saddle (ΔE = {high['barrier']:.3g}) takes {measured} of the escapes in the window, against its "
            f"term's share {high['predicted']:.3f} of the sum"
        )
        if high["measured_err"] is not None:
            share += f", which {_against(high['measured'], high['measured_err'], high['predicted'], 'it')}"
        cells.append(
            f"at ΔE/T = {r['barrier_over_T']:g} the rate over the two-saddle sum Σ_s k_KL,s is "
            f"{_ve(r['ratio'], r['ratio_err'])}, which {_against(r['ratio'], r['ratio_err'], 1.0, '1')}, and over the "
            f"lowest saddle's term alone (ΔE = {low['barrier']:.3g}) "
            f"{_ve(r['ratio_lowest'], r['ratio_lowest_err'])}, which "
            f"{_against(r['ratio_lowest'], r['ratio_lowest_err'], 1.0, '1')}; {share}"
        )
    return "; ".join(cells)


def _pct(row, key) -> str:
    """A fraction of a record as a percentage: value ± error, or its one-sided bound at 0 or 1."""
    if row.get(f"{key}_err") is not None:
        return f"{_ve(100 * row[key], 100 * row[key + '_err'])} %"
    up, low = row.get(f"{key}_upper95"), row.get(f"{key}_lower95")
    return format_bound(up, None, pct=True) if up is not None else format_bound(None, low * 100) + " %"


def _noise_no_drag_survivors(get: Loader) -> str:
    d = get("noise", None)
    surv = d.get("no_drag_survivors")
    if not surv:
        return "the survivors' energies are not in this scale's numbers"
    lo, hi = d["conventions"]["nodrag_window"]
    rates = {(r["energy"], r["sigma"]): r for r in d["no_drag"]}
    s_max = max(r["sigma"] for r in surv)
    out, lost, fall = [], [], []
    for E in sorted({r["energy"] for r in surv}, reverse=True):
        rows = sorted((r for r in surv if r["energy"] == E and r["sigma"] == s_max), key=lambda r: r["t"])
        with_e = [r for r in rows if r.get("mean_energy") is not None]
        means = ", ".join(f"{_ve(r['mean_energy'], r['mean_energy_err'])} at t = {r['t']:g}" for r in with_e)
        below = [r for r in with_e if verdict(r["mean_energy"], r["mean_energy_err"], E).word == "differs"]
        below = [r for r in below if r["mean_energy"] < E]
        where = (
            "below E0 by more than 2σ at every one of these times"
            if below and len(below) == len(with_e)
            else "below E0 by more than 2σ at t = " + ", ".join(f"{r['t']:g}" for r in below)
            if below
            else "below E0 by more than 2σ at none of them"
        )
        end = next((r for r in reversed(with_e) if r["t"] <= hi), None)
        cell = f"at E0 = {E:g} the mean energy of the orbits still inside is {means} ({where})"
        if end is not None:
            cell += (
                f", while the whole ensemble's mean energy E0 + σ²t is {end['ensemble_mean_energy']:.3g} at t = "
                f"{end['t']:g}; {_pct(end, 'below_ec')} of the {_int(end['n_alive'])} orbits inside at t = {end['t']:g} "
                f"lie below E_c, where no exit is open"
            )
            if verdict(end["mean_energy"], end["mean_energy_err"], E).word == "differs" and end["mean_energy"] < E:
                lost.append(f"{E:g}")
        rate = rates.get((E, s_max))
        if rate is not None and rate.get("halves_z") is not None and math.isfinite(rate["halves_z"]):
            k1, k2 = rate["rate_first_half"], rate["rate_second_half"]
            z = rate["halves_z"]
            state = "constant within the halves' errors" if rate["constant_in_window"] else "not constant"
            cell += (
                f". Its escape rate on [{lo:g}, {hi:g}] is {state}: {_ve(k1, rate['rate_first_half_err'])} on the "
                f"first half, {_ve(k2, rate['rate_second_half_err'])} on the second (z = {signed(z)})"
            )
            if not rate["constant_in_window"] and k2 < k1:
                fall.append(f"{E:g}")
        out.append(cell)
    text = f"at σ = {s_max:g}: " + "; ".join(out)
    if lost and fall and set(fall) <= set(lost):
        text += (
            f". At E0 = {', '.join(fall)} the orbits that stay have lost energy although the noise raises the "
            "ensemble's mean, and the rate falls inside the window: the lower κ/κ0 on the window goes with survivors "
            "that have fallen toward and below E_c, not with a gain of energy"
        )
    return text


# -- comparisons on the study pages (closer, farther, below, differs, within) -------------------------------------
#: the names the fig5 page gives the rows of its 5b − 5a table
FIG5_ROW_NAMES = {
    "old": "reference not cut",
    "cut": "cut",
    "cut_offsets": "placements",
    "cut_offsets_random": "random momenta",
    "ours": "ours",
}


def interval_side(lo, hi, level: float) -> str:
    """interval_side(lo, hi, level) -> "below", "above" or "straddles": where an interval lies against a level.

    >>> interval_side(0.02, 0.05, 0.1), interval_side(0.2, 0.3, 0.1), interval_side(0.05, 0.15, 0.1)
    ('below', 'above', 'straddles')
    """
    if hi < level:
        return "below"
    if lo > level:
        return "above"
    return "straddles"


def _ci(value, lo, hi) -> str:
    return f"{signed(value, '+.3f')}, 95 % [{signed(lo, '+.3f')}, {signed(hi, '+.3f')}]"


def _fig2_law_below_break(get: Loader) -> str:
    """a and b of the κ(E) law below the break against the paper's, convention by convention: each convention's
    value with the law's statistical error (the conventions share the orbits) against the paper's printed value and
    its half-unit, by the 2σ rule."""
    d = get("fig2", None)
    law = d["kappa_conventions"]["law"]
    rows = {r["quantity"]: r for r in d["paper_comparison"]}
    out = []
    for p in ("a", "b"):
        ref = rows[f"{p} (κ(E) law across conventions)"]
        cells = [
            (conv, verdict(v, law[p]["err_stat"], ref["paper"], ref.get("paper_err") or 0.0).word == "agrees")
            for conv, v in law[p]["per_convention"].items()
        ]
        if all(not ok for _, ok in cells):
            out.append(
                f"{p} differs from the paper's {ref['paper']:g} in every convention ({', '.join(c for c, _ in cells)})"
            )
        else:
            out.append(f"{p} against the paper's {ref['paper']:g}: " + pass_fail_words(cells, "agrees", "differs"))
    return "; ".join(out)


def _fig5_ours_5b(get: Loader) -> str:
    """Our construction's 5b − 5a: farther, closer or as close, from the 95 % interval of Δ = d(5b) − d(5a)."""
    r = next(x for x in get("fig5", None)["verdict_5b"]["rows"] if x["construction"] == "ours")
    lo, hi = r["delta_interval"]
    side = interval_side(lo, hi, 0.0)
    word = {
        "above": "5b lies farther from μ_c^0.30 than 5a",
        "below": "5b lies nearer to μ_c^0.30 than 5a",
        "straddles": "5b and 5a are as near to μ_c^0.30 (the interval of Δ holds 0)",
    }[side]
    return f"{word}: Δ = d(5b) − d(5a) = {_ci(r['delta'], lo, hi)}"


def _fig5_eps_first(get: Loader) -> str:
    """The agreement scale ε*_δ at the largest γ of panel (d): its value and interval, or "none" with the reason
    read from the curve (d > δ at every informative side, or no run of sides with d ≤ δ from the largest down)."""
    pd_ = get("fig5", None)["panel_d"]
    c = max(pd_["curves"], key=lambda x: x["gamma"])
    if c.get("eps_delta") is not None:
        lo, hi = c["eps_delta_interval"]
        return f"{c['eps_delta']:g} [{lo:g}, {hi:g}]"
    d = [v for v, ok in zip(c["d"], c["informative"], strict=True) if ok]
    if all(v > pd_["delta"] for v in d):
        return f"none (d > δ at all {len(d)} informative sides)"
    return "none (d ≤ δ at no side from the largest down)"


#: the 5b − 5a rows that compare like with like (the reference cut like 5a and 5b)
FIG5_LIKE_FOR_LIKE = ("cut", "cut_offsets", "cut_offsets_random")


def _fig5_rows_by_scale(get: Loader) -> str:
    """The like-for-like 5b − 5a rows (:data:`FIG5_LIKE_FOR_LIKE`) at both scales: those whose 95 % interval of Δ
    excludes 0, with their sign; and whether random momenta give Δ the other sign than tangential ones."""
    parts = []
    for scale, name in (("quick", "the quick scale"), (None, "the paper scale")):
        rows = [r for r in get("fig5", scale)["verdict_5b"]["rows"] if r["construction"] in FIG5_LIKE_FOR_LIKE]
        off = [
            f"{FIG5_ROW_NAMES.get(r['construction'], r['construction'])} ({signed(r['delta'], '+.3f')})"
            for r in rows
            if interval_side(*r["delta_interval"], 0.0) != "straddles"
        ]
        part = f"at {name} Δ's 95 % interval excludes 0 in {len(off)} of the {len(rows)} like-for-like rows" + (
            f": {', '.join(off)}" if off else ""
        )
        by = {r["construction"]: r for r in rows}
        t, rnd = by.get("cut_offsets"), by.get("cut_offsets_random")
        if t and rnd and np.sign(t["delta"]) != np.sign(rnd["delta"]):
            resolved = [interval_side(*x["delta_interval"], 0.0) != "straddles" for x in (t, rnd)]
            part += "; random momenta give Δ the other sign than tangential ones" + (
                "" if any(resolved) else " (neither resolved from 0)"
            )
        parts.append(part)
    return "; ".join(parts)


def _fig5_intervals_by_scale(get: Loader) -> str:
    """The 5b − 5a rows at both scales, matched by construction: how many times narrower the paper-scale 95 %
    intervals of Δ are than the quick ones (the range over the rows), how many quick values lie inside their
    paper-scale interval, and whether every pair of intervals overlaps (the move is then read as statistics)."""
    quick = {r["construction"]: r for r in get("fig5", "quick")["verdict_5b"]["rows"]}
    paper = {r["construction"]: r for r in get("fig5", None)["verdict_5b"]["rows"]}
    both = [c for c in paper if c in quick]
    if not both:
        return "no 5b − 5a row is at both scales"
    ratios, inside, apart = [], 0, []
    for c in both:
        (ql, qh), (pl, ph) = quick[c]["delta_interval"], paper[c]["delta_interval"]
        ratios.append((qh - ql) / (ph - pl))
        inside += pl <= quick[c]["delta"] <= ph
        if qh < pl or ql > ph:
            apart.append(FIG5_ROW_NAMES.get(c, c))
    span = f"{min(ratios):.1f} to {max(ratios):.1f}" if len(ratios) > 1 else f"{ratios[0]:.1f}"
    head = (
        f"the paper-scale 95 % intervals are {span} times narrower than the quick ones; {inside} of {len(both)} "
        "quick values lie inside their paper-scale interval"
    )
    if apart:
        return f"{head}, and the two intervals do not overlap for {', '.join(apart)}: not statistics alone there"
    return f"{head}, and every quick interval overlaps its paper-scale one: statistics"


def _resc_paper_radius(get: Loader) -> str:
    """The paper's escape radius (the smallest the study tests) against the exits' Lyapunov orbits, energy by
    energy: beyond each orbit
    (r_esc > its largest radius: an orbit crossing r_esc has passed the saddle), cutting it, or inside it (r_esc
    below its smallest radius: an orbit crossing r_esc may still come back), the energies of each class named."""
    d = get("resc", None)
    r = min(d["r_esc"])
    groups: dict[str, list[str]] = {"beyond": [], "cuts": [], "inside": []}
    for key, orbit in sorted(d["lyapunov"].items(), key=lambda kv: float(kv[0].split("=")[1])):
        e = key.split("=")[1]
        if r > orbit["r_max"]:
            groups["beyond"].append(e)
        elif r < orbit["r_min"]:
            groups["inside"].append(e)
        else:
            groups["cuts"].append(e)
    words = {
        "inside": "lies inside the exits' Lyapunov orbits (an orbit crossing it may come back) at E = ",
        "cuts": "cuts them at E = ",
        "beyond": "lies beyond them at E = ",
    }
    parts = [words[k] + ", ".join(groups[k]) for k in ("inside", "cuts", "beyond") if groups[k]]
    return f"r_esc = {r:g} " + "; ".join(parts)


def _noise_reactivation(get: Loader) -> str:
    """The drag-only survival extended by re-activation against the heat-bath P(t): its largest deviation in units
    of P's standard error (fails beyond 2), and the tail's rate against the thermal rate by the 2σ rule."""
    r = get("noise", None)["reactivation"]
    dev, at, sig = r["model_max_deviation"], r["model_max_deviation_at"], r["model_max_deviation_sigma"]
    fit = (
        f"fails in the transient: it differs from the measured P(t) by up to {dev:.3f} (at t = {at:.3g}, {sig:.3g} "
        "standard errors)"
        if sig > Z_RESOLVED
        else f"holds within 2 standard errors (largest deviation {dev:.3f} at t = {at:.3g}, {sig:.3g} standard errors)"
    )
    q = r["tail_over_thermal"]
    v = verdict(q["value"], q["err"], 1.0)
    tail = (
        "after it the measured tail decays at the thermal rate"
        if v.word == "agrees"
        else "after it the measured tail does not decay at the thermal rate"
    )
    return f"{fit}; {tail} (ratio {_ve(q['value'], q['err'])}, z = {signed(v.z)} against 1)"


def _noise_window_halves(get: Loader) -> str:
    """Whether the two halves of every heat-bath window give one rate within ``constancy_z`` σ (the study's flag)."""
    d = get("noise", None)
    z = d["config"]["study"]["constancy_z"]
    if d["conventions"]["all_constant_in_window"]:
        return f"in every heat-bath window the two halves give rates within {z:.3g}σ of each other"
    return f"in at least one heat-bath window the two halves give rates more than {z:.3g}σ apart"


def _operator_tolerance(get: Loader) -> str:
    """The operator's three measures against fig1's c-measure at the same energy (E = 0.30): each debiased
    Hellinger distance's interval against the tolerance δ of fig5's panel (d)."""
    tol = get("fig5", None)["panel_d"]["delta"]
    rows = [
        r
        for r in get("operator", None)["cmeasure_distances"]
        if abs(r["fig1_energy"] - 0.3) < 1e-9 and abs(r["operator_energy"] - 0.3) < 1e-9
    ]
    groups: dict = {"below": [], "above": [], "straddles": []}
    for r in rows:
        lo, hi = r.get("hellinger_debiased_lo"), r.get("hellinger_debiased_hi")
        side = interval_side(lo, hi, tol) if lo is not None and hi is not None else "straddles"
        groups[side].append(f"{r['measure']} {r['hellinger_debiased']:.3f} [{lo:.3f}, {hi:.3f}]")
    words = {
        "below": f"below fig5's tolerance δ = {tol:g}",
        "above": f"above δ = {tol:g}",
        "straddles": f"with an interval that holds δ = {tol:g}",
    }
    parts = [f"{words[k]} for {', '.join(v)}" for k, v in groups.items() if v]
    return "the debiased distance to fig1's c-measure at E = 0.30 (95 % interval) lies " + "; ".join(parts)


def _operator_grid_fit(rows: list[dict]) -> dict:
    """The fit ln κ = a + s·ln M + t·ln b over the (box side b, samples per box M) grid of the eigenvector
    convergence table, with equal weights and the errors scaled by the scatter about the fit (χ²/dof): the
    grid's κ carry no error of their own. Returns {s, s_err, t, t_err, dof, n}."""
    k = np.log([r["kappa"] for r in rows])
    m = np.log([r["samples_per_box"] for r in rows])
    b = np.log([r["box"] for r in rows])
    if len(rows) < 4:
        raise ValueError(f"the (b, M) grid needs at least 4 points for 3 parameters and an error, got {len(rows)}")
    fit = weighted_least_squares(np.column_stack([np.ones_like(k), m, b]), k, errors="scaled")
    return {
        "s": float(fit.coef[1]),
        "s_err": float(math.sqrt(fit.cov[1, 1])),
        "t": float(fit.coef[2]),
        "t_err": float(math.sqrt(fit.cov[2, 2])),
        "dof": fit.dof,
        "n": len(rows),
    }


def _exponent_words(slope: float, err: float, rises: str, falls: str, flat: str, law: str) -> str:
    z = slope / err
    fit = f"{law}, exponent {_ve(slope, err)}, z = {signed(z)}"
    if abs(z) > Z_RESOLVED:
        return f"{rises if slope > 0 else falls} ({fit})"
    return f"{flat} resolved at 2σ ({fit})"


def _operator_grid_rows(get: Loader) -> list[dict]:
    rows = get("operator", None)["cmeasure_convergence"]
    e = sorted({r["energy"] for r in rows})[0]
    return [r for r in rows if r["energy"] == e]


def _operator_samples_trend(get: Loader) -> str:
    """κ against the samples per box M at fixed box side b, from the fit ln κ = a + s·ln M + t·ln b over the (b, M)
    grid of the eigenvector convergence table (equal weights, errors from the scatter): "κ falls as M grows" only
    when s < 0 by more than 2σ."""
    rows = _operator_grid_rows(get)
    f = _operator_grid_fit(rows)
    words = _exponent_words(
        f["s"],
        f["s_err"],
        "at fixed box side κ rises as M grows",
        "at fixed box side κ falls as M grows",
        "at fixed box side κ shows no trend in M",
        "κ ∝ M^s",
    )
    return (
        f"{words}; the fit of ln κ on ln M and ln b over the {f['n']} partitions of the grid at "
        f"E = {rows[0]['energy']:g}, equal weights, errors from the scatter about the fit ({f['dof']} dof)"
    )


def _operator_box_trend(get: Loader) -> str:
    """κ against the box side b at fixed samples per box, from the same fit as :func:`_operator_samples_trend`:
    "κ rises as the boxes shrink" only when t < 0 by more than 2σ."""
    f = _operator_grid_fit(_operator_grid_rows(get))
    return _exponent_words(
        f["t"],
        f["t_err"],
        "at fixed samples per box κ falls as the boxes shrink",
        "at fixed samples per box κ rises as the boxes shrink",
        "at fixed samples per box κ shows no trend in b",
        "κ ∝ b^t",
    )


def _operator_reduced(get: Loader) -> str:
    """The operator on ρ(E) alone against the simulated P(t): its rms of ln(P_op/P_sim) over the compared times
    against the spread of ln P_sim over the same times (the share of ln P_sim's variance it leaves, 1 − rms²/var,
    from the P(t) rows up to the compared time), and against the full operator's rms."""
    d = get("operator", None)["dissipative"]
    pts = [r for r in d["P_at"] if r["t"] <= d["compared_until"] and r.get("sim") and r["sim"] > 0]
    ln = np.log([r["sim"] for r in pts])
    red, full = d["lnP_rms_reduced"], d["lnP_rms_operator"]
    decades = (ln.max() - ln.min()) / math.log(10)
    share = 1 - red**2 / float(np.var(ln)) if len(pts) > 1 and np.var(ln) > 0 else float("nan")
    vs = "above" if red > full else "below" if red < full else "equal to"
    return (
        f"ρ(E) alone follows ln P(t) to an rms of {red:.2f}, {vs} the full operator's {full:.2f}, while P_sim "
        f"falls by {decades:.1f} decades over t = {pts[0]['t']:g} to {pts[-1]['t']:g}: its mean square is "
        f"{100 * (1 - share):.1f} % of the variance of ln P_sim at the table's times up to t = {pts[-1]['t']:g}"
    )


def _operator_t_star_spread(get: Loader) -> str:
    """The operator's spread of the survivors' energy at t* against the simulated one; the simulated spread's error
    is that of a sample standard deviation of N normal points, s/√(2(N − 1)) (the operator's is not recorded)."""
    d = get("operator", None)["dissipative"]
    s_op, s_sim = d["t_star_std_energy"]["operator"], d["t_star_std_energy"]["sim"]
    n = d["t_star_points_sim"]
    err = s_sim / math.sqrt(2 * (n - 1))
    z = (s_op - s_sim) / err
    if abs(z) <= Z_RESOLVED:
        side = "within 2σ of the simulated spread"
    else:
        side = f"{'wider' if z > 0 else 'narrower'} than the simulated spread by more than 2σ"
    d = max(0, 1 - math.floor(math.log10(err))) if err > 0 else 4  # two significant digits of the error
    return (
        f"its spread is {s_op:.{d}f} against {s_sim:.{d}f} ± {err:.{d}f} simulated ({_int(n)} survivors; the error of a sample "
        f"standard deviation, normal approximation): {side} (ratio {s_op / s_sim:.2f}, z = {signed(z)})"
    )


def _operator_cost(get: Loader) -> str:
    """The orbit-time for κ at 1 % of the P(t) route against the operator's lower bound, energy by energy: the P(t)
    route needs less where its cost lies below the operator's lower bound; where it does not, the bound decides
    nothing."""
    rows = sorted(get("operator", None)["cost"], key=lambda r: r["energy"])
    less = [r for r in rows if r["pt_orbit_time_1pct"] < r["op_orbit_time_1pct"]]
    ratios = [r["op_orbit_time_1pct"] / r["pt_orbit_time_1pct"] for r in less]
    es = ", ".join(f"{r['energy']:g}" for r in less)
    if len(less) == len(rows):
        head = f"for κ alone the P(t) route needs less orbit-time at all {len(rows)} cost energies ({es})"
    elif less:
        rest = ", ".join(f"{r['energy']:g}" for r in rows if r not in less)
        head = (
            f"for κ alone the P(t) route needs less orbit-time at E = {es}; at E = {rest} the operator's lower "
            "bound lies under the P(t) route's cost, which does not decide the order there"
        )
    else:
        return (
            "for κ alone the operator's lower bound lies under the P(t) route's cost at every cost energy, which "
            "does not decide which route is cheaper"
        )
    return head + f" (the operator's lower bound over the P(t) route's: {min(ratios):.1f} to {max(ratios):.1f})"


#: the energy at which the README quotes the finest partition's κ
OPERATOR_HEADLINE_ENERGY = 0.30


def _operator_finest(get: Loader) -> str:
    """Ulam's κ on the finest boxes (its statistical error) against fig2's κ0 at each energy, by the verdict rule:
    at :data:`OPERATOR_HEADLINE_ENERGY` with its verdict, and the energies where it differs."""
    rows = sorted(get("operator", None)["kappa_ulam"], key=lambda r: r["energy"])
    cells = [(r, verdict(r["kappa"], r["kappa_stat_err"], r["fig2_kappa"], r["fig2_err"])) for r in rows]
    head = next((c for c in cells if abs(c[0]["energy"] - OPERATOR_HEADLINE_ENERGY) < 1e-9), None)
    differ = [f"{r['energy']:g} (z = {signed(v.z)})" for r, v in cells if v.word == "differs"]
    out = []
    if head is not None:
        r, v = head
        out.append(
            f"the finest boxes alone give {_ve(r['kappa'], r['kappa_stat_err'])} at E = {r['energy']:g} "
            f"(statistical error), against fig2's κ0: {v.text()}"
        )
    out.append(
        f"of the {len(cells)} energies, they differ from it at E = {', '.join(differ)}"
        if differ
        else f"they differ from it at none of the {len(cells)} energies"
    )
    return "; ".join(out)


def _fig6_fit_range(get: Loader) -> str:
    """fig6's fits at the quick and the paper scale, matched by (pair, model, hazard): the ratio of their orbits
    per pair, the points each fit gains, and in how many fits the rms log residual grows (the ones where it does
    not, named)."""
    quick = {(r["pair"], r["model"], r["hazard"]): r for r in get("fig6", "quick")["fits"]}
    pairs = [
        (quick[k], r) for r in get("fig6", "paper")["fits"] if (k := (r["pair"], r["model"], r["hazard"])) in quick
    ]
    if not pairs:
        return "no fit is made at both scales"
    ratios = sorted({p["N"] / q["N"] for q, p in pairs})
    ratio = f"{ratios[0]:g}" if len(ratios) == 1 else f"{ratios[0]:g} to {ratios[-1]:g}"
    gained = [p["n_points"] - q["n_points"] for q, p in pairs]
    not_up = [
        f"{p['pair']} {p['model']} ({p['hazard']})" for q, p in pairs if p["rms_log_residual"] <= q["rms_log_residual"]
    ]
    grows = len(pairs) - len(not_up)
    text = (
        f"with {ratio} times the orbits per pair the fits take {min(gained)} to {max(gained)} more points each, and "
        f"the rms log residual grows in {grows} of the {len(pairs)} fits (pair × model × hazard)"
    )
    return text + (f"; it does not grow in {', '.join(not_up)}" if not_up else "")


def _ratios(xs) -> str:
    return ", ".join(f"{x:g}" for x in xs) + " E_c"


def _generality_resc_shift(get: Loader) -> str:
    """κ0 at the second escape radius against the default, per system and convention, sorted by the rows' verdicts
    (the verdicts the study wrote by the one rule: "shifts", "no shift resolved", "undetermined")."""
    d = get("generality", None)
    conventions = {"plateau": "all orbits", "escaping": "Escaping orbits"}
    out = []
    for label in d.get("systems") or {}:
        parts = []
        for conv, what in conventions.items():
            rows = sorted(
                (r for r in d["resc_kappa"] if r["label"] == label and r["convention"] == conv),
                key=lambda r: r["e_ratio"],
            )
            if not rows:
                continue
            shifts = [r for r in rows if str(r["verdict"]).startswith("shifts")]
            flat = [r["e_ratio"] for r in rows if str(r["verdict"]).startswith("no shift")]
            none = [r["e_ratio"] for r in rows if r not in shifts and r["e_ratio"] not in flat]
            words = (
                [
                    "shifts at "
                    + ", ".join(f"{r['e_ratio']:g} E_c ({_ve(r['shift']['value'], r['shift']['err'])})" for r in shifts)
                ]
                if shifts
                else []
            )
            words += [f"no shift resolved at {_ratios(flat)}"] if flat else []
            words += [f"undetermined (κ0 ill-defined at a radius) at {_ratios(none)}"] if none else []
            parts.append(f"{what}: " + "; ".join(words))
        r0 = next((r for r in d["resc_kappa"] if r["label"] == label), None)
        radius = f" (r_esc = {r0['r_esc']:.3g})" if r0 else ""
        out.append(f"For {label}{radius}, " + ". ".join(parts))
    return "κ0(1.03 r_s)/κ0(default) − 1 by system and convention. " + ". ".join(out)


def _generality_map_coverage(get: Loader) -> str:
    """The energies and systems the validity map has cells for, and where each cell's κ0 comes from."""
    d = get("generality", None)
    cells = d["validity_map"]
    grid = sorted(set(d["config"]["study"]["ratios"]))
    out = []
    for label in d.get("systems") or {}:
        mine = [c for c in cells if c["label"] == label]
        have = sorted({c["e_ratio"] for c in mine})
        missing = [x for x in grid if x not in have]
        beyond = [x for x in have if x not in grid]
        text = f"{label} {len(mine)} cells" + (
            f", the claims' grid without {_ratios(missing)}" if missing else ", the whole claims' grid"
        )
        out.append(text + (f" and {_ratios(beyond)} beyond it" if beyond else ""))
    return f"the map ({d.get('scale')} scale) has " + "; ".join(out)


def _side(a: dict, b: dict, what: str) -> str:
    """Where the value ``a`` lies against ``b`` by the verdict rule (2σ, their errors in quadrature), and its z."""
    z = (a["value"] - b["value"]) / math.hypot(a["err"], b["err"])
    side = f"within 2σ of {what}" if abs(z) <= Z_RESOLVED else f"{'above' if z > 0 else 'below'} {what}"
    return f"{side} (z = {signed(z)})"


def _move(a: dict, b: dict) -> tuple[str, float]:
    """The difference b − a with its error (in quadrature) and z, in words, and the z."""
    d, e = b["value"] - a["value"], math.hypot(a["err"], b["err"])
    return f"{_ve(d, e)}, z = {signed(d / e)}", d / e


def _generality_mu_radius(get: Loader) -> str:
    """μ measured from ⟨E⟩(t) and μ predicted from the conservative ⟨K⟩ at the default escape radius and the second
    one, per system, on the paper's window (``mu_by_window.paper``): whether the measured μ moves between the radii, where the prediction
    lies against the measured μ at each radius (2σ), whether it moves, and at which radii the two agree."""
    d = get("generality", None)
    out, agree = [], []
    for label, info in (d.get("systems") or {}).items():
        window = list((info.get("mu_by_window") or {}).get("paper", {}).get("window") or [])
        rows = [r for r in d["resc"] if r["label"] == label and r["window"] == window]
        rows = sorted(
            (r for r in rows if r.get("mu_measured") and r.get("mu_predicted")), key=lambda r: not r["default"]
        )
        if len(rows) != 2 or not rows[0]["default"] or rows[1]["default"]:
            continue
        (r0, r1), radii = rows, [f"{r['r_esc']:.3g}" for r in rows]
        moved, z_m = _move(r0["mu_measured"], r1["mu_measured"])
        measured = f"the measured μ {'moves' if abs(z_m) > Z_RESOLVED else 'does not move resolved at 2σ'} ({moved})"
        sides = [_side(r["mu_predicted"], r["mu_measured"], "it") for r in rows]
        shift, z_p = _move(r0["mu_predicted"], r1["mu_predicted"])
        z0, z1 = (
            (r["mu_predicted"]["value"] - r["mu_measured"]["value"])
            / math.hypot(r["mu_predicted"]["err"], r["mu_measured"]["err"])
            for r in rows
        )
        crosses = min(abs(z0), abs(z1)) > Z_RESOLVED and z0 * z1 < 0
        predicted = (
            f"the prediction from the conservative ⟨K⟩ lies {sides[0]} at r_esc = {radii[0]} (the default) and "
            f"{sides[1]} at {radii[1]}"
            + (": it crosses the measured μ between the radii" if crosses else "")
            + f"; the prediction {'moves' if abs(z_p) > Z_RESOLVED else 'does not move resolved at 2σ'} ({shift})"
        )
        out.append(f"for {label} on [{window[0]:g}, {window[1]:g}] (the paper's window), {measured}; {predicted}")
        ok = [radii[i] for i, z in enumerate((z0, z1)) if abs(z) <= Z_RESOLVED]
        agree.append(f"{label} at {' and '.join(ok)}" if ok else f"{label} at neither radius")
    return (
        "μ between the default escape radius and the second one: "
        + "; ".join(out)
        + ". The prediction agrees with the measured μ within 2σ for "
        + "; ".join(agree)
    )


def _resc_other_radii(d: dict) -> dict[str, list[tuple[str, dict]]]:
    """{energy key: [(radius key, shift), …]} of the κ shifts against the reference radius, the reference left out."""
    ref = f"r_esc={d['r_ref']:g}"
    return {e: [(r, row["shift_vs_ref"]) for r, row in rows.items() if r != ref] for e, rows in d["kappa"].items()}


def _resc_shifts(get: Loader) -> str:
    """Per energy: whether the shifts of κ against the reference radius are resolved from zero (2σ) and whether the
    radii's shifts agree with each other (2σ, their errors in quadrature)."""
    out = []
    for e, shifts in _resc_other_radii(get("resc", None)).items():
        z = [abs(s["value"]) / s["err"] for _, s in shifts]
        where = e.replace("E=", "E = ")
        if min(z) >= Z_RESOLVED:
            words = f"every shift lies {min(z):.1f}–{max(z):.1f}σ from zero"
        elif max(z) < Z_RESOLVED:
            words = f"no shift is resolved from zero (|z| ≤ {max(z):.1f})"
        else:
            words = f"{sum(x >= Z_RESOLVED for x in z)} of {len(z)} shifts are resolved from zero"
        pair = max(
            abs(a["value"] - b["value"]) / math.hypot(a["err"], b["err"])
            for i, (_, a) in enumerate(shifts)
            for _, b in shifts[i + 1 :]
        )
        same = "the radii's shifts agree within 2σ" if pair <= Z_RESOLVED else "the radii's shifts differ"
        out.append(f"at {where} {words}, {same} (largest difference {pair:.1f}σ)")
    return "; ".join(out)


def _resc_scale_moves(get: Loader) -> str:
    """How far the shifts moved from the quick to the paper scale, in units of their quick-scale errors."""
    quick, paper = _resc_other_radii(get("resc", "quick")), _resc_other_radii(get("resc", "paper"))
    moves = []
    for e, shifts in paper.items():
        q = dict(quick.get(e, []))
        for r, s in shifts:
            if r in q and q[r]["err"]:
                moves.append((abs(s["value"] - q[r]["value"]) / q[r]["err"], e, r, q[r], s))
    z, e, r, a, b = max(moves, key=lambda m: m[0])
    where = f"{e.replace('E=', 'E = ')}, {r.replace('r_esc=', 'r_esc = ')}"
    return (
        f"the κ shifts moved by at most {z:.1f}σ of their quick-scale errors (the largest at {where}: "
        f"{_ve(a['value'], a['err'])} → {_ve(b['value'], b['err'])})"
    )


#: the systems' names as the pages write them (any other label is written as it is)
_SYSTEM_NAMES = {"henon_heiles": "Hénon–Heiles", "contopoulos": "Contopoulos", "barbanis": "Barbanis"}


def _saddle_t_max(d: dict, label: str) -> float:
    """The t_max of a system's runs in the saddle study: the system's own, else the study's."""
    study = d["config"]["study"]
    system = next((s for s in study["systems"] if s["label"] == label), {})
    return float(system.get("t_max", study["t_max"]))


def _saddle_lambda_offset(get: Loader) -> str:
    """λ∞ (the 1/T fit's intercept) against ΣΛ/ΣT per point, by the fit's 1/T term Λ₀ (``b``) and its σ: Λ₀ > 0
    resolved at 2σ puts λ∞ below ΣΛ/ΣT, Λ₀ < 0 above; each point with its selection's t_min as a share of t_max
    (the lifetimes fitted run from t_min to t_max: the fit's lever arm)."""
    d = get("saddle", None)
    above: dict[str, list[str]] = {}
    below: dict[str, list[str]] = {}
    flat = []
    for p in d["saddle"]:
        b = (p.get("lyapunov_detail") or {}).get("b")
        if not b or b.get("value") is None or not b.get("err") or p.get("t_min") is None:
            continue
        share = p["t_min"] / _saddle_t_max(d, p["system"])
        z = b["value"] / b["err"]
        if abs(z) <= Z_RESOLVED:
            flat.append(share)
            continue
        side = below if z > 0 else above
        side.setdefault(_SYSTEM_NAMES.get(p["system"], p["system"]), []).append(
            f"{p['ratio']:g} (Λ₀ = {_ve(b['value'], b['err'])}, t_min = {share:.2f} t_max)"
        )

    def points(side: dict[str, list[str]]) -> str:
        return "; ".join(f"{name} E/E_c = {', '.join(cells)}" for name, cells in side.items())

    parts = []
    if below:
        parts.append(f"Λ₀ > 0 by more than 2σ, λ∞ below ΣΛ/ΣT, at {points(below)}")
    if above:
        parts.append(f"Λ₀ < 0 by more than 2σ, λ∞ above ΣΛ/ΣT, at {points(above)}")
    if flat:
        rest = "the other" if below or above else "all"
        which = (
            f"{rest} {len(flat)} points" if len(flat) > 1 else ("the other point" if below or above else "the point")
        )
        span = f"{flat[0]:.2f}" if len(flat) == 1 else f"from {min(flat):.2f} to {max(flat):.2f}"
        parts.append(f"Λ₀ within 2σ of 0 at {which} (t_min {span} t_max)")
    return ". ".join(parts) if parts else "no point of this scale has a 1/T fit"


def _saddle_no_lyapunov(get: Loader) -> str:
    """The points without λ̄ (``lyapunov`` None with a 1/T fit, ``lyapunov_detail.by_T``): per point λ̄(T) in the
    first and last bins of T, whether it falls, stays or rises between them by the verdict rule (2σ, both errors),
    λ∞ of the fit, and the share of the selected orbits whose finite-time exponent lies below the stated fraction
    of ΣΛ/ΣT (``hyperbolic``), with d₁ of the section and on lines where measured."""
    d = get("saddle", None)
    cells = []
    for p in d["saddle"]:
        det = p.get("lyapunov_detail") or {}
        if p.get("lyapunov") is not None or len(det.get("by_T") or []) < 2:
            continue
        a, b = det["by_T"][0], det["by_T"][-1]
        v = verdict(b["value"], b["err"], a["value"], a["err"])
        move = "stays at" if v.word == "agrees" else ("falls to" if b["value"] < a["value"] else "rises to")
        text = (f"{p['ratio']:g} (λ̄(T) = {_ve(a['value'], a['err'])} at T = {a['T']:.0f} {move} "
                f"{_ve(b['value'], b['err'])} at T = {b['T']:.0f}, z = {signed(v.z)}; λ∞ = "
                f"{_ve(det['extrapolated'], det['extrapolated_err'])}")  # fmt: skip
        h = p.get("hyperbolic")
        if h:
            mid = next(s for s in h["shares"] if s["threshold"] == h["threshold"])
            text += f"; Λ/T below {h['threshold']:g}·ΣΛ/ΣT at a share {_ve(mid['share']['value'], mid['share']['err'])} of the orbits"
        if p.get("d1") is not None:
            text += f"; d₁ = {_ve(p['d1'], p['d1_err'])} on the section"
        if p.get("d1_lines"):
            text += f", {_ve(p['d1_lines']['value'], p['d1_lines']['err'])} on lines"
        cells.append((p["system"], text + ")"))
    if not cells:
        return "every point of this scale with a 1/T fit has λ̄"
    return f"no λ̄ at {_by_system(cells)}"


def _saddle_tangent_orbits(get: Loader) -> str:
    """Whether λ̄'s tangent run followed the selected orbits: with the key ``tangent_same_orbits`` (per point: the
    selected orbits and those the tangent run ended at the main run's t_end) the counts summed over the points;
    without it (a scale made before that check) the tangent run was the earlier one, which followed other
    orbits, and λ̄ rests on the orbits it kept (``lyapunov_detail.n_orbits`` per point)."""
    d = get("saddle", None)
    pts = [p for p in d["saddle"] if p.get("lyapunov") is not None]
    if not pts:
        return "no point of this scale has λ̄"
    checked = [p["tangent_same_orbits"] for p in pts if p.get("tangent_same_orbits")]
    if len(checked) == len(pts):
        same, sel = sum(c["same_t_end"] for c in checked), sum(c["selected"] for c in checked)
        where = "" if len(pts) == 1 else f" (over its {len(pts)} points)"
        return f"at this scale the tangent run ended {same:,} of {sel:,} selected orbits at the main run's t_end{where}".replace(
            ",", " "
        )
    kept = [int((p.get("lyapunov_detail") or {}).get("n_orbits") or 0) for p in pts]
    lo, hi = (f"{k:,}".replace(",", " ") for k in (min(kept), max(kept)))
    span = lo if lo == hi else f"from {lo} to {hi}"
    return (
        "this scale's numbers come from an earlier tangent run, whose tangent vector entered the step-size control "
        f"and so followed other orbits than the selected ones; λ̄ rests on the orbits that run kept, {span} per point"
    )


def _by_system(cells: list[tuple[str, str]]) -> str:
    """[(system label, cell)] as "Hénon–Heiles E/E_c = a, b; Barbanis E/E_c = c", systems in their first order."""
    groups: dict[str, list[str]] = {}
    for label, cell in cells:
        groups.setdefault(_SYSTEM_NAMES.get(label, label), []).append(cell)
    return "; ".join(f"{name} E/E_c = {', '.join(cs)}" for name, cs in groups.items())


def _saddle_floor_scan(get: Loader) -> str:
    """Whether d₁ moves with the floor of its scaling range: per point with ``d1_floor_scan``, d₁ at each other
    floor (the rule's floor times ``rules.d1_floor_factors``) against d₁ at the rule's floor (factor 1) by the
    verdict rule (within 2σ, both errors; the floors share their points, so the test is loose). The points where
    some floor moves d₁ beyond 2σ (those floors named with d₁ and z), those where none does, those without d₁ at
    the rule's floor, and the floors without d₁ (the estimator refused them: fewer than four scales above)."""
    d = get("saddle", None)
    moved, still, untested, refused = [], [], [], {}
    for p in d["saddle"]:
        scan = p.get("d1_floor_scan")
        if not scan:
            continue
        where = (p["system"], f"{p['ratio']:g}")
        ref = next((r["d1"] for r in scan["rows"] if r["factor"] == 1.0 and r["d1"]), None)
        if ref is None:
            untested.append(where)
            continue
        out = []
        for r in scan["rows"]:
            if r["factor"] == 1.0:
                continue
            if not r["d1"]:
                refused.setdefault(f"{r['factor']:g}", []).append(where)
                continue
            v = verdict(r["d1"]["value"], r["d1"]["err"], ref["value"], ref["err"])
            if v.word != "agrees":
                out.append(f"×{r['factor']:g}: d₁ = {_ve(r['d1']['value'], r['d1']['err'])}, z = {signed(v.z)}")
        if out:
            moved.append((where[0], f"{where[1]} ({'; '.join(out)})"))
        else:
            still.append(where)
    if not (moved or still or untested):
        return "no point of this scale has d₁'s floor scan"
    factors = ", ".join(f"{f:g}" for f in d["rules"]["d1_floor_factors"] if f != 1.0)
    parts = []
    if moved:
        parts.append(f"d₁ moves beyond 2σ with the floor at {_by_system(moved)}")
    if still:
        head = "at every other point" if moved or untested else "at every point"
        parts.append(f"d₁ stays within 2σ with the floor × {factors} {head} ({_by_system(still)})")
    if untested:
        parts.append(f"no d₁ at the floor at {_by_system(untested)}")
    for fac, where in refused.items():
        parts.append(f"no d₁ with the floor × {fac} (fewer than four scales above it) at {_by_system(where)}")
    return "; ".join(parts)


#: the readings a page may name: ``[[reading:<name>]]``
READINGS: dict[str, Callable[[Loader], str]] = {
    "basins.cutoff": _basins_cutoff,
    "basins.energy_scan": _basins_energy_scan,
    "basins.kantz_grassberger": _basins_kantz_grassberger,
    "basins.smooth_order": _basins_smooth_order,
    "fig5.premise": _fig5_premise,
    "generality.b_onset": _generality_b_onset,
    "generality.law_slope": _generality_law_slope,
    "generality.escape_excess": _generality_escape_excess,
    "generality.mu_gap": _generality_mu_gap,
    "generality.one_exponential": _generality_one_exponential,
    "generality.hh_1_05": _generality_hh_1_05,
    "noise.kramers": _noise_kramers,
    "noise.turnover": _noise_turnover,
    "noise.turnover_theory": _noise_turnover_theory,
    "noise.turnover_barriers": _noise_turnover_barriers,
    "noise.saddles_turnover": _noise_saddles_turnover,
    "noise.low_gamma_theory": _noise_low_gamma_theory,
    "noise.no_drag": _noise_no_drag,
    "noise.no_drag_survivors": _noise_no_drag_survivors,
    "noise.finite_barrier": _noise_finite_barrier,
    "noise.absorbing_radius": _noise_absorbing_radius,
    "noise.two_saddles": _noise_two_saddles,
    "b_relation": _b_relation,
    "fig5.tightening": _fig5_tightening,
    "fig5.shrink": _fig5_shrink,
    "operator.residuals": _operator_residuals,
    "operator.convergence": _operator_convergence,
    "operator.mixed_refinement": _operator_mixed_refinement,
    "generality.validity": _generality_validity,
    "generality.regular_majority": _generality_regular_majority,
    "generality.indicator_systematic": _generality_indicator_systematic,
    "generality.resc_rule": _generality_resc_rule,
    "generality.claims_by_system": _generality_claims_by_system,
    "generality.resc_shift": _generality_resc_shift,
    "generality.map_coverage": _generality_map_coverage,
    "generality.mu_radius": _generality_mu_radius,
    "resc.shifts": _resc_shifts,
    "resc.paper_radius": _resc_paper_radius,
    "resc.scale_moves": _resc_scale_moves,
    "fig2.law_below_break": _fig2_law_below_break,
    "fig5.ours_5b": _fig5_ours_5b,
    "fig5.eps_first": _fig5_eps_first,
    "fig5.rows_by_scale": _fig5_rows_by_scale,
    "fig5.intervals_by_scale": _fig5_intervals_by_scale,
    "noise.reactivation": _noise_reactivation,
    "noise.window_halves": _noise_window_halves,
    "operator.tolerance": _operator_tolerance,
    "operator.samples_trend": _operator_samples_trend,
    "operator.box_trend": _operator_box_trend,
    "operator.reduced": _operator_reduced,
    "operator.t_star_spread": _operator_t_star_spread,
    "operator.cost": _operator_cost,
    "operator.finest": _operator_finest,
    "fig6.fit_range": _fig6_fit_range,
    "saddle.floor_scan": _saddle_floor_scan,
    "saddle.lambda_offset": _saddle_lambda_offset,
    "saddle.no_lyapunov": _saddle_no_lyapunov,
    "saddle.tangent_orbits": _saddle_tangent_orbits,
}


def reading(get: Loader, name: str) -> str:
    """reading(loader, name) -> the sentence of :data:`READINGS` ``name``, its negative numbers with the minus sign;
    ``get(study, scale)`` returns a study's numbers JSON (``scale=None``: the headline scale). KeyError for a name it
    does not know. Pages name readings as ``[[reading:name]]`` (:func:`hhscatter.publish.numbers.render_refs`).

    Examples
    --------
    >>> docs = {"noise": {"kramers": [{"barrier_over_T": x, "ratio": 0.9, "ratio_err": 0.01} for x in (3, 4, 5)]}}
    >>> reading(lambda study, scale: docs[study], "noise.kramers")[:58]
    'the ratio lies below 1 by more than 2σ at ΔE/T = 3, 4, 5; '
    """
    if name not in READINGS:
        raise KeyError(f"no reading {name!r} (known: {', '.join(sorted(READINGS))})")
    return typographic_minus(READINGS[name](get))  # a negative number with the minus sign, as every rendered number
