"""Study noise — thermal and noisy scattering in Hénon–Heiles (beyond the paper).

Stages (``hhscatter study noise simulate|analyze|plot [--scale S]``):

``simulate(study, workers=None, progress=True)``
    Engine runs with a scene ``[noise]`` (:class:`hhscatter.scene.scene.Noise`; the noise scheduler of
    :mod:`hhscatter.integrate.noise`), orbits uniform in the disk r < radius, r_esc = 1.5:

    * ``kramers_b<b>``: γ = gamma_kramers, T = ΔE/b for each barrier b of ``barriers``, orbits started in the
      well at E0 = well_energy < E_c, t_max from ``kramers_t_max``;
    * ``kramers_b<b>_r<r>``: the same for each barrier of ``resc_barriers`` with r_esc = resc_radius (its own seed);
    * ``saddles_b<b>``: the declared system ``saddles_potential`` (two exit saddles of different heights) at
      γ = gamma_kramers, T = ΔE/b (ΔE its lowest barrier) for each b of ``saddles_barriers``;
    * ``turnover_g<γ>``: T = ΔE/turnover_barrier for each γ of ``turnover_gammas``;
    * ``turnover_b<b>_g<γ>``: the same gammas at T = ΔE/b, b = turnover_high_barrier (windows
      ``turnover_high_t_max``, ``turnover_high_n`` orbits);
    * ``saddles_turnover_g<γ>``: the two-saddle system at T = ΔE/saddles_turnover_barrier (ΔE its lowest barrier)
      for each γ of ``saddles_turnover_gammas``;
    * ``react_T0`` and ``react_T``: the paper's dissipative ensemble (E0 = react_energy, γ = react_gamma) without
      and with the heat bath T = ΔE/react_barrier; ``react_well``: the thermal rate at that (γ, T) from the well;
    * ``nodrag_E<E>_s<σ>``: γ = 0, noise strength σ (σ = 0: the conservative κ0) at each E0 of nodrag_energies;
      ``nodrag_E<E>_s<σ>_t<t>`` (σ > 0): the same orbits (seed, initial conditions, kicks) run to each t of
      ``nodrag_times``, whose censored orbits' end energies are the survivors' energies at t.

``analyze(study)``
    Reads the runs and passes their arrays to :mod:`hhscatter.reproduction.noise_records`, which assembles the
    records: rates by the constant-hazard MLE on [t_relax + relax_widths/γ, t_max] (left-truncated,
    right-censored; the window's halves compared: ``halves_z``, ``constant_in_window``) against Kramers–Langer
    from the system's saddles; the Kramers ratios against T/ΔE (the fit of their first correction beside its
    transition-state part); the rate at r_esc = resc_radius over the rate at the default radius; every turnover
    rate (both barriers and the two-saddle system, each saddle's terms beside) against Mel'nikov–Meshkov/PGH
    Υ(δ) k_KL, read where γ/ω_b ≤ theory_gamma_max, both Kramers limits and the energy-diffusion rates of the
    well's energy shells (up to E_b + shell_top_widths T on a shell_grid² lattice and shell_energies energies,
    read at γ ≤ energy_diffusion_gamma_max); the two-saddle rates against the multi-saddle sum and the escapes'
    exits against each term's share; the heat-bath P(t) against the drag-only one extended by re-activation;
    the no-drag rates on ``nodrag_window`` against κ0, their halves and the survivors' energies at each time.
    Writes ``noise.json`` (keys ``kramers``, ``finite_barrier``, ``absorbing_radius``, ``two_saddles``,
    ``turnover``, ``turnover_high``, ``two_saddles_turnover``, ``reactivation``, ``no_drag``, ``no_drag_survivors``,
    ``conventions``) and the derived tables ``rates``, ``reactivation``, ``no_drag`` and ``no_drag_rates``.

``plot(study)``
    ``noise.png`` via ``plot_noise`` of the folder's ``figure.py``.
"""

from __future__ import annotations

import zlib

import numpy as np
import pandas as pd

