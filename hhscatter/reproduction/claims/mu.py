"""Claims 3 and 5 (moment): μ measured from ⟨E⟩(t), μ predicted from the conservative 2⟨K⟩/E, the survivors' own ⟨K⟩."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.dissipative.decay import (
    bootstrap_mu_first_orbits,
    fit_energy_decay,
    inside_mean_energy,
    snapshot_grid,
)
from hhscatter.analysis.dissipative.kinetic import (
    decay_path,
    kinetic_fraction_by_time,
    kinetic_fraction_from_energies,
    microcanonical_kinetic_fraction,
)
from hhscatter.analysis.stats.library_warnings import counted
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.stats.verdicts import signed
from hhscatter.reproduction.claims.keys import diss_key, probe_key
from hhscatter.reproduction.claims.records import z_verdict


def mu_conservative(runs, label, m, fits, keys=None):
    """2⟨K⟩/E of the conservative flow per probe ratio (c-measure: trapped orbits dropped; all survivors beside)
    and the microcanonical value of the well below E_c."""
    p = runs.params
    rows = []
    keys = keys or {r: probe_key(label, r) for r in p.probe_ratios}
    for r, key in keys.items():
        # κ, τ0 of the escaping orbits of the κ0(E) run at r: defined even where a trapped plateau is not
        res = fits.get(
            ("escaping", min((k[1] for k in fits if isinstance(k, tuple)), key=lambda x: abs(x - r), default=math.nan))
        )
        t0, t1, relaxed = probe_window(res, p)
        if t0 is None:
            rows.append(
                {"system": label, "ratio": r, "kind": "c-measure", "mu": math.nan, "mu_err": math.nan, "relaxed": False}
            )
            continue
        lt = runs.lifetimes(key)
        # only the rows the average uses (kinetic_fraction_from_energies keeps t_from ≤ t ≤ t_to): the same
        # result, without reading the sticky systems' whole probe tables (2.5e7 rows at paper scale)
        with counted("claims.mu.probe_window"):  # an empty window (no snapshot in it) is counted, not printed
            sn = runs.snapshots(key, t_from=t0, t_to=t1)
        escaping = lt.loc[lt["outcome"] != "censored", "traj_id"].to_numpy()
        for kind, keep in (("c-measure", escaping), ("all survivors", None)):
            k = kinetic_fraction_from_energies(
                sn["traj_id"], sn["t"], sn["energy"], p.probe_gamma, t0, t1, keep=keep, n_boot=p.n_boot, rng=p.fit_seed
            )
            rows.append(
                {
                    "system": label,
                    "ratio": r,
                    "kind": kind,
                    "mu": k.value,
                    "mu_err": k.err,
                    "t_from": t0,
                    "t_to": t1,
                    "relaxed": relaxed,
                    "n_orbits": k.n_orbits,
                    "n_intervals": k.n_intervals,
                }
            )
    for r in p.mc_ratios:
        v = microcanonical_kinetic_fraction(m.potential, r * m.critical_energy, 2.5 * m.saddle_radius)
        rows.append({"system": label, "ratio": r, "kind": "microcanonical well", "mu": v, "mu_err": 0.0})
    return rows


def probe_window(res, p):
    """(t_from, t_to, relaxed) of the probe average: [τ0 + n_rec/κ, + n_sample/κ] (κ, τ0 of the escaping orbits);
    where it reaches beyond probe_t_max, the last half of the probe run, flagged relaxed = False."""
    if res is None or not (res.kappa > 0):
        return None, None, False
    t0 = res.tau0 + p.probe_rec_efolds / res.kappa
    t1 = t0 + p.probe_sample_efolds / res.kappa
    if t1 <= p.probe_t_max:
        return t0, t1, True
    return max(res.tau0, p.probe_t_max / 2), p.probe_t_max, False


def mu_of_E(mu_rows: pd.DataFrame, ec: float, shift: float = 0.0, kind: str = "c-measure"):
    """μ(E): microcanonical below E_c, the ``kind`` value above (± shift·σ), linear in E/E_c, flat beyond."""
    below = mu_rows[mu_rows["kind"] == "microcanonical well"]
    above = mu_rows[(mu_rows["kind"] == kind) & np.isfinite(mu_rows["mu"])]
    r = np.concatenate([below["ratio"], above["ratio"]])
    v = np.concatenate([below["mu"], above["mu"] + shift * above["mu_err"].fillna(0.0)])
    o = np.argsort(r)
    r, v = r[o], v[o]
    return lambda E: np.interp(np.asarray(E) / ec, r, v)


def mu_measured(runs, label, m, E0, key=None, n=None):
    """fig3's μ: ⟨E⟩(t) of the orbits not escaped (settled continued), log fit on each window of
    :func:`mu_windows` (all orbits, streamed part by part); bootstrap error over orbits, as fig3 on the orbits
    traj_id < n_boot_orbits with the errors scaled by √(K/N) (the snapshot table of 10⁶ sticky orbits is
    ~10⁸ rows: read whole it took 5.8 GB). The survivors' own-⟨K⟩ path (claim 5, moment test) is taken on the
    same K orbits. Returns ({name: (μ, σ)}, ⟨E⟩ table, own-⟨K⟩ result)."""
    p = runs.params
    key = key or diss_key(label, p.mu_gamma)
    n = n or p.diss_n
    ime = inside_mean_energy(runs.snapshot_parts(key), m.critical_energy)
    wins = mu_windows(runs)
    k = min(p.n_boot_orbits, n)
    rows = runs.snapshots(key, max_id=k)
    b, scale = bootstrap_mu_first_orbits(
        rows, n, k, E0, p.mu_gamma, list(wins.values()), n_boot=p.n_boot, seed=p.fit_seed
    )
    out = {}
    for name, w in wins.items():
        mu = fit_energy_decay(ime.inside["t"], ime.inside["mean_E"], E0, p.mu_gamma, w).mu
        bw = b[(b["t_lo"] == w[0]) & (b["t_hi"] == w[1])]
        out[name] = (mu, float(bw["mu"].std(ddof=1)) * scale)
    return out, ime.inside, mu_own(rows, E0, p.mu_gamma, wins)


def own_path_mu(rows, E0, gamma, wins):
    """{window: μ} of the path d ln E/dt = −γ μ_K(t), μ_K the survivors' own 2⟨K⟩/⟨E⟩ (kinetic_fraction_by_time)."""
    d = kinetic_fraction_by_time(rows["traj_id"], rows["t"], rows["energy"], gamma).dropna()
    t = np.concatenate([[d["t_lo"].iloc[0]], d["t_hi"].to_numpy()])
    path = E0 * np.exp(-gamma * np.concatenate([[0.0], np.cumsum(d["mu_K"] * (d["t_hi"] - d["t_lo"]))]))
    return {name: fit_energy_decay(t, path, E0, gamma, w).mu for name, w in wins.items()}, (t, path)


