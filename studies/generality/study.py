"""Study generality — the paper's claims tested on three open systems (beyond the paper).

The paper concludes with "a generally-applicable model for the study of dissipative chaotic scattering",
tested on Hénon–Heiles only. This study runs the same chain, the system a parameter of every stage
(``[study] systems``, the built-in systems), at energies placed alike relative to each threshold
(E = r·E_c on one grid of r), with ICs alike (disk r < radius_frac·r_s, tangential momenta) and linear drag.
Rules in the header of ``studies/generality/study.toml``.

Stages (``hhscatter study generality simulate|analyze|plot [--scale S]``):

``simulate(study, workers=None, progress=True)``
    per system (raw keys prefixed with its label): the κ0(E) runs ``<label>_r<r>`` (γ = 0, ``grid_n`` orbits);
    the probe runs ``<label>_probe_r<r>`` (γ = probe_gamma, energies every probe_step: the conservative flow's
    kinetic energy); the dissipative runs ``<label>_g<γ>`` at E0 = e0_ratio·E_c, the same ICs for every γ,
    the γ = mu_gamma run with snapshots and settled orbits continued (⟨E⟩(t)); the section-recording conservative
    runs ``<label>_cm_r<r>`` at cm_ratios and e0_ratio (every crossing of ṙ = 0, φ̇ > 0 in [0, cm_t_to]: claims 2
    and 5) and the dissipative run ``<label>_sec_g<mu_gamma>`` recording the crossings around t* (claim 5).

``analyze(study)``
    Claim 1 (κ0(E) law per system, two window conventions), claim 2 (κ from the c-measure,
    Eq. (eqn:kappa_cmeasure_truetime), :mod:`hhscatter.analysis.survival.cmeasure`), claim 3 (μ measured, μ
    predicted from the conservative system, :mod:`hhscatter.analysis.dissipative.kinetic`), claim 4 (τ0, τ1, τ2
    against γ and Eq. (eq:tau2)), claim 5 (Fig. 5's paired distance,
    :func:`hhscatter.analysis.geometry.paired_distance.paired_hellinger_replicates`, and a moment test), claims 6 and 7;
    derived tables and ``generality.json`` with the list ``claims`` of records
    {claim, quantity, system, value, err, verdict, note}.

``plot(study)``
    ``generality.png`` (figure.py).
"""
from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd

from hhscatter.scene.scene import MOMENTA, REGIONS
from hhscatter.scene.schema import (
    Integer,
    Number,
    NumberLists,
    Numbers,
    OneOf,
    StudyParams,
    Text,
)


class SystemEntry(StudyParams):
    """One entry of ``[study] systems``: a label (raw keys, tables) and a built-in system with its parameters."""

    label: Text
    name: Text
    params: dict[str, Number] = None  # the built-in's defaults where absent


class Params(StudyParams):
    """``[study]`` of studies/generality/study.toml (rules in its header comment)."""

    systems: list[SystemEntry]
    radius_frac: Number
    alt_region: OneOf(*REGIONS) = None     # a second IC convention for κ0(E): the same grid with these ICs
    alt_momentum: OneOf(*MOMENTA) = "random"
    ratios: Numbers
    grid_n: Integer
    min_survivors: Number
    p_levels: Numbers
    max_plateau_bias: Number
    n_boot: Integer
    n_boot_orbits: Integer = 200000  # μ's bootstrap and own-⟨K⟩ path on orbits traj_id < this (fig3's rule)
    fit_seed: Integer
    probe_ratios: Numbers
    probe_gamma: Number
    probe_n: Integer
    probe_step: Number
    probe_t_max: Number
    probe_rec_efolds: Number
    probe_sample_efolds: Number
    mc_ratios: Numbers
    e0_ratio: Number
    gammas: Numbers
    mu_gamma: Number
    diss_n: Integer
    diss_t_max: Number
    snapshot_grid: NumberLists
    mu_window: Numbers
    alpha: Number
    tau_grid_step: Number
    paper_mu: Number
    hazard_bin: Number = 5.0      # claim 7: width of the time bins of the escape hazard (time units)
    sm_dt: Number = 0.5           # claim 6 (fig6 rule)
    sm_fit_dt: Number = 2.0
    sm_min_count: Number = 20.0
    # claim 2 (κ from the c-measure) and claim 5 (Fig. 5's distance): conservative runs recording every section
    # crossing in [0, cm_t_to], at cm_ratios and at e0_ratio
    cm_ratios: Numbers = [1.5, 1.9, 2.6]
    cm_n: Integer = 5000
    cm_t_to: Number = 400.0
    cm_t_max: Number = 800.0
    cm_rec_efolds: Number = 2.0   # sampling from t_rec = ⌈τ0 + cm_rec_efolds/κ⌉ (escaping orbits' P(t) of the run)
    cm_margin: Number = 40.0      # … to cm_t_to − cm_margin
    c5_ratio: Number = 1.5        # E(t*)/E_c of claim 5 (one of cm_ratios, below e0_ratio)
    c5_mu_range: Numbers = [0.6, 1.3]   # sections of the dissipative run recorded for t* of any μ in this range
    c5_pad: Number = 25.0
    c5_box_frac: Number = 0.25    # box side of the Hellinger distance, in units of the saddle distance r_s
    c5_offsets: Integer = 2
    c5_boot: Integer = 100
    c5_level: Number = 0.95


# κ conventions: all orbits with the data-driven plateau windows (fig2's) or P-level windows (both ill-defined where
# the orbits still inside at t_max bias the window's end), and the escaping orbits only with plateau windows
CONVENTIONS = ("plateau", "plevel", "escaping")
HH_PAPER_BREAK = (0.27 - 1 / 6) / (1 / 6)  # the paper's E_b ≈ 0.27 for Hénon–Heiles, as (E_b − E_c)/E_c


def grid_key(label: str, r: float) -> str:
    """grid_key('contopoulos', 1.5) -> 'contopoulos_r1.500': the κ0(E) run at E = r·E_c."""
    return f"{label}_r{r:.3f}"


def alt_key(label: str, r: float, region: str) -> str:
    """alt_key('barbanis', 1.5, 'well') -> 'barbanis_well_r1.500': the κ0(E) run with the alternative ICs."""
    return f"{label}_{region}_r{r:.3f}"


def probe_key(label: str, r: float) -> str:
    """probe_key(label, r) -> '<label>_probe_r<r>': the probe-drag run at E = r·E_c."""
    return f"{label}_probe_r{r:.3f}"


def diss_key(label: str, gamma: float) -> str:
    """diss_key(label, γ) -> '<label>_g<γ:g>', e.g. 'barbanis_g0.01' (γ = 0: the conservative reference)."""
    return f"{label}_g{float(gamma):g}"


def cm_key(label: str, r: float) -> str:
    """cm_key('barbanis', 2.6) -> 'barbanis_cm_r2.600': the conservative run recording every section crossing."""
    return f"{label}_cm_r{r:.3f}"


def sec_key(label: str, gamma: float) -> str:
    """sec_key(label, γ) -> '<label>_sec_g<γ>': the dissipative run recording the section crossings around t*."""
    return f"{label}_sec_g{float(gamma):g}"


def _cm_ratios(p) -> list:
    """The energies (E/E_c) of the section-recording conservative runs: cm_ratios and e0_ratio (claim 5's μ_c^{E0})."""
    return sorted({*map(float, p.cm_ratios), float(p.e0_ratio)})


def _c5_window(p, ec):
    """(t_from, t_to) of the dissipative section recording: t* = ln(E0/E*)/(μγ) for every μ in c5_mu_range, + pad."""
    from hhscatter.analysis.dissipative.decay import time_to_energy

    E0, Es = p.e0_ratio * ec, p.c5_ratio * ec
    lo, hi = p.c5_mu_range
    return (float(time_to_energy(E0, Es, hi, p.mu_gamma)),
            float(time_to_energy(E0, Es, lo, p.mu_gamma)) + p.c5_pad)


def _systems(study):
    """[(label, spec, System)] of [study] systems."""
    from hhscatter.model.spec import system_from_spec

    out = []
    for e in study.params.systems:  # typed entries read as dicts
        spec = {"name": e["name"], "params": dict(e.get("params") or {})}
        out.append((e["label"], spec, system_from_spec(spec)))
    return out