from hhscatter.scene.schema import Integer, Number, Numbers, Text
from hhscatter.studies.keys import RunKeys, number_key
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, SCALE, figure_stage


class Params(StudyParams):
    """``[study]`` of studies/noise/study.toml."""

    well_energy: Number  # E0 of the orbits started in the well
    t_relax: Number  # the rate window opens at t_relax + relax_widths/γ
    relax_widths: Number  # relaxation times 1/γ waited before the rate window opens
    constancy_z: Number  # the two halves of a rate window agree when |k₂ − k₁| < constancy_z σ
    flow: Text  # the noise flow between kicks: "taylor" or "symplectic" (hhscatter.scene.noise.Noise)
    gamma_kramers: Number
    barriers: Numbers  # ΔE/T
    kramers_t_max: Numbers
    turnover_barrier: Number
    turnover_gammas: Numbers
    turnover_t_max: Numbers
    turnover_n: Integer
    react_energy: Number
    react_gamma: Number
    react_barrier: Number
    react_n: Integer
    react_t_max: Number
    react_tail_start: Number  # start of the tail window of P_T(t)
    nodrag_energies: Numbers
    nodrag_sigmas: Numbers
    nodrag_n: Integer
    nodrag_t_max: Number
    nodrag_window: Numbers
    nodrag_times: Numbers  # the survivors' energies are read at these times (each a run to that time)
    resc_barriers: Numbers  # ΔE/T of the Kramers records measured again with r_esc = resc_radius
    resc_radius: Number  # the larger absorbing radius (length)
    saddles_potential: Text  # a declared system with two exit saddles of different barrier heights
    saddles_barriers: Numbers  # ΔE/T (ΔE its lowest barrier) of its Kramers records at γ = gamma_kramers
    saddles_t_max: Numbers
    turnover_high_barrier: Number  # ΔE/T of the second turnover series, at the gammas of turnover_gammas
    turnover_high_t_max: Numbers  # one per γ of turnover_gammas
    turnover_high_n: Integer
    saddles_turnover_barrier: Number  # ΔE/T (lowest saddle) of the two-saddle system's turnover
    saddles_turnover_gammas: Numbers
    saddles_turnover_t_max: Numbers
    saddles_turnover_n: Integer
    theory_gamma_max: Number  # the turnover theory's ratios are read where γ/ω_b ≤ this (underdamped crossing)
    energy_diffusion_gamma_max: Number  # the shells' energy-diffusion theories are read at γ ≤ this
    shell_top_widths: Number  # the well's energy shells reach E_b + shell_top_widths T
    shell_grid: Integer  # the shells' phase volume on a shell_grid × shell_grid lattice
    shell_energies: Integer  # ... at shell_energies energies from V(min) to the top
    nodrag_grid: Integer  # points of the no-drag P(t) table on [0, nodrag_t_max]


def _barrier(study, system: dict | None = None) -> float:
    """ΔE = E_c − V(min) (energy units), the lowest saddle above the well's minimum, of the study's system or of
    ``system`` (the keyword arguments of :func:`hhscatter.model.make_system`)."""
    from hhscatter.analysis.noise import well_barrier
    from hhscatter.model import make_system

    return well_barrier(study.model if system is None else make_system(**system))


def _pairs(study, a, b):
    p = study.params
    xs, ys = getattr(p, a), getattr(p, b)
    if len(xs) != len(ys):
        raise ValueError(f"[study] {a} and {b} must have the same length, got {len(xs)} and {len(ys)}")
    return list(zip(xs, ys))


def _kramers_key(b) -> str:
    return f"kramers_b{number_key(b, 'g')}"


def _turnover_key(g) -> str:
    return f"turnover_g{number_key(g, 'g')}"


def _turnover_high_key(g, b) -> str:
    return f"turnover_b{number_key(b, 'g')}_g{number_key(g, 'g')}"


def _saddles_turnover_key(g) -> str:
    return f"saddles_turnover_g{number_key(g, 'g')}"


def _nodrag_key(E, s) -> str:
    return f"nodrag_E{number_key(E, '.2f')}_s{number_key(s, 'g')}"


