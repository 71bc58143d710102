"""Study ``operator``: transfer operators on the section ṙ = 0, φ̇ > 0 (beyond the paper).

The paper's second open question (Discussion): "spectral approaches considering Perron–Frobenius (or similar)
operators acting on these densities". Every orbit runs through the engine (runner + an initial-condition table +
a one-return section scene, ``sections.first_only`` and ``stop``); the analysis is in
:mod:`hhscatter.analysis.geometry.ulam` and :mod:`hhscatter.analysis.geometry.transfer`.

1. **Ulam's method, conservative, per energy E**: boxes of side ``box`` in (x, y) on the section inside Ω,
   k × k stratified points per box weighted by the return map's invariant density |ṗ_r|/v; κ(E) as the root
   of ρ(M(κ)) = 1 on the chaotic saddle's class; its convergence in box side and samples per box, and its
   extrapolation to both limits (:func:`~hhscatter.analysis.geometry.ulam.kappa_convergence`).
2. **μ_c against fig1's sprinkler points**: the left Perron vector carried one return forward with the
   sprinkler weight, debiased Hellinger distances.
3. **Dissipative**: the operator on (box × energy bin) with drag, carried forward in time steps; P(t) and the
   first crossing after t* against an ensemble simulated here; then the operator on ρ(E) alone.
4. **Cost**: orbit-time of each route for κ at 1 %.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import transfer as tf
from hhscatter.analysis.geometry import ulam
from hhscatter.scene.schema import Integer, Integers, Number, Numbers, StudyParams
from hhscatter.studies import _upstream as up


class Params(StudyParams):
    """``[study]`` of studies/operator/study.toml."""

    energies: Numbers
    box: Number
    coarsen: Integers
    samples: Integer
    sample_subsets: Integers
    n_boot: Integer
    n_boot_grid: Integer = 4  # bootstrap replicates of the whole extrapolation grid (each: 9 roots of ρ(M(κ)) = 1)
    seed: Integer
    cm_energies: Numbers
    cm_boxes: Numbers
    cm_box_headline: Number
    n_splits: Integer
    mixed_energies: Numbers
    diss_energy: Number
    diss_gamma: Number
    diss_box: Number
    diss_bins: Integer
    diss_samples: Integer
    dt: Number
    max_return_time: Number
    t_horizon: Number
    t_star: Number
    sim_n: Integer
    cost_energies: Numbers
    cost_n: Integer
    target_rel: Number
    probe_t_max: Number


# -- keys and geometry -----------------------------------------------------------------------------
def ulam_key(E):
    return f"ulam_E{E:.3f}"


def probe_key(E):
    return f"probe_E{E:.3f}"


def cost_key(E):
    return f"pt_E{E:.3f}"


DISS_KEY, SIM_KEY = "diss_operator", "diss_sim"


def _r_esc(study) -> float:
    return float(study.config["scene"]["r_esc"])


def _extent(study):
    """The square [−r_esc, r_esc]² that holds Ω on the section (from the scene, no constants here)."""
    r = _r_esc(study)
    return (-r, r, -r, r)


def _k(n: int, what: str) -> int:
    k = int(round(math.sqrt(n)))
    if k * k != n or k < 1:
        raise ValueError(f"operator [study].{what} must be a square number (k × k strata per box), got {n}")
    return k


def section_samples(model, energy, extent, box, k, r_esc, rng, *, e_width=0.0) -> pd.DataFrame:
    """One row per sample point of :func:`~hhscatter.analysis.geometry.ulam.stratified_section_points` with its
    section state px, py (tangential velocity, φ̇ > 0)."""
    from hhscatter.scene.ics import section_velocities

    df = ulam.stratified_section_points(model, energy, extent, box, k, r_esc, rng, e_width=e_width)
    px, py = section_velocities(model, df["x"].to_numpy(), df["y"].to_numpy(), df["energy"].to_numpy())
    return df.assign(px=px, py=py)


def _samples(study, E, box, k, salt, e_width=0.0):
    rng = np.random.default_rng([study.params.seed, int(round(E * 1e6)), salt])
    return section_samples(study.model, E, _extent(study), box, k, _r_esc(study), rng, e_width=e_width)


def _write_ics(study, key, df):
    """The initial-condition table of run ``key`` from the points of ``df``: (path, number of orbits)."""
    path = study.raw(key + "_ics.parquet")
    path.parent.mkdir(parents=True, exist_ok=True)
    ics = pd.DataFrame(
        {
            "traj_id": np.arange(len(df), dtype=np.int64),
            "x": df["x"].to_numpy(),
            "y": df["y"].to_numpy(),
            "px": df["px"].to_numpy(),
            "py": df["py"].to_numpy(),
        }
    )
    # rewritten only when different: the scene's hash includes the file's, and resume relies on it
    if not path.exists() or not pd.read_parquet(path).equals(ics):
        ics.to_parquet(path, index=False)
    return path, len(ics)


def _one_return(study, key, df, gamma, workers, progress):
    """Run the sample points of ``df`` through the engine to their next crossing or their end."""
    path, n = _write_ics(study, key, df)
    scene = study.scene(key, ics=str(path), n=n, gamma=float(gamma), sections={"first_only": True, "stop": True})
    return study.run(key, scene, workers=workers, progress=progress)


def _diss_bins(study):
    """Energy bin edges from E_c (the model's) to E0 + ΔE/2: E0 is the centre of the top bin."""
    Ec = study.model.critical_energy
    E0 = study.params.diss_energy
    nb = study.params.diss_bins
    dE = (E0 - Ec) / (nb - 0.5)
    return Ec + dE * np.arange(nb + 1)


def _diss_samples(study):
    edges = _diss_bins(study)
    k = _k(study.params.diss_samples, "diss_samples")
    parts = []
    for b in range(len(edges) - 1):
        c, wdt = 0.5 * (edges[b] + edges[b + 1]), edges[b + 1] - edges[b]
        df = _samples(study, c, study.params.diss_box, k, 7 + b, e_width=wdt)
        parts.append(df.assign(ebin=b))
    return pd.concat(parts, ignore_index=True)


def _probe_ics(df):
    """One probe per finest box: its sample of rank 0 (or its lowest rank present)."""
    first = df.sort_values(["cell", "rank"]).drop_duplicates("cell")
    return first.reset_index(drop=True)


def _probe_scene(study, E, df):
    """The probes of the KAM test: one orbit per finest box, no section, up to probe_t_max; still inside
    then (censored) = trapped (fig2's rule for KAM-trapped orbits)."""
    path, n = _write_ics(study, probe_key(E), _probe_ics(df))
    return study.scene(probe_key(E), ics=str(path), n=n, t_max=study.params.probe_t_max)


def _sim_scene(study):
    E0, g = study.params.diss_energy, study.params.diss_gamma
    return study.scene(
        SIM_KEY,
        energy=E0,
        n=study.params.sim_n,
        gamma=g,
        t_max=study.params.t_horizon,
        sections={"t_from": study.params.t_star, "first_only": True},
    )


def _cost_scene(study, E):
    return study.scene(cost_key(E), energy=float(E), n=study.params.cost_n, seed=2602, t_max=5000.0)


def _ulam_energies(study):
    return sorted(set(study.params.energies) | set(study.params.mixed_energies))


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None) -> None: one-return runs of the Ulam samples per energy, the dissipative
    samples, the dissipative comparison ensemble and the P(t)-route runs of the cost comparison."""
    k = _k(study.params.samples, "samples")
    for E in _ulam_energies(study):
        df = _samples(study, E, study.params.box, k, 0)
        _one_return(study, ulam_key(E), df, 0.0, workers, progress)
        study.run(probe_key(E), _probe_scene(study, E, df), workers=workers, progress=progress)
    _one_return(study, DISS_KEY, _diss_samples(study), study.params.diss_gamma, workers, progress)
    study.run(SIM_KEY, _sim_scene(study), workers=workers, progress=progress)
    for E in study.params.cost_energies:
        study.run(cost_key(E), _cost_scene(study, E), workers=workers, progress=progress)


# -- analysis: the conservative operator -----------------------------------------------------------
def one_return_table(study, key, df) -> pd.DataFrame:
    """The samples of ``df`` (in traj_id order) with their fate: ``ret`` (crossed again), ``T`` (time of the
    crossing), ``t_end`` (time of the next event), ``x1, y1, e1`` (the crossing), ``censored``."""
    from hhscatter.data.read import read_lifetimes, read_sections

    raw = study.raw(key)
    lt = read_lifetimes(raw, columns=["traj_id", "outcome", "t_end"]).sort_values("traj_id")
    if len(lt) != len(df):
        raise ValueError(f"{key}: {len(lt)} orbits in the run, {len(df)} samples: re-run `simulate`")
    sec = read_sections(raw, columns=["traj_id", "t", "x", "y", "energy"])
    return ulam.one_return_samples(df, lt, sec, key)


def transitions(tab, study, c=1, m_max=None, ebins=None):
    """The samples of ``tab`` as Transitions (:func:`~hhscatter.analysis.geometry.ulam.sample_transitions`) on
    the study's partition: finest side ``box`` (``diss_box`` with energy bins ``ebins``), merged c × c."""
    box = study.params.box if ebins is None else study.params.diss_box
    return ulam.sample_transitions(tab, _extent(study), box, c=c, m_max=m_max, ebins=ebins)