def mu_own(rows, E0, gamma, wins, groups: int = 10):
    """({window: (μ, σ)}, (t, path)): μ of the survivors' own ⟨K⟩ path; σ from ``groups`` disjoint groups of orbits
    (traj_id mod groups: σ = sd/√groups), orbits being the independent unit."""
    full, path = own_path_mu(rows, E0, gamma, wins)
    parts = [own_path_mu(rows[rows["traj_id"] % groups == k], E0, gamma, wins)[0] for k in range(groups)]
    return {
        name: (v, float(np.std([q[name] for q in parts], ddof=1) / math.sqrt(groups))) for name, v in full.items()
    }, path


def mu_windows(runs) -> dict:
    """{'paper': mu_window (fig3's [0, 200]), 'above': [0, τ2] with τ2 = ln(e0_ratio)/(paper_mu γ) (⟨E⟩ > E_c)}."""
    p = runs.params
    t2 = math.log(p.e0_ratio) / (p.paper_mu * p.mu_gamma)
    return {"paper": tuple(p.mu_window), "above": (0.0, float(math.floor(t2)))}


def mu_predicted(runs, mdf, ec, E0):
    """{(kind, window name): (μ, σ)} of the path dE/dt = −γ μ(E) E fitted like the measured ⟨E⟩(t); σ from the
    probe errors (all shifted by ±1σ); and the path of the c-measure kind."""
    p = runs.params
    grid = snapshot_grid(p.snapshot_grid)
    out, paths = {}, {}
    for kind in ("c-measure", "all survivors"):
        for shift in (0.0, 1.0, -1.0):
            paths[kind, shift] = decay_path(grid, E0, p.mu_gamma, mu_of_E(mdf, ec, shift, kind))
        for name, w in mu_windows(runs).items():
            v = {sh: fit_energy_decay(grid, paths[kind, sh], E0, p.mu_gamma, w).mu for sh in (0.0, 1.0, -1.0)}
            out[kind, name] = (v[0.0], abs(v[1.0] - v[-1.0]) / 2)
    return out, grid, paths["c-measure", 0.0]