def _check(study):
    ratios, probes = list(study.params.ratios), list(study.params.probe_ratios)
    off = [r for r in probes if not np.isclose(ratios, r).any()]
    if off:
        raise ValueError(f"[study].probe_ratios must be among ratios (their κ, τ0 set the window); {off} are not")
    gs = list(study.params.gammas)
    if 0.0 not in gs or study.params.mu_gamma not in gs or sorted(gs) != gs:
        raise ValueError(f"[study].gammas must be increasing, contain 0 and mu_gamma; got {gs}")
    if any(r <= 1 for r in ratios) or any(r >= 1 for r in study.params.mc_ratios):
        raise ValueError("[study].ratios must be > 1 (above E_c) and mc_ratios < 1 (below)")
    off = [r for r in study.params.cm_ratios if not np.isclose(ratios, r).any()]
    if off:
        raise ValueError(f"[study].cm_ratios must be among ratios (claim 2 compares with their κ0); {off} are not")
    c5 = study.params.c5_ratio
    if not np.isclose(study.params.cm_ratios, c5).any() or not 1 < c5 < study.params.e0_ratio:
        raise ValueError(f"[study].c5_ratio = {c5} must be one of cm_ratios and between 1 and e0_ratio")
    if not study.params.cm_t_max > study.params.cm_t_to:
        raise ValueError("[study].cm_t_max must exceed cm_t_to (orbits still inside at t_max are dropped as KAM-trapped)")