def _ulam_energy(study, E):
    """Every number of one energy: κ at every box side and sample count, on the grid of the three finest sides
    × the sample subsets (with bootstrap replicates there, for the extrapolation), classes, cost."""
    k = _k(study.params.samples, "samples")
    box = study.params.box
    df = _samples(study, E, box, k, 0)
    tab = one_return_table(study, ulam_key(E), df)
    rows = []
    for c in study.params.coarsen:
        tr, _, _ = transitions(tab, study, c=int(c))
        kap, kmap, info, _, _ = ulam.saddle_kappa(tr)
        rows.append(
            {
                "energy": E,
                "box": box * int(c),
                "samples": int(k * k * c * c),
                "kappa": kap,
                "kappa_map": kmap,
                "vary": "box",
                **info,
            }
        )
    for m in study.params.sample_subsets:
        tr, _, _ = transitions(tab, study, m_max=int(m))
        kap, kmap, info, _, _ = ulam.saddle_kappa(tr)
        rows.append(
            {"energy": E, "box": box, "samples": int(m), "kappa": kap, "kappa_map": kmap, "vary": "samples", **info}
        )
    grid, boot_grid = ulam.convergence_grid(
        tab,
        _extent(study),
        box,
        list(study.params.coarsen)[:3],
        study.params.sample_subsets,
        k * k,
        study.params.n_boot_grid,
        [study.params.seed, int(round(E * 1e6)), 17],
    )
    tr, ids, t = transitions(tab, study)
    boot = tf.bootstrap_kappa(tr, study.params.n_boot, rng=study.params.seed + int(E * 1000))
    kap, kmap, info, keep, sub = ulam.saddle_kappa(tr)
    full_classes = tf.communicating_classes(tr)[1]
    ok = ~tab["censored"]
    cost = {
        "orbit_time": float(tab["t_end"].sum()),
        "orbits": int(len(tab)),
        "censored": int((~ok).sum()),
        "mean_return_time": float(np.average(tab.loc[tab["ret"], "T"], weights=tab.loc[tab["ret"], "w"])),
    }
    islands = _islands(study, E, df, tr, ids, keep, sub)
    return {
        "tab": tab,
        "t": t,
        "rows": rows,
        "boot": boot,
        "kappa": kap,
        "kappa_map": kmap,
        "info": info,
        "keep": keep,
        "ids": ids,
        "sub": sub,
        "tr": tr,
        "cost": cost,
        "islands": islands,
        "grid": grid,
        "boot_grid": boot_grid,
        "largest_classes": [dict(c.__dict__) for c in full_classes[:3]],
    }


