"""Study generality — the paper's claims tested on three open systems (beyond the paper).

The paper concludes with "a generally-applicable model for the study of dissipative chaotic scattering", tested on
Hénon–Heiles only. This study runs the same chain, the system a parameter of every stage (``[study] systems``), at
energies placed alike relative to each threshold (E = r·E_c), ICs alike (disk r < radius_frac·r_s, tangential
momenta), linear drag. Rules in the header of ``studies/generality/study.toml``; the science in
:mod:`hhscatter.reproduction.claims` (this module runs and reads, the library analyses).

``simulate`` — ``[study] parts``: "claims": per system the κ0(E) runs ``<label>_r<r>``, the probe runs
``<label>_probe_r<r>``, the dissipative runs ``<label>_g<γ>`` at E0, the section runs ``<label>_cm_r<r>`` and
``<label>_sec_g<γ>``; "evidence": the long runs ``<label>_ev_<ics>_r<r>`` and Poincaré runs ``<label>_ps_r<r>``,
each with the shadow run of its orbits still inside near t_max (``…_shadow``), the labelled sets
``<label>_ev_disk_r<r>_label`` (the disk ensembles' ambiguous band again with the tangent dynamics), the κ0 runs
``<label>_map_r<r>`` at the validity map's energies off the claims' grid and the r_esc runs ``<label>_resc<R>_…``.

``analyze`` — claims 1–7 (records {claim, quantity, system, value, err, verdict, note}) and the evidence
(regular_fraction, survival_long, long_time, validity_map and its validity_rules, resc, resc_kappa, r_esc_rule) in
``generality.json``; evidence alone merges into the generality.json already in the output folder.

``plot`` — ``generality.png`` (the claims) and ``generality_regular.png``, ``generality_sections.png``,
``generality_decay.png`` (the evidence), figure.py.
"""

from __future__ import annotations

import numpy as np

from hhscatter.reproduction.claims.chain import analyze_claims, analyze_evidence, check_params
from hhscatter.reproduction.claims.keys import (
    alt_key,
    cm_key,
    cm_ratios,
    diss_key,
    ev_key,
    grid_key,
    lab_key,
    map_key,
    map_ratios,
    probe_key,
    ps_key,
    resc_key,
    sec_key,
)
from hhscatter.reproduction.claims.resc import resc_values
from hhscatter.scene.scene import MOMENTA, REGIONS
from hhscatter.scene.schema import Integer, Number, NumberLists, Numbers, OneOf, Text
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, Sibling, Table, figure_stage, figures


class SystemEntry(StudyParams):
    """One entry of ``[study] systems``: a label (raw keys, tables) and a built-in system with its parameters."""

    label: Text
    name: Text
    params: dict[str, Number] = None  # the built-in's defaults where absent