def claim3(claims, label, meas, pred, wins, mu_c0, paper_mu, is_hh, relaxed):
    how = (
        "dE/dt = −γ μ(E) E with μ(E) = 2⟨K⟩/E of the conservative flow ({}) above E_c and of the microcanonical "
        "well below, fitted like the measured ⟨E⟩(t)"
        + ("" if relaxed else "; probe window not relaxed at some energy (clipped)")
    )
    for wname, w in wins.items():
        where = f"on [{w[0]:g}, {w[1]:g}]" + (" (fig3's window)" if wname == "paper" else " (⟨E⟩ > E_c)")
        mu_m, mu_m_err = meas[wname]
        claims.add(
            "3",
            f"μ measured {where}",
            label,
            mu_m,
            mu_m_err,
            z_verdict(mu_m, mu_m_err, paper_mu, "agrees with the paper's 0.91", "differs from the paper's 0.91")
            if is_hh and wname == "paper"
            else "measured",
            "⟨E⟩(t) of the orbits not escaped, fixed-intercept log fit (fig3's); bootstrap over orbits; this "
            "study's setup (r_esc the system's default)",
            paper_mu if is_hh and wname == "paper" else None,
        )
        for kind, name in (("c-measure", "c-measure: censored orbits dropped"), ("all survivors", "all survivors")):
            v, e = pred[kind, wname]
            claims.add(
                "3",
                f"μ predicted {where}, {kind}",
                label,
                v,
                e,
                z_verdict(v, e, mu_m, "agrees with μ measured", "differs from μ measured", mu_m_err),
                how.format(name),
                mu_m,
            )
    claims.add(
        "3",
        "2⟨K⟩/E of the c-measure at E0",
        label,
        mu_c0,
        None,
        "for reference (instantaneous μ at E0)",
        "interpolated between probe energies",
    )


def claim5_moment(claims, label, meas, own, pred, wins):
    """μ_meas = μ of the survivors' own ⟨K⟩ + selection (escape, settling); own ⟨K⟩ against the conservative one."""
    for wname, w in wins.items():
        where = f"on [{w[0]:g}, {w[1]:g}]"
        v, e = own[wname]
        m, me = meas[wname]
        claims.add(
            "5",
            f"moment test: μ of the survivors' own ⟨K⟩ {where} (no selection)",
            label,
            v,
            e,
            z_verdict(
                m,
                me,
                v,
                "selection by escape/settling negligible",
                f"selection by escape/settling shifts μ by {signed(m - v, '+.3f')}",
                e,
            ),
            "2⟨K⟩/⟨E⟩ of the dissipative survivors from their energy loss (ΔE = −2γ∫K dt), path fitted "
            "like ⟨E⟩(t), on the orbits traj_id < n_boot_orbits; σ from 10 groups of them; reference: μ measured",
            m,
        )
        pv, pe = pred["c-measure", wname]
        claims.add(
            "5",
            f"moment test: survivors' ⟨K⟩ against the conservative c-measure's {where}",
            label,
            v - pv,
            math.hypot(e, pe),
            z_verdict(
                v - pv,
                math.hypot(e, pe),
                0.0,
                "survivors carry the c-measure's ⟨K⟩",
                "survivors' ⟨K⟩ differs from the c-measure's",
            ),
            "value: μ(own ⟨K⟩) − μ predicted (c-measure above E_c, microcanonical well below): a moment test "
            "of claim 5 (not the distance of Fig. 5)",
            0.0,
        )


def analyze_mu(runs, claims, label, spec, m, E0, fits):
    """Claims 3 and 5 of one system: (μ rows, ⟨E⟩ curves, (μ, σ) measured on fig3's window, its JSON numbers)."""
    p = runs.params
    ec = m.critical_energy
    mrows = mu_conservative(runs, label, m, fits)
    mdf = pd.DataFrame(mrows)
    meas, inside, (own, own_path) = mu_measured(runs, label, m, E0)
    pred, grid, path = mu_predicted(runs, mdf, ec, E0)
    mu_c0 = float(mu_of_E(mdf, ec)(E0))
    relaxed = bool(mdf.loc[mdf["kind"] == "c-measure", "relaxed"].fillna(False).astype(bool).all())
    wins = mu_windows(runs)
    claim3(claims, label, meas, pred, wins, mu_c0, p.paper_mu, spec["name"] == "henon_heiles", relaxed)
    claim5_moment(claims, label, meas, own, pred, wins)
    curves = [
        pd.DataFrame({"system": label, "t": t, "mean_E_over_E0": e / E0, "kind": kind})
        for t, e, kind in (
            (inside["t"], inside["mean_E"], "measured"),
            (grid, path, "predicted"),
            (own_path[0], own_path[1], "survivors' own ⟨K⟩"),
        )
    ]
    numbers = {
        "mu_measured": Measured.of(*meas["paper"]).to_dict(),
        "mu_predicted": Measured.of(*pred["c-measure", "paper"]).to_dict(),
        "mu_by_window": {
            name: {
                "window": list(w),
                "measured": Measured.of(*meas[name]).to_dict(),
                "predicted_c_measure": Measured.of(*pred["c-measure", name]).to_dict(),
                "predicted_all_survivors": Measured.of(*pred["all survivors", name]).to_dict(),
                "survivors_own_K": Measured.of(*own[name]).to_dict(),
            }
            for name, w in wins.items()
        },
        "mu_c_at_E0": mu_c0,
        "mu_conservative": [
            {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in r.items()} for r in mrows
        ],
    }
    return mrows, curves, meas["paper"], numbers
