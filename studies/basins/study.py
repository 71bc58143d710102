"""Study ``basins``: exit basins and their fractality under dissipation (beyond the paper).

The paper's conclusion expects fractal structure in dissipative scattering
"in suitable limits of E0, γ and t", with a cut-off in the scaling coming
from the mixing of c-measures of different energies. This study measures it
on the standard figures of chaotic scattering (Aguirre, Vallejo & Sanjuán,
PRE 64, 066208 (2001); Daza et al., Sci. Rep. 6, 31416 (2016)):

1. **Basin maps.** Initial conditions on the section ṙ = 0, φ̇ > 0 at E0
   (:func:`hhscatter.scene.ics.section_grid`, tangential velocities) on a regular
   grid over the authors' square [−1, 1]²; each cell coloured by its outcome
   (exit channel 0/1/2, settled, censored at t_max), from the engine's exact
   event outcomes with r_esc = 1.5 (beyond every exit's Lyapunov orbit, study
   resc). Two magnifications of one boundary region, centred on the most
   mixed cell of the γ = 0 map.
2. **Measures** per (E0, γ) (:mod:`hhscatter.analysis.geometry.basins`): basin
   fractions (Wilson), basin entropy S_b and boundary basin entropy S_bb over
   box sizes with the log 2 test, the Wada merging test, and the uncertainty
   exponent α from f(ε), the fraction of initial conditions whose outcome
   changes under a shift ε of x (fresh initial conditions at each ε, down to
   ε = 1e-9: exact event times and tol 1e-15 resolve it); d = 2 − α.
3. **The paper's cut-off.** A broken power law against the single one for
   f(ε) (:func:`~hhscatter.analysis.geometry.uncertainty.uncertainty_cutoff`): ε_c(γ) or an
   upper bound; and the lifetimes of the orbits that decide the outcome at
   the smallest ε, against τ2 = ln(E0/E_c)/γ (Eq. (eq:tau2) with μ = 1, the
   late-time exponent of study fig3).
4. **The cut-off re-predicted** with study saddle's λ̄(E) of the tangent dynamics, with the ensemble's μ and
   with ``mu_own``, μ of the orbits that decide at the smallest resolved ε (their own start and end energies);
   and ``stretch``: where f(ε) and ε_c lie in the distribution of every orbit's own stretch Λ (``orbit_stretch``).

Outcome codes: 0, 1, 2 exit channel (the 120° sector of the escape point);
3 settled; 4 censored (still inside at t_max; code name ``trapped``); −1 forbidden cell (V ≥ E0).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.stats.measured import Measured
from hhscatter.reproduction import basin_summary as bs
from hhscatter.reproduction.basin_summary import CODE_NAMES, CODES, OUTSIDE, outcome_codes
from hhscatter.scene.schema import Integer, Integers, Number, Numbers
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, SCALE, figure_stage


class Params(StudyParams):
    """``[study]`` of studies/basins/study.toml."""

    energies: Numbers
    gammas: Numbers
    extent: Numbers
    grid: Integer
    zoom_energy: Number
    zoom_gammas: Numbers
    zoom_factors: Numbers
    zoom_grid: Integer
    boxes: Numbers
    box_headline: Integer
    eps: Numbers
    n_uncertainty: Integer
    fit_min_count: Integer = 10
    wada_r: Integer = 3
    wada_min_share: Number = 0.005
    symmetry_radius: Number = 0.9
    scan_energies: Numbers = ()
    scan_grid: Integer = 200
    scan_eps: Numbers = ()
    scan_n_uncertainty: Integer = 4000
    E_b_key: str = "kappa_fit.E_b"
    kappa_energy_key: str = "kappa_energy"
    mu_key: str = "mu"
    box_sides: Numbers = (0.01, 0.02, 0.025, 0.05, 0.1, 0.2)  # S_b, S_bb also at these sides (position units)
    # the map read also on every k-th cell (k = grid/subgrid odd: the coarse grid's cell centres are cells of the
    # fine grid, the same orbits), its entropies at the same sides: resolution alone, like for like
    box_subgrids: Integers = (400,)


# -- keys and grids ----------------------------------------------------------------
def _tag(E, g):
    return f"E{E:.2f}_g{g:g}"


def map_key(E, g):
    return f"map_{_tag(E, g)}"


def zoom_key(E, g, factor):
    return f"zoom{factor:g}_{_tag(E, g)}"


def unc_key(E, g, i):
    return f"unc{i}_{_tag(E, g)}"


def scan_map_key(E):
    return f"scan_map_E{E:g}_g0"  # full precision: scan energies such as 0.17 and 0.175 stay apart


def scan_unc_key(E, i):
    return f"scan_unc{i}_E{E:g}_g0"


def _scan(study):
    """(energies, ε) of the γ = 0 energy scan; energies must lie above E_c."""
    energies = list(study.params.scan_energies)
    eps = np.asarray(study.params.scan_eps)
    if energies:
        ec = study.model.critical_energy
        if min(energies) <= ec:
            raise ValueError(f"basins [study].scan_energies must lie above E_c = {ec:.6g}")
        if not (eps.size >= 2 and np.all(eps > 0) and np.all(np.diff(eps) < 0)):
            raise ValueError("basins [study].scan_eps must be decreasing positive numbers")
    return energies, eps


def _eps(study):
    eps = np.asarray(study.params.eps)
    if not (eps.size >= 2 and np.all(eps > 0) and np.all(np.diff(eps) < 0)):
        raise ValueError("basins [study].eps must be decreasing positive numbers")
    return eps


# -- simulate --------------------------------------------------------------------------
def _run_table(study, key, states, gamma, workers, progress):
    """Run the initial conditions ``states`` (m, 4) through the engine (runner: resume, progress, Dask)."""
    path = study.raw(key + "_ics.parquet")
    path.parent.mkdir(parents=True, exist_ok=True)
    df = pd.DataFrame(states, columns=["x", "y", "px", "py"])
    df.insert(0, "traj_id", np.arange(len(df), dtype=np.int64))
    # rewritten only when different: the scene's hash includes the file's, and resume relies on it
    if not path.exists() or not pd.read_parquet(path).equals(df):
        df.to_parquet(path, index=False)
    scene = study.scene(key, ics=str(path), n=len(df), gamma=float(gamma))
    return study.run(key, scene, workers=workers, progress=progress)


def _map_states(study, E, extent, n):
    from hhscatter.scene.ics import section_grid

    return section_grid(study.model, E, extent, (n, n))


def _uncertainty_states(study, E, i, eps, n=None, seed_offset=0):
    """Fresh reference ICs for ε index i (uniform on the allowed square) and their copies shifted by ε in x."""
    from hhscatter.scene.ics import perturbed_on_section, region_ics

    n = study.params.n_uncertainty if n is None else int(n)
    seed = int(study.config["scene"]["seed"]) * 100 + seed_offset + i
    ref = region_ics(study.scene("unc", energy=E, region="square", n=n, seed=seed), 0, n)
    moved, ok = perturbed_on_section(study.model, ref, E, dx=float(eps))
    return np.concatenate([ref[ok], moved[ok]])


def _zoom_centre(study, extent, n):
    """The zooms' centre: the most mixed box of the γ = 0 map at zoom_energy whose widest zoom window (the
    smallest factor) lies wholly in the allowed region."""
    Ez = study.params.zoom_energy
    clearance = math.ceil(math.sqrt(2.0) * n / (2.0 * min(study.params.zoom_factors)))
    return bs.zoom_centre(basin_image(study, map_key(Ez, 0.0), Ez, extent, n), extent, clearance=clearance)


def basin_image(study, key, E, extent, n):
    """basin_image(study, key, E, extent, n) -> (n, n) int8 outcome codes (−1 forbidden) of a map run."""
    from hhscatter.data.read import read_lifetimes

    _, _, allowed, _, cell = _map_states(study, E, extent, n)
    lt = read_lifetimes(study.raw(key), columns=["traj_id", "outcome", "exit_channel"])
    img = np.full(allowed.size, OUTSIDE, dtype=np.int8)
    img[cell] = outcome_codes(lt)
    return img.reshape(allowed.shape)


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None) -> None: basin maps, zooms and uncertainty runs, each through the runner."""
    extent = tuple(study.params.extent)
    n = study.params.grid
    eps = _eps(study)
    for E in study.params.energies:
        for g in study.params.gammas:
            _run_table(study, map_key(E, g), _map_states(study, E, extent, n)[3], g, workers, progress)
            for i, e in enumerate(eps):
                _run_table(study, unc_key(E, g, i), _uncertainty_states(study, E, i, e), g, workers, progress)
    Ez = study.params.zoom_energy
    centre = _zoom_centre(study, extent, n)
    for g in study.params.zoom_gammas:
        for f in study.params.zoom_factors:
            ext = bs.zoom_extent(extent, centre, f)
            _run_table(
                study, zoom_key(Ez, g, f), _map_states(study, Ez, ext, study.params.zoom_grid)[3], g, workers, progress
            )
    scan_E, scan_eps = _scan(study)
    ns = study.params.scan_grid
    for E in scan_E:
        _run_table(study, scan_map_key(E), _map_states(study, E, extent, ns)[3], 0.0, workers, progress)
        for i, e in enumerate(scan_eps):
            _run_table(
                study,
                scan_unc_key(E, i),
                _uncertainty_states(study, E, i, e, study.params.scan_n_uncertainty, seed_offset=50),
                0.0,
                workers,
                progress,
            )