# ---------------------------------------------------------------------------
# simulate
# ---------------------------------------------------------------------------
def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None, progress=True) -> None: per system the κ0(E), probe and dissipative runs."""
    from hhscatter.analysis.dissipative.decay import snapshot_grid

    _check(study)
    p = study.params
    probe_times = tuple(np.round(np.arange(0.0, p.probe_t_max + 1e-9, p.probe_step), 9))
    grid = tuple(snapshot_grid(p.snapshot_grid))
    for label, spec, m in _systems(study):
        ec, radius = m.critical_energy, p.radius_frac * m.saddle_radius
        for r in p.ratios:
            sc = study.scene(grid_key(label, r), system=spec, energy=r * ec, n=p.grid_n, radius=radius)
            study.run(grid_key(label, r), sc, workers=workers, progress=progress)
        if p.alt_region is not None:  # the same grid with other ICs: is a trapped plateau the ICs' doing?
            for r in p.ratios:
                key = alt_key(label, r, p.alt_region)
                sc = study.scene(key, system=spec, energy=r * ec, n=p.grid_n, region=p.alt_region,
                                 momentum=p.alt_momentum)
                study.run(key, sc, workers=workers, progress=progress)
        for r in p.probe_ratios:
            sc = study.scene(probe_key(label, r), system=spec, energy=r * ec, n=p.probe_n, radius=radius,
                             gamma=p.probe_gamma, t_max=p.probe_t_max, snapshots=probe_times)
            study.run(probe_key(label, r), sc, workers=workers, progress=progress)
        for g in p.gammas:
            extra = {"snapshots": grid, "continue_settled": True} if g == p.mu_gamma else {}
            sc = study.scene(diss_key(label, g), system=spec, energy=p.e0_ratio * ec, n=p.diss_n, radius=radius,
                             gamma=g, t_max=p.diss_t_max, **extra)
            study.run(diss_key(label, g), sc, workers=workers, progress=progress)
        for r in _cm_ratios(p):  # claims 2 and 5: every section crossing in [0, cm_t_to], conservative
            sc = study.scene(cm_key(label, r), system=spec, energy=r * ec, n=p.cm_n, radius=radius,
                             t_max=p.cm_t_max, sections={"t_from": 0.0, "t_to": p.cm_t_to})
            study.run(cm_key(label, r), sc, workers=workers, progress=progress)
        t_lo, t_hi = _c5_window(p, ec)  # claim 5: the dissipative survivors' crossings around t*; stop after
        sc = study.scene(sec_key(label, p.mu_gamma), system=spec, energy=p.e0_ratio * ec, n=p.diss_n, radius=radius,
                         gamma=p.mu_gamma, sections={"t_from": t_lo, "t_to": t_hi, "stop": True})
        study.run(sec_key(label, p.mu_gamma), sc, workers=workers, progress=progress)


# ---------------------------------------------------------------------------
# analyze: claim 1, κ0(E)
# ---------------------------------------------------------------------------
def _lifetimes(path):
    from hhscatter.data.read import read_lifetimes

    return read_lifetimes(path, columns=["traj_id", "outcome", "t_end"], categorical=True)


def _kappa_rows(study, label, m):
    """One row per (r, convention): κ (1/time), its error, τ0, window, trapped fraction, defined."""
    from hhscatter.analysis.survival.escape_rate import escape_rate_from_lifetimes
    from hhscatter.analysis.survival.fits import lifetimes_to_arrays
    from hhscatter.analysis.survival.kappa_conventions import (
        escape_rate_p_levels,
        plateau_rate,
    )

    p = study.params
    rows, fits = [], {}
    for r in p.ratios:
        lt = _lifetimes(study.raw(grid_key(label, r)))
        t_end, obs = lifetimes_to_arrays(lt)
        rates = {}
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res = escape_rate_from_lifetimes(lt, detect_tail=False, min_survivors=p.min_survivors)
            fits[r] = res
            rates["plateau"] = plateau_rate(res, t_end, obs, max_bias=p.max_plateau_bias)
        except (ValueError, RuntimeError) as exc:  # too few escapes for the window rule: said, not hidden
            rates["plateau"] = None
            reason = f"window rule failed: {exc}"
        rates["plevel"] = escape_rate_p_levels(t_end, obs, p_hi=p.p_levels[0], p_lo=p.p_levels[1],
                                               max_bias=p.max_plateau_bias)
        # the escaping orbits only (those still inside at t_max dropped: KAM-trapped, or sticky beyond t_max)
        esc = lt[lt["outcome"] != "censored"]
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res_e = escape_rate_from_lifetimes(esc, detect_tail=False, min_survivors=p.min_survivors)
            te, oe = lifetimes_to_arrays(esc)
            rates["escaping"] = plateau_rate(res_e, te, oe, max_bias=p.max_plateau_bias)
            fits[("escaping", r)] = res_e
        except (ValueError, RuntimeError) as exc:
            rates["escaping"] = None
            reason = f"window rule failed on the escaping orbits: {exc}"
        if p.alt_region is not None:
            lt_a = _lifetimes(study.raw(alt_key(label, r, p.alt_region)))
            ta, oa = lifetimes_to_arrays(lt_a)
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    res_a = escape_rate_from_lifetimes(lt_a, detect_tail=False, min_survivors=p.min_survivors)
                rates[p.alt_region] = plateau_rate(res_a, ta, oa, max_bias=p.max_plateau_bias)
                trapped_alt = float((~oa).mean())
            except (ValueError, RuntimeError) as exc:
                rates[p.alt_region] = None
                reason = f"window rule failed with {p.alt_region} ICs: {exc}"
        for conv, c in rates.items():
            base = {"system": label, "ratio": r, "eps": r - 1.0, "energy": r * m.critical_energy,
                    "convention": conv, "n": int(t_end.size)}
            if c is None:
                rows.append({**base, "kappa": math.nan, "kappa_err": math.nan, "tau0": math.nan,
                             "t_lo": math.nan, "t_hi": math.nan,
                             "trapped_fraction": math.nan if conv == p.alt_region else float((~obs).mean()),
                             "defined": False, "reason": reason})
                continue
            rows.append({**base, "kappa": c.kappa, "kappa_err": c.kappa_err, "tau0": c.t_lo, "t_lo": c.t_lo,
                         "t_hi": c.t_hi,
                         "trapped_fraction": trapped_alt if conv == p.alt_region else float((~obs).mean()),
                         "defined": bool(c.defined and c.kappa > 0), "reason": c.reason})
    return rows, fits


def _exponents(eps, kappa, err, eps_b):
    """κ ∝ ε^β below and above the break: ((β_low, σ), (β_high, σ)), None where < 2 points."""
    from hhscatter.analysis.dissipative.transitions import power_law_exponent

    out = []
    for sel in (eps < eps_b, eps >= eps_b):
        p, e = power_law_exponent(eps[sel], kappa[sel], err[sel])
        out.append(None if p is None else (-p, e))
    return out


def _law(study, table):
    """Per convention: the continuous law in ε (fit_kappa_energy with E → r, E_c → 1) and the exponents β."""
    from hhscatter.analysis.survival.kappa_energy import fit_kappa_energy

    per = {}
    for conv in [*CONVENTIONS, *([study.params.alt_region] if study.params.alt_region else [])]:
        d = table[(table["convention"] == conv) & table["defined"]].sort_values("ratio")
        if len(d) < 5:  # a, b and the break need points on both sides
            per[conv] = None
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            f = fit_kappa_energy(d["ratio"], d["kappa"], d["kappa_err"], 1.0, continuous=True,
                                 n_boot=study.params.n_boot, rng=study.params.fit_seed)
        eps_b = f.E_b - 1.0
        lo, hi = _exponents(d["eps"].to_numpy(), d["kappa"].to_numpy(), d["kappa_err"].to_numpy(), eps_b)
        err = lambda v, e, b: float(max(e, b)) if b is not None and math.isfinite(b) else float(e)
        be = f.boot_err if f.boot_err else (math.nan,) * 4
        per[conv] = {"a": _ve(f.a, err(f.a, f.a_err, be[0])), "b": _ve(f.b, err(f.b, f.b_err, be[1])),
                     "c": _ve(f.c, err(f.c, f.c_err, be[2])), "eps_b": _ve(eps_b, err(eps_b, f.E_b_err, be[3])),
                     "chi2": f.chi2, "dof": f.dof, "beta_low": None if lo is None else _ve(*lo),
                     "beta_high": None if hi is None else _ve(*hi), "n_points": len(d)}
    return per


def _across(per: dict, key: str):
    """(mean, √(stat² + half range²)) of law parameter ``key`` over the conventions that fitted it."""
    vals = [(v[key]["value"], v[key]["err"]) for v in per.values() if v and v.get(key)]
    if not vals:
        return None, None
    x = np.array([v for v, _ in vals])
    stat = max((e for _, e in vals if e is not None and math.isfinite(e)), default=0.0)
    return float(x.mean()), float(math.hypot(stat, (x.max() - x.min()) / 2))


# ---------------------------------------------------------------------------
# analyze: claim 3, μ
# ---------------------------------------------------------------------------
def _mu_conservative(study, label, m, fits):
    """2⟨K⟩/E of the conservative flow per probe ratio (c-measure: trapped orbits dropped; all survivors beside)
    and the microcanonical value of the well below E_c."""
    from hhscatter.analysis.dissipative.kinetic import (
        kinetic_fraction_from_energies,
        microcanonical_kinetic_fraction,
    )
    import pyarrow.dataset as pads

    from hhscatter.data.read import read_lifetimes, read_snapshots

    p = study.params
    rows = []
    for r in p.probe_ratios:
        # κ, τ0 of the escaping orbits of the κ0(E) run at r: defined even where a trapped plateau is not
        res = fits.get(("escaping", min((k[1] for k in fits if isinstance(k, tuple)), key=lambda x: abs(x - r),
                                        default=math.nan)))
        raw = study.raw(probe_key(label, r))
        t0, t1, relaxed = _probe_window(res, p)
        if t0 is None:
            rows.append({"system": label, "ratio": r, "kind": "c-measure", "mu": math.nan, "mu_err": math.nan,
                         "relaxed": False})
            continue
        lt = read_lifetimes(raw, columns=["traj_id", "outcome"], categorical=True)
        # only the rows the average uses (kinetic_fraction_from_energies keeps t_from ≤ t ≤ t_to): the same
        # result, without reading the sticky systems' whole probe tables (2.5e7 rows at paper scale)
        sn = read_snapshots(raw, columns=["traj_id", "t", "energy"],
                            filters=(pads.field("t") >= t0) & (pads.field("t") <= t1))
        escaping = lt.loc[lt["outcome"] != "censored", "traj_id"].to_numpy()
        for kind, keep in (("c-measure", escaping), ("all survivors", None)):
            k = kinetic_fraction_from_energies(sn["traj_id"], sn["t"], sn["energy"], p.probe_gamma, t0, t1,
                                               keep=keep, n_boot=p.n_boot, rng=p.fit_seed)
            rows.append({"system": label, "ratio": r, "kind": kind, "mu": k.value, "mu_err": k.err,
                         "t_from": t0, "t_to": t1, "relaxed": relaxed, "n_orbits": k.n_orbits,
                         "n_intervals": k.n_intervals})
    for r in p.mc_ratios:
        v = microcanonical_kinetic_fraction(m.potential, r * m.critical_energy, 2.5 * m.saddle_radius)
        rows.append({"system": label, "ratio": r, "kind": "microcanonical well", "mu": v, "mu_err": 0.0})
    return rows


def _probe_window(res, p):
    """(t_from, t_to, relaxed) of the probe average: [τ0 + n_rec/κ, + n_sample/κ] (κ, τ0 of the escaping orbits);
    where it reaches beyond probe_t_max, the last half of the probe run, flagged relaxed = False."""
    if res is None or not (res.kappa > 0):
        return None, None, False
    t0 = res.tau0 + p.probe_rec_efolds / res.kappa
    t1 = t0 + p.probe_sample_efolds / res.kappa
    if t1 <= p.probe_t_max:
        return t0, t1, True
    return max(res.tau0, p.probe_t_max / 2), p.probe_t_max, False


def _mu_of_E(mu_rows: pd.DataFrame, ec: float, shift: float = 0.0, kind: str = "c-measure"):
    """μ(E): microcanonical below E_c, the ``kind`` value above (± shift·σ), linear in E/E_c, flat beyond."""
    below = mu_rows[mu_rows["kind"] == "microcanonical well"]
    above = mu_rows[(mu_rows["kind"] == kind) & np.isfinite(mu_rows["mu"])]
    r = np.concatenate([below["ratio"], above["ratio"]])
    v = np.concatenate([below["mu"], above["mu"] + shift * above["mu_err"].fillna(0.0)])
    o = np.argsort(r)
    r, v = r[o], v[o]
    return lambda E: np.interp(np.asarray(E) / ec, r, v)


def _mu_measured(study, label, m, E0):
    """fig3's μ: ⟨E⟩(t) of the orbits not escaped (settled continued), log fit on each window of
    :func:`_mu_windows` (all orbits, streamed part by part); bootstrap error over orbits, as fig3 on the orbits
    traj_id < n_boot_orbits with the errors scaled by √(K/N) (the snapshot table of 10⁶ sticky orbits is
    ~10⁸ rows: read whole it took 5.8 GB). The survivors' own-⟨K⟩ path (claim 5, moment test) is taken on the
    same K orbits. Returns ({name: (μ, σ)}, ⟨E⟩ table, own-⟨K⟩ result)."""
    import pyarrow.dataset as pads

    from hhscatter.analysis.dissipative.decay import (
        bootstrap_mu_first_orbits,
        fit_energy_decay,
        inside_mean_energy,
    )
    from hhscatter.data.read import iter_parts, read_snapshots

    p = study.params
    raw = study.raw(diss_key(label, p.mu_gamma))
    ime = inside_mean_energy(iter_parts(raw, "snapshots", ["t", "energy"]), m.critical_energy)
    wins = _mu_windows(study)
    k = min(p.n_boot_orbits, p.diss_n)
    rows = read_snapshots(raw, columns=["traj_id", "t", "energy"], filters=pads.field("traj_id") < k)
    b, scale = bootstrap_mu_first_orbits(rows, p.diss_n, k, E0, p.mu_gamma, list(wins.values()),
                                         n_boot=p.n_boot, seed=p.fit_seed)
    out = {}
    for name, w in wins.items():
        mu = fit_energy_decay(ime.inside["t"], ime.inside["mean_E"], E0, p.mu_gamma, w).mu
        bw = b[(b["t_lo"] == w[0]) & (b["t_hi"] == w[1])]
        out[name] = (mu, float(bw["mu"].std(ddof=1)) * scale)
    return out, ime.inside, _mu_own(rows, E0, p.mu_gamma, wins)


def _own_path_mu(rows, E0, gamma, wins):
    """{window: μ} of the path d ln E/dt = −γ μ_K(t), μ_K the survivors' own 2⟨K⟩/⟨E⟩ (kinetic_fraction_by_time)."""
    from hhscatter.analysis.dissipative.decay import fit_energy_decay
    from hhscatter.analysis.dissipative.kinetic import kinetic_fraction_by_time

    d = kinetic_fraction_by_time(rows["traj_id"], rows["t"], rows["energy"], gamma).dropna()
    t = np.concatenate([[d["t_lo"].iloc[0]], d["t_hi"].to_numpy()])
    path = E0 * np.exp(-gamma * np.concatenate([[0.0], np.cumsum(d["mu_K"] * (d["t_hi"] - d["t_lo"]))]))
    return {name: fit_energy_decay(t, path, E0, gamma, w).mu for name, w in wins.items()}, (t, path)


def _mu_own(rows, E0, gamma, wins, groups: int = 10):
    """({window: (μ, σ)}, (t, path)): μ of the survivors' own ⟨K⟩ path; σ from ``groups`` disjoint groups of orbits
    (traj_id mod groups: σ = sd/√groups), orbits being the independent unit."""
    full, path = _own_path_mu(rows, E0, gamma, wins)
    parts = [_own_path_mu(rows[rows["traj_id"] % groups == k], E0, gamma, wins)[0] for k in range(groups)]
    return {name: (v, float(np.std([q[name] for q in parts], ddof=1) / math.sqrt(groups)))
            for name, v in full.items()}, path