def _islands(study, E, df, tr, ids, keep, sub):
    """Mixed phase space: the probes still inside at probe_t_max mark trapped (KAM) boxes; the leading modes
    of P on the saddle's class with their mass on trapped boxes, and κ with the trapped boxes taken out."""
    from hhscatter.data.read import read_lifetimes

    pr = _probe_ics(df)
    lt = read_lifetimes(study.raw(probe_key(E)), columns=["traj_id", "outcome"]).sort_values("traj_id")
    trapped_cells = pr["cell"].to_numpy()[lt["outcome"].astype(str).to_numpy() == "censored"]
    return {"probes": int(len(pr)), **ulam.islands_record(trapped_cells, tr, ids, keep, sub)}


# -- μ_c against fig1's sprinkler points -----------------------------------------------------------
def _cmeasure_distances(study, results, inputs):
    """μ_c: the operator's measures against fig1's sprinkler points, per energy and kind of measure."""
    other = study.upstream("cmeasure")
    cm, name = up.published_table(study, other, "cmeasure_points")
    boxes = list(study.params.cm_boxes)
    head = study.params.cm_box_headline
    rng = np.random.default_rng(study.params.seed + 5)
    rows, tabs = [], []
    for E in list(study.params.cm_energies):
        Q = cm[np.isclose(cm["energy"], E, rtol=0, atol=1e-9)][["x", "y"]].to_numpy()
        inputs[f"cmeasure_E{E:.2f}"] = {"source": f"{other}: derived/{name}", "n_points": int(len(Q))}
        for ref_E in [e for e in results if any(np.isclose(e, c) for c in study.params.cm_energies)]:
            kinds = ("sprinkler", "flux", "map") if np.isclose(ref_E, E) else ("sprinkler",)
            for kind in kinds:
                P = ulam.measure_points(results[ref_E], kind, len(Q), rng)
                tab, j = ulam.hellinger_by_box(
                    P, Q, boxes, _extent(study), study.params.n_splits, study.params.seed, head
                )
                tabs.append(tab.assign(fig1_energy=E, operator_energy=ref_E, kind=kind))
                rows.append(
                    {
                        "fig1_energy": E,
                        "operator_energy": ref_E,
                        "measure": kind,
                        "n": int(len(Q)),
                        **ulam.hellinger_row(tab, j),
                    }
                )
    conv = _cmeasure_convergence(study, results, cm, boxes, head)
    return rows, (pd.concat(tabs, ignore_index=True) if tabs else pd.DataFrame()), conv