# -- analyze ---------------------------------------------------------------------------
def _uncertainty(study, E, g, eps, keys=None, times=None, deciders=None, refs=None):
    """f(ε) rows and the lifetimes of the pairs whose outcome changed, per ε (``keys``: the run per ε, default
    the main runs; ``times``: a list that receives each ε's decision times, for the decision rate λ;
    ``deciders``: a list that receives each ε's (e0, e_end, t_end) of the reference orbits of those pairs;
    ``refs``: a list that receives each ε's (e0, e_end, t_end) of every reference orbit)."""
    from hhscatter.data.read import read_lifetimes

    rows = []
    keys = [unc_key(E, g, i) for i in range(len(eps))] if keys is None else keys
    for i, e in enumerate(eps):
        lt = read_lifetimes(study.raw(keys[i]), columns=["traj_id", "outcome", "exit_channel", "t_end", "e0", "e_end"])
        lt_sorted = lt.sort_values("traj_id")
        codes = outcome_codes(lt)
        row, t_dec = bs.uncertainty_row(codes, lt_sorted["t_end"].to_numpy(), E, g, e)
        if times is not None:
            times.append(t_dec)
        m = len(codes) // 2
        if deciders is not None:
            ref = lt_sorted.iloc[:m][codes[:m] != codes[m:]]
            deciders.append(tuple(ref[c].to_numpy(dtype=float) for c in ("e0", "e_end", "t_end")))
        if refs is not None:
            refs.append(tuple(lt_sorted.iloc[:m][c].to_numpy(dtype=float) for c in ("e0", "e_end", "t_end")))
        rows.append(row)
    return pd.DataFrame(rows)


