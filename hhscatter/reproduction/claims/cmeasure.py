"""Claims 2 and 5 (distance): κ from the c-measure against κ0, and Fig. 5's paired distance of the survivors."""

from __future__ import annotations

import math

import numpy as np

from hhscatter.analysis.dissipative.decay import time_to_energy
from hhscatter.analysis.geometry import distance as dist
from hhscatter.analysis.geometry import paired_distance as pdist
from hhscatter.analysis.geometry.distance import first_crossings
from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.stats.verdicts import signed
from hhscatter.analysis.survival.cmeasure import (
    cmeasure_sample_from_sections,
    kappa_from_cmeasure,
)
from hhscatter.reproduction.claims.kappa import rate_or_reason
from hhscatter.reproduction.claims.keys import cm_key, sec_key
from hhscatter.reproduction.claims.records import z_verdict
from hhscatter.reproduction.model_tables import number_or_none


def c5_window(p, ec):
    """(t_from, t_to) of the dissipative section recording: t* = ln(E0/E*)/(μγ) for every μ in c5_mu_range, + pad."""
    E0, Es = p.e0_ratio * ec, p.c5_ratio * ec
    lo, hi = p.c5_mu_range
    return (float(time_to_energy(E0, Es, hi, p.mu_gamma)), float(time_to_energy(E0, Es, lo, p.mu_gamma)) + p.c5_pad)


def cm_sample(runs, label, r):
    """The c-measure of the conservative run at E = r·E_c (orbits still inside at cm_t_max, censored, dropped):
    its recording time t_rec = ⌈τ0 + cm_rec_efolds/κ⌉ (κ, τ0 of the run's escaping orbits, fig1's sprinkler rule),
    the return-time sample of Eq. (eqn:kappa_cmeasure_truetime) on [t_rec, cm_t_to − cm_margin] and the first
    crossing at t ≥ t_rec of each orbit (sprinkler points). Returns a dict (κ_cm None with a reason where not)."""
    p = runs.params
    key = cm_key(label, r)
    lt = runs.lifetimes(key)
    trapped = float((lt["outcome"] == "censored").mean())
    out = {
        "ratio": r,
        "n": len(lt),
        "trapped_fraction": trapped,
        "kappa_cm": None,
        "kappa_cm_err": None,
        "mu_exit": None,
        "n_samples": 0,
        "n_orbits": 0,
        "n_undetermined": 0,
        "t_rec": None,
        "t_to": None,
        "points": None,
        "points_all": None,
        "reason": "",
    }
    esc = lt[lt["outcome"] != "censored"]
    res, why = rate_or_reason(esc, p.min_survivors)
    if res is None:
        out["reason"] = f"no κ, τ0 from the escaping orbits' P(t) for t_rec: {why}"
        return out
    t_rec = float(math.ceil(res.tau0 + p.cm_rec_efolds / res.kappa))
    t_to = p.cm_t_to - p.cm_margin
    out.update(t_rec=t_rec, t_to=t_to)
    if t_rec >= p.cm_t_to:
        out["reason"] = (
            f"t_rec = ⌈τ0 + {p.cm_rec_efolds:g}/κ⌉ = {t_rec:g} ≥ cm_t_to = {p.cm_t_to:g} (escaping orbits' "
            f"τ0 = {res.tau0:.0f}, κ = {res.kappa:.3g}): no relaxed sample within the recording"
        )
        return out
    # only crossings at t ≥ t_rec enter (first crossings, return times: a crossing's successor is later), so the
    # reader drops the rest (the sticky systems' tables are ~10⁷ rows at paper scale)
    sec = runs.sections(key, t_rec)
    out["points"] = first_crossings(sec[sec["traj_id"].isin(esc["traj_id"])], t_rec)
    out["points_all"] = first_crossings(sec, t_rec)  # the censored orbits kept: all conservative survivors
    if not t_to > t_rec:
        out["reason"] = (
            f"t_rec = {t_rec:g} ≥ cm_t_to − cm_margin = {t_to:g} (escaping orbits' τ0 = {res.tau0:.0f}, "
            f"κ = {res.kappa:.3g}): no sampling window"
        )
        return out
    with counted("claims.cmeasure.sample"):
        T, n_exit, n_und, orb, exit_orb = cmeasure_sample_from_sections(
            sec, lt, t_rec, t_to, t_record_end=p.cm_t_to, drop_censored=True, with_orbits=True
        )
    n_orb = int(np.unique(np.concatenate([orb, exit_orb])).size) if T.size + n_exit else 0
    out.update(n_samples=int(T.size + n_exit), n_orbits=n_orb, n_undetermined=int(n_und))
    if n_orb < p.min_survivors:
        out["reason"] = f"only {n_orb} orbits cross the section in [{t_rec:g}, {t_to:g}] (< min_survivors)"
        return out
    k = kappa_from_cmeasure(T, n_exit, orbits=orb, exit_orbits=exit_orb, n_boot=p.n_boot, rng=p.fit_seed)
    out.update(kappa_cm=k.kappa, kappa_cm_err=k.kappa_err, mu_exit=k.mu_exit)
    return out