def _survivors_key(E, s, t) -> str:
    return f"{_nodrag_key(E, s)}_t{number_key(t, 'g')}"


def _saddles_key(b) -> str:
    return f"saddles_b{number_key(b, 'g')}"


def _saddles_system(p) -> dict:
    """The ``[system]`` table of the two-saddle system."""
    return {"potential": p.saddles_potential}


def _resc_key(b, r) -> str:
    return f"{_kramers_key(b)}_r{number_key(r, 'g')}"


def _survivor_times(p) -> list:
    """The times at which the no-drag survivors' energies are read: ``nodrag_times`` and the runs' t_max."""
    bad = [t for t in p.nodrag_times if not 0 < t <= p.nodrag_t_max]
    if bad:
        raise ValueError(f"[study] nodrag_times: {bad} outside (0, nodrag_t_max = {p.nodrag_t_max:g}]")
    return sorted({float(t) for t in p.nodrag_times} | {float(p.nodrag_t_max)})


def _record_seed(seed: int, key: str) -> int:
    """The seed of the rate record ``key``: derived from the study's seed and the key, so that no two records share
    initial conditions or noise streams."""
    return int(np.random.SeedSequence([int(seed), zlib.crc32(key.encode())]).generate_state(1)[0])


def _window_start(p, gamma: float) -> float:
    """The rate window's start (time units): t_relax + relax_widths/γ, after the start's relaxation."""
    return p.t_relax + p.relax_widths / gamma