def _own_decay(g, ok, deciders):
    """μ of the orbits that decide at the smallest resolved ε (their own start and end energies), or None."""
    from hhscatter.analysis.dissipative.decay import orbit_decay_exponent

    idx = np.flatnonzero(np.asarray(ok))
    if g <= 0 or idx.size == 0:
        return None
    e0, e_end, t_end = deciders[idx[-1]]
    keep = (e_end > 0) & (t_end > 0) & (e0 > e_end)
    if keep.sum() < 2:
        return None
    r = orbit_decay_exponent(e0[keep], e_end[keep], t_end[keep], g, n_boot=200, seed=0)
    return {**r.measured("mu").to_dict(), "n_orbits": r.n_orbits}


def analyze(study):
    """analyze(study) -> None: derived tables (maps, entropies, f(ε)) and basins.json."""
    extent = tuple(study.params.extent)
    n = study.params.grid
    eps = _eps(study)
    ec = study.model.critical_energy
    boxes = list(study.params.boxes)
    hb = study.params.box_headline
    maps, ent_rows, unc_tabs, per, loc_tabs, by_box = [], [], [], [], [], []
    E_b, E_b_err = _upstream_value(study, "kappa", "E_b_key")
    mu, mu_err = _upstream_value(study, "mu", "mu_key")
    tangent, lam_source = _tangent(study)
    stretches = []
    for E in study.params.energies:
        for g in study.params.gammas:
            img, ent, unc, loc, m = _measure_point(study, E, g, eps, extent, n, boxes, tangent)
            stretches.append(m.pop("stretch"))
            maps.append(pd.DataFrame({"energy": E, "gamma": g, "label": img.ravel()}))
            ent_rows.append(ent)
            unc_tabs.append(unc)
            loc_tabs.append(loc)
            per.append({**bs.point_record(E, g, hb, ec, ent, unc, loc, m), "mu_own": m["mu_own"]})
            by_box.extend(_entropy_by_box(study, img, E, g, extent))
            by_box.extend(_entropy_by_subgrid(study, img, E, g, extent))
    study.write_table(pd.concat(maps, ignore_index=True), "basins_maps.parquet", grid=n, extent=list(extent))
    study.write_table(pd.concat(ent_rows, ignore_index=True), "basins_entropy.parquet")
    study.write_table(pd.concat(unc_tabs, ignore_index=True), "basins_uncertainty.parquet")
    study.write_table(pd.concat(loc_tabs, ignore_index=True), "basins_local_exponent.parquet")
    scan, scan_unc = _energy_scan(study, extent, boxes, hb, E_b, by_box)
    scan = bs.kantz_grassberger(scan, _upstream_value(study, "kappa", "kappa_energy_key")[0])
    study.write_table(scan, "basins_energy_scan.parquet")
    study.write_table(scan_unc, "basins_energy_scan_uncertainty.parquet")
    cut_pred = bs.cutoff_records(per, scan, mu, mu_err, ec)
    saddle = _saddle_cutoff(study, per, scan, tangent, mu, mu_err, lam_source)
    by_point = {(r["E0"], r["gamma"]): r for r in saddle["cutoff_saddle"]}
    stretch = [
        bs.stretch_record(p, u, L, by_point.get((p["energy"], p["gamma"])), min_count=study.params.fit_min_count)
        for p, u, L in zip(per, unc_tabs, stretches)
    ]
    trend = bs.energy_trend(scan, E_b)
    zooms, centre = _zoom_maps(study, extent, n)
    study.write_table(zooms, "basins_zooms.parquet", grid=study.params.zoom_grid)
    for row in bs.comparison_rows(per, hb):  # α, S_bb against ln 2, the paper's expected cut-off for γ > 0
        study.compare(**row)
    study.write_numbers(
        {
            "codes": dict(zip(CODE_NAMES, CODES)),
            "grid": n,
            "extent": list(extent),
            "eps": [float(e) for e in eps],
            "zoom_centre": list(centre),
            "per_point": per,
            "point_table": bs.point_table(per),
            "E_b": {
                **Measured(E_b, E_b_err).to_dict(),
                "source": f"{study.upstream('kappa')}.json {study.params.E_b_key}",
            },
            "mu": {**Measured(mu, mu_err).to_dict(), "source": f"{study.upstream('mu')}.json {study.params.mu_key}"},
            "cutoff_prediction": cut_pred,
            "cutoff_summary": bs.cutoff_summary(cut_pred),
            "entropy_by_box": by_box,
            "entropy_by_box_at": bs.entropy_by_box_at(by_box),
            "entropy_exponent_by_grid": bs.entropy_exponents(by_box),
            "energy_scan": scan.to_dict(orient="records"),
            "energy_trend": trend,
            **saddle,
            "stretch": stretch,
            "stretch_table": bs.stretch_table(stretch),
            "stretch_summary": bs.stretch_summary(stretch),
            "convention": "square [−1, 1]² on the section ṙ = 0, φ̇ > 0 (forbidden cells blank); r_esc = 1.5",
        }
    )