def _cmeasure_convergence(study, results, cm, boxes, head):
    """The debiased Hellinger distance (at the headline box) of the operator's sprinkler measure to fig1's
    points at the first cm energy, for merged boxes and fewer samples per box: the eigenvector's convergence."""
    E = float(study.params.cm_energies[0])
    if E not in results:
        return []
    Q = cm[np.isclose(cm["energy"], E, rtol=0, atol=1e-9)][["x", "y"]].to_numpy()
    rows = ulam.eigenvector_convergence(
        results[E]["tab"],
        _extent(study),
        study.params.box,
        list(study.params.coarsen)[:3],
        study.params.sample_subsets,
        Q,
        boxes,
        study.params.n_splits,
        study.params.seed,
        head,
    )
    return [{"energy": E, **r} for r in rows]


# -- the dissipative operator ----------------------------------------------------------------------
def _initial_density(study, ids, n_cells, top_bin):
    """The initial ensemble (uniform in the scene's disk at E0, on the section) on the operator's states."""
    sc = _sim_scene(study)
    if sc.region != "disk":
        raise ValueError(
            f"operator: the dissipative comparison needs region 'disk' (its initial density is the "
            f"disk's), got {sc.region!r}"
        )
    return ulam.disk_density(float(sc.radius), _extent(study), study.params.diss_box, ids, n_cells, top_bin)


