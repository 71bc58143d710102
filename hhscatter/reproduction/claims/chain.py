"""The paper's chain of claims run on each system, and the evidence behind their readings, as one call each.

``runs`` is the reading side of a study (what :mod:`hhscatter.reproduction.claims` reads): ``params`` (the study's
parameters), ``lifetimes(key)``, ``sections(key, t_from=None, columns=…)``, ``snapshots(key, …)``,
``snapshot_parts(key)`` and, for the evidence, ``shadow_ics(key)`` (the shadow run's ICs with traj_id and d0, or
None where no orbit was left to shadow). ``systems`` is a list of (label, spec, System). Nothing here writes a
file: the functions return the numbers and the tables ({name: (DataFrame, description)}) for the study to write.

Every verdict depends on its own system's runs and on Hénon–Heiles' (claim 6's reference, found by its name),
never on the order of ``systems``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from hhscatter.analysis.survival.fits import lifetimes_to_arrays
from hhscatter.reproduction.claims import cmeasure, dissipative, evidence, kappa, mu
from hhscatter.reproduction.claims.keys import cm_ratios, ev_key, lab_key, map_key, map_ratios, ps_key
from hhscatter.reproduction.claims.records import RULES, Claims
from hhscatter.reproduction.claims.resc import r_esc_rule, resc_kappa_rows, resc_rows

__all__ = ["analyze_claims", "analyze_evidence", "check_params", "labelled_set", "validity_rules"]

#: the system whose fits are claim 6's reference (the paper's system)
REFERENCE_SYSTEM = "henon_heiles"


def check_params(p) -> None:
    """Refuse parameters of the claims' study that contradict each other, naming the keys (before any run).

    Raises
    ------
    ValueError
        probe_ratios, cm_ratios not among ratios; gammas not increasing or without 0 and mu_gamma; ratios not above
        1 or mc_ratios not below; c5_ratio not among cm_ratios or outside (1, e0_ratio); ev_times beyond ev_t_max
        or ev_window outside (0, min(ev_t_max, ps_t_max)); resc_ratios without e0_ratio; cm_t_max ≤ cm_t_to;
        lab_t_max below 1.5 ev_t_max, lab_band not (lo, hi) with 0 < lo < hi, lab_ftle_regular not in
        (0, lab_ftle_chaotic].

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> check_params(NS(ratios=[1.5], probe_ratios=[1.6]))
    Traceback (most recent call last):
    ...
    ValueError: [study].probe_ratios must be among ratios (their κ, τ0 set the window); [1.6] are not
    """
    ratios, probes = list(p.ratios), list(p.probe_ratios)
    off = [r for r in probes if not np.isclose(ratios, r).any()]
    if off:
        raise ValueError(f"[study].probe_ratios must be among ratios (their κ, τ0 set the window); {off} are not")
    gs = list(p.gammas)
    if 0.0 not in gs or p.mu_gamma not in gs or sorted(gs) != gs:
        raise ValueError(f"[study].gammas must be increasing, contain 0 and mu_gamma; got {gs}")
    if any(r <= 1 for r in ratios) or any(r >= 1 for r in p.mc_ratios):
        raise ValueError("[study].ratios must be > 1 (above E_c) and mc_ratios < 1 (below)")
    off = [r for r in p.cm_ratios if not np.isclose(ratios, r).any()]
    if off:
        raise ValueError(f"[study].cm_ratios must be among ratios (claim 2 compares with their κ0); {off} are not")
    c5 = p.c5_ratio
    if not np.isclose(p.cm_ratios, c5).any() or not 1 < c5 < p.e0_ratio:
        raise ValueError(f"[study].c5_ratio = {c5} must be one of cm_ratios and between 1 and e0_ratio")
    if max(p.ev_times) > p.ev_t_max or not 0 < p.ev_window < min(p.ev_t_max, p.ps_t_max):
        raise ValueError("[study].ev_times must be ≤ ev_t_max and ev_window inside (0, min(ev_t_max, ps_t_max))")
    if not np.isclose(p.resc_ratios, p.e0_ratio).any():
        raise ValueError(f"[study].resc_ratios must contain e0_ratio = {p.e0_ratio:g} (2⟨K⟩/E measured at E0)")
    if not p.cm_t_max > p.cm_t_to:
        raise ValueError("[study].cm_t_max must exceed cm_t_to (orbits still inside at t_max, censored, are dropped)")
    if not p.lab_t_max >= 1.5 * p.ev_t_max:
        raise ValueError(
            f"[study].lab_t_max = {p.lab_t_max:g} must be at least 1.5 ev_t_max = {1.5 * p.ev_t_max:g} (the labels "
            "come from a longer run than the indicator's)"
        )
    if len(p.lab_band) != 2 or not 0 < p.lab_band[0] < p.lab_band[1]:
        raise ValueError(f"[study].lab_band must be (lo, hi) with 0 < lo < hi, got {list(p.lab_band)}")
    if not 0 < p.lab_ftle_regular <= p.lab_ftle_chaotic:
        raise ValueError("[study].lab_ftle_regular must be positive and at most lab_ftle_chaotic")


def _system_claims(runs, claims, label, spec, m):
    """Claims 1–5 and 7 of one system and its fit of claim 6: (tables' rows, the system's record, claim 6's fit)."""
    p = runs.params
    ec = m.critical_energy
    E0 = p.e0_ratio * ec
    rows, fits = kappa.kappa_rows(runs, label, m)
    table = pd.DataFrame(rows)
    per = kappa.fit_law(runs, table)
    kappa.claim1(claims, label, per, table)
    mrows, cur, (mu_m, mu_m_err), mu_numbers = mu.analyze_mu(runs, claims, label, spec, m, E0, fits)
    taus = dissipative.taus(runs, label, m, E0, mu_m, mu_m_err)
    dissipative.claim4(claims, label, taus, p.mu_gamma)
    sm6 = dissipative.fit_claim6(runs, label, m, per, taus, E0, mu_m)
    samples = {r: cmeasure.cm_sample(runs, label, r) for r in cm_ratios(p)}
    cm_rows = cmeasure.claim2(runs, claims, label, table, samples)
    kcm = [{"system": label, **{k: v for k, v in r.items() if not isinstance(v, dict)}} for r in cm_rows]
    c5 = cmeasure.claim5_distance(runs, claims, label, m, E0, mu_m, samples)
    hz = dissipative.claim7(runs, claims, label, m, table, taus, E0, mu_m)
    record = {
        "spec": spec,
        "E_c": ec,
        "n_exits": len(m.exits),
        "saddle_radius": m.saddle_radius,
        "ic_radius": p.radius_frac * m.saddle_radius,
        "r_esc_at_E0": float(m.default_escape_radius(E0)),
        "E0": E0,
        "kappa_law": per,
        **mu_numbers,
        "taus": taus.drop(columns=["system"]).to_dict(orient="records"),
        "kappa_cmeasure": cm_rows,
        "cmeasure_distance": c5,
    }
    return (rows, mrows, cur, taus, kcm, hz), record, sm6


def analyze_claims(runs, systems, compare=None) -> tuple[dict, dict]:
    """Claims 1–7 on every system (5 as Fig. 5's distance and as a moment): the numbers and the tables.

    Parameters
    ----------
    runs
        The reading side of the study (module docstring).
    systems : list of (label, spec, System)
        The systems in the study's order (the order of the records; no verdict depends on it).
    compare : callable, optional
        Called with every claim record (a study's comparison table: ``compare(label, value, err, reference,
        verdict=, note=)``).

    Returns
    -------
    (dict, dict)
        The numbers {rules, systems, claims, kappa} and the tables {name: (DataFrame, description)}: kappa,
        mu_conservative, energy_curves, taus, kappa_cmeasure and hazard (claim 7, where any system has one).
        Claim 6's verdicts are given once every system is fitted, against Hénon–Heiles wherever it stands.
    """
    claims = Claims(compare)
    parts = {k: [] for k in ("kappa", "mu", "curves", "taus", "kcm", "hazard")}
    records, sm6 = {}, {}
    for label, spec, m in systems:
        (rows, mrows, cur, taus, kcm, hz), records[label], sm6[label] = _system_claims(runs, claims, label, spec, m)
        parts["kappa"] += rows
        parts["mu"] += mrows
        parts["curves"] += cur
        parts["taus"].append(taus)
        parts["kcm"] += kcm
        if hz is not None:
            parts["hazard"].append(hz)
    hh = next((label for label, spec, _ in systems if spec["name"] == REFERENCE_SYSTEM), None)
    for label, rec in dissipative.claim6(claims, sm6, hh, runs.params).items():
        records[label]["survival_model"] = rec
    ktab = pd.DataFrame(parts["kappa"])
    tables = {
        "kappa": (ktab, "κ0(E) per system, E/E_c and window convention"),
        "mu_conservative": (
            pd.DataFrame(parts["mu"]),
            "2⟨K⟩/E of the conservative system: c-measure (probe drag) and microcanonical well",
        ),
        "energy_curves": (
            pd.concat(parts["curves"], ignore_index=True),
            "⟨E⟩(t)/E0 measured and the predicted path dE/dt = −γ μ(E) E",
        ),
        "taus": (pd.concat(parts["taus"], ignore_index=True), "τ0, τ1, τ2 per γ"),
        "kappa_cmeasure": (
            pd.DataFrame(parts["kcm"]),
            "claim 2: κ from the c-measure, Eq. (eqn:kappa_cmeasure_truetime), beside κ0",
        ),
    }
    if parts["hazard"]:
        tables["hazard"] = (
            pd.concat(parts["hazard"], ignore_index=True),
            "claim 7: escape hazard of the smallest γ per time bin, κ0 at E0 e^(−μγt)",
        )
    numbers = {
        "rules": RULES,
        "systems": records,
        "claims": claims.rows,
        "kappa": ktab.replace({np.nan: None}).to_dict(orient="records"),
    }
    return numbers, tables


def _indicator(runs, key, t_from):
    """(lifetimes, shadow indicator frame) of the pair ``key`` / ``key_shadow``: an empty frame where no orbit was
    left to shadow."""
    from hhscatter.analysis.geometry.regularity import shadow_indicator  # deferred: scipy loads on first use

    lt = runs.lifetimes(key)
    ics = runs.shadow_ics(key)
    if ics is None:
        return lt, pd.DataFrame({"traj_id": [], "regular": [], "kind": []})
    ind = shadow_indicator(
        runs.sections(key, t_from, columns=None),
        runs.sections(key + "_shadow", t_from, columns=None),
        ics["traj_id"],
        ics["d0"],
        t_from,
        g_max=runs.params.ev_g_max,
    )
    return lt, ind


def _ensemble_evidence(runs, label, head, ics, r, t_from, grid):
    """The regular record, the long-time rows and fit, and the decay curves of one ensemble (system, ICs, E/E_c)."""
    from hhscatter.analysis.geometry.regularity import INDICATOR  # deferred: scipy loads on first use

    p = runs.params
    lt, ind = _indicator(runs, ev_key(label, ics, r), t_from)
    name = "disk/tangential" if ics == "disk" else f"{ics}/{p.alt_momentum}"
    at = {"id": f"{label}-{r:g}-{ics}", **head, "e_ratio": r, "ics": name}
    reg = {
        **at,
        **evidence.regular_record(lt, ind, p.ev_g_max),
        "indicator": INDICATOR,
        "t_from": t_from,
        "g_max": p.ev_g_max,
        "delta": p.ev_delta,
    }
    reg.update(_labelled_evidence(runs, label, ics, r, len(lt), ind, reg))
    regular = ind.loc[ind["regular"].astype(bool), "traj_id"]
    rows, fit = evidence.long_time_record(lt, regular, p.ev_times, p.ev_fit_t0, p.ev_hazard_edges)
    surv = [{**at, **row, "id": f"{at['id']}-t{row['t']:g}"} for row in rows] if ics == "disk" else []
    curves = evidence.decay_curves(lt, regular, grid).assign(label=label, e_ratio=r, ics=ics)
    return reg, surv, {**at, **fit}, curves


def labelled_set(runs, label, r):
    """The orbits of the disk ensemble at E = r·E_c to label by the variational FTLE (traj_id, growth, in_band and
    their initial states x, y, px, py), or None where its regular fraction is 0 or 1
    (:func:`~hhscatter.reproduction.claims.evidence.labelled_selection`; the study's lab_* parameters)."""
    p = runs.params
    key = ev_key(label, "disk", r)
    lt, ind = _indicator(runs, key, p.ev_t_max - p.ev_window)
    sel = evidence.labelled_selection(ind, len(lt), p.lab_band, p.lab_band_n, p.lab_side_n, p.lab_seed)
    if sel is None:
        return None
    ics = runs.initial_states(key).set_index("traj_id").loc[sel["traj_id"]]
    return sel.assign(**{q: ics[f"{q}0"].to_numpy() for q in ("x", "y", "px", "py")})


def _labelled_evidence(runs, label, ics, r, n, ind, reg) -> dict:
    """The indicator systematic of one ensemble's record: {syst_indicator, err_total, labelled} (syst_indicator and
    labelled None where no labelled set was run: other ICs, or a regular fraction of 0 or 1; err_total, the binomial
    error and both systematics in quadrature, None at a count of 0, where the fraction is a one-sided bound)."""
    from hhscatter.analysis.geometry.regularity import G_MAX_RANGE  # deferred: scipy loads on first use

    p = runs.params
    got = runs.labelled(lab_key(label, r)) if ics == "disk" else None
    rec = None
    if got is not None:
        sel, lt = got
        rec = evidence.indicator_record(
            n,
            ind,
            sel,
            lt,
            p.lab_t_max,
            band=p.lab_band,
            ftle_regular=p.lab_ftle_regular,
            ftle_chaotic=p.lab_ftle_chaotic,
            thresholds=[p.ev_g_max, *sorted(set(map(float, G_MAX_RANGE)) - {float(p.ev_g_max)})],
        )
    syst = None if rec is None else rec["syst"]
    # at a count of 0 the fraction is a one-sided bound, no error to add to
    total = None if reg["err"] is None else evidence.total_error(reg["err"], reg["syst"], syst)
    return {"syst_indicator": syst, "err_total": total, "labelled": rec}


def _map_kappa_rows(runs, systems) -> list:
    """κ0 of all orbits (plateau windows, the claims' rule and scene) at the map's energies off the claims' grid
    (:func:`~hhscatter.reproduction.claims.keys.map_ratios`), as the claims' ``kappa`` rows (``source`` 'map')."""
    p = runs.params
    rows = []
    for label, _spec, m in systems:
        for r in map_ratios(p):
            lt = runs.lifetimes(map_key(label, r))
            t_end, obs = lifetimes_to_arrays(lt)
            c, _, why = kappa.window_rate(lt, p, "window rule failed")
            row = {
                "system": label,
                "ratio": float(r),
                "energy": r * m.critical_energy,
                "convention": "plateau",
                "n": int(obs.size),
                "trapped_fraction": float((~obs).mean()),
                "t_first": kappa.first_escape(t_end[obs]),
                "source": "map",
            }
            if c is None:
                row.update(
                    kappa=None, kappa_err=None, tau0=None, t_hi=None, plateau_bias=None, defined=False, reason=why
                )
            else:
                bias = c.bias_at_end if np.isfinite(c.bias_at_end) else None
                row.update(
                    kappa=c.kappa,
                    kappa_err=c.kappa_err,
                    tau0=c.t_lo,
                    t_hi=c.t_hi,
                    plateau_bias=bias,
                    defined=bool(c.defined and c.kappa > 0),
                    reason=c.reason,
                )
            rows.append(row)
    return rows


def validity_rules(p) -> dict:
    """The rules of every validity-map cell, in words, from the study's parameters: how the regular fraction is
    counted and what decides "κ0 defined" (:func:`~hhscatter.reproduction.claims.evidence.kappa0_rule`)."""
    return {
        "regular_fraction": (
            f"n_regular of n orbits regular by the shadow indicator (growth < {p.ev_g_max:g} after "
            f"t = {p.ev_t_max - p.ev_window:g}); orbits that left before, and those crossing the section in "
            "neither run, count as not regular; ± its binomial 1σ, at a count of 0 its one-sided 95 % upper "
            "bound instead; ± the threshold's systematic (the largest shift with the threshold a decade either side); "
            "± the indicator's systematic where the fraction is neither 0 nor 1 (the share of all orbits that would "
            f"change class were the orbits with a shadow growth in ({p.lab_band[0]:g}, {p.lab_band[1]:g}) labelled "
            f"by their variational FTLE over [0, {p.lab_t_max:g}]: regular below {p.lab_ftle_regular:g}, chaotic "
            f"above {p.lab_ftle_chaotic:g} or when the orbit leaves, undecided between; measured on up to "
            f"{p.lab_band_n} of them and scaled to the whole band); the map's error is the total, the three in "
            "quadrature"
        ),
        "kappa0_defined": evidence.kappa0_rule(p.max_plateau_bias, p.min_survivors),
        "kappa0_source": (
            f"the claims' κ0 run at that E/E_c ({p.grid_n} orbits to t_max, disk ICs); at the map's energies off "
            "the claims' grid a κ0 run of the map with the same scene"
        ),
        "max_plateau_bias": float(p.max_plateau_bias),
        "min_survivors": float(p.min_survivors),
    }


def analyze_evidence(runs, systems, claims_numbers: dict) -> tuple[dict, dict]:
    """The evidence behind the claims' readings: regular orbits counted, long-time escape resolved, where the claims
    hold, the r_esc sensitivity of claims 3 and 5.

    Parameters
    ----------
    runs, systems
        As for :func:`analyze_claims`.
    claims_numbers : dict
        The claims' numbers (``kappa``, ``claims``) the validity map joins; may be empty.

    Returns
    -------
    (dict, dict)
        The numbers {regular_fraction, survival_long, long_time, validity_map, validity_rules, regular_below_1pc,
        resc, resc_kappa, r_esc_rule} and the
        tables {name: (DataFrame, description)}: sections_regular (where there are Poincaré runs), survival_long,
        long_time.
    """
    p = runs.params
    reg, surv, fits, points, curves = [], [], [], [], []
    t_from = p.ev_t_max - p.ev_window
    grid = np.linspace(0.0, p.ev_t_max, 401)
    for label, spec, _m in systems:
        head = {"system": spec["name"], "label": label}
        for ics in p.ev_ics:
            for r in p.ev_ratios:
                rec, rows, fit, cur = _ensemble_evidence(runs, label, head, ics, r, t_from, grid)
                reg.append(rec)
                surv += rows
                fits.append(fit)
                curves.append(cur)
        for r in p.ps_ratios:
            _, ind = _indicator(runs, ps_key(label, r), p.ps_t_max - p.ev_window)
            sec = runs.sections(ps_key(label, r), columns=["traj_id", "t", "x", "y", "px", "py"])
            kind = sec["traj_id"].map(ind.set_index("traj_id")["kind"]).fillna("escaped")
            points.append(sec.assign(system=label, e_ratio=r, kind=kind.astype(str)))
    tables = {}
    if points:
        tables["sections_regular"] = (
            pd.concat(points, ignore_index=True),
            "section crossings of the Poincaré runs with each orbit's indicator verdict",
        )
    tables["survival_long"] = (
        pd.concat(curves, ignore_index=True),
        "Kaplan–Meier P(t) to ev_t_max of all and of the non-regular orbits",
    )
    tables["long_time"] = (
        pd.DataFrame(fits).drop(columns=["hazard_nonregular"]),
        "plateau-plus-exponential fits and the non-regular decay per system, E/E_c, ICs",
    )
    kap = [{**k, "source": "claims"} for k in claims_numbers.get("kappa", [])] + _map_kappa_rows(runs, systems)
    vmap = evidence.validity_map(
        reg, fits, kap, claims_numbers.get("claims", []), ics="disk/tangential", max_bias=p.max_plateau_bias
    )
    numbers = {
        "regular_fraction": reg,
        "survival_long": surv,
        "long_time": fits,
        "validity_map": vmap,
        "validity_rules": validity_rules(p),
        "regular_below_1pc": evidence.first_below(reg, 0.01, ics="disk/tangential"),
        "resc": resc_rows(runs, systems),
        "resc_kappa": resc_kappa_rows(runs, systems),
        "r_esc_rule": {
            label: r_esc_rule(m, sorted({*map(float, p.ratios), *map(float, p.ev_ratios)})) for label, _, m in systems
        },
    }
    return numbers, tables