def _measure_point(study, E, g, eps, extent, n, boxes, tangent):
    """One (E0, γ) map and its measures (:func:`~hhscatter.reproduction.basin_summary.map_measures`).

    Returns (labels image, entropy table, f(ε) table, local-exponent table, dict of the other measures, with
    ``stretch``: Λ of every reference orbit along its own energy history, with λ̄(E) of ``tangent``).
    """
    from hhscatter.analysis.geometry.cutoff import orbit_stretch

    img = basin_image(study, map_key(E, g), E, extent, n)
    gx, gy = _map_states(study, E, extent, n)[:2]
    times, deciders, refs = [], [], []
    unc = _uncertainty(study, E, g, eps, times=times, deciders=deciders, refs=refs)
    p = study.params
    ent, loc, m = bs.map_measures(
        img,
        np.hypot(*np.meshgrid(gx, gy)),
        unc,
        eps,
        times,
        E,
        g,
        boxes,
        wada_min_share=p.wada_min_share,
        wada_r=p.wada_r,
        symmetry_radius=p.symmetry_radius,
        fit_min_count=p.fit_min_count,
    )
    m["mu_own"] = _own_decay(g, m["ok"], deciders)
    e0, e_end, t_end = (np.concatenate([r[i] for r in refs]) for i in range(3))  # e_end kept > 0 for ln E
    E_lam = (tangent[c].to_numpy() for c in ("energy", "lam"))
    m["stretch"] = orbit_stretch(e0, np.maximum(e_end, study.model.critical_energy * 1e-9), t_end, *E_lam)
    return img, ent, unc, loc, m