def _dissipative(study, inputs):
    """The dissipative comparison at (diss_energy, diss_gamma): P(t) of the operator on (box × E bin), of the
    reduced operator on ρ(E) and of the simulated ensemble; the energies and points of the first crossing after
    t*. Returns (numbers, P(t) curves, t* points, t* distances)."""
    edges = _diss_bins(study)
    dt = study.params.dt
    op = _operator_survival(study, edges)
    P_red, kappa_bins = ulam.reduced_survival(
        op["tr"], op["t"], op["ids"], op["n_cells"], len(edges) - 1, dt, op["max_lag"], op["steps"]
    )
    sim = _simulated_survival(study, op["grid"])
    P_sim, P_op, N, grid, pred = sim["P"], op["P"], sim["N"], op["grid"], op["pred"]
    agreement = ulam.survival_agreement(grid, dt, study.params.t_star, P_sim, P_op, P_red, N)
    dtab, j = _t_star_distance(study, pred, sim["pts"])
    numbers = {
        "energy": study.params.diss_energy,
        "gamma": study.params.diss_gamma,
        "t_star": study.params.t_star,
        "dt": dt,
        "energy_bins": edges.tolist(),
        "states": int(op["tr"].n_states),
        "samples": int(len(op["tab"])),
        "initial_mass_lost": op["lost"],
        "returns_capped_share": tf.capped_share(op["tr"], dt, op["max_lag"]),
        "max_return_time": op["max_lag"] * dt,
        "operator_orbit_time": float(op["tab"]["t_end"].sum()),
        "sim_orbits": int(N),
        "sim_orbit_time": float(sim["lt"]["t_end"].sum()),
        **agreement,
        **ulam.t_star_energies(pred, sim["pts"]),
        "t_star_hellinger_debiased": {
            "box": float(dtab["box"].iloc[j]),
            "value": float(dtab.hellinger_debiased.iloc[j]),
            "lo": float(dtab.lo.iloc[j]),
            "hi": float(dtab.hi.iloc[j]),
            "noise": float(dtab["hellinger_noise"].iloc[j]),
        },
        "kappa_bins": [
            {"energy": float(0.5 * (edges[a] + edges[a + 1])), "kappa": kb} for a, kb in enumerate(kappa_bins)
        ],
    }
    curves = pd.DataFrame({"t": grid, "sim": P_sim, "operator": P_op, "reduced": P_red})
    pts = pd.concat(
        [pred.assign(set="operator"), sim["pts"][["x", "y", "energy"]].assign(w=1.0, set="sim")], ignore_index=True
    )
    return numbers, curves, pts, dtab


def _operator_survival(study, edges):
    """The operator on (box × E bin) from the one-return samples: P(t) from the disk's initial density, and the
    weighted image points of the first crossing after t*."""
    n_bins = len(edges) - 1
    dt = study.params.dt
    steps = int(round(study.params.t_horizon / dt))
    k_star = int(round(study.params.t_star / dt))
    df = _diss_samples(study)
    tab = one_return_table(study, DISS_KEY, df)
    tr, ids, t = transitions(tab, study, ebins=edges)
    nx, _ = ulam.grid_shape(_extent(study), study.params.diss_box)
    n_cells = nx * nx
    n0, lost = _initial_density(study, ids, n_cells, n_bins - 1)
    max_lag = int(round(study.params.max_return_time / dt))
    P_op, pred = ulam.operator_survival(tr, t, n0, dt, steps, k_star, max_lag)
    grid = np.arange(steps + 1) * dt
    return {
        "tab": tab,
        "tr": tr,
        "ids": ids,
        "t": t,
        "n_cells": n_cells,
        "lost": lost,
        "max_lag": max_lag,
        "steps": steps,
        "P": P_op,
        "grid": grid,
        "pred": pred,
    }


def _simulated_survival(study, grid):
    """The simulated ensemble: its lifetimes, empirical P(t) on ``grid``, size N and first crossings after t*."""
    from hhscatter.analysis.geometry import distance as dist
    from hhscatter.analysis.survival.fits import observed_from_outcome
    from hhscatter.data.read import read_lifetimes, read_sections

    raw = study.raw(SIM_KEY)
    lt = read_lifetimes(raw, columns=["traj_id", "outcome", "t_end"])
    leaving = observed_from_outcome(lt["outcome"])
    P_sim = ulam.empirical_survival(lt["t_end"].to_numpy(), leaving, grid)
    sec = read_sections(raw, columns=["traj_id", "t", "x", "y", "energy"])
    sim_pts = dist.first_crossings(sec, study.params.t_star)
    return {"lt": lt, "P": P_sim, "pts": sim_pts, "N": len(lt)}