def _runs(study):
    """{key: scene} of every raw run (module docstring); each key names one run (:class:`RunKeys`). The Kramers
    and turnover records each have their own seed (:func:`_record_seed`)."""
    p, dE = study.params, _barrier(study)
    runs = RunKeys()
    for b, t_max in _pairs(study, "barriers", "kramers_t_max"):
        runs[_kramers_key(b)] = dict(
            energy=p.well_energy, gamma=p.gamma_kramers, t_max=t_max, noise={"temperature": dE / b, "flow": p.flow}
        )
    t_max_of = dict(_pairs(study, "barriers", "kramers_t_max"))
    for b in p.resc_barriers:
        if b not in t_max_of:
            raise ValueError(f"[study] resc_barriers: {b:g} is not one of barriers {list(p.barriers)}")
        runs[_resc_key(b, p.resc_radius)] = dict(runs[_kramers_key(b)], r_esc=p.resc_radius)
    low = _barrier(study, _saddles_system(p)) if p.saddles_barriers or p.saddles_turnover_gammas else None
    for b, t_max in _pairs(study, "saddles_barriers", "saddles_t_max"):
        runs[_saddles_key(b)] = dict(
            energy=p.well_energy,
            gamma=p.gamma_kramers,
            t_max=t_max,
            noise={"temperature": low / b, "flow": p.flow},
            system=_saddles_system(p),
        )
    b_high = p.turnover_high_barrier
    for b, windows, n, key in (
        (p.turnover_barrier, "turnover_t_max", p.turnover_n, _turnover_key),
        (b_high, "turnover_high_t_max", p.turnover_high_n, lambda g: _turnover_high_key(g, b_high)),
    ):
        for g, t_max in _pairs(study, "turnover_gammas", windows):
            runs[key(g)] = dict(
                energy=p.well_energy, gamma=g, t_max=t_max, n=n, noise={"temperature": dE / b, "flow": p.flow}
            )
    for g, t_max in _pairs(study, "saddles_turnover_gammas", "saddles_turnover_t_max"):
        runs[_saddles_turnover_key(g)] = dict(
            energy=p.well_energy,
            gamma=g,
            t_max=t_max,
            n=p.saddles_turnover_n,
            noise={"temperature": low / p.saddles_turnover_barrier, "flow": p.flow},
            system=_saddles_system(p),
        )
    react = dict(energy=p.react_energy, gamma=p.react_gamma, t_max=p.react_t_max, n=p.react_n)
    runs["react_T0"] = react
    bath = {"temperature": dE / p.react_barrier, "flow": p.flow}
    runs["react_T"] = dict(react, noise=bath)
    runs["react_well"] = dict(react, energy=p.well_energy, noise=bath)
    for E in p.nodrag_energies:
        for s in p.nodrag_sigmas:
            runs[_nodrag_key(E, s)] = dict(
                energy=E,
                gamma=0.0,
                t_max=p.nodrag_t_max,
                n=p.nodrag_n,
                noise={"sigma": s, "flow": p.flow} if s > 0 else None,
            )
            for t in _survivor_times(p)[:-1] if s > 0 else ():  # the same orbits, read at t (their energies)
                runs[_survivors_key(E, s, t)] = dict(runs[_nodrag_key(E, s)], t_max=t)
    scenes = {k: study.scene(k, **kw) for k, kw in runs.items()}
    for k, sc in scenes.items():
        if k.startswith(("kramers_", "turnover_", "saddles_")):
            scenes[k] = sc.replace(seed=_record_seed(sc.seed, k))
    return scenes


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None, progress=True) -> None: every raw run of :func:`_runs`."""
    for key, scene in _runs(study).items():
        study.run(key, scene, workers=workers, progress=progress)


# -- analyze ----------------------------------------------------------------
def _lifetimes(study, key):
    """(t_end, escaped, settled) arrays of raw run ``key``, in orbit order."""
    from hhscatter.data.read import read_by_orbit

    c = read_by_orbit(study.raw(key), ["outcome", "t_end"])
    o = np.asarray(c["outcome"].astype(str))
    return c["t_end"], o == "escaped", o == "settled"


def _rate_row(study, key, scene):
    """The rate record of raw run ``key`` (its scene ``scene``) against Kramers–Langer."""
    from hhscatter.reproduction.noise_records import rate_record

    t_end, escaped, _ = _lifetimes(study, key)
    window = (_window_start(study.params, scene.gamma), scene.t_max)
    T = scene.noise.temperature
    z_max = study.params.constancy_z
    return rate_record(
        t_end, escaped, scene.model, scene.gamma, T, window, n=scene.n, r_esc=scene.r_esc, seed=scene.seed, z_max=z_max
    )


def _two_saddles(study, runs) -> dict:
    """The Kramers rate of the two-saddle system against the multi-saddle Kramers–Langer sum and its lowest term
    alone, and the share of the escapes over each saddle against its term's share of the sum."""
    from hhscatter.data.read import read_by_orbit
    from hhscatter.reproduction.noise_records import pretty_potential, saddle_terms, two_saddle_record

    p = study.params
    rows, saddles = [], []
    for b, _ in _pairs(study, "saddles_barriers", "saddles_t_max"):
        key = _saddles_key(b)
        sc = runs[key]
        row = _rate_row(study, key, sc)
        c = read_by_orbit(study.raw(key), ["outcome", "t_end", "exit_channel"])
        escaped = np.asarray(c["outcome"].astype(str)) == "escaped"
        rows.append(two_saddle_record(row, c["exit_channel"], c["t_end"], escaped, sc.model))
        saddles = saddle_terms(sc.model, sc.gamma, row["temperature"])
    return {
        "potential": p.saddles_potential,
        "potential_text": pretty_potential(p.saddles_potential),
        "saddles": saddles,
        "records": rows,
    }


def _turnover_row(study, key, runs) -> dict:
    """The rate record of turnover run ``key`` against the turnover theory (Mel'nikov–Meshkov/PGH, both limits) and
    the energy-diffusion theories of the well's shells."""
    from hhscatter.reproduction.noise_records import turnover_theories_record

    p, sc = study.params, runs[key]
    row = _rate_row(study, key, sc)
    shells = dict(shell_top_widths=p.shell_top_widths, shell_grid=p.shell_grid, shell_energies=p.shell_energies)
    return {**row, **turnover_theories_record(row, sc.model, gamma_max=p.theory_gamma_max, **shells)}