def claim2(runs, claims, label, table, samples):
    """κ_cm/κ0 − 1 per cm ratio against κ0 of the claim-1 grid run at that energy (independent orbits), in the
    paper's convention (all orbits, plateau windows) and with the escaping orbits only (like for like with the
    c-measure, whose censored orbits are dropped). Returns the JSON rows."""
    rows = []
    for r in runs.params.cm_ratios:
        s = samples[r]
        row = {k: v for k, v in s.items() if not k.startswith("points")}
        for conv, what in (
            ("plateau", "all orbits, plateau windows: the paper's κ0"),
            ("escaping", "escaping orbits only, as the c-measure"),
        ):
            k0 = table[(table["convention"] == conv) & np.isclose(table["ratio"], r)].iloc[0]
            row[f"kappa_{conv}"], row[f"kappa_{conv}_err"] = (
                number_or_none(k0["kappa"]),
                number_or_none(k0["kappa_err"]),
            )
            q = f"κ_cm/κ0 − 1 at E/E_c = {r:g} ({what})"
            cm = (
                f"κ_cm = {s['kappa_cm']:.4g} ± {s['kappa_cm_err']:.2g}"
                if s["kappa_cm"] is not None
                else "κ_cm undetermined"
            )
            note = (
                f"Eq. (eqn:kappa_cmeasure_truetime) on the crossings of [{s['t_rec']}, {s['t_to']}] of a second "
                f"conservative run ({s['n']} orbits, {s['n_orbits']} sampled, {s['n_samples']} crossings, "
                f"μ_c(𝓔) = {s['mu_exit'] if s['mu_exit'] is None else round(s['mu_exit'], 4)}; "
                f"{s['trapped_fraction']:.0%} still inside at t_max dropped); {cm} (bootstrap over orbits); "
                f"κ0 = {k0['kappa']:.4g} ± {k0['kappa_err']:.2g} of the claim-1 run (independent orbits)"
            )
            if s["kappa_cm"] is None:
                claims.add("2", q, label, None, None, f"undetermined: {s['reason']}", note, 0.0)
                continue
            if not bool(k0["defined"]):
                claims.add(
                    "2",
                    q,
                    label,
                    None,
                    None,
                    f"undetermined: κ0 ill-defined ({k0['trapped_fraction']:.0%} of the orbits still inside at "
                    f"t_max; {k0['reason']}); {cm}",
                    note,
                    0.0,
                )
                continue
            v = s["kappa_cm"] / k0["kappa"] - 1
            # the absolute form of the ratio's error (Measured.ratio's relative form differs in the last digit)
            e = math.hypot(s["kappa_cm_err"] / k0["kappa"], s["kappa_cm"] * k0["kappa_err"] / k0["kappa"] ** 2)
            row[f"ratio_minus_1_{conv}"] = Measured.of(v, e).to_dict()
            claims.add(
                "2",
                q,
                label,
                v,
                e,
                z_verdict(v, e, 0.0, "κ_cm = κ0", f"κ_cm ≠ κ0 ({signed(100 * v, '+.0f')} %)"),
                note,
                0.0,
            )
        rows.append(row)
    return rows


