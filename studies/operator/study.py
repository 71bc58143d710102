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

from hhscatter.analysis.geometry import ulam
from hhscatter.analysis.geometry import ulam_convergence as uc
from hhscatter.reproduction.kappa_references import kappa_references
from hhscatter.reproduction.operator_cmeasure import measure_distances
from hhscatter.reproduction.operator_records import (
    convergence_summary,
    cost_rows,
    dissipative_comparison,
    kappa_comparisons,
    kappa_records,
    probe_islands,
)
from hhscatter.scene.schema import Integer, Integers, Number, Numbers
from hhscatter.studies import _upstream as up
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, Sibling, Table, Upstream, figure_stage, figures


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
    then (censored) = a KAM box (fig2's rule for censored orbits)."""
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
    """Every number of one energy (:func:`~hhscatter.analysis.geometry.ulam_convergence.energy_results`), the
    KAM islands and where the c-measure lives against the partition."""
    p = study.params
    df = _samples(study, E, p.box, _k(p.samples, "samples"), 0)
    tab = one_return_table(study, ulam_key(E), df)
    res = uc.energy_results(
        tab, _extent(study), p.box, p.coarsen, p.sample_subsets, p.samples, p.n_boot, p.n_boot_grid, p.seed, E
    )
    res["islands"] = _islands(study, E, df, res["tr"], res["ids"], res["keep"], res["sub"])
    res["cut_boxes"] = uc.measure_on_cut_boxes(res, p.samples)
    return res


def _islands(study, E, df, tr, ids, keep, sub):
    """Mixed phase space (:func:`~hhscatter.reproduction.operator_records.probe_islands`): the probes still inside at
    probe_t_max (censored) mark KAM boxes."""
    from hhscatter.data.read import read_lifetimes

    lt = read_lifetimes(study.raw(probe_key(E)), columns=["traj_id", "outcome"]).sort_values("traj_id")
    return probe_islands(_probe_ics(df)["cell"].to_numpy(), lt["outcome"].to_numpy(), tr, ids, keep, sub)


# -- μ_c against fig1's sprinkler points -----------------------------------------------------------
def _cmeasure_distances(study, results, inputs):
    """μ_c: the operator's measures against fig1's sprinkler points, per energy and kind of measure
    (:func:`~hhscatter.reproduction.operator_cmeasure.measure_distances`)."""
    other = study.upstream("cmeasure")
    cm, name = up.published_table(study, other, "cmeasure_points")
    boxes = list(study.params.cm_boxes)
    head = study.params.cm_box_headline
    rng = np.random.default_rng(study.params.seed + 5)
    p = study.params
    rows, tab, counts = measure_distances(
        results, cm, list(p.cm_energies), boxes, _extent(study), p.n_splits, p.seed, head, rng
    )
    for E, n in counts.items():
        inputs[f"cmeasure_E{E:.2f}"] = {"source": f"{other}: derived/{name}", "n_points": n}
    conv = _cmeasure_convergence(study, results, cm, boxes, head)
    return rows, tab, conv


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
def _dissipative(study, inputs):
    """The dissipative comparison at (diss_energy, diss_gamma) on this study's runs
    (:func:`~hhscatter.reproduction.operator_records.dissipative_comparison`). Returns (numbers, P(t) curves,
    t* points, distances)."""
    from hhscatter.data.read import read_lifetimes, read_sections

    p, sc, edges = study.params, _sim_scene(study), _diss_bins(study)
    if sc.region != "disk":
        raise ValueError(
            f"operator: the dissipative comparison needs region 'disk' (its initial density is the disk's), got {sc.region!r}"
        )
    tab = one_return_table(study, DISS_KEY, _diss_samples(study))
    raw = study.raw(SIM_KEY)
    lt = read_lifetimes(raw, columns=["traj_id", "outcome", "t_end"])
    sec = read_sections(raw, columns=["traj_id", "t", "x", "y", "energy"])
    return dissipative_comparison(
        tab, lt, sec, extent=_extent(study), box=p.diss_box, edges=edges, radius=float(sc.radius), dt=p.dt,
        t_horizon=p.t_horizon, t_star=p.t_star, max_return_time=p.max_return_time, boxes=list(p.cm_boxes),
        n_splits=p.n_splits, seed=p.seed, box_headline=p.cm_box_headline, energy=p.diss_energy, gamma=p.diss_gamma,
    )  # fmt: skip


# -- cost: orbit-time for κ at 1 % -----------------------------------------------------------------
def _cost(study, records, kappa0):
    """Orbit-time of each route for κ at [study].target_rel (:func:`~hhscatter.reproduction.operator_records.cost_rows`)."""
    from hhscatter.data.read import read_lifetimes

    lifetimes = {
        E: read_lifetimes(study.raw(cost_key(E)), columns=["outcome", "t_end"]) for E in study.params.cost_energies
    }
    return cost_rows(lifetimes, records, kappa0, study.params.target_rel)


# -- analyze ---------------------------------------------------------------------------------------
def _fig2_kappa(study, inputs):
    other = study.upstream("kappa")
    inputs["kappa0"] = {
        "source": f"{other}.json: kappa_energy (P(t) route, paper setup) and cmeasure (the "
        "true-time relation on long-run section crossings)"
    }
    try:
        return kappa_references(up.numbers(study, other))
    except KeyError:
        raise up.UpstreamError(f"{other}.json has no list 'kappa_energy'") from None


def kappa_part(study, inputs):
    """κ at every Ulam energy (:func:`~hhscatter.reproduction.operator_records.kappa_records` of
    :func:`_ulam_energy`), its comparison with fig2's κ0 recorded: {results per E, records (kappa_ulam),
    convergence (kappa_convergence), mixed (mixed phase space), rows (κ per partition), grids, kappa0}."""
    from hhscatter.reproduction.verdicts import SMOKE_SCALES

    kappa0, kappa_cm = _fig2_kappa(study, inputs)
    results = {E: _ulam_energy(study, E) for E in _ulam_energies(study)}
    p = study.params
    out = kappa_records(
        results, kappa0, kappa_cm, samples=p.samples, box=p.box, grid_energies=p.energies,
        verdicts=study.scale not in SMOKE_SCALES,  # a smoke-test scale states no verdicts
    )  # fmt: skip
    for kw in kappa_comparisons(out["convergence"], p.box):
        paper_err = kw.pop("paper_err")
        study.compare(**kw)["paper_err"] = paper_err  # the reference's own error: the rule takes both
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
            "kappa_convergence_summary": convergence_summary(k["convergence"]),
            "mixed_phase_space": k["mixed"],
            "cmeasure_distances": cm_rows,
            "cmeasure_convergence": cm_conv,
            "dissipative": diss,
            "cost": _cost(study, k["records"], k["kappa0"]),
            "tables": {"convergence": "convergence.parquet", "survival": "survival.parquet"},
        }
    )


plot = figures(
    figure_stage(
        "plot_operator",
        NUMBERS,
        "convergence",
        "survival",
        "t_star_points",
        Table("ulam_measure_points", optional=True),
        Upstream("cmeasure", "cmeasure_points"),  # absent: the figure shows the operator's measure alone
        PATH,
    ),
    figure_stage("plot_residuals", NUMBERS, Table("convergence_grid", optional=True), Sibling("_residuals")),
)