def _saddles_turnover(study, runs) -> dict:
    """The two-saddle system's rate against γ at one barrier: against the multi-saddle Kramers–Langer sum, the
    Mel'nikov–Meshkov/PGH sum Σ_s Υ(δ_s) k_KL,s and the energy-diffusion limit Σ_s δ_s k_TST,s, each saddle's
    terms beside."""
    from hhscatter.model import make_system
    from hhscatter.reproduction.noise_records import two_saddle_turnover_record

    p = study.params
    pairs = _pairs(study, "saddles_turnover_gammas", "saddles_turnover_t_max")
    rows = [_turnover_row(study, _saddles_turnover_key(g), runs) for g, _ in pairs]
    model = make_system(**_saddles_system(p))
    return two_saddle_turnover_record(
        rows, model, barrier_over_T=p.saddles_turnover_barrier, potential=p.saddles_potential
    )


def _absorbing_radius(study, runs, kramers) -> list:
    """The Kramers rate at r_esc = resc_radius against the same record at the default radius (independent seeds)."""
    from hhscatter.reproduction.noise_records import absorbing_radius_record

    p = study.params
    by_b = {r["barrier_over_T"]: r for r in kramers}
    out = []
    for b in p.resc_barriers:
        key = _resc_key(b, p.resc_radius)
        far = _rate_row(study, key, runs[key])
        out.append(absorbing_radius_record(by_b[far["barrier_over_T"]], far))
    return out


def _no_drag_survivors(study, runs) -> list:
    """The energies of the no-drag orbits still inside at each time of :func:`_survivor_times` (σ > 0)."""
    from hhscatter.data.read import read_by_orbit
    from hhscatter.reproduction.noise_records import survivor_record

    p = study.params
    e_c = study.model.critical_energy
    times = _survivor_times(p)
    rows = []
    for E in p.nodrag_energies:
        for s in p.nodrag_sigmas:
            if s <= 0:
                continue
            for t in times:
                key = _nodrag_key(E, s) if t == times[-1] else _survivors_key(E, s, t)
                c = read_by_orbit(study.raw(key), ["outcome", "e_end"])
                alive = np.asarray(c["outcome"].astype(str)) == "censored"
                rows.append(survivor_record(E, s, t, alive, c["e_end"], e_c))
    return rows


def _reactivation(study, runs):
    """P(t) with and without the heat bath, the extension's prediction, and their numbers."""
    from hhscatter.reproduction.noise_records import reactivation_record

    p = study.params
    sc = runs["react_T"]
    about = {
        "energy": p.react_energy,
        "gamma": sc.gamma,
        "temperature": sc.noise.temperature,
        "barrier_over_T": p.react_barrier,
        "n": sc.n,
    }
    try:
        return reactivation_record(
            _lifetimes(study, "react_T0"),
            _lifetimes(study, "react_T")[:2],
            _lifetimes(study, "react_well")[:2],
            t_max=sc.t_max,
            tail_start=p.react_tail_start,
            window_start=_window_start(p, sc.gamma),
            about=about,
        )
    except ValueError as e:
        raise ValueError(f"[study] react_tail_start: {e}") from None


def _no_drag(study, runs):
    from hhscatter.reproduction.noise_records import no_drag_records

    p = study.params
    rows = []
    for E in p.nodrag_energies:
        samples = [_lifetimes(study, _nodrag_key(E, s))[:2] for s in p.nodrag_sigmas]
        rows += no_drag_records(E, p.nodrag_sigmas, samples, p.nodrag_window, p.constancy_z)
    return rows


def _survival_tables(study, runs):
    """P(t) of every no-drag run on a common grid (the figure's panel)."""
    from hhscatter.reproduction.noise_records import no_drag_survival

    p = study.params
    grid = np.linspace(0.0, p.nodrag_t_max, p.nodrag_grid)
    frames = []
    for E in p.nodrag_energies:
        for s in p.nodrag_sigmas:
            t_end, esc, _ = _lifetimes(study, _nodrag_key(E, s))
            frames.append(no_drag_survival(E, s, t_end, esc, grid))
    return pd.concat(frames, ignore_index=True)