def _zoom_maps(study, extent, n):
    """The zoom maps around the most mixed cell of the γ = 0 map: (table of labels per (γ, factor), centre)."""
    zooms = []
    Ez = study.params.zoom_energy
    centre = _zoom_centre(study, extent, n)
    for g in study.params.zoom_gammas:
        for f in study.params.zoom_factors:
            ext = bs.zoom_extent(extent, centre, f)
            img = basin_image(study, zoom_key(Ez, g, f), Ez, ext, study.params.zoom_grid)
            zooms.append(
                pd.DataFrame(
                    {
                        "gamma": g,
                        "factor": f,
                        "x0": ext[0],
                        "x1": ext[1],
                        "y0": ext[2],
                        "y1": ext[3],
                        "label": img.ravel(),
                    }
                )
            )
    return pd.concat(zooms, ignore_index=True), centre


def _tangent(study):
    """(λ̄(E) DataFrame of the saddle study's points at this study's system, its source): the system is found by
    its full spec among the saddle's [study].systems, never by its name alone."""
    from hhscatter.model.spec import resolve
    from hhscatter.studies import _upstream as up

    other = study.upstream("lyapunov")
    doc = up.numbers(study, other)
    mine = resolve(study.model)[1]
    labels = [e["label"] for e in doc["config"]["study"]["systems"]
              if resolve({"name": e["name"], "params": dict(e.get("params") or {})})[1] == mine]  # fmt: skip
    if len(labels) != 1:
        raise ValueError(f"basins: {other}.json has {len(labels)} systems with this study's spec {mine} (need 1)")
    tangent = bs.tangent_lambda(doc["saddle"], labels[0])
    if tangent.empty:
        raise ValueError(f"basins: {other}.json has no λ̄ of the tangent dynamics for system {labels[0]!r}")
    return tangent, f"{other}.json saddle (system {labels[0]})"