class Params(StudyParams):
    """``[study]`` of studies/generality/study.toml (rules in its header comment)."""

    systems: list[SystemEntry]
    radius_frac: Number
    alt_region: OneOf(*REGIONS) = None  # a second IC convention for κ0(E): the same grid with these ICs
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
    hazard_bin: Number = 5.0  # claim 7: width of the time bins of the escape hazard (time units)
    sm_dt: Number = 0.5  # claim 6 (fig6 rule)
    sm_fit_dt: Number = 2.0
    sm_min_count: Number = 20.0
    # claim 2 (κ from the c-measure) and claim 5 (Fig. 5's distance): conservative runs recording every section
    # crossing in [0, cm_t_to], at cm_ratios and at e0_ratio
    cm_ratios: Numbers = [1.5, 1.9, 2.6]
    cm_n: Integer = 5000
    cm_t_to: Number = 400.0
    cm_t_max: Number = 800.0
    cm_rec_efolds: Number = 2.0  # sampling from t_rec = ⌈τ0 + cm_rec_efolds/κ⌉ (escaping orbits' P(t) of the run)
    cm_margin: Number = 40.0  # … to cm_t_to − cm_margin
    c5_ratio: Number = 1.5  # E(t*)/E_c of claim 5 (one of cm_ratios, below e0_ratio)
    c5_mu_range: Numbers = [0.6, 1.3]  # sections of the dissipative run recorded for t* of any μ in this range
    c5_pad: Number = 25.0
    c5_box_frac: Number = 0.25  # box side of the Hellinger distance, in units of the saddle distance r_s
    c5_offsets: Integer = 2
    c5_boot: Integer = 100
    c5_level: Number = 0.95
    # the evidence behind the claims' readings (rules in study.toml): which parts a scale runs
    parts: list[OneOf("claims", "evidence")] = ["claims", "evidence"]
    ev_ratios: Numbers = [1.05, 1.1, 1.2, 1.35, 1.5, 1.7, 1.9, 2.2, 2.6, 3.5, 5.0]  # the claims' grid and beyond
    ev_ics: list[OneOf(*REGIONS)] = ["disk", "well"]  # disk: radius_frac·r_s, tangential; others: alt_momentum
    ev_n: Integer = 2000
    ev_t_max: Number = 2000.0
    ev_window: Number = 100.0  # the indicator compares first crossings after ev_t_max − ev_window
    ev_delta: Number = 1e-9
    ev_g_max: Number = 1e4
    ev_times: Numbers = [100.0, 200.0, 400.0, 800.0, 2000.0]
    ev_fit_t0: Number = 100.0
    ev_hazard_edges: Numbers = [100.0, 200.0, 400.0, 800.0, 1400.0, 2000.0]
    lab_band: Numbers = [10.0, 1e7]
    lab_band_n: Integer = 400
    lab_side_n: Integer = 50
    lab_seed: Integer = 47
    lab_t_max: Number = 3000.0
    lab_ftle_regular: Number = 0.003
    lab_ftle_chaotic: Number = 0.005
    ps_ratios: Numbers = [1.05, 1.5]
    ps_n: Integer = 150
    ps_t_max: Number = 1000.0
    resc_values: Numbers = [1.03]  # r_esc sensitivity: these × r_s beside the default, where beyond the saddle
    resc_ratios: Numbers = [1.2, 1.5, 1.8, 1.9, 2.6]
    resc_n: Integer = 2000
    resc_probe_n: Integer = 1000
    resc_diss_n: Integer = 4000
    resc_boot: Integer = 100  # replicates of the paired bootstrap of κ0's shift between the radii


def _systems(study):
    """[(label, spec, System)] of [study] systems."""
    from hhscatter.model.spec import system_from_spec

    out = []
    for e in study.params.systems:  # typed entries read as dicts
        spec = {"name": e["name"], "params": dict(e.get("params") or {})}
        out.append((e["label"], spec, system_from_spec(spec)))
    return out