def _t_star_distance(study, pred, sim_pts):
    """Debiased Hellinger distance over box sizes between the operator's t* points (drawn by weight, seeded)
    and the simulated ones: (table, index of the headline box)."""
    from hhscatter.analysis.geometry import distance as dist

    rng = np.random.default_rng(study.params.seed + 9)
    draw = pred.iloc[rng.choice(len(pred), size=max(len(sim_pts), 4), p=pred["w"] / pred["w"].sum())]
    return ulam.hellinger_by_box(
        draw[["x", "y"]].to_numpy(),
        dist.points(sim_pts),
        list(study.params.cm_boxes),
        _extent(study),
        study.params.n_splits,
        study.params.seed,
        study.params.cm_box_headline,
    )


# -- cost: orbit-time for κ at 1 % -----------------------------------------------------------------
def _cost(study, records, kappa0):
    """Orbit-time of each route for κ at [study].target_rel (:func:`~hhscatter.analysis.geometry.ulam.cost_row`)."""
    from hhscatter.analysis.survival.escape_rate import escape_rate
    from hhscatter.analysis.survival.fits import observed_from_outcome
    from hhscatter.data.read import read_lifetimes

    rows = []
    for E in list(study.params.cost_energies):
        lt = read_lifetimes(study.raw(cost_key(E)), columns=["outcome", "t_end"])
        r = escape_rate(
            lt["t_end"].to_numpy(), observed_from_outcome(lt["outcome"]), detect_tail=False, min_survivors=100.0
        )
        pt = {"kappa": r.kappa, "kappa_err": r.kappa_err, "orbits": len(lt), "orbit_time": float(lt["t_end"].sum())}
        rec = next((x for x in records if np.isclose(x["energy"], E)), None)
        rows.append(ulam.cost_row(E, pt, rec, kappa0, study.params.target_rel))
    return rows


# -- analyze ---------------------------------------------------------------------------------------
def _fig2_kappa(study, inputs):
    other = study.upstream("kappa")
    doc = up.numbers(study, other)
    ke = doc.get("kappa_energy")
    if not ke:
        raise up.UpstreamError(f"{other}.json has no list 'kappa_energy'")
    inputs["kappa0"] = {
        "source": f"{other}.json: kappa_energy (P(t) route, paper setup) and cmeasure (the "
        "true-time relation on long-run section crossings)"
    }
    k0 = {float(r["energy"]): (float(r["kappa"]), float(r["kappa_err"])) for r in ke}
    kcm = {
        float(v["energy"]): (float(v["kappa_cm"]["value"]), float(v["kappa_cm"]["err"]))
        for v in doc.get("cmeasure", {}).values()
        if "kappa_cm" in v
    }
    return k0, kcm


def kappa_part(study, inputs):
    """κ at every Ulam energy: {results per E, records (kappa_ulam), convergence (kappa_convergence), mixed
    (mixed phase space), rows (κ per partition), grids (the extrapolation grids and their replicates), kappa0}."""
    from hhscatter.analysis.stats.verdicts import verdict

    kappa0, kappa_cm = _fig2_kappa(study, inputs)
    out = {"results": {}, "records": [], "convergence": [], "mixed": [], "rows": [], "grids": [], "kappa0": kappa0}
    for E in _ulam_energies(study):
        res = out["results"][E] = _ulam_energy(study, E)
        k0, kc = kappa0.get(E), kappa_cm.get(E)
        rec = ulam.kappa_record(E, res, study.params.samples, study.params.box)
        rec.update(
            {
                "fig2_kappa": k0[0] if k0 else None,
                "fig2_err": k0[1] if k0 else None,
                "fig2_kappa_cm": kc[0] if kc else None,
                "fig2_kappa_cm_err": kc[1] if kc else None,
            }
        )
        if k0:
            rec["z_vs_fig2"] = (rec["kappa"] - k0[0]) / math.hypot(rec["err"], k0[1])
        out["rows"].extend(res["rows"])
        isl = res["islands"]
        out["mixed"].append({"energy": E, **isl, "largest_classes": res["largest_classes"]})
        if any(np.isclose(E, e) for e in study.params.energies):
            out["records"].append(rec)
            out["convergence"].append(
                ulam.convergence_record(E, res["grid"], res["boot_grid"], res["kappa"], {"kappa0": k0, "kappa_cm": kc})
            )
            out["grids"] += [
                res["grid"].assign(energy=E, kind="estimate"),
                res["boot_grid"].assign(energy=E, kind="bootstrap"),
            ]
        else:
            out["mixed"][-1]["record"] = {**rec, "note": "mixed phase space (below the κ grid)"}
    for r in out["convergence"]:
        if r.get("kappa0") is not None and r.get("kappa_inf") is not None:
            row = study.compare(
                f"κ_Ulam({r['energy']:g}) extrapolated vs fig2's κ0",
                r["kappa_inf"],
                r["err"],
                r["kappa0"],
                verdict=verdict(r["kappa_inf"], r["err"], r["kappa0"], r["kappa0_err"]).text(),
                note=f"fig2 ± {r['kappa0_err']:.2g}; finest boxes {study.params.box:g}: κ = {r['kappa_finest']:.4g}",
            )
            row["paper_err"] = r["kappa0_err"]  # the reference's own error: the rule takes both
    return out