def _mu_windows(study) -> dict:
    """{'paper': mu_window (fig3's [0, 200]), 'above': [0, τ2] with τ2 = ln(e0_ratio)/(paper_mu γ) (⟨E⟩ > E_c)}."""
    p = study.params
    t2 = math.log(p.e0_ratio) / (p.paper_mu * p.mu_gamma)
    return {"paper": tuple(p.mu_window), "above": (0.0, float(math.floor(t2)))}


def _mu_predicted(study, mdf, ec, E0):
    """{(kind, window name): (μ, σ)} of the path dE/dt = −γ μ(E) E fitted like the measured ⟨E⟩(t); σ from the
    probe errors (all shifted by ±1σ); and the path of the c-measure kind."""
    from hhscatter.analysis.dissipative.decay import fit_energy_decay, snapshot_grid
    from hhscatter.analysis.dissipative.kinetic import decay_path

    p = study.params
    grid = snapshot_grid(p.snapshot_grid)
    out, paths = {}, {}
    for kind in ("c-measure", "all survivors"):
        for shift in (0.0, 1.0, -1.0):
            paths[kind, shift] = decay_path(grid, E0, p.mu_gamma, _mu_of_E(mdf, ec, shift, kind))
        for name, w in _mu_windows(study).items():
            v = {sh: fit_energy_decay(grid, paths[kind, sh], E0, p.mu_gamma, w).mu for sh in (0.0, 1.0, -1.0)}
            out[kind, name] = (v[0.0], abs(v[1.0] - v[-1.0]) / 2)
    return out, grid, paths["c-measure", 0.0]


# ---------------------------------------------------------------------------
# analyze: claim 2, κ from the c-measure; claim 5, Fig. 5's distance
# ---------------------------------------------------------------------------
def _cm_sample(study, label, r):
    """The c-measure of the conservative run at E = r·E_c (orbits still inside at cm_t_max dropped: KAM-trapped):
    its recording time t_rec = ⌈τ0 + cm_rec_efolds/κ⌉ (κ, τ0 of the run's escaping orbits, fig1's sprinkler rule),
    the return-time sample of Eq. (eqn:kappa_cmeasure_truetime) on [t_rec, cm_t_to − cm_margin] and the first
    crossing at t ≥ t_rec of each orbit (sprinkler points). Returns a dict (κ_cm None with a reason where not)."""
    import pyarrow.dataset as pads

    from hhscatter.analysis.geometry.distance import first_crossings
    from hhscatter.analysis.survival.cmeasure import cmeasure_sample_from_sections, kappa_from_cmeasure
    from hhscatter.analysis.survival.escape_rate import escape_rate_from_lifetimes
    from hhscatter.data.read import read_sections

    p = study.params
    raw = study.raw(cm_key(label, r))
    lt = _lifetimes(raw)
    trapped = float((lt["outcome"] == "censored").mean())
    out = {"ratio": r, "n": len(lt), "trapped_fraction": trapped, "kappa_cm": None, "kappa_cm_err": None,
           "mu_exit": None, "n_samples": 0, "n_orbits": 0, "n_undetermined": 0, "t_rec": None, "t_to": None,
           "points": None, "points_all": None, "reason": ""}
    esc = lt[lt["outcome"] != "censored"]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = escape_rate_from_lifetimes(esc, detect_tail=False, min_survivors=p.min_survivors)
    except (ValueError, RuntimeError) as exc:
        out["reason"] = f"no κ, τ0 from the escaping orbits' P(t) for t_rec: {exc}"
        return out
    t_rec = float(math.ceil(res.tau0 + p.cm_rec_efolds / res.kappa))
    t_to = p.cm_t_to - p.cm_margin
    out.update(t_rec=t_rec, t_to=t_to)
    if t_rec >= p.cm_t_to:
        out["reason"] = (f"t_rec = ⌈τ0 + {p.cm_rec_efolds:g}/κ⌉ = {t_rec:g} ≥ cm_t_to = {p.cm_t_to:g} (escaping orbits' "
                         f"τ0 = {res.tau0:.0f}, κ = {res.kappa:.3g}): no relaxed sample within the recording")
        return out
    # only crossings at t ≥ t_rec enter (first crossings, return times: a crossing's successor is later), so the
    # reader drops the rest (the sticky systems' tables are ~10⁷ rows at paper scale)
    sec = read_sections(raw, columns=["traj_id", "t", "x", "y", "energy"], filters=pads.field("t") >= t_rec)
    out["points"] = first_crossings(sec[sec["traj_id"].isin(esc["traj_id"])], t_rec)
    out["points_all"] = first_crossings(sec, t_rec)  # the trapped orbits kept: all conservative survivors
    if not t_to > t_rec:
        out["reason"] = (f"t_rec = {t_rec:g} ≥ cm_t_to − cm_margin = {t_to:g} (escaping orbits' τ0 = {res.tau0:.0f}, "
                         f"κ = {res.kappa:.3g}): no sampling window")
        return out
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the undetermined count is reported
        T, n_exit, n_und, orb, exit_orb = cmeasure_sample_from_sections(
            sec, lt, t_rec, t_to, t_record_end=p.cm_t_to, drop_censored=True, with_orbits=True)
    n_orb = int(np.unique(np.concatenate([orb, exit_orb])).size) if T.size + n_exit else 0
    out.update(n_samples=int(T.size + n_exit), n_orbits=n_orb, n_undetermined=int(n_und))
    if n_orb < p.min_survivors:
        out["reason"] = f"only {n_orb} orbits cross the section in [{t_rec:g}, {t_to:g}] (< min_survivors)"
        return out
    k = kappa_from_cmeasure(T, n_exit, orbits=orb, exit_orbits=exit_orb, n_boot=p.n_boot, rng=p.fit_seed)
    out.update(kappa_cm=k.kappa, kappa_cm_err=k.kappa_err, mu_exit=k.mu_exit)
    return out


def _claim2(study, claims, label, table, samples):
    """κ_cm/κ0 − 1 per cm ratio against κ0 of the claim-1 grid run at that energy (independent orbits), in the
    paper's convention (all orbits, plateau windows) and with the escaping orbits only (like for like with the
    c-measure, whose KAM-trapped orbits are dropped). Returns the JSON rows."""
    rows = []
    for r in study.params.cm_ratios:
        s = samples[r]
        row = {k: v for k, v in s.items() if not k.startswith("points")}
        for conv, what in (("plateau", "all orbits, plateau windows: the paper's κ0"),
                           ("escaping", "escaping orbits only, as the c-measure")):
            k0 = table[(table["convention"] == conv) & np.isclose(table["ratio"], r)].iloc[0]
            row[f"kappa_{conv}"], row[f"kappa_{conv}_err"] = _ve(k0["kappa"])["value"], _ve(k0["kappa_err"])["value"]
            q = f"κ_cm/κ0 − 1 at E/E_c = {r:g} ({what})"
            cm = (f"κ_cm = {s['kappa_cm']:.4g} ± {s['kappa_cm_err']:.2g}" if s["kappa_cm"] is not None
                  else "κ_cm undetermined")
            note = (f"Eq. (eqn:kappa_cmeasure_truetime) on the crossings of [{s['t_rec']}, {s['t_to']}] of a second "
                    f"conservative run ({s['n']} orbits, {s['n_orbits']} sampled, {s['n_samples']} crossings, "
                    f"μ_c(𝓔) = {s['mu_exit'] if s['mu_exit'] is None else round(s['mu_exit'], 4)}; "
                    f"{s['trapped_fraction']:.0%} still inside at t_max dropped); {cm} (bootstrap over orbits); "
                    f"κ0 = {k0['kappa']:.4g} ± {k0['kappa_err']:.2g} of the claim-1 run (independent orbits)")
            if s["kappa_cm"] is None:
                claims.add("2", q, label, None, None, f"undetermined: {s['reason']}", note, 0.0)
                continue
            if not bool(k0["defined"]):
                claims.add("2", q, label, None, None,
                           f"undetermined: κ0 ill-defined ({k0['trapped_fraction']:.0%} of the orbits still inside at "
                           f"t_max; {k0['reason']}); {cm}", note, 0.0)
                continue
            v = s["kappa_cm"] / k0["kappa"] - 1
            e = math.hypot(s["kappa_cm_err"] / k0["kappa"], s["kappa_cm"] * k0["kappa_err"] / k0["kappa"] ** 2)
            row[f"ratio_minus_1_{conv}"] = _ve(v, e)
            claims.add("2", q, label, v, e, _z_verdict(v, e, 0.0, "κ_cm = κ0", f"κ_cm ≠ κ0 ({100 * v:+.0f} %)"),
                       note, 0.0)
        rows.append(row)
    return rows