# ---------------------------------------------------------------------------
# simulate
# ---------------------------------------------------------------------------
def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None, progress=True) -> None: per system the κ0(E), probe and dissipative runs."""
    from hhscatter.analysis.dissipative.decay import snapshot_grid
    from hhscatter.reproduction.claims.cmeasure import c5_window

    check_params(study.params)
    p = study.params
    if "evidence" in p.parts:
        _simulate_evidence(study, workers, progress)
    if "claims" not in p.parts:
        return
    probe_times = tuple(np.round(np.arange(0.0, p.probe_t_max + 1e-9, p.probe_step), 9))
    grid = tuple(snapshot_grid(p.snapshot_grid))
    for label, spec, m in _systems(study):
        ec, radius = m.critical_energy, p.radius_frac * m.saddle_radius
        for r in p.ratios:
            sc = study.scene(grid_key(label, r), system=spec, energy=r * ec, n=p.grid_n, radius=radius)
            study.run(grid_key(label, r), sc, workers=workers, progress=progress)
        if p.alt_region is not None:  # the same grid with other ICs: is a plateau of censored orbits the ICs' doing?
            for r in p.ratios:
                key = alt_key(label, r, p.alt_region)
                sc = study.scene(
                    key, system=spec, energy=r * ec, n=p.grid_n, region=p.alt_region, momentum=p.alt_momentum
                )
                study.run(key, sc, workers=workers, progress=progress)
        for r in p.probe_ratios:
            sc = study.scene(
                probe_key(label, r),
                system=spec,
                energy=r * ec,
                n=p.probe_n,
                radius=radius,
                gamma=p.probe_gamma,
                t_max=p.probe_t_max,
                snapshots=probe_times,
            )
            study.run(probe_key(label, r), sc, workers=workers, progress=progress)
        for g in p.gammas:
            extra = {"snapshots": grid, "continue_settled": True} if g == p.mu_gamma else {}
            sc = study.scene(
                diss_key(label, g),
                system=spec,
                energy=p.e0_ratio * ec,
                n=p.diss_n,
                radius=radius,
                gamma=g,
                t_max=p.diss_t_max,
                **extra,
            )
            study.run(diss_key(label, g), sc, workers=workers, progress=progress)
        for r in cm_ratios(p):  # claims 2 and 5: every section crossing in [0, cm_t_to], conservative
            sc = study.scene(
                cm_key(label, r),
                system=spec,
                energy=r * ec,
                n=p.cm_n,
                radius=radius,
                t_max=p.cm_t_max,
                sections={"t_from": 0.0, "t_to": p.cm_t_to},
            )
            study.run(cm_key(label, r), sc, workers=workers, progress=progress)
        t_lo, t_hi = c5_window(p, ec)  # claim 5: the dissipative survivors' crossings around t*; stop after
        sc = study.scene(
            sec_key(label, p.mu_gamma),
            system=spec,
            energy=p.e0_ratio * ec,
            n=p.diss_n,
            radius=radius,
            gamma=p.mu_gamma,
            sections={"t_from": t_lo, "t_to": t_hi, "stop": True},
        )
        study.run(sec_key(label, p.mu_gamma), sc, workers=workers, progress=progress)


# ---------------------------------------------------------------------------
# analyze
# ---------------------------------------------------------------------------
def _lifetimes(path):
    from hhscatter.data.read import read_lifetimes

    return read_lifetimes(path, columns=["traj_id", "outcome", "t_end"], categorical=True)


class _Runs:
    """The study's raw runs as the claims' analysis reads them (:mod:`hhscatter.reproduction.claims`): params and the
    tables of a run key, read with only the rows the analysis uses (pushed-down filters)."""

    def __init__(self, study):
        self.study, self.params = study, study.params

    def lifetimes(self, key):
        return _lifetimes(self.study.raw(key))

    def sections(self, key, t_from=None, columns=("traj_id", "t", "x", "y", "energy")):
        """The section crossings of run ``key`` at t ≥ t_from (all without t_from), these columns (None: all)."""
        import pyarrow.dataset as pads

        from hhscatter.data.read import read_sections

        flt = None if t_from is None else pads.field("t") >= t_from
        return read_sections(self.study.raw(key), columns=None if columns is None else list(columns), filters=flt)

    def shadow_ics(self, key):
        """The ICs of the shadow run of ``key`` (traj_id, x, y, px, py, d0); None where no orbit was left."""
        import pyarrow.parquet as pq

        path = self.study.derived(f"{key}_shadow_ics.parquet")
        return pq.read_table(path).to_pandas() if path.exists() else None

    def initial_states(self, key):
        """traj_id, x0, y0, px0, py0 of every orbit of run ``key``."""
        from hhscatter.data.read import read_lifetimes

        return read_lifetimes(self.study.raw(key), columns=["traj_id", "x0", "y0", "px0", "py0"])

    def labelled(self, key):
        """(selection, lifetimes with log_stretch) of the labelled run ``key``; None where none was run."""
        import pyarrow.parquet as pq

        from hhscatter.data.read import read_lifetimes

        path = self.study.derived(f"{key}_ics.parquet")
        if not path.exists():
            return None
        sel = pq.read_table(path, columns=["traj_id", "growth", "in_band"]).to_pandas()
        lt = read_lifetimes(self.study.raw(key), columns=["traj_id", "outcome", "t_end", "log_stretch"])
        return sel, lt

    def snapshots(self, key, *, t_from=None, t_to=None, max_id=None):
        import pyarrow.dataset as pads

        from hhscatter.data.read import read_snapshots

        f = (
            pads.field("traj_id") < max_id
            if max_id is not None
            else ((pads.field("t") >= t_from) & (pads.field("t") <= t_to))
        )
        return read_snapshots(self.study.raw(key), columns=["traj_id", "t", "energy"], filters=f)

    def snapshot_parts(self, key):
        from hhscatter.data.read import iter_parts

        return iter_parts(self.study.raw(key), "snapshots", ["t", "energy"])


def analyze(study):
    """analyze(study) -> None: claims 1–7 per system (5 as Fig. 5's distance and as a moment) and the evidence
    (regular fraction, long-time escape, validity map, r_esc), per ``[study] parts``; derived tables and
    generality.json. A scale that runs one part publishes that part alone (sealed, made from its own runs): the
    validity map of an evidence-only record has no claims' verdicts beside its regular fractions."""
    check_params(study.params)
    p, runs, systems = study.params, _Runs(study), _systems(study)
    if "claims" in p.parts:
        compare = lambda *a, **k: study.compare(*a, **k, convention=study.convention_label)  # noqa: E731
        numbers, tables = analyze_claims(runs, systems, compare)
        _write_tables(study, tables)
    else:
        numbers = {}
    if "evidence" in p.parts:
        ev, tables = analyze_evidence(runs, systems, numbers)
        _write_tables(study, tables)
        numbers.update(ev)
    study.write_numbers(numbers)


def _write_tables(study, tables: dict) -> None:
    """Write the derived tables {name: (DataFrame, description)} as <name>.parquet."""
    for name, (df, what) in tables.items():
        study.write_table(df, f"{name}.parquet", description=what)


# ---------------------------------------------------------------------------
# evidence: regular orbits (shadow indicator), long-time escape, r_esc sensitivity
# ---------------------------------------------------------------------------
def _ics_kw(p, ics: str, radius: float) -> dict:  # disk: the study's ICs; another region: alt_momentum
    return {"radius": radius} if ics == "disk" else {"region": ics, "momentum": p.alt_momentum}


def _run_pair(study, key, spec, m, t_from, workers, progress, **kw):
    """The base run ``key`` and the shadow run ``key_shadow`` of its orbits still inside at ``t_from`` (same energy
    shell, x + ev_delta; the same r_esc, t_max and section window)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from hhscatter.analysis.geometry.regularity import shadow_ics
    from hhscatter.data.read import read_lifetimes

    sc = study.scene(key, system=spec, **kw)
    study.run(key, sc, workers=workers, progress=progress)
    lt = read_lifetimes(study.raw(key), columns=["traj_id", "x0", "y0", "px0", "py0", "t_end"])
    alive = lt[lt["t_end"] > t_from]
    if alive.empty:
        return
    states, d0 = shadow_ics(alive[["x0", "y0", "px0", "py0"]].to_numpy(), m.potential, study.params.ev_delta)
    path = study.derived(f"{key}_shadow_ics.parquet")
    cols = {"traj_id": alive["traj_id"].to_numpy(), **dict(zip(("x", "y", "px", "py"), states.T)), "d0": d0}
    pq.write_table(pa.table(cols), path)
    sh = study.scene(
        key + "_shadow",
        system=spec,
        ics=str(path),
        n=len(alive),
        t_max=sc.t_max,
        r_esc=sc.r_esc,
        sections=kw["sections"],
    )
    study.run(key + "_shadow", sh, workers=workers, progress=progress)


def _simulate_evidence(study, workers, progress):
    p = study.params
    t_from = p.ev_t_max - p.ev_window
    sysl = _systems(study)
    for label, spec, m in sysl:  # κ0 at the validity map's energies off the claims' grid: the claims' scene
        for r in map_ratios(p):
            sc = study.scene(
                map_key(label, r),
                system=spec,
                energy=r * m.critical_energy,
                n=p.grid_n,
                radius=p.radius_frac * m.saddle_radius,
            )
            study.run(map_key(label, r), sc, workers=workers, progress=progress)
    for ics in p.ev_ics:  # the disk ICs of every system first: the record's core
        for label, spec, m in sysl:
            ec, radius = m.critical_energy, p.radius_frac * m.saddle_radius
            for r in p.ev_ratios:
                _run_pair(
                    study,
                    ev_key(label, ics, r),
                    spec,
                    m,
                    t_from,
                    workers,
                    progress,
                    energy=r * ec,
                    n=p.ev_n,
                    t_max=p.ev_t_max,
                    sections={"t_from": t_from, "t_to": p.ev_t_max},
                    **_ics_kw(p, ics, radius),
                )
        if ics != p.ev_ics[0]:
            continue
        if ics == "disk":
            _simulate_labelled(study, sysl, workers, progress)
        for label, spec, m in sysl:
            _simulate_resc(study, label, spec, m, workers, progress)
        for label, spec, m in sysl:
            for r in p.ps_ratios:
                _run_pair(
                    study,
                    ps_key(label, r),
                    spec,
                    m,
                    p.ps_t_max - p.ev_window,
                    workers,
                    progress,
                    energy=r * m.critical_energy,
                    n=p.ps_n,
                    t_max=p.ps_t_max,
                    sections={"t_from": 0.0, "t_to": p.ps_t_max},
                    radius=p.radius_frac * m.saddle_radius,
                )


def _simulate_labelled(study, sysl, workers, progress):
    """The labelled sets (:func:`~hhscatter.reproduction.claims.chain.labelled_set`): per disk ensemble of regular
    fraction neither 0 nor 1, its shadow band and a sample either side, again with the tangent dynamics."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from hhscatter.reproduction.claims.chain import labelled_set

    p, runs = study.params, _Runs(study)
    for label, spec, m in sysl:
        for r in p.ev_ratios:
            sel = labelled_set(runs, label, r)
            if sel is None:
                continue
            key = lab_key(label, r)
            path = study.derived(f"{key}_ics.parquet")
            pq.write_table(pa.Table.from_pandas(sel, preserve_index=False), path)
            base = study.scene(ev_key(label, "disk", r), system=spec, energy=r * m.critical_energy, n=p.ev_n)
            sc = study.scene(
                key, system=spec, ics=str(path), n=len(sel), t_max=p.lab_t_max, r_esc=base.r_esc, tangent=True
            )
            study.run(key, sc, workers=workers, progress=progress)


def _simulate_resc(study, label, spec, m, workers, progress):
    """κ0 (windows), probe and dissipative runs at every r_esc of :func:`resc_values` (none with one value)."""
    from hhscatter.analysis.dissipative.decay import snapshot_grid

    p = study.params
    ec, radius = m.critical_energy, p.radius_frac * m.saddle_radius
    probe_times = tuple(np.round(np.arange(0.0, p.probe_t_max + 1e-9, p.probe_step), 9))
    values = resc_values(p, m)
    for R in values if len(values) > 1 else ():
        for r in p.resc_ratios:
            key = resc_key(label, R, f"r{r:.3f}")
            study.run(
                key,
                study.scene(key, system=spec, energy=r * ec, n=p.resc_n, radius=radius, r_esc=R),
                workers=workers,
                progress=progress,
            )
            key = resc_key(label, R, f"probe_r{r:.3f}")
            sc = study.scene(
                key,
                system=spec,
                energy=r * ec,
                n=p.resc_probe_n,
                radius=radius,
                r_esc=R,
                gamma=p.probe_gamma,
                t_max=p.probe_t_max,
                snapshots=probe_times,
            )
            study.run(key, sc, workers=workers, progress=progress)
        key = resc_key(label, R, f"g{p.mu_gamma:g}")
        sc = study.scene(
            key,
            system=spec,
            energy=p.e0_ratio * ec,
            n=p.resc_diss_n,
            radius=radius,
            r_esc=R,
            gamma=p.mu_gamma,
            t_max=p.diss_t_max,
            snapshots=tuple(snapshot_grid(p.snapshot_grid)),
            continue_settled=True,
        )
        study.run(key, sc, workers=workers, progress=progress)


plot = figures(
    figure_stage(
        "plot_generality", "kappa", "mu_conservative", "energy_curves", NUMBERS, PATH, when=("parts", "claims")
    ),
    figure_stage("plot_regular", NUMBERS, Sibling("_regular"), when=("parts", "evidence")),
    figure_stage(
        "plot_sections", Table("sections_regular", skip=True), Sibling("_sections"), when=("parts", "evidence")
    ),
    figure_stage("plot_decay", "survival_long", NUMBERS, Sibling("_decay"), when=("parts", "evidence")),
)