def _saddle_cutoff(study, per, scan, tangent, mu, mu_err, source) -> dict:
    """The cut-off re-predicted with λ̄ of the tangent dynamics (the JSON keys lambda_tangent, rate_table,
    cutoff_saddle and cutoff_saddle_summary)."""
    from hhscatter.reproduction.verdicts import NO_VERDICT, SMOKE_SCALES

    rates = bs.rate_table(scan, tangent)
    cut = bs.saddle_cutoff_records(per, tangent, mu, mu_err, study.model.critical_energy)
    summary = bs.saddle_cutoff_summary(cut, rates, mu)
    if study.scale in SMOKE_SCALES:  # a smoke test states no verdict (these verdicts are not under "verdict")
        rates = [{k: NO_VERDICT if k.endswith("_vs_tangent") else v for k, v in r.items()} for r in rates]
        cut = [{k: NO_VERDICT if k.startswith("verdict_") else v for k, v in r.items()} for r in cut]
    lam = {"rows": tangent.to_dict(orient="records"), "source": source}
    return {"lambda_tangent": lam, "rate_table": rates, "cutoff_saddle": cut, "cutoff_saddle_summary": summary}


def _upstream_value(study, role, key_param):
    """(value, err) of a number in the JSON of the study [needs].role, at the dotted path [study].key_param."""
    from hhscatter.studies import _upstream as up

    v, e = up.lookup(
        up.numbers(study, study.upstream(role)), getattr(study.params, key_param), what=f"{study.upstream(role)}.json"
    )
    return (float(v), float(e)) if isinstance(v, (int, float)) else (v, e)


def _entropy_by_box(study, img, E, g, extent, which="map"):
    """S_b, S_bb at the fixed box sides [study].box_sides (position units) that are whole cells of ``img``."""
    from hhscatter.analysis.geometry.basins import commensurate_sides, entropy_by_box

    sides = commensurate_sides(study.params.box_sides, extent, img.shape[0], min_cells=2)
    if not sides:
        return []
    t = entropy_by_box(img, extent, sides, outside=OUTSIDE)
    return t.assign(E0=E, gamma=g, map=which).to_dict(orient="records")


def _entropy_by_subgrid(study, img, E, g, extent):
    """S_b, S_bb at the fixed box sides of the map read on every k-th cell ([study].box_subgrids)."""
    from hhscatter.analysis.geometry.basins import every_kth_cell

    rows = []
    for k, sub in every_kth_cell(img, study.params.box_subgrids):
        rows += _entropy_by_box(study, sub, E, g, extent, which=f"every {k}th cell")
    return rows


def _energy_scan(study, extent, boxes, hb, E_b, by_box):
    """γ = 0 energy scan: per E0 a row of :func:`~hhscatter.reproduction.basin_summary.scan_row`; ``by_box``
    receives the entropies at fixed box sides of the scan maps at the study's energies (a second grid at the
    same E0)."""
    energies, eps = _scan(study)
    ns = study.params.scan_grid
    p = study.params
    rows, uncs = [], []
    for E in energies:
        img = basin_image(study, scan_map_key(E), E, extent, ns)
        times = []
        unc = _uncertainty(study, E, 0.0, eps, keys=[scan_unc_key(E, i) for i in range(len(eps))], times=times)
        uncs.append(unc)
        if any(np.isclose(E, e) for e in study.params.energies):
            by_box.extend(_entropy_by_box(study, img, E, 0.0, extent, which="scan"))
        scan_boxes = [b for b in boxes if b <= ns // 4]
        rows.append(
            bs.scan_row(
                img,
                unc,
                eps,
                times,
                E,
                E_b,
                scan_boxes,
                hb,
                wada_min_share=p.wada_min_share,
                wada_r=p.wada_r,
                fit_min_count=p.fit_min_count,
            )
        )
    return (
        pd.DataFrame(rows, columns=bs.SCAN_COLUMNS),
        pd.concat(uncs, ignore_index=True) if uncs else pd.DataFrame(columns=["energy", "eps", "f", "k", "n"]),
    )


# -- plot -----------------------------------------------------------------------------------
plot = figure_stage(
    "plot_basins",
    "basins_maps",
    "basins_zooms",
    "basins_entropy",
    "basins_uncertainty",
    NUMBERS,
    PATH,
    scale=SCALE,
    local="basins_local_exponent",
    scan="basins_energy_scan",
)