def analyze(study):
    """κ(E) records and their convergence, mixed phase space, μ_c distances, the dissipative predictions and the
    cost comparison: derived tables and operator.json."""
    inputs = {}
    k = kappa_part(study, inputs)
    results = k["results"]
    cm_rows, cm_tab, cm_conv = _cmeasure_distances(study, results, inputs)
    diss, curves, pts, dtab = _dissipative(study, inputs)
    study.write_table(pd.DataFrame(k["rows"]), "convergence.parquet")
    study.write_table(pd.concat(k["grids"], ignore_index=True), "convergence_grid.parquet")
    if len(cm_tab):
        study.write_table(cm_tab, "cmeasure_distances.parquet")
    for name, tab in (("survival", curves), ("t_star_points", pts), ("t_star_distances", dtab)):
        study.write_table(tab, f"{name}.parquet")
    img = [
        pd.DataFrame(
            ulam.measure_points(results[E], "sprinkler", 200000, np.random.default_rng(3)), columns=["x", "y"]
        ).assign(energy=E)
        for E in study.params.cm_energies
        if E in results
    ]
    if img:
        study.write_table(pd.concat(img, ignore_index=True), "ulam_measure_points.parquet")
    study.write_numbers(
        {
            "inputs": inputs,
            "kappa_ulam": k["records"],
            "kappa_convergence": k["convergence"],
            "kappa_convergence_summary": ulam.convergence_summary(k["convergence"]),
            "mixed_phase_space": k["mixed"],
            "cmeasure_distances": cm_rows,
            "cmeasure_convergence": cm_conv,
            "dissipative": diss,
            "cost": _cost(study, k["records"], k["kappa0"]),
            "tables": {"convergence": "convergence.parquet", "survival": "survival.parquet"},
        }
    )


def plot(study):
    """plot(study) -> None: the figure from operator.json and the derived tables."""
    import pyarrow.parquet as pq

    from .figure import plot_operator, plot_residuals

    read = lambda f: pq.read_table(study.out / "derived" / f).to_pandas()
    cm_pts = study.out / "derived" / "ulam_measure_points.parquet"
    fig1_pts = None
    try:
        fig1_pts, _ = up.published_table(study, study.upstream("cmeasure"), "cmeasure_points")
    except up.UpstreamError:  # the figure then shows the operator's measure alone
        pass
    plot_operator(
        study.read_numbers(),
        read("convergence.parquet"),
        read("survival.parquet"),
        read("t_star_points.parquet"),
        read("ulam_measure_points.parquet") if cm_pts.exists() else None,
        fig1_pts,
        study.figure_path,
    )
    grid = study.out / "derived" / "convergence_grid.parquet"
    plot_residuals(
        study.read_numbers(),
        read(grid.name) if grid.exists() else None,
        study.figure_path.with_name("operator_residuals.png"),
    )