def _claim5_distance(study, claims, label, m, E0, mu, samples):
    """Fig. 5's test: the first section crossing after t* (E0 e^{−μγt*} = c5_ratio·E_c, μ measured) of the
    dissipative survivors against the c-measures μ_c^{E(t*)} and μ_c^{E0} (sprinkler points of the conservative
    runs: the first crossing after t_rec), paired debiased Hellinger at one box side, half-sampling the orbits of
    every set (one group: the runs share the seed, hence the id space); no cut on any set. Two references: the
    c-measure proper (orbits still inside at cm_t_max dropped: KAM-trapped) and all conservative survivors (kept).
    Δ = d(μ_c^{E0}) − d(μ_c^{E(t*)}) > 0: closer to μ_c^{E(t*)}. Returns the JSON record."""
    import pyarrow.dataset as pads

    from hhscatter.analysis.dissipative.decay import time_to_energy
    from hhscatter.analysis.geometry import distance as dist
    from hhscatter.analysis.geometry import paired_distance as pdist
    from hhscatter.data.read import read_lifetimes, read_sections

    p = study.params
    ec = m.critical_energy
    t_star = float(time_to_energy(E0, p.c5_ratio * ec, mu, p.mu_gamma))
    t_lo, t_hi = _c5_window(p, ec)
    ss, s0 = samples[p.c5_ratio], samples[float(p.e0_ratio)]
    rec = {"t_star": t_star, "E_star": p.c5_ratio * ec, "gamma": p.mu_gamma, "box": p.c5_box_frac * m.saddle_radius,
           "t_rec_star": ss["t_rec"], "t_rec_E0": s0["t_rec"]}
    refs = {"c-measure": "μ_c: KAM-trapped orbits dropped", "all": "all conservative survivors, trapped kept"}
    qs = {k: f"Fig. 5's distance: d(μ_c^E0) − d(μ_c^E(t*)), E(t*) = {p.c5_ratio:g} E_c ({v})" for k, v in refs.items()}
    if not t_lo <= t_star <= t_hi - p.c5_pad:
        for q in qs.values():
            claims.add("5", q, label, None, None, f"undetermined: t* = {t_star:.1f} outside the recorded window "
                       f"[{t_lo:.1f}, {t_hi - p.c5_pad:.1f}] (μ = {mu:.3g} outside c5_mu_range)", "", 0.0)
        return rec
    raw = study.raw(sec_key(label, p.mu_gamma))
    sec = read_sections(raw, columns=["traj_id", "t", "x", "y", "energy"], filters=pads.field("t") >= t_star)
    diss = dist.first_crossings(sec, t_star)
    rec.update(n_alive=int((read_lifetimes(raw, columns=["t_end"])["t_end"] > t_star).sum()), n_diss=len(diss),
               mean_E_diss=float(diss["energy"].mean()) if len(diss) else None)
    for kind, col in (("c-measure", "points"), ("all", "points_all")):
        q, ref_s, ref_0 = qs[kind], ss[col], s0[col]
        if ref_s is None or ref_0 is None:
            claims.add("5", q, label, None, None, "undetermined: no c-measure sample at E(t*) or E0: "
                       + "; ".join(x["reason"] for x in (ss, s0) if x[col] is None), "", 0.0)
            continue
        sizes = f"{len(diss)} / {len(ref_s)} / {len(ref_0)} points (survivors / E(t*) / E0)"
        rec[kind] = r = {"n_ref_star": len(ref_s), "n_ref_E0": len(ref_0)}
        sets = {n: pdist.UnitSet(dist.points(df), df["traj_id"].to_numpy(), "orbits")
                for n, df in (("diss", diss), ("star", ref_s), ("E0", ref_0))}
        allpts = np.concatenate([x.points for x in sets.values()])
        extent = (float(allpts[:, 0].min()), float(allpts[:, 0].max()), float(allpts[:, 1].min()),
                  float(allpts[:, 1].max())) if len(allpts) else (0.0, 1.0, 0.0, 1.0)
        try:
            if min(len(diss), len(ref_s), len(ref_0)) < 4:
                raise ValueError(sizes)
            reps = pdist.paired_hellinger_replicates(sets, [("diss", "star"), ("diss", "E0")], [rec["box"]], extent,
                                                    offsets=p.c5_offsets, n_boot=p.c5_boot, seed=p.fit_seed)[:, :, 0]
        except ValueError as exc:  # too few points (tiny scale, or a KAM-dominated system)
            claims.add("5", q, label, None, None, f"undetermined: too few points ({exc})", sizes, 0.0)
            continue
        d, lo, hi = pdist.percentile_interval(reps[:, 1] - reps[:, 0], p.c5_level)
        ds, ds_lo, ds_hi = pdist.percentile_interval(reps[:, 0], p.c5_level)
        d0, d0_lo, d0_hi = pdist.percentile_interval(reps[:, 1], p.c5_level)
        r.update(delta={"value": d, "interval": [lo, hi]}, d_star={"value": ds, "interval": [ds_lo, ds_hi]},
                 d_E0={"value": d0, "interval": [d0_lo, d0_hi]}, extent=list(extent))
        lev = int(100 * p.c5_level)
        verdict = (f"closer to μ_c^E(t*) ({lev} % interval [{lo:+.3f}, {hi:+.3f}] excludes 0)" if lo > 0 else
                   f"closer to μ_c^E0 ({lev} % interval [{lo:+.3f}, {hi:+.3f}])" if hi < 0 else
                   f"no significant difference ({lev} % interval [{lo:+.3f}, {hi:+.3f}] contains 0)")
        claims.add("5", q, label, d, (hi - lo) / (2 * 1.96), verdict,
                   f"t* = {t_star:.1f} (μ measured, γ = {p.mu_gamma:g}); the survivors' first crossing after t* "
                   f"(mean E/E_c {rec['mean_E_diss'] / ec:.3f}) against the first crossing after t_rec = "
                   f"{rec['t_rec_star']:g} / {rec['t_rec_E0']:g} of conservative runs at E(t*) / E0; {sizes}; "
                   f"debiased Hellinger d = {ds:.3f} / {d0:.3f} at box {rec['box']:.3g} (= {p.c5_box_frac:g} r_s), "
                   f"{p.c5_offsets ** 2} grid placements, {p.c5_boot} paired half-samples over orbits; no cut on any "
                   f"set; err = interval width/3.92", 0.0)
    return rec


# ---------------------------------------------------------------------------
# analyze: claim 4, τ0, τ1, τ2
# ---------------------------------------------------------------------------
def _taus(study, label, m, E0, mu, mu_err):
    """τ0 (P_0), τ1 (P_γ = α P_0), τ2 observed (first settling) and Eq. (eq:tau2) per γ; paired bootstrap."""
    from hhscatter.analysis.dissipative.transitions import (
        bootstrap_transition_times,
        settle_time_quantiles,
        survival_on_grid,
        tau1,
        tau2_observed_interval,
        tau2_predicted,
    )
    from hhscatter.analysis.survival.fits import observed_from_outcome
    from hhscatter.analysis.survival.windows import choose_windows

    p = study.params
    gs = list(p.gammas)
    lts = {g: _lifetimes(study.raw(diss_key(label, g))).sort_values("traj_id", ignore_index=True) for g in gs}
    N = len(lts[0.0])
    t_last = max(float(lt["t_end"].max()) for lt in lts.values())
    grid = np.round(np.arange(0.0, t_last + p.tau_grid_step, p.tau_grid_step), 9)
    P = {g: survival_on_grid(lt["t_end"].to_numpy(), observed_from_outcome(lt["outcome"]), grid)
         for g, lt in lts.items()}

    def rule(t, P0, n):
        return choose_windows(t, P0, n_total=n).tau0

    tau0 = float(rule(grid, P[0.0], N))
    boot = bootstrap_transition_times({g: (lt["t_end"].to_numpy(), lt["outcome"].to_numpy()) for g, lt in lts.items()},
                                      0.0, grid, tau0=rule, alpha=p.alpha, n_boot=p.n_boot, seed=p.fit_seed)
    rows = []
    for g in gs[1:]:
        b = boot[boot["label"] == g]

        def sd(col, b=b):
            v = b[col].to_numpy(float)
            v = v[np.isfinite(v)]
            return float(np.std(v, ddof=1)) if v.size > 1 else math.nan

        t1 = tau1(grid, P[g], P[0.0], tau0, p.alpha)
        t2 = tau2_observed_interval(lts[g])
        q = settle_time_quantiles(lts[g]["t_end"].to_numpy(), lts[g]["outcome"], (0.01, 0.5))
        pred = float(tau2_predicted(E0, m.critical_energy, mu, g))
        rows.append({"system": label, "gamma": g, "n": N, "tau0": tau0, "tau0_err": float(boot["tau0"].std(ddof=1)),
                     "tau1": math.nan if t1 is None else t1, "tau1_err": sd("tau1"),
                     "tau2_obs": math.nan if t2.n_settled == 0 else t2.value,
                     "tau2_obs_lo": math.nan if t2.n_settled == 0 else t2.lo,
                     "tau2_obs_hi": math.nan if t2.n_settled == 0 else t2.hi,
                     "f_settled": float(np.mean(lts[g]["outcome"] == "settled")),
                     "p0_trapped": float(np.mean(lts[0.0]["outcome"] == "censored")),
                     "t_settle_q50": math.nan if q is None else float(q[1]), "t_settle_q50_err": sd("t_settle_q0.5"),
                     "tau2_pred": pred, "tau2_pred_err": pred * mu_err / mu})
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------
# claims
# ---------------------------------------------------------------------------
def _ve(v, e=None):
    f = lambda x: None if x is None or not math.isfinite(float(x)) else float(x)
    return {"value": f(v), "err": f(e)}