def analyze(study):
    """analyze(study) -> None: rates against Kramers–Langer, the heat-bath P(t), the no-drag rates; noise.json."""
    from hhscatter.reproduction.noise_records import finite_barrier_record, rates_table, theory_conventions

    p = study.params
    runs = _runs(study)
    kramers = [
        _rate_row(study, _kramers_key(b), runs[_kramers_key(b)]) for b, _ in _pairs(study, "barriers", "kramers_t_max")
    ]
    turnover, turnover_high = (
        [_turnover_row(study, key(g), runs) for g in p.turnover_gammas]
        for key in (_turnover_key, lambda g: _turnover_high_key(g, p.turnover_high_barrier))
    )
    saddles_turnover = _saddles_turnover(study, runs)
    react, react_table = _reactivation(study, runs)
    no_drag = _no_drag(study, runs)
    survivors = _no_drag_survivors(study, runs)
    series = {"kramers": kramers, "turnover": turnover, "turnover_high": turnover_high}
    study.write_table(rates_table({**series, "saddles_turnover": saddles_turnover["records"]}), "rates.parquet")
    study.write_table(react_table, "reactivation.parquet")
    study.write_table(_survival_tables(study, runs), "no_drag.parquet")
    study.write_table(pd.DataFrame(no_drag), "no_drag_rates.parquet")
    absorbing = _absorbing_radius(study, runs, kramers)
    saddles = _two_saddles(study, runs)
    hi = kramers[-1]
    study.compare(
        f"escape rate / Kramers–Langer at ΔE/T = {hi['barrier_over_T']:.3g}, γ = {hi['gamma']:g}",
        hi["ratio"],
        hi["ratio_err"],
        1.0,
        note="Kramers–Langer is the large-barrier limit; the ratio should tend to 1 as ΔE/T grows",
        convention="disk r < 0.5 at E0 = well_energy, rate window [t_relax + relax_widths/γ, t_max], r_esc 1.5",
    )
    study.write_numbers(
        {
            "kramers": kramers,
            "finite_barrier": finite_barrier_record(kramers, study.model),
            "absorbing_radius": absorbing,
            "two_saddles": saddles,
            "turnover": turnover,
            "turnover_high": turnover_high,
            "two_saddles_turnover": saddles_turnover,
            "reactivation": react,
            "no_drag": no_drag,
            "no_drag_survivors": survivors,
            "conventions": {
                "r_esc": runs["react_T"].r_esc,
                "ic_region": "disk r < 0.5",
                "rate": "constant-hazard MLE on [t_relax + relax_widths/γ, t_max], left-truncated, right-censored",
                "t_relax": p.t_relax,
                "relax_widths": p.relax_widths,
                "window_rule": f"t ≥ {p.t_relax:g} + {p.relax_widths:g}/γ; constant when the halves agree within "
                f"{p.constancy_z:g}σ",
                # every heat-bath rate: Kramers, turnover, the second radius and the two-saddle system
                "all_constant_in_window": all(
                    r["constant_in_window"] for r in kramers + turnover + absorbing + saddles["records"]
                ),
                "seeds": "one per Kramers and turnover record, derived from the study's seed and the record's key",
                "nodrag_window": list(p.nodrag_window),
                "nodrag_times": _survivor_times(p),
                "E_c": study.model.critical_energy,
                "resc_radius": p.resc_radius,
                "kick": "0.1 min(1/ω, 1/γ) (the scene default)",
                "flow": p.flow,
                **theory_conventions(
                    gamma_max=p.theory_gamma_max,
                    energy_diffusion_gamma_max=p.energy_diffusion_gamma_max,
                    shell_top_widths=p.shell_top_widths,
                    shell_grid=p.shell_grid,
                    shell_energies=p.shell_energies,
                ),
            },
        }
    )


# -- plot -------------------------------------------------------------------
plot = figure_stage(
    "plot_noise",
    rates="rates",
    reactivation="reactivation",
    no_drag="no_drag",
    numbers=NUMBERS,
    path=PATH,
    scale=SCALE,
)