def claim5_distance(runs, claims, label, m, E0, mu, samples):
    """Fig. 5's test: the first section crossing after t* (E0 e^{−μγt*} = c5_ratio·E_c, μ measured) of the
    dissipative survivors against the c-measures μ_c^{E(t*)} and μ_c^{E0} (sprinkler points of the conservative
    runs: the first crossing after t_rec), paired debiased Hellinger at one box side, half-sampling the orbits of
    every set (one group: the runs share the seed, hence the id space); no cut on any set. Two references: the
    c-measure proper (orbits still inside at cm_t_max, censored, dropped) and all conservative survivors (kept).
    Δ = d(μ_c^{E0}) − d(μ_c^{E(t*)}) > 0: closer to μ_c^{E(t*)}. Returns the JSON record."""
    p = runs.params
    ec = m.critical_energy
    t_star = float(time_to_energy(E0, p.c5_ratio * ec, mu, p.mu_gamma))
    t_lo, t_hi = c5_window(p, ec)
    ss, s0 = samples[p.c5_ratio], samples[float(p.e0_ratio)]
    rec = {
        "t_star": t_star,
        "E_star": p.c5_ratio * ec,
        "gamma": p.mu_gamma,
        "box": p.c5_box_frac * m.saddle_radius,
        "t_rec_star": ss["t_rec"],
        "t_rec_E0": s0["t_rec"],
    }
    refs = {"c-measure": "μ_c: censored orbits dropped", "all": "all conservative survivors, censored kept"}
    qs = {k: f"Fig. 5's distance: d(μ_c^E0) − d(μ_c^E(t*)), E(t*) = {p.c5_ratio:g} E_c ({v})" for k, v in refs.items()}
    if not t_lo <= t_star <= t_hi - p.c5_pad:
        for q in qs.values():
            claims.add(
                "5",
                q,
                label,
                None,
                None,
                f"undetermined: t* = {t_star:.1f} outside the recorded window "
                f"[{t_lo:.1f}, {t_hi - p.c5_pad:.1f}] (μ = {mu:.3g} outside c5_mu_range)",
                "",
                0.0,
            )
        return rec
    key = sec_key(label, p.mu_gamma)
    sec = runs.sections(key, t_star)
    diss = dist.first_crossings(sec, t_star)
    rec.update(
        n_alive=int((runs.lifetimes(key)["t_end"] > t_star).sum()),
        n_diss=len(diss),
        mean_E_diss=float(diss["energy"].mean()) if len(diss) else None,
    )
    for kind, col in (("c-measure", "points"), ("all", "points_all")):
        q, ref_s, ref_0 = qs[kind], ss[col], s0[col]
        if ref_s is None or ref_0 is None:
            claims.add(
                "5",
                q,
                label,
                None,
                None,
                "undetermined: no c-measure sample at E(t*) or E0: "
                + "; ".join(x["reason"] for x in (ss, s0) if x[col] is None),
                "",
                0.0,
            )
            continue
        sizes = f"{len(diss)} / {len(ref_s)} / {len(ref_0)} points (survivors / E(t*) / E0)"
        rec[kind] = r = {"n_ref_star": len(ref_s), "n_ref_E0": len(ref_0)}
        sets = {
            n: pdist.UnitSet(dist.points(df), df["traj_id"].to_numpy(), "orbits")
            for n, df in (("diss", diss), ("star", ref_s), ("E0", ref_0))
        }
        allpts = np.concatenate([x.points for x in sets.values()])
        extent = (
            (float(allpts[:, 0].min()), float(allpts[:, 0].max()), float(allpts[:, 1].min()), float(allpts[:, 1].max()))
            if len(allpts)
            else (0.0, 1.0, 0.0, 1.0)
        )
        try:
            if min(len(diss), len(ref_s), len(ref_0)) < 4:
                raise ValueError(sizes)
            reps = pdist.paired_hellinger_replicates(
                sets,
                [("diss", "star"), ("diss", "E0")],
                [rec["box"]],
                extent,
                offsets=p.c5_offsets,
                n_boot=p.c5_boot,
                seed=p.fit_seed,
            )[:, :, 0]
        except ValueError as exc:  # too few points (tiny scale, or a KAM-dominated system)
            claims.add("5", q, label, None, None, f"undetermined: too few points ({exc})", sizes, 0.0)
            continue
        d, lo, hi = pdist.percentile_interval(reps[:, 1] - reps[:, 0], p.c5_level)
        ds, ds_lo, ds_hi = pdist.percentile_interval(reps[:, 0], p.c5_level)
        d0, d0_lo, d0_hi = pdist.percentile_interval(reps[:, 1], p.c5_level)
        r.update(
            delta={"value": d, "interval": [lo, hi]},
            d_star={"value": ds, "interval": [ds_lo, ds_hi]},
            d_E0={"value": d0, "interval": [d0_lo, d0_hi]},
            extent=list(extent),
        )
        lev = int(100 * p.c5_level)
        verdict = (
            f"closer to μ_c^E(t*) ({lev} % interval [{signed(lo, '+.3f')}, {signed(hi, '+.3f')}] excludes 0)"
            if lo > 0
            else f"closer to μ_c^E0 ({lev} % interval [{signed(lo, '+.3f')}, {signed(hi, '+.3f')}])"
            if hi < 0
            else f"no significant difference ({lev} % interval [{signed(lo, '+.3f')}, {signed(hi, '+.3f')}] contains 0)"
        )
        claims.add(
            "5",
            q,
            label,
            d,
            (hi - lo) / (2 * 1.96),
            verdict,
            f"t* = {t_star:.1f} (μ measured, γ = {p.mu_gamma:g}); the survivors' first crossing after t* "
            f"(mean E/E_c {rec['mean_E_diss'] / ec:.3f}) against the first crossing after t_rec = "
            f"{rec['t_rec_star']:g} / {rec['t_rec_E0']:g} of conservative runs at E(t*) / E0; {sizes}; "
            f"debiased Hellinger d = {ds:.3f} / {d0:.3f} at box {rec['box']:.3g} (= {p.c5_box_frac:g} r_s), "
            f"{p.c5_offsets**2} grid placements, {p.c5_boot} paired half-samples over orbits; no cut on any "
            f"set; err = interval width/3.92",
            0.0,
        )
    return rec