def _z_verdict(value, err, ref, label_ok, label_bad, ref_err=0.0):
    if value is None or ref is None or err is None or not math.isfinite(err):
        return "undetermined"
    s = math.hypot(err, ref_err or 0.0)
    z = (value - ref) / s if s > 0 else math.inf
    return f"{label_ok} (z = {z:+.1f})" if abs(z) <= 2 else f"{label_bad} (z = {z:+.1f})"


class _Claims:
    """The list of claim records; each also enters the study's comparison table (docs, report)."""

    def __init__(self, study):
        self.study, self.rows = study, []

    def add(self, claim, quantity, system, value, err, verdict, note="", reference=None):
        rec = {"claim": claim, "quantity": quantity, "system": system, **_ve(value, err), "reference": reference,
               "verdict": verdict, "note": note}
        self.rows.append(rec)
        self.study.compare(f"[{claim}] {quantity} — {system}", rec["value"], rec["err"], reference,
                           verdict=verdict, note=note, convention=self.study.convention_label)


def _claim1(claims, label, per, table):
    allk = table[table["convention"] == "plateau"]
    bad = allk[~allk["defined"]]
    claims.add("1", "κ0 well defined (all orbits, plateau windows) at every E/E_c", label,
               float(allk["defined"].mean()), None,
               "yes" if bad.empty else "no: ill-defined at E/E_c = " + ", ".join(f"{r:g}" for r in bad["ratio"])
               + f" (orbits still inside at t_max up to {bad['trapped_fraction'].max():.0%})",
               "value: fraction of the grid energies where κ0 is defined; the paper's convention (all orbits)")
    alt = table[~table["convention"].isin(CONVENTIONS)]
    if len(alt):
        name = alt["convention"].iloc[0]
        bad_a = alt[~alt["defined"]]
        claims.add("1", f"κ0 well defined with {name} ICs (all orbits, plateau windows)", label,
                   float(alt["defined"].mean()), None,
                   "yes" if bad_a.empty else "no: ill-defined at E/E_c = " + ", ".join(f"{r:g}" for r in bad_a["ratio"])
                   + (f" (orbits still inside at t_max up to {bad_a['trapped_fraction'].max():.0%})"
                      if bad_a["trapped_fraction"].notna().any() else ""),
                   "the same grid, N and t_max with ICs uniform in that region, random momentum directions")
    fitted = [k for k, v in per.items() if v]
    prim = per.get("plateau") or per.get("escaping") or per.get("plevel")
    if prim is None:
        claims.add("1", "κ0(E) law fitted", label, None, None, "undetermined",
                   "fewer than 5 defined κ0 points in every window convention")
        return
    lo, hi = prim.get("beta_low"), prim.get("beta_high")
    b_lo = _across({k: v and {"x": v["beta_low"]} for k, v in per.items()}, "x")
    b_hi = _across({k: v and {"x": v["beta_high"]} for k, v in per.items()}, "x")
    eb = _across(per, "eps_b")
    if lo:
        claims.add("1", "exponent β below the break (κ0 ∝ ε^β)", label, b_lo[0], b_lo[1],
                   _z_verdict(b_lo[0], b_lo[1], 2.0, "quadratic", "not quadratic"),
                   "ε = (E − E_c)/E_c; mean over the conventions fitted (" + ", ".join(fitted)
                   + "), err √(stat² + spread²)", 2.0)
    if hi:
        claims.add("1", "exponent β above the break", label, b_hi[0], b_hi[1],
                   _z_verdict(b_hi[0], b_hi[1], 1.0, "linear", "not linear"), "as above", 1.0)
    claims.add("1", "break ε_b = (E_b − E_c)/E_c", label, eb[0], eb[1],
               _z_verdict(eb[0], eb[1], HH_PAPER_BREAK, "same as the paper's HH break",
                          "differs from the paper's HH break"),
               "continuous law a ε² + b ε, c ε; the paper's E_b ≈ 0.27 for HH is ε_b = 0.62", HH_PAPER_BREAK)
    bl = _across(per, "b")
    if bl[0] is not None:
        claims.add("1", "linear term b of the law at threshold (κ0 ≈ b ε)", label, bl[0], bl[1],
                   _z_verdict(bl[0], bl[1], 0.0, "quadratic onset (b = 0)", "linear onset (b ≠ 0)"),
                   "reduced units (κ in well frequencies, ε = E/E_c − 1); the paper's HH b = 0.03 is 0.005 here", 0.0)
    chi = prim["chi2"] / max(prim["dof"], 1)
    claims.add("1", f"law family fits (χ²/dof, {'plateau' if per.get('plateau') else 'escaping'} convention)",
               label, chi, None,
               "fits" if chi <= 3 else "poor fit (χ²/dof > 3)", f"{prim['n_points']} points, dof {prim['dof']}")


def _claim3(claims, label, meas, pred, wins, mu_c0, paper_mu, is_hh, relaxed):
    how = ("dE/dt = −γ μ(E) E with μ(E) = 2⟨K⟩/E of the conservative flow ({}) above E_c and of the microcanonical "
           "well below, fitted like the measured ⟨E⟩(t)" + ("" if relaxed else
                                                          "; probe window not relaxed at some energy (clipped)"))
    for wname, w in wins.items():
        where = f"on [{w[0]:g}, {w[1]:g}]" + (" (fig3's window)" if wname == "paper" else " (⟨E⟩ > E_c)")
        mu_m, mu_m_err = meas[wname]
        claims.add("3", f"μ measured {where}", label, mu_m, mu_m_err,
                   _z_verdict(mu_m, mu_m_err, paper_mu, "agrees with the paper's 0.91", "differs from the paper's 0.91")
                   if is_hh and wname == "paper" else "measured",
                   "⟨E⟩(t) of the orbits not escaped, fixed-intercept log fit (fig3's); bootstrap over orbits; this "
                   "study's setup (r_esc the system's default)", paper_mu if is_hh and wname == "paper" else None)
        for kind, name in (("c-measure", "c-measure: trapped orbits dropped"), ("all survivors", "all survivors")):
            v, e = pred[kind, wname]
            claims.add("3", f"μ predicted {where}, {kind}", label, v, e,
                       _z_verdict(v, e, mu_m, "agrees with μ measured", "differs from μ measured", mu_m_err),
                       how.format(name), mu_m)
    claims.add("3", "2⟨K⟩/E of the c-measure at E0", label, mu_c0, None, "for reference (instantaneous μ at E0)",
               "interpolated between probe energies")


def _claim5(claims, label, meas, own, pred, wins):
    """μ_meas = μ of the survivors' own ⟨K⟩ + selection (escape, settling); own ⟨K⟩ against the conservative one."""
    for wname, w in wins.items():
        where = f"on [{w[0]:g}, {w[1]:g}]"
        v, e = own[wname]
        m, me = meas[wname]
        claims.add("5", f"moment test: μ of the survivors' own ⟨K⟩ {where} (no selection)", label, v, e,
                   _z_verdict(m, me, v, "selection by escape/settling negligible",
                              f"selection by escape/settling shifts μ by {m - v:+.3f}", e),
                   "2⟨K⟩/⟨E⟩ of the dissipative survivors from their energy loss (ΔE = −2γ∫K dt), path fitted "
                   "like ⟨E⟩(t), on the orbits traj_id < n_boot_orbits; σ from 10 groups of them; reference: μ measured", m)
        pv, pe = pred["c-measure", wname]
        claims.add("5", f"moment test: survivors' ⟨K⟩ against the conservative c-measure's {where}", label, v - pv,
                   math.hypot(e, pe),
                   _z_verdict(v - pv, math.hypot(e, pe), 0.0, "survivors carry the c-measure's ⟨K⟩",
                              "survivors' ⟨K⟩ differs from the c-measure's"),
                   "value: μ(own ⟨K⟩) − μ predicted (c-measure above E_c, microcanonical well below): a moment test "
                   "of claim 5 (not the distance of Fig. 5)", 0.0)


