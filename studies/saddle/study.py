"""Study saddle — the chaotic saddle measured and the Kantz–Grassberger relation κ = λ̄ (1 − d₁) (beyond the paper).

Rules: the header of ``study.toml``. Stages (``hhscatter study saddle simulate|analyze|plot [--scale S]``):

``simulate(study, workers=None, progress=True)``
    Per system and E = r·E_c: the main run (raw key ``<label>_r<r>``: disk ICs, every section crossing to t_max),
    its κ (:func:`~hhscatter.analysis.survival.escape_rate.escape_rate_from_lifetimes`) and t_min = tmin_efolds/κ,
    and the tangent run (``<label>_r<r>_tangent``, ``[scene] tangent = true``, the main run's events: the same
    orbits) of the orbits that left at t_end ≥ t_min; the lines run (``_lines``: pairs moved by each ε of d0_eps)
    and the dense lines (``_dlines``). κ and t_min are written to ``raw/saddle_choices.json``.

``analyze(study)``
    ``saddle.json``: per point κ, λ̄, d₁ on the section and on lines, d₀ = 1 − α of the lines run, the relation's
    verdicts (the estimators of :mod:`hhscatter.analysis.geometry.saddle`, assembled by
    :mod:`hhscatter.reproduction.saddle_records`; study basins re-predicts its cut-off with λ̄); derived table
    ``saddle_ftle.parquet`` (the finite-time exponents
    Λ/T of the tangent runs).

``plot(study)``
    ``saddle.png`` via ``plot_saddle`` of the folder's ``figure.py``.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np

from hhscatter.analysis.geometry.saddle import information_dimension_neighbours, neighbour_floor_scan
from hhscatter.analysis.stats.measured import Measured
from hhscatter.errors import ConfigError
from hhscatter.reproduction import saddle_records as sr
from hhscatter.scene.schema import Integer, Number, Numbers, Text
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, figure_stage


class SystemEntry(StudyParams):
    """One entry of ``[study] systems``: a label, a built-in system with its parameters and its E/E_c."""

    label: Text
    name: Text
    params: dict[str, Number] = None  # the built-in's defaults where absent
    ratios: Numbers  # E/E_c of the points
    t_max: Number = None  # the system's own t_max ([study] t_max where absent)
    tmin_efolds: Number = None  # the system's own t_min·κ ([study] tmin_efolds where absent)
    lines_efolds: Number = None  # the system's own t_min·κ of d₁ on lines (at most [study]'s; theirs where absent)
    lines_checks: Numbers = None  # the system's own lines_checks (each at most the latest of [study]'s)


class Params(StudyParams):
    """``[study]`` of studies/saddle/study.toml (rules in its header comment)."""

    systems: list[SystemEntry]
    radius_frac: Number  # IC disk r < radius_frac·r_s
    n: Integer  # orbits per main run
    t_max: Number
    tmin_efolds: Number  # t_min = tmin_efolds/κ
    tmin_checks: Numbers  # d₁ also at t_min = c/κ for these c
    tmin_trend: Numbers = (1.0, 2.0, 3.0)  # d₁ and λ̄ also at t_min·κ = tmin_efolds + s (their trend in t_min)
    window: Numbers  # (lo, hi): fractions of each orbit's lifetime
    min_boxes: Number  # d₁'s largest scale: the points' extent/min_boxes
    d1_floor: Number  # d₁'s smallest scale: this fraction of the points' extent
    d1_floor_factors: Numbers  # d₁ also with the floor times these (its convergence in the floor)
    k_max: Integer  # d₁'s largest neighbour rank
    n_bins: Integer  # λ̄(T) bins
    n_boot: Integer
    d0_eps: Numbers  # ε of the uncertainty algorithm, decreasing (position units)
    d0_n: Integer  # reference initial conditions per ε
    d0_min_count: Integer  # an ε enters α's fit with ≥ this many uncertain pairs
    ftle_low: Numbers = (0.25, 0.5, 0.75)  # Λ/T < this·λ̄ is near 0 (the middle one for the hyperbolic part)
    lines_count: Integer  # d₁ on lines: lines y = const through the IC disk
    lines_n: Integer  # initial conditions per line
    lines_efolds: Number  # d₁ on lines: the orbits that left at t_end ≥ lines_efolds/κ
    lines_checks: Numbers  # d₁ on lines also at these t_min·κ (its convergence in the selection)
    lines_floor: Number  # d₁ on lines: scales down to this fraction of a line's extent


FTLE_TABLE = "saddle_ftle.parquet"


def _systems(study):
    """[(label, spec, System, ratios, t_max)] of [study] systems."""
    from hhscatter.model.spec import system_from_spec

    out = []
    for e in study.params.systems:  # typed entries read as dicts
        spec = {"name": e["name"], "params": dict(e.get("params") or {})}
        t_max = float(e.get("t_max") or study.params.t_max)
        out.append((e["label"], spec, system_from_spec(spec), [float(r) for r in e["ratios"]], t_max))
    return out


def _tmin_efolds(study, label: str) -> float:
    """t_min·κ of the system ``label``: its own ``tmin_efolds``, else [study] tmin_efolds."""
    e = next(e for e in study.params.systems if e["label"] == label)
    return float(e.get("tmin_efolds") or study.params.tmin_efolds)


def _tmin_overrides(study) -> dict:
    """{"tmin_efolds_by_system": {label: t_min·κ}} of the systems with their own tmin_efolds and
    {"lines_by_system": {label: {lines_efolds, lines_checks}}} of those with their own lines rules, where any."""
    own = {e["label"]: float(e["tmin_efolds"]) for e in study.params.systems if e.get("tmin_efolds")}
    lines = {e["label"]: dict(zip(("lines_efolds", "lines_checks"), _lines_rules(study, e["label"])))
             for e in study.params.systems if e.get("lines_efolds") or e.get("lines_checks")}  # fmt: skip
    return {**({"tmin_efolds_by_system": own} if own else {}), **({"lines_by_system": lines} if lines else {})}


def _lines_rules(study, label: str) -> tuple:
    """(lines_efolds, [lines_checks]) of the system ``label``: its own where given, else [study]'s. A system's own
    may not lie after the latest of [study]'s (the lines run to 3 e-folds after that, the same run for every system):
    refused, naming the key."""
    p = study.params
    e = next(e for e in study.params.systems if e["label"] == label)
    efolds = float(e.get("lines_efolds") or p.lines_efolds)
    checks = [float(c) for c in (e.get("lines_checks") or p.lines_checks)]
    latest = max(p.lines_efolds, *p.lines_checks)
    if max(efolds, *checks) > latest:
        raise ConfigError(f"saddle [study].systems[{label}] lines_efolds/lines_checks must be ≤ {latest:g} (the latest "
                          f"of [study] lines_efolds and lines_checks), got {efolds:g} and {checks!r}")  # fmt: skip
    return efolds, checks


def _d0_eps(study):
    eps = np.asarray(study.params.d0_eps, dtype=float)
    if not (eps.size >= 3 and np.all(eps > 0) and np.all(np.diff(eps) < 0)):
        raise ConfigError(f"saddle [study].d0_eps must be ≥ 3 decreasing positive numbers, got {list(eps)!r}")
    if study.params.d0_n < 1 or study.params.d0_min_count < 1:
        raise ConfigError("saddle [study].d0_n and d0_min_count must be integers ≥ 1")
    return eps


def point_key(label: str, ratio: float) -> str:
    """point_key(label, r) -> raw-run key 'henon_heiles_r1.50' of the main run at E = r·E_c."""
    return f"{label}_r{ratio:.2f}"


def _choices_path(study):
    return study.out / "raw" / "saddle_choices.json"


def _lifetimes(path, extra=()):
    from hhscatter.data.read import read_lifetimes

    return read_lifetimes(path, columns=["traj_id", "e0", "gamma", "outcome", "t_end", *extra], categorical=True)


def _kappa(path):
    """κ of the orbits that left by t_max (those still inside at t_max, censored, are not on the saddle)."""
    from hhscatter.analysis.survival.escape_rate import escape_rate_from_lifetimes
    from hhscatter.outcomes import LEAVING_OUTCOMES

    lt = _lifetimes(path)
    return escape_rate_from_lifetimes(lt[lt["outcome"].astype(object).isin(LEAVING_OUTCOMES)], detect_tail=False)


# ---------------------------------------------------------------------------
# simulate
# ---------------------------------------------------------------------------
def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None, progress=True) -> None: per point the main run and the tangent run."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from hhscatter.data.read import read_lifetimes
    from hhscatter.studies import write_json_atomic

    p, choices = study.params, {}
    d0_eps, _ = _d0_eps(study), _tmin_overrides(study)  # refused before any work (the lines rules with them)
    for label, spec, m, ratios, t_max in _systems(study):
        for r in ratios:
            key = point_key(label, r)
            sc = study.scene(
                key,
                system=spec,
                energy=r * m.critical_energy,
                n=p.n,
                radius=p.radius_frac * m.saddle_radius,
                t_max=t_max,
                sections={"t_from": 0.0},
            )
            study.run(key, sc, workers=workers, progress=progress)
            k = _kappa(study.raw(key))
            t_min = _tmin_efolds(study, label) / k.kappa
            lt = read_lifetimes(study.raw(key), columns=["traj_id", "x0", "y0", "px0", "py0", "outcome", "t_end"])
            sel = sr.long_lived(lt, t_min)
            print(f"  saddle {key}: κ = {k.kappa:.4f} ± {k.kappa_err:.4f}, t_min = {t_min:.1f}, {len(sel)} orbits")
            choices[key] = {"system": label, "ratio": r, "energy": r * m.critical_energy, "kappa": k.kappa,
                            "kappa_err": k.kappa_err, "t_min": t_min, "n_tangent": len(sel), "r_esc": sc.r_esc}  # fmt: skip
            _run_lines(study, key, sc, spec, d0_eps, workers, progress)
            _run_dense_lines(study, key, sc, spec, k.kappa, workers, progress)
            if len(sel) == 0:
                continue
            path = study.derived(f"{key}_tangent_ics.parquet")
            cols = {"traj_id": sel["traj_id"].to_numpy(), "x": sel["x0"].to_numpy(), "y": sel["y0"].to_numpy(),
                    "px": sel["px0"].to_numpy(), "py": sel["py0"].to_numpy()}  # fmt: skip
            pq.write_table(pa.table(cols), path)
            # the main run's events (its sections too): the tangent dynamics never set a step, so these are the
            # very orbits selected, bit for bit (their t_end checked in analyze)
            tsc = study.scene(key + "_tangent", system=spec, ics=str(path), n=len(sel), t_max=t_max, r_esc=sc.r_esc,
                              sections={"t_from": 0.0}, tangent=True)  # fmt: skip
            study.run(key + "_tangent", tsc, workers=workers, progress=progress)
            for part, w in zip(("lo", "hi"), p.window):  # Λ at window·t_min (all still inside): the mid-life λ̄
                study.run(f"{key}_tangent_{part}", tsc.replace(name=f"{study.name}/{key}_tangent_{part}",
                          t_max=w * t_min), workers=workers, progress=progress)  # fmt: skip
    write_json_atomic(_choices_path(study), choices)


def _lines_path(study, key):
    return study.derived(f"{key}_lines_ics.parquet")


def _run_lines(study, key, sc, spec, eps, workers, progress):
    """The lines run of a point: per ε, d0_n fresh ICs of the main run's disk (seed·100 + 1 + index) and their
    copies moved by ε along x (tangential momenta at the same E), in one run; its layout in a derived table."""
    import pandas as pd

    from hhscatter.scene.ics import perturbed_on_section, region_ics

    p, base, parts = study.params, int(study.config["scene"]["seed"]), []
    for i, e in enumerate(eps):
        ref = region_ics(sc.replace(seed=base * 100 + 1 + i, n=p.d0_n), 0, p.d0_n)
        moved, ok = perturbed_on_section(sc.model, ref, sc.energy, dx=float(e))
        m = int(ok.sum())
        for states, is_moved in ((ref[ok], False), (moved[ok], True)):
            part = pd.DataFrame(states, columns=["x", "y", "px", "py"])
            parts.append(part.assign(eps=float(e), eps_index=i, pair=np.arange(m), moved=is_moved))
    df = pd.concat(parts, ignore_index=True)
    df.insert(0, "traj_id", np.arange(len(df), dtype=np.int64))
    path = _lines_path(study, key)
    # rewritten only when different: the scene's hash includes the file's, and resume relies on it
    if not path.exists() or not pd.read_parquet(path).equals(df):
        df.to_parquet(path, index=False)
    lsc = study.scene(key + "_lines", system=spec, ics=str(path), n=len(df), t_max=sc.t_max, r_esc=sc.r_esc,
                      sections=None)  # fmt: skip
    study.run(key + "_lines", lsc, workers=workers, progress=progress)


def _dense_lines_path(study, key):
    return study.derived(f"{key}_dlines_ics.parquet")


def _lines_t_max(study, kappa: float, t_max: float) -> float:
    """t_max of the dense lines: 3 e-folds after the latest t_min·κ of [study] (a system's own lie before it), at
    most the main run's (a cheaper end)."""
    p = study.params
    return min(t_max, (max(p.lines_efolds, *p.lines_checks) + 3.0) / kappa)


def _run_dense_lines(study, key, sc, spec, kappa, workers, progress):
    """The dense lines of a point (``<key>_dlines``): lines_count × lines_n ICs of ``scene.ics.chord_lines`` across
    the disk (seeded by the key), run to :func:`_lines_t_max` with the main run's r_esc; the layout derived."""
    import zlib

    import pandas as pd

    from hhscatter.scene.ics import chord_lines

    rng = np.random.default_rng([int(study.config["scene"]["seed"]), 52, zlib.crc32(key.encode())])
    st, line = chord_lines(sc.model, sc.energy, float(sc.radius), study.params.lines_count, study.params.lines_n, rng)
    df = pd.DataFrame({"traj_id": np.arange(len(st), dtype=np.int64), "x": st[:, 0], "y": st[:, 1], "px": st[:, 2],
                       "py": st[:, 3], "line": line})  # fmt: skip
    path = _dense_lines_path(study, key)
    if not path.exists() or not pd.read_parquet(path).equals(df):  # the scene's hash includes the file's
        df.to_parquet(path, index=False)
    lsc = study.scene(key + "_dlines", system=spec, ics=str(path), n=len(df), r_esc=sc.r_esc, sections=None,
                      t_max=_lines_t_max(study, kappa, sc.t_max))  # fmt: skip
    study.run(key + "_dlines", lsc, workers=workers, progress=progress)


# ---------------------------------------------------------------------------
# analyze
# ---------------------------------------------------------------------------
def _d1_lines(study, key, label, k, lam, t_max):
    """d₁ on the point's dense lines (:func:`~hhscatter.reproduction.saddle_records.lines_measurement`)."""
    import pandas as pd

    p = study.params
    efolds, checks = _lines_rules(study, label)
    layout = pd.read_parquet(_dense_lines_path(study, key), columns=["traj_id", "x", "line"])
    rows = layout.merge(_lifetimes(study.raw(key + "_dlines")), on="traj_id")
    top = 1.0 / p.min_boxes  # decades from the floor; the last one ends at the top scale (at least an octave wide)
    edges = [e for e in (p.lines_floor * 10.0**j for j in range(12)) if e < top / 2] + [top]
    decades = list(zip(edges[:-1], edges[1:]))
    return sr.lines_measurement(rows, k.kappa, k.kappa_err, lam["value"], lam["err"], efolds=efolds,
                                checks=checks, floor=p.lines_floor, bands=decades,
                                section_band=(p.d1_floor, 1.0 / p.min_boxes), factors=p.d1_floor_factors,
                                k_max=p.k_max, n_boot=p.n_boot, t_max=_lines_t_max(study, k.kappa, t_max),
                                n_lines=p.lines_count)  # fmt: skip


def _lyapunov(lt, t_min, p):
    """λ̄ of the tangent run's orbits that left at t_end ≥ t_min (saddle_records.lyapunov_record)."""
    return sr.lyapunov_record(sr.long_lived(lt, t_min), n_bins=p.n_bins, n_boot=p.n_boot)


def _extent(sp) -> float:
    """The saddle points' longest side (position units)."""
    P = sp.points[["x", "y"]].to_numpy()
    return float(np.max(P.max(axis=0) - P.min(axis=0))) if len(P) else 0.0


def _d1_args(sp, p) -> dict:
    """The neighbour estimator's arguments for a SaddlePoints: the points, their orbits and the study's rules."""
    return {"points": sp.points[["x", "y"]].to_numpy(), "groups": sp.points["traj_id"].to_numpy(), "k_max": p.k_max,
            "eps_max": _extent(sp) / p.min_boxes, "n_boot": p.n_boot, "seed": 0}  # fmt: skip


def _d1_estimator(p):
    """The section's information dimension of a SaddlePoints over the scales d1_floor·extent … extent/min_boxes."""
    return lambda sp: information_dimension_neighbours(**_d1_args(sp, p), floor=p.d1_floor)


def _checks(study, key, tangent, t_min, efolds, k):
    """λ̄ and the fluctuations' d₂ of the mid-life (the ``_lo``/``_hi`` tangent runs: Λ at window·t_min) and λ̄ at
    the t_min of tmin_trend."""
    p, kappa = study.params, k.kappa
    lo, hi = (_lifetimes(study.raw(f"{key}_tangent_{s}"), ("log_stretch",)) for s in ("lo", "hi"))
    ts, mid = [c / kappa for c in (efolds, *(efolds + s for s in p.tmin_trend))], (p.window[0] * t_min, p.window[1] * t_min)  # fmt: skip
    return {**sr.mid_lyapunov_record(lo, hi, *mid, n_boot=p.n_boot),
            **sr.fluctuation_record(sr.long_lived(tangent, t_min), kappa, k.kappa_err, (lo, hi, *mid), n_boot=p.n_boot),
            "lyapunov_by_t_min": sr.lyapunov_by_t_min(sr.long_lived(tangent, ts[0]), ts, kappa, n_boot=p.n_boot)}  # fmt: skip


def _d1_radius(sp, d, p):
    """d₁ of the same points by the fixed-radius mass (the second estimator), up to the largest scale d fitted."""
    from hhscatter.analysis.geometry.saddle_checks import information_dimension_radius

    try:
        r = information_dimension_radius(sp.points[["x", "y"]].to_numpy(), groups=sp.points["traj_id"].to_numpy(),
                                         eps_min=p.d1_floor * _extent(sp), eps_max=d.eps_range[1],
                                         n_boot=p.n_boot, seed=0)  # fmt: skip
    except ConfigError as exc:
        return {"d1_radius_note": str(exc)}
    return {"d1_radius": Measured(r.value, r.err).scaled(0.5).to_dict(), "d1_radius_eps_range": list(r.eps_range)}


def _d0(study, key):
    """d₀ = 1 − α of the point's lines run (:func:`~hhscatter.reproduction.saddle_records.d0_record`)."""
    import pandas as pd

    layout = pd.read_parquet(_lines_path(study, key)).sort_values("traj_id")
    lt = _lifetimes(study.raw(key + "_lines"), ("exit_channel",))  # in traj_id order, as the layout
    return sr.d0_record(layout, lt, min_count=study.params.d0_min_count)


def _point(study, key, ch):
    """One point's record and its FTLE rows."""
    from hhscatter.analysis.geometry.saddle import kantz_grassberger, saddle_points, window_dependence
    from hhscatter.data.read import read_sections

    p = study.params
    k = _kappa(study.raw(key))
    efolds = _tmin_efolds(study, ch["system"])
    t_min = efolds / k.kappa
    rec = {"id": f"{ch['system']}-{ch['ratio']:.2f}", "system": ch["system"], "ratio": ch["ratio"], "energy": ch["energy"], "kappa": k.kappa,
           "kappa_err": k.kappa_err, "lyapunov": None, "lyapunov_err": None, "d0": None, "d0_err": None,
           "d1": None, "d1_err": None, "t_min": t_min, "notes": []}  # fmt: skip
    if abs(t_min - ch["t_min"]) > 1e-9 * t_min:
        rec["notes"].append(f"t_min of the tangent run {ch['t_min']:.6g} differs from {t_min:.6g}: re-run simulate")
    if ch["n_tangent"] == 0:
        rec["notes"].append("no orbit left at t_end ≥ t_min")
        return rec, None
    tangent, lt = _lifetimes(study.raw(key + "_tangent"), ("log_stretch",)), _lifetimes(study.raw(key))
    main = sr.long_lived(lt, ch["t_min"]).set_index("traj_id")["t_end"]  # one integration: the same orbits, same ends
    same = int((tangent.set_index("traj_id")["t_end"].reindex(main.index) == main).sum())
    rec["tangent_same_orbits"] = {"same_t_end": same, "selected": len(main)}
    if same < len(main):
        rec["notes"].append(
            f"the tangent run ends {len(main) - same} of {len(main)} orbits elsewhere than the main run"
        )
    lam = _lyapunov(tangent, ch["t_min"], p)
    if lam is None:
        rec["notes"].append("fewer than 2 orbits of the tangent run left at t_end ≥ t_min")
        return rec, None
    lam, ftle = lam
    rec.update({"lyapunov": lam["value"], "lyapunov_err": lam["err"], "lyapunov_detail": lam})
    if lam["value"] is None:
        rec["notes"].append(sr.no_lyapunov_words(lam))
    _label, _spec, model, _ratios, t_max = next(s for s in _systems(study) if s[0] == ch["system"])
    lines = _d1_lines(study, key, ch["system"], k, lam, t_max)
    if "notes_lines" in lines:
        rec["notes"].append(lines.pop("notes_lines"))
    rec.update(lines)
    rec.update(_checks(study, key, tangent, ch["t_min"], efolds, k))
    sec = read_sections(study.raw(key), columns=["traj_id", "t", "x", "y", "px", "py"])
    est = _d1_estimator(p)
    cs = (*p.tmin_checks, efolds, *(efolds + s for s in p.tmin_trend))
    wd = window_dependence(lt, sec, est, t_mins=[c / k.kappa for c in cs], windows=[tuple(p.window)],
                           columns=["x", "y"])  # fmt: skip
    rec["d1_by_t_min"] = [{"t_min_kappa": c, "n_orbits": int(r.n_orbits), "n_points": int(r.n_points), "note": r.note,
                           "d1_section": None if math.isnan(r.value) else Measured.of(r.value, r.err, n=int(r.n_orbits)).to_dict()}
                          for c, r in zip(cs, wd.itertuples())]  # fmt: skip
    rec["d1_by_t_min"], trend = rec["d1_by_t_min"][: len(p.tmin_checks) + 1], rec["d1_by_t_min"][len(p.tmin_checks) :]
    rec["d1_trend_by_t_min"] = trend
    try:
        sp = saddle_points(lt, sec, t_min=t_min, window=tuple(p.window), columns=["x", "y", "px", "py"])
        d = est(sp)
    except ConfigError as exc:
        rec["notes"].append(sr.d1_refusal_words(f"d1: {exc}"))
        return rec, ftle
    # d₁ does not depend on λ̄: measured at every point with section points, the relation only where λ̄ is
    rec.update({"d1": 0.5 * float(d.value), "d1_err": 0.5 * float(d.err), "d1_section": d.value, "d1_section_err": d.err,
                "d1_eps_range": list(d.eps_range), "d1_n_orbits": sp.n_orbits, "d1_n_points": sp.n_points})  # fmt: skip
    rec.update(sr.d1_error_record(d, _extent(sp), p.d1_floor * _extent(sp)))
    scan = neighbour_floor_scan(**_d1_args(sp, p), floor=p.d1_floor, factors=p.d1_floor_factors)
    lam_v = lam["value"]
    rec["d1_floor_scan"] = sr.floor_scan_record(
        scan, None if lam_v is None else math.exp(-lam_v * sp.window[0] * sp.t_min)
    )
    rec.update(_d1_radius(sp, d, p))
    rec.update(sr.sheets_record(sp.points, model.force, floor=p.d1_floor, k_max=p.k_max, n_boot=p.n_boot,
                                min_boxes=p.min_boxes))  # fmt: skip
    rec.update(sr.hyperbolic_record(sr.long_lived(tangent, ch["t_min"]), sp.points, lambda pts: est(replace(sp, points=pts)), d, p.ftle_low, n_boot=p.n_boot))  # fmt: skip
    if lam_v is None:  # no λ̄: the record's note says why
        return rec, ftle
    try:
        kg = kantz_grassberger(k.kappa, k.kappa_err, lam_v, lam["err"], d.value, d.err, dimension="section")
    except ConfigError as exc:
        rec["notes"].append(f"relation: {exc}")
        return rec, ftle
    rec.update({"predicted": kg.predicted, "predicted_err": kg.predicted_err, "d1_implied": kg.d1_implied,
                "d1_implied_err": kg.d1_implied_err, "z": kg.z, "verdict": kg.verdict,
                "d1_section_implied": 2 * kg.d1_implied, "d1_section_implied_err": 2 * kg.d1_implied_err})  # fmt: skip
    return rec, ftle


def analyze(study):
    """analyze(study) -> None; writes saddle.json and saddle_ftle.parquet."""
    import pandas as pd

    _d0_eps(study), _tmin_overrides(study)  # refused before any work (the lines rules with them)
    if not 0 < study.params.d1_floor < 1 / study.params.min_boxes:
        raise ConfigError(f"saddle [study].d1_floor must lie in (0, 1/min_boxes), got {study.params.d1_floor!r}")
    choices = json.loads(_choices_path(study).read_text())
    records, ftles = [], []
    for label, _spec, _m, ratios, _t_max in _systems(study):
        for r in ratios:
            key = point_key(label, r)
            rec, ftle = _point(study, key, choices[key])
            records.append(sr.with_gap(sr.with_d0(rec, _d0(study, key))))
            if ftle is not None:
                ftles.append(ftle[["traj_id", "t_end", "ftle"]].assign(system=label, ratio=r))
    scales = [sr.scales_row(x) for x in records]
    cols = ["traj_id", "t_end", "ftle", "system", "ratio"]
    study.write_table(
        pd.concat(ftles, ignore_index=True) if ftles else pd.DataFrame(columns=cols),
        FTLE_TABLE,
        description="finite-time Lyapunov exponents Λ/t_end of the tangent runs (orbits left at t_end ≥ t_min)",
    )
    study.write_numbers(
        {
            "saddle": records,
            "relation": [sr.relation_row(x) for x in records],
            "summary": sr.relation_summary(records),
            "dimensions": [sr.dimension_row(x) for x in records],
            "dimensions_summary": sr.dimension_summary(records),
            "d1_precision": sr.d1_precision(records),
            "lines": [sr.lines_row(x) for x in records],
            "lines_summary": sr.lines_summary(records),
            "scales": scales,
            "scales_summary": sr.scales_summary(scales),
            "gap": [sr.gap_row(x) for x in records],
            "gap_summary": sr.gap_summary(records),
            "rules": {
                "tmin_efolds": study.params.tmin_efolds,
                **_tmin_overrides(study),
                "window": list(study.params.window),
                "tmin_checks": list(study.params.tmin_checks),
                "tmin_trend": list(study.params.tmin_trend),
                "ftle_low": list(study.params.ftle_low),
                "d1_floor": study.params.d1_floor,
                "d1_floor_factors": list(study.params.d1_floor_factors),
                "n_orbits_per_point": study.params.n,
                "d0_eps": [float(e) for e in _d0_eps(study)],
                "d0_n": study.params.d0_n,
                "d0_min_count": study.params.d0_min_count,
                "lines_count": study.params.lines_count,
                "lines_n": study.params.lines_n,
                "lines_efolds": study.params.lines_efolds,
                "lines_checks": list(study.params.lines_checks),
                "lines_floor": study.params.lines_floor,
            },  # fmt: skip
        }
    )


plot = figure_stage("plot_saddle", NUMBERS, PATH)