def _claim6(study, claims, label, m, per, taus, E0, mu, rms_ref):
    """The survival model, Eq. (eqn:surv_prob_model), both hazards, fig6's fitting rule, at γ = mu_gamma."""
    from hhscatter.analysis.dissipative.model_comparison import (
        fit_homogeneous_hazards,
        survival_fit_points,
    )
    from hhscatter.analysis.survival.fits import survival_from_lifetimes
    from hhscatter.analysis.survival.kappa_law import PiecewiseKappa

    p = study.params
    conv = "plateau" if per.get("plateau") else "escaping"
    law = per.get(conv)
    g = p.mu_gamma
    if law is None:
        for h in ("paper", "integrated"):
            claims.add("6", f"survival model ({h} hazard) at γ = {g:g}: rms log residual", label, None, None,
                       "undetermined", "no κ0(E) law fitted (fewer than 5 defined points)")
        return {}
    ec = m.critical_energy
    kappa = PiecewiseKappa(E_c=ec, a2=law["a"]["value"] / ec**2, a1=law["b"]["value"] / ec,
                           slope=law["c"]["value"] / ec, E_switch=ec * (1 + law["eps_b"]["value"]))
    lt = _lifetimes(study.raw(diss_key(label, g)))
    n = len(lt)
    c = survival_from_lifetimes(lt[["t_end", "outcome"]], np.arange(0.0, float(lt["t_end"].max()) + p.sm_dt, p.sm_dt))
    tau0 = float(taus["tau0"].iloc[0])
    tf, Pf, sf = survival_fit_points(c.t, c.P, c.P_err, tau0, p.sm_fit_dt, n, p.sm_min_count)
    out, reason = {}, ""
    tau2 = float(taus.loc[taus["gamma"] == g, "tau2_pred"].iloc[0])
    try:
        if tau0 >= tau2:  # the model's escape regime [τ0, τ2] is empty
            raise ValueError(f"τ0 = {tau0:.0f} (on P_0) ≥ τ2 = {tau2:.0f} by Eq. (eq:tau2): the model has no escape "
                             "regime")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fits = fit_homogeneous_hazards(c.t, c.P, c.P_err, tf, Pf, sf, kappa=kappa, E0=E0, mu=mu, gamma=g,
                                           tau0=tau0, E_c=ec, hazards=["paper", "integrated"], fit_tau2=False,
                                           P_min=p.sm_min_count / n * 0.999)
    except (RuntimeError, ValueError) as exc:
        fits, reason = {}, str(exc)
    for h in ("paper", "integrated"):
        f = fits.get(h)
        if f is None:
            claims.add("6", f"survival model ({h} hazard) at γ = {g:g}: rms log residual", label, None, None,
                       f"not applicable: {reason}", "fig6's rule could not fit")
            continue
        ref = rms_ref.get(h)
        verdict = ("reference (Hénon–Heiles)" if ref is None else
                   "as good as on Hénon–Heiles (rms ≤ 1.5× its)" if f.rms_log_residual <= 1.5 * ref else
                   f"worse than on Hénon–Heiles ({f.rms_log_residual / ref:.1f}× its rms)")
        claims.add("6", f"survival model ({h} hazard) at γ = {g:g}: rms log residual", label, f.rms_log_residual,
                   None, verdict, f"fig6's rule (points every {p.sm_fit_dt:g} from τ0 = {tau0:.1f} with N·P ≥ "
                   f"{p.sm_min_count:g}, P(τ0) held, best of 3 starts); κ0(E) the {conv} law, μ measured; χ²/dof = "
                   f"{f.chi2_red:.3g} over {f.n_points} points (correlated Kaplan–Meier points: indicative)")
        out[h] = {"rms_log_residual": f.rms_log_residual, "chi2_red": f.chi2_red, "n_points": f.n_points,
                  "values": {k: float(v) for k, v in f.values.items() if np.ndim(v) == 0},
                  "curve": {"t": c.t[c.t >= tau0][::4].tolist(), "P": c.P[c.t >= tau0][::4].tolist(),
                            "model": [float(x) for x in f.predict(c.t[c.t >= tau0][::4])]}}
    return out


def _claim7(study, claims, label, m, table, taus, E0, mu):
    """κγ(t) = κ0(E(t)) for the smallest γ: escapes observed over those expected from κ0 at E0 e^{−μγt}."""
    from hhscatter.analysis.dissipative.effective_rate import (
        binned_hazard,
        observed_over_expected,
    )

    p = study.params
    g = min(x for x in p.gammas if x > 0)
    conv = "plateau"
    k = table[(table["convention"] == conv) & table["defined"]].sort_values("eps")
    if len(k) < 2:
        conv = "escaping"
        k = table[(table["convention"] == conv) & table["defined"]].sort_values("eps")
    lt = _lifetimes(study.raw(diss_key(label, g)))
    t_end = lt["t_end"].to_numpy()
    esc = (lt["outcome"] == "escaped").to_numpy()
    tau0 = float(taus["tau0"].iloc[0])
    t_lo_e = math.log(E0 / (m.critical_energy * (1 + float(k["eps"].min())))) / (mu * g) if len(k) else tau0
    edges = np.arange(tau0, max(tau0, t_lo_e) + 1e-9, p.hazard_bin)
    if len(k) < 2 or edges.size < 2:
        why = ("κ0 defined at fewer than 2 energies" if len(k) < 2 else
               f"τ0 = {tau0:.0f} comes after E(t) has reached the lowest defined κ0 energy (t = {t_lo_e:.0f})")
        claims.add("7", f"κγ(t)/κ0(E(t)) at γ = {g:g} (observed/expected escapes)", label, None, None,
                   f"undetermined: {why}", f"{conv} κ0 points")
        return None
    b = binned_hazard(t_end, esc, edges)
    at_risk = b["exposure"] / p.hazard_bin
    b = b[at_risk >= p.min_survivors]
    eps_t = E0 * np.exp(-mu * g * b["t_mid"].to_numpy()) / m.critical_energy - 1
    lk = np.interp(eps_t, k["eps"], np.log(k["kappa"]), left=np.nan, right=np.nan)
    b = b.assign(eps=eps_t, kappa0=np.exp(lk))
    r, e, expected = observed_over_expected(b, b["kappa0"])
    claims.add("7", f"κγ(t)/κ0(E(t)) at γ = {g:g} (observed/expected escapes)", label, r, e,
               _z_verdict(r, e, 1.0, "κγ(t) = κ0(E(t))", f"κγ differs from κ0(E(t)) by {100 * (r - 1):+.0f} %"),
               f"bins of {p.hazard_bin:g} from τ0 = {tau0:.1f} while E(t) = E0 e^(−μγt) ≥ the lowest defined κ0 "
               f"energy; κ0 interpolated (log) between the {conv} points; {expected:.0f} escapes expected", 1.0)
    return b.assign(system=label, gamma=g, convention=conv)


def _claim4(claims, label, taus: pd.DataFrame, mu_gamma):
    from hhscatter.analysis.dissipative.transitions import power_law_exponent

    claims.add("4", "τ0 (on P_0)", label, float(taus["tau0"].iloc[0]), float(taus["tau0_err"].iloc[0]),
               "measured", "choose_windows on the conservative curve")
    t1 = taus["tau1"].to_numpy()
    ok = np.isfinite(t1)
    mono = bool(np.all(np.diff(t1[ok]) <= 0)) if ok.sum() > 1 else None
    p1, p1e = power_law_exponent(taus["gamma"], taus["tau1"], taus["tau1_err"])
    undefined = ", ".join(f"{g:g}" for g, v in zip(taus["gamma"], t1) if not np.isfinite(v))
    claims.add("4", "τ1 ∝ γ^−p1", label, p1, p1e,
               (f"undetermined: P_γ never reaches α P_0 after τ0 = {taus['tau0'].iloc[0]:.0f} at γ = {undefined} "
                f"(τ2 by Eq. (eq:tau2) = {', '.join(f'{v:.0f}' for v in taus['tau2_pred'])}: the irregular regime "
                f"outlasts the dissipative one; P_0 keeps {taus['p0_trapped'].iloc[0]:.0%} orbits to t_max)")
               if mono is None else
               ("τ1 increases as γ decreases" if mono else "τ1 not monotone in γ")
               + (f"; undefined at γ = {undefined}" if undefined and mono is not None else ""),
               "paper: τ1 and τ2 increase with decreasing γ; a linear κ0(E) gives p1 = 1/2")
    p50, p50e = power_law_exponent(taus["gamma"], taus["t_settle_q50"], taus["t_settle_q50_err"])
    claims.add("4", "median settling time ∝ γ^−p", label, p50, p50e,
               _z_verdict(p50, p50e, 1.0, "τ2 ∝ 1/γ", "not ∝ 1/γ"), "Eq. (eq:tau2): p = 1 (N-independent)", 1.0)
    r = taus[taus["gamma"] == mu_gamma]
    if len(r) and np.isfinite(r["tau2_obs"].iloc[0]):
        r = r.iloc[0]
        ratio = r["tau2_obs"] / r["tau2_pred"]
        claims.add("4", f"τ2 observed / Eq. (eq:tau2) at γ = {mu_gamma:g}", label, ratio, None,
                   "agrees within 15 %" if abs(ratio - 1) <= 0.15 else f"differs by {100 * (ratio - 1):+.0f} %",
                   f"τ2,obs = {r['tau2_obs']:.1f} (first settling, N = {int(r['n'])}: decreases with N; order-statistic "
                   f"interval [{r['tau2_obs_lo']:.1f}, {r['tau2_obs_hi']:.1f}]), ln(E0/E_c)/(μγ) = "
                   f"{r['tau2_pred']:.1f} ± {r['tau2_pred_err']:.1f} with μ measured", 1.0)


def _analyze_mu(study, claims, label, spec, m, E0, fits):
    """Claims 3 and 5 of one system: (μ rows, ⟨E⟩ curves, (μ, σ) measured on fig3's window, its JSON numbers)."""
    p = study.params
    ec = m.critical_energy
    mrows = _mu_conservative(study, label, m, fits)
    mdf = pd.DataFrame(mrows)
    meas, inside, (own, own_path) = _mu_measured(study, label, m, E0)
    pred, grid, path = _mu_predicted(study, mdf, ec, E0)
    mu_c0 = float(_mu_of_E(mdf, ec)(E0))
    relaxed = bool(mdf.loc[mdf["kind"] == "c-measure", "relaxed"].fillna(False).astype(bool).all())
    wins = _mu_windows(study)
    _claim3(claims, label, meas, pred, wins, mu_c0, p.paper_mu, spec["name"] == "henon_heiles", relaxed)
    _claim5(claims, label, meas, own, pred, wins)
    curves = [pd.DataFrame({"system": label, "t": t, "mean_E_over_E0": e / E0, "kind": kind}) for t, e, kind in (
        (inside["t"], inside["mean_E"], "measured"), (grid, path, "predicted"),
        (own_path[0], own_path[1], "survivors' own ⟨K⟩"))]
    numbers = {
        "mu_measured": _ve(*meas["paper"]), "mu_predicted": _ve(*pred["c-measure", "paper"]),
        "mu_by_window": {name: {"window": list(w), "measured": _ve(*meas[name]),
                                "predicted_c_measure": _ve(*pred["c-measure", name]),
                                "predicted_all_survivors": _ve(*pred["all survivors", name]),
                                "survivors_own_K": _ve(*own[name])} for name, w in wins.items()},
        "mu_c_at_E0": mu_c0,
        "mu_conservative": [{k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                             for k, v in r.items()} for r in mrows],
    }
    return mrows, curves, meas["paper"], numbers


def analyze(study):
    """analyze(study) -> None: claims 1–7 per system (5 as Fig. 5's distance and as a moment); derived tables and
    generality.json."""

    _check(study)
    p = study.params
    claims = _Claims(study)
    kappa_rows, mu_rows, tau_tables, curves, hazards, systems, rms_ref = [], [], [], [], [], {}, {}
    kcm_rows = []
    for label, spec, m in _systems(study):
        ec = m.critical_energy
        E0 = p.e0_ratio * ec
        rows, fits = _kappa_rows(study, label, m)
        kappa_rows += rows
        table = pd.DataFrame(rows)
        per = _law(study, table)
        _claim1(claims, label, per, table)

        mrows, cur, (mu_m, mu_m_err), mu_numbers = _analyze_mu(study, claims, label, spec, m, E0, fits)
        mu_rows += mrows
        curves += cur

        taus = _taus(study, label, m, E0, mu_m, mu_m_err)
        tau_tables.append(taus)
        _claim4(claims, label, taus, p.mu_gamma)
        sm6 = _claim6(study, claims, label, m, per, taus, E0, mu_m, rms_ref)
        if spec["name"] == "henon_heiles":
            rms_ref.update({h: v["rms_log_residual"] for h, v in sm6.items()})
        samples = {r: _cm_sample(study, label, r) for r in _cm_ratios(p)}
        cm_rows = _claim2(study, claims, label, table, samples)
        kcm_rows += [{"system": label, **{k: v for k, v in r.items() if not isinstance(v, dict)}} for r in cm_rows]
        c5 = _claim5_distance(study, claims, label, m, E0, mu_m, samples)
        hz = _claim7(study, claims, label, m, table, taus, E0, mu_m)
        if hz is not None:
            hazards.append(hz)
        systems[label] = {
            "spec": spec, "E_c": ec, "n_exits": len(m.exits), "saddle_radius": m.saddle_radius,
            "ic_radius": p.radius_frac * m.saddle_radius, "r_esc_at_E0": float(m.default_escape_radius(E0)),
            "E0": E0, "kappa_law": per, **mu_numbers,
            "taus": taus.drop(columns=["system"]).to_dict(orient="records"),
            "survival_model": sm6, "kappa_cmeasure": cm_rows, "cmeasure_distance": c5,
        }
    ktab = pd.DataFrame(kappa_rows)
    study.write_table(ktab, "kappa.parquet", description="κ0(E) per system, E/E_c and window convention")
    study.write_table(pd.DataFrame(mu_rows), "mu_conservative.parquet",
                      description="2⟨K⟩/E of the conservative system: c-measure (probe drag) and microcanonical well")
    study.write_table(pd.concat(curves, ignore_index=True), "energy_curves.parquet",
                      description="⟨E⟩(t)/E0 measured and the predicted path dE/dt = −γ μ(E) E")
    study.write_table(pd.concat(tau_tables, ignore_index=True), "taus.parquet", description="τ0, τ1, τ2 per γ")
    study.write_table(pd.DataFrame(kcm_rows), "kappa_cmeasure.parquet",
                      description="claim 2: κ from the c-measure, Eq. (eqn:kappa_cmeasure_truetime), beside κ0")
    if hazards:
        study.write_table(pd.concat(hazards, ignore_index=True), "hazard.parquet",
                          description="claim 7: escape hazard of the smallest γ per time bin, κ0 at E0 e^(−μγt)")
    study.write_numbers({
        "rules": {
            "energies": "E = r·E_c on the grid ratios, the same for every system",
            "ics": "uniform in the disk r < radius_frac·r_s, tangential momenta; r_esc the system's default",
            "kappa": "escape_rate (plateau windows) and P-level windows, trapped-plateau check; law in ε = E/E_c − 1",
            "mu_measured": "fig3's: <E>(t) of orbits not escaped, settled continued; fixed-intercept log fit",
            "mu_predicted": "2<K>/E of the conservative flow (probe drag, c-measure) above E_c, microcanonical "
                            "well below; path dE/dt = -gamma mu(E) E fitted like the measured curve",
            "taus": "fig4's: tau0 choose_windows(P_0), tau1 P_g = alpha P_0, tau2 first settling, Eq. (eq:tau2)",
            "kappa_cmeasure": "claim 2: every section crossing of a conservative run (KAM-trapped orbits dropped) on "
                              "[ceil(tau0 + cm_rec_efolds/kappa), cm_t_to - cm_margin], Eq. (eqn:kappa_cmeasure_"
                              "truetime), bootstrap over orbits; against kappa0 of the claim-1 run at that E/E_c",
            "cmeasure_distance": "claim 5: first crossing after t* of the dissipative survivors vs the sprinkler "
                                 "points of mu_c at E(t*) and E0; paired debiased Hellinger, half-samples of orbits",
        },
        "systems": systems,
        "claims": claims.rows,
        "kappa": ktab.replace({np.nan: None}).to_dict(orient="records"),
    })


def plot(study):
    """plot(study) -> None: generality.png from the derived tables and generality.json."""
    from .figure import plot_generality

    d = study.out / "derived"
    plot_generality(pd.read_parquet(d / "kappa.parquet"), pd.read_parquet(d / "mu_conservative.parquet"),
                    pd.read_parquet(d / "energy_curves.parquet"), study.read_numbers(), study.figure_path)
