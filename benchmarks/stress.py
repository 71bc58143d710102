"""Numerical stress tests of the engine (``make stress``).

Each case is a function that takes its size as arguments, runs the engine
(:func:`hhscatter.integrate.engine.run_chunk` or :func:`hhscatter.run.runner.simulate`)
and an independent reference (heyoka long double, :mod:`.reference`), and
returns a :class:`CaseResult` (table rows, a one-line finding, and ``ok``:
whether the case's acceptance rule holds). ``tests/bench/test_stress.py`` calls the
same functions at small size; ``python -m benchmarks.stress`` runs them at
the sizes of ``benchmarks/stress.toml`` and writes CSVs, a PNG and
``summary.md`` under ``benchmarks/out/stress/<scale>/``.

Cases:
  energy_drift        orbits censored at t = 5000 (E = 0.2) to t = 5000 and 5e4 per tolerance:
                      relative energy error vs t and its growth exponent.
  near_threshold      E − E_c ∈ {1e-2, 1e-3, 1e-4}: valid outcomes, energy at escape,
                      escape times vs the reference, cost per orbit bounded by t_max.
  saddle_starts       orbits started next to the saddles: escape times vs the reference.
  tangent_resc        orbits built to touch r = r_esc tangentially (gap ε, both signs):
                      escape events missed or spurious vs the reference.
  section_skim        orbits built to skim the section ṙ = 0 (near double roots):
                      section crossings missed or duplicated vs the reference.
  dissipation_extremes γ ∈ {1e-5, 1e-1, 1} and r_far up to 1e8 (finite-time blow-up of
                      escaping orbits): no NaN/inf in any table, outcomes vs the reference.
  statistics          P(t) at tol 1e-12 vs 1e-15 on the same ICs: two-sample KS, κ.
  cmeasure_distance   the fig5 section point set at tol 1e-12 vs 1e-15: sliced Wasserstein
                      distance against the split-half noise.
"""

from __future__ import annotations

import argparse
import functools
import math
import tempfile
import time
from dataclasses import dataclass, field

import numpy as np

from benchmarks.config import load_config, machine_note, out_dir
from benchmarks.plots import plot_energy_drift
from benchmarks.reference import reference_orbits
from hhscatter.data.read import read_lifetimes, read_sections, read_snapshots
from hhscatter.integrate.engine import (
    CENSORED,
    ESCAPED,
    SETTLED,
    run_chunk,
    simulate_orbit,
    state_at,
)
from hhscatter.model import HenonHeiles
from hhscatter.run.runner import simulate
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene, SectionWindow

MODEL = HenonHeiles()
E_C = MODEL.critical_energy


@dataclass
class CaseResult:
    """Outcome of one stress case: ``rows`` (list of dicts), ``finding`` (one line), ``ok`` (acceptance rule holds)."""

    name: str
    rows: list
    finding: str
    ok: bool
    extra: dict = field(default_factory=dict)


def _energy(s):
    s = np.asarray(s, dtype=float)
    return MODEL.energy(s[..., 0], s[..., 1], s[..., 2], s[..., 3])


def _run(
    ics,
    *,
    tol,
    energy=None,
    gamma=0.0,
    t_max=5000.0,
    r_esc=1.03,
    r_far=None,
    sections=None,
    snapshots=None,
    batch_size=4,
):
    ics = np.ascontiguousarray(ics, dtype=float)
    if energy is None:
        energy = float(_energy(ics[0]))
    sc = Scene(
        energy=max(energy, E_C + 1e-12),
        n=len(ics),
        gamma=gamma,
        tol=tol,
        t_max=t_max,
        r_esc=r_esc,
        r_far=r_far,
        sections=sections,
        snapshots=snapshots,
        batch_size=batch_size,
    )
    return run_chunk(sc, ics, np.arange(len(ics)), batch_size=batch_size)


def _disk_ics(energy, n, seed, gamma=0.0):
    return region_ics(Scene(energy=energy, gamma=gamma, n=n, seed=seed), 0, n)


def backward(state, T):
    """backward(state, T) -> float64 state at time −T (long double, conservative, no events)."""

    return np.asarray(state_at(Scene(energy=0.3, n=1), state, -T, fp_type=np.longdouble), dtype=float)


# -- long integrations ----------------------------------------------------------


def kam_trapped_ics(energy=0.2, n_want=8, n_try=600, seed=4, t_sel=5000.0):
    """kam_trapped_ics(E, n_want, n_try, seed, t_sel) -> (n ≤ n_want, 4) ICs still inside at t_sel.

    ICs uniform in the saddle triangle ('well'); at E = 0.2 the orbits still
    inside at t = 5000 are censored there (the paper's non-hyperbolic regime):
    not classified, regular orbits on KAM tori and sticky chaotic ones alike.
    The selection is memoised per process (the 5000 and 5e4 cases share it).
    """
    return _kam_trapped(float(energy), int(n_want), int(n_try), int(seed), float(t_sel)).copy()


@functools.lru_cache(maxsize=8)
def _kam_trapped(energy, n_want, n_try, seed, t_sel):
    ics = region_ics(Scene(energy=energy, n=n_try, seed=seed, region="well"), 0, n_try)
    res = _run(ics, tol=1e-15, energy=energy, t_max=t_sel)
    keep = np.flatnonzero(res.lifetimes["outcome"] == CENSORED)[:n_want]
    return ics[keep]


def case_energy_drift(
    energy=0.2,
    n_orbits=8,
    tols=(1e-9, 1e-12, 1e-15),
    t_max=5000.0,
    n_times=12,
    seed=4,
    n_try=600,
    t_sel=5000.0,
    limit_1e15=1e-12,
):
    """case_energy_drift(...) -> CaseResult: |H(t) − H(0)|/H(0) of orbits censored at t_sel at log-spaced t ≤ t_max.

    Energies before t_max are the engine's snapshots (dense output at the
    snapshot times); at t_max the energy of the censored end state. Orbits
    that leave before t_max (chaotic, not regular) drop out of the later rows
    (column n). Acceptance: at tol 1e-15 the maximum error at t_max stays
    below ``limit_1e15`` and every selected orbit is still inside at t_sel.
    Growth exponent: slope of log(max error) vs log t for t ≥ 10.
    """
    ics = kam_trapped_ics(energy, n_orbits, n_try=n_try, seed=seed, t_sel=t_sel)
    grid = np.geomspace(1.0, t_max, n_times)
    times = tuple(float(t) for t in np.unique(np.round(grid[:-1], 6)))
    e0 = _energy(ics)
    rows = []
    slopes = {}
    for tol in tols:
        t0 = time.perf_counter()
        res = _run(ics, tol=tol, energy=energy, t_max=t_max, snapshots=times)
        wall = time.perf_counter() - t0
        sn, lt = res.snapshots, res.lifetimes
        cens = lt["outcome"] == CENSORED
        ts = np.concatenate([sn["t"], np.full(cens.sum(), t_max)])
        ids = np.concatenate([sn["traj_id"], lt["traj_id"][cens]])
        es = np.concatenate([sn["energy"], lt["e_end"][cens]])
        err = np.abs(es - e0[ids]) / e0[ids]
        for t in times + (t_max,):
            m = ts == t
            if not m.any():
                continue
            rows.append(
                {
                    "tol": tol,
                    "t": t,
                    "n": int(m.sum()),
                    "max_rel_energy_err": float(err[m].max()),
                    "median_rel_energy_err": float(np.median(err[m])),
                    "wall_s": wall,
                }
            )
        tt = np.array([r["t"] for r in rows if r["tol"] == tol])
        mx = np.array([r["max_rel_energy_err"] for r in rows if r["tol"] == tol])
        sel = (tt >= 10) & (mx > 0)
        slopes[tol] = float(np.polyfit(np.log(tt[sel]), np.log(mx[sel]), 1)[0]) if sel.sum() >= 2 else math.nan
    last = {r["tol"]: r for r in rows if r["t"] == t_max}
    ok = len(ics) > 0 and 1e-15 in last and last[1e-15]["max_rel_energy_err"] < limit_1e15
    finding = (
        f"{len(ics)} censored orbits (E={energy}, inside at t={t_sel:g}) to t={t_max:g}: max |ΔH|/H at "
        "t_max = "
        + ", ".join(
            f"{last[t]['max_rel_energy_err']:.1e} (tol {t:g}, {last[t]['n']} orbits, growth ∝ t^{slopes[t]:.2f})"
            for t in tols
            if t in last
        )
    )
    return CaseResult("energy_drift", rows, finding, ok, {"slopes": slopes, "n_orbits": len(ics)})


# -- near threshold ------------------------------------------------------------


def case_near_threshold(
    deltas=(1e-2, 1e-3, 1e-4), n=200, t_max=5000.0, n_ref=20, t_ref=200.0, t_short=50.0, seed=4, tol=1e-15
):
    """case_near_threshold(...) -> CaseResult for E = E_c + δ.

    Acceptance: outcomes are escaped or censored, t_end ∈ (0, t_max], energies
    at escape within 1e-12 of H(0), the escape times of the first ``n_ref``
    orbits agree with the long-double reference (run to ``t_ref``) within 1e-6
    relative where the reference escapes before ``t_short`` (little chaotic
    amplification). The cost is reported as steps per unit of orbit time
    (bounded: the run time is at most t_max × that rate per orbit).
    """
    rows = []
    ok = True
    for d in deltas:
        E = E_C + d
        ics = _disk_ics(E, n, seed)
        t0 = time.perf_counter()
        res = _run(ics, tol=tol, energy=E, t_max=t_max)
        wall = time.perf_counter() - t0
        lt = res.lifetimes
        oc, te = lt["outcome"], lt["t_end"]
        esc = oc == ESCAPED
        e_err = np.abs(lt["e_end"][esc] - lt["e0"][esc]) / lt["e0"][esc]
        valid = bool(
            np.isin(oc, (ESCAPED, CENSORED)).all()
            and np.isfinite(te).all()
            and (te > 0).all()
            and (te <= t_max).all()
            and np.isfinite(lt["e_end"]).all()
        )
        ref = reference_orbits(ics[:n_ref], t_max=t_ref)
        sub = _run(ics[:n_ref], tol=tol, energy=E, t_max=t_ref).lifetimes
        short = (ref["outcome"] == ESCAPED) & (ref["t_end"] <= t_short)
        agree = (sub["outcome"] == ref["outcome"]) & (
            (ref["outcome"] != ESCAPED) | (np.abs(sub["t_end"] - ref["t_end"]) <= 1e-6 * ref["t_end"])
        )
        # cost: steps per unit orbit time is bounded; a censored orbit is the most expensive one
        us = 1e6 * wall / n
        row = {
            "delta": d,
            "energy": E,
            "n": n,
            "escaped": int(esc.sum()),
            "censored": int((oc == CENSORED).sum()),
            "median_t_end": float(np.median(te)),
            "max_energy_err_at_escape": float(e_err.max()) if esc.any() else 0.0,
            "valid": valid,
            "ref_n": n_ref,
            "ref_short_escapes": int(short.sum()),
            "ref_agree_short": int(agree[short].sum()),
            "ref_agree_all_t_le_t_ref": int(agree.sum()),
            "us_per_orbit": us,
            "steps_per_orbit": res.n_steps / n,
            "steps_per_unit_time": res.n_steps / float(te.sum()),
        }
        rows.append(row)
        ok &= valid and row["max_energy_err_at_escape"] < 1e-12 and bool(agree[short].all())
    finding = "; ".join(
        f"δ={r['delta']:g}: {r['escaped']}/{r['n']} escaped, median t_end {r['median_t_end']:.0f}, "
        f"max |ΔH|/H at escape {r['max_energy_err_at_escape']:.1e}, short escapes matching ref "
        f"{r['ref_agree_short']}/{r['ref_short_escapes']}, outcome and t_end (1e-6) as the reference to "
        f"t={t_ref:g} for {r['ref_agree_all_t_le_t_ref']}/{r['ref_n']}, "
        f"{r['steps_per_unit_time']:.2f} steps per unit time"
        for r in rows
    )
    return CaseResult("near_threshold", rows, finding, ok)


# -- grazing events ------------------------------------------------------------


def _classify(t_eng, o_eng, t_ref, o_ref, rtol=1e-6):
    """(agree, missed, spurious) per orbit: missed = engine ends later than the reference (or not at all)."""
    both = (o_eng == ESCAPED) & (o_ref == ESCAPED)
    close = both & (np.abs(t_eng - t_ref) <= rtol * np.maximum(t_ref, 1e-300))
    agree = close | ((o_eng != ESCAPED) & (o_ref != ESCAPED))
    eng_t = np.where(o_eng == ESCAPED, t_eng, np.inf)
    ref_t = np.where(o_ref == ESCAPED, t_ref, np.inf)
    missed = ~agree & (eng_t > ref_t)
    spurious = ~agree & (eng_t < ref_t)
    return agree, missed, spurious


def saddle_start_ics(offsets=(0.0, 1e-8, 1e-4, 1e-2), n_dir=8, energy=0.27):
    """saddle_start_ics(offsets, n_dir, E) -> (ics, offset per ic): at distance ``offset`` inward of each saddle.

    Velocities point in ``n_dir`` directions evenly spread over the circle,
    speed fixed by E. Offset 0 is exactly at the saddle (outside r < r_esc only
    by the saddle distance 1).
    """
    ics, offs = [], []
    for k, (sx, sy) in enumerate(MODEL.saddles):
        for off in offsets:
            x, y = sx * (1 - off), sy * (1 - off)
            v = math.sqrt(2 * (energy - float(MODEL.potential(x, y))))
            for j in range(n_dir):
                a = 2 * math.pi * (j + 0.5 * k / 3) / n_dir
                ics.append((x, y, v * math.cos(a), v * math.sin(a)))
                offs.append(off)
    return np.array(ics), np.array(offs)


def case_saddle_starts(offsets=(0.0, 1e-8, 1e-4, 1e-2), n_dir=8, tols=(1e-9, 1e-12, 1e-15), t_max=20.0):
    """case_saddle_starts(...) -> CaseResult: escape events of orbits started at the saddles vs the reference.

    t_max = 20 keeps chaotic amplification below the tolerance effects.
    Acceptance at tol 1e-15: no missed or spurious escape.
    """
    ics, offs = saddle_start_ics(offsets, n_dir)
    ref = reference_orbits(ics, t_max=t_max)
    rows, ok = [], True
    for tol in tols:
        lt = _run(ics, tol=tol, t_max=t_max).lifetimes
        agree, missed, spur = _classify(lt["t_end"], lt["outcome"], ref["t_end"], ref["outcome"])
        for off in offsets:
            m = offs == off
            rows.append(
                {
                    "tol": tol,
                    "offset": off,
                    "n": int(m.sum()),
                    "ref_escaped": int((ref["outcome"][m] == 0).sum()),
                    "agree": int(agree[m].sum()),
                    "missed": int(missed[m].sum()),
                    "spurious": int(spur[m].sum()),
                }
            )
        if tol == min(tols):
            ok = not (missed.any() or spur.any())
    bad = {t: sum(r["missed"] + r["spurious"] for r in rows if r["tol"] == t) for t in tols}
    finding = f"{len(ics)} saddle starts: disagreements with the reference " + ", ".join(
        f"{bad[t]} at tol {t:g}" for t in tols
    )
    return CaseResult("saddle_starts", rows, finding, ok)


def _tangent_points(energy=0.27, r_t=1.03, rdd=-0.02):
    """Points on r = r_t with tangential velocity (ṙ = 0) and r̈ = rdd < 0 at energy E: (x, y, px, py) list.

    In polar form V = r²/2 + r³ sin(3φ)/3; r̈ = v²/r − ∂V/∂r with v² = 2(E − V).
    φ is solved on both sides of each channel axis; both senses of rotation.
    """
    from scipy.optimize import brentq  # deferred: scipy loads on first use

    def rddot(phi):
        V = r_t**2 / 2 + r_t**3 * math.sin(3 * phi) / 3
        return 2 * (energy - V) / r_t - (r_t + r_t**2 * math.sin(3 * phi)) - rdd

    pts = []
    for axis in MODEL.channel_angles:
        for side in (-1, 1):
            # r̈ decreases away from the axis until V reaches E; bracket inside the allowed arc
            def f(u, axis=axis, side=side):
                return rddot(axis + side * u)

            us = np.linspace(0.0, 0.5, 2001)
            vals = [
                f(u) if 2 * (energy - (r_t**2 / 2 + r_t**3 * math.sin(3 * (axis + side * u)) / 3)) > 0 else np.nan
                for u in us
            ]
            j = next((i for i in range(len(us) - 1) if vals[i] > 0 > vals[i + 1]), None)
            if j is None:
                continue
            u = brentq(f, us[j], us[j + 1], xtol=1e-15)
            phi = axis + side * u
            V = r_t**2 / 2 + r_t**3 * math.sin(3 * phi) / 3
            v = math.sqrt(2 * (energy - V))
            x, y = r_t * math.cos(phi), r_t * math.sin(phi)
            for sense in (-1, 1):
                pts.append((x, y, -sense * v * math.sin(phi), sense * v * math.cos(phi)))
    return pts


def case_tangent_resc(
    gaps=(1e-4, 1e-6, 1e-9, 1e-12, 1e-14, -1e-14, -1e-12, -1e-9, -1e-6, -1e-4),
    tols=(1e-9, 1e-12, 1e-15),
    T=0.3,
    r_esc=1.03,
):
    """case_tangent_resc(...) -> CaseResult: orbits whose r(t) has a maximum r_esc − gap at t = T.

    gap > 0: the orbit touches r = r_esc − gap from inside (no escape there);
    gap < 0: it pokes out by |gap| (escape at the first crossing, shortly before T).
    ICs: the tangent state integrated back by T in long double. Orbits are
    followed to T + 0.5. Acceptance at tol 1e-15: no missed/spurious escape for
    |gap| ≥ 1e-9 (smaller gaps are reported only: the state error of a double
    integration is ~1e-15 and the crossing lasts ~√(|gap|/|r̈|)).
    """
    ics, gs = [], []
    for g in gaps:
        for p in _tangent_points(r_t=r_esc - g):
            ics.append(backward(p, T))
            gs.append(g)
    ics, gs = np.array(ics), np.array(gs)
    ref = reference_orbits(ics, t_max=T + 0.5, r_esc=r_esc)
    rows, ok = [], True
    for tol in tols:
        lt = _run(ics, tol=tol, t_max=T + 0.5, r_esc=r_esc).lifetimes
        agree, missed, spur = _classify(lt["t_end"], lt["outcome"], ref["t_end"], ref["outcome"])
        for g in gaps:
            m = gs == g
            rows.append(
                {
                    "tol": tol,
                    "gap": g,
                    "n": int(m.sum()),
                    "ref_escaped": int((ref["outcome"][m] == 0).sum()),
                    "agree": int(agree[m].sum()),
                    "missed": int(missed[m].sum()),
                    "spurious": int(spur[m].sum()),
                }
            )
        if tol == min(tols):
            big = np.abs(gs) >= 1e-9
            ok = not (missed[big].any() or spur[big].any())
    finding = "tangent to r_esc: " + "; ".join(
        f"tol {t:g}: missed {sum(r['missed'] for r in rows if r['tol'] == t)}, spurious "
        f"{sum(r['spurious'] for r in rows if r['tol'] == t)} of {len(ics)}"
        for t in tols
    )
    return CaseResult("tangent_resc", rows, finding, ok)


def _skim_points(etas, radii=(0.45, 0.6, 0.75), n_phi=4):
    """States with ṙ = η/r·… : tangential speed v² = r ∂V/∂r (so d(x px + y py)/dt = 0 at η = 0) plus radial η."""
    pts, es = [], []
    for r in radii:
        for j in range(n_phi):
            phi = 2 * math.pi * (j + 0.25) / n_phi
            dVdr = r + r**2 * math.sin(3 * phi)
            if dVdr <= 0:
                continue
            v = math.sqrt(r * dVdr)
            x, y = r * math.cos(phi), r * math.sin(phi)
            for eta in etas:
                px = -v * math.sin(phi) + eta * math.cos(phi)
                py = v * math.cos(phi) + eta * math.sin(phi)
                if _energy((x, y, px, py)) <= E_C:
                    continue
                pts.append((x, y, px, py))
                es.append(eta)
    return pts, es


def reference_section_times(ic, t_max, r_esc=1.03):
    """reference_section_times(ic, t_max) -> array of times of all crossings ṙ = 0 with φ̇ > 0.

    The engine's scalar driver in long double (tolerance its epsilon, ~1e-19),
    with every crossing recorded (no window).
    """
    sc = Scene(energy=0.3, n=1, r_esc=r_esc, t_max=t_max, sections=SectionWindow())
    res = simulate_orbit(sc, ic, fp_type=np.longdouble)
    return np.array([float(r[0]) for r in res.sections])


def case_section_skim(
    etas=(1e-2, 1e-5, 1e-8, 1e-11, 1e-13, -1e-13, -1e-11, -1e-8, -1e-5, -1e-2),
    tols=(1e-9, 1e-12, 1e-15),
    T=1.0,
    window=0.3,
    match=1e-7,
):
    """case_section_skim(...) -> CaseResult: near double roots of x px + y py = 0 at t = T.

    At t = T the orbit has ṙ ≈ η and d(r ṙ)/dt ≈ η²: two crossings a time
    ~√|η| apart or none, depending on the sign of η and of the curvature.
    Counts the section crossings (φ̇ > 0) in [T − window, T + window] and over
    the whole run [0, T + 1] against the long-double reference (a crossing
    matches if their times differ by ≤ ``match``; near a double root the
    crossing time is ill-conditioned, δt ~ δg/ġ with ġ ~ √|η|).
    Acceptance at tol 1e-15: no missed/duplicated crossing for |η| ≥ 1e-8.
    """
    pts, es = _skim_points(etas)
    ics = np.array([backward(p, T) for p in pts])
    es = np.array(es)
    ref = [reference_section_times(ic, T + 1.0) for ic in ics]
    rows, ok = [], True
    for tol in tols:
        res = _run(ics, tol=tol, t_max=T + 1.0, sections=SectionWindow())
        sec = res.sections
        missed = np.zeros(len(ics), int)
        dup = np.zeros(len(ics), int)
        for i in range(len(ics)):
            te = np.sort(sec["t"][sec["traj_id"] == i])
            tr = ref[i]
            ne, nr = (np.abs(te - T) <= window).sum(), (np.abs(tr - T) <= window).sum()
            # all crossings of the run, matched in time within 1e-6
            unmatched_ref = sum(not np.any(np.abs(te - t) <= match) for t in tr)
            unmatched_eng = sum(not np.any(np.abs(tr - t) <= match) for t in te)
            missed[i] = max(nr - ne, unmatched_ref, 0)
            dup[i] = max(ne - nr, unmatched_eng, 0)
        for eta in etas:
            m = es == eta
            rows.append(
                {
                    "tol": tol,
                    "eta": eta,
                    "n": int(m.sum()),
                    "ref_crossings_near_T": int(sum((np.abs(ref[i] - T) <= window).sum() for i in np.flatnonzero(m))),
                    "missed": int(missed[m].sum()),
                    "duplicated": int(dup[m].sum()),
                }
            )
        if tol == min(tols):
            big = np.abs(es) >= 1e-8
            ok = not (missed[big].any() or dup[big].any())
    finding = "skimming the section: " + "; ".join(
        f"tol {t:g}: missed {sum(r['missed'] for r in rows if r['tol'] == t)}, duplicated "
        f"{sum(r['duplicated'] for r in rows if r['tol'] == t)} ({len(ics)} orbits)"
        for t in tols
    )
    return CaseResult("section_skim", rows, finding, ok)


# -- dissipation extremes ------------------------------------------------------


def case_dissipation_extremes(
    gammas=(1e-5, 1e-1, 1.0),
    n=500,
    r_fars=(None, 1e3, 1e8),
    r_far_gamma=1e-1,
    n_ref=20,
    t_max=5000.0,
    seed=6,
    tol=1e-15,
):
    """case_dissipation_extremes(...) -> CaseResult: runs through :func:`hhscatter.run.runner.simulate` and its Parquet tables.

    Acceptance: every float column of every table is finite; outcomes valid;
    settled orbits end at H = E_c within 1e-12; escaped orbits have
    H_end ≤ H_0; the first ``n_ref`` orbits match the long-double reference
    (outcome, and t_end within 1e-6 relative for t_ref ≤ 20). The r_far sweep
    (at γ = r_far_gamma) follows escaping orbits towards their finite-time
    blow-up before they are stopped.
    """

    cases = [(g, None) for g in gammas] + [(r_far_gamma, rf) for rf in r_fars if rf is not None]
    rows, ok = [], True
    for g, rf in cases:
        sc = Scene(
            energy=0.3,
            gamma=g,
            n=n,
            seed=seed,
            tol=tol,
            t_max=t_max,
            r_far=rf,
            chunk_size=max(n // 2, 1),
            sections=SectionWindow(t_from=1.0),
            snapshots=(0.0, 1.0, 10.0, 100.0),
        )
        err = None
        with tempfile.TemporaryDirectory() as d:
            t0 = time.perf_counter()
            try:
                simulate(sc, d, workers=1, progress=False, overwrite=True)
            except Exception as exc:  # noqa: BLE001 - reported as the finding
                err = f"{type(exc).__name__}: {exc}"
            wall = time.perf_counter() - t0
            if err is None:
                lt = read_lifetimes(d)
                tabs = {"lifetimes": lt, "sections": read_sections(d), "snapshots": read_snapshots(d)}
        if err is not None:
            rows.append({"gamma": g, "r_far": rf, "error": err})
            ok = False
            continue
        nonfinite = {
            k: int(sum((~np.isfinite(v[c].to_numpy(dtype=float))).sum() for c in v.columns if v[c].dtype.kind == "f"))
            for k, v in tabs.items()
        }
        oc = lt["outcome"].to_numpy()
        e0, ee = lt["e0"].to_numpy(), lt["e_end"].to_numpy()
        settled, esc = oc == "settled", oc == "escaped"
        s_err = float(np.abs(ee[settled] - E_C).max()) if settled.any() else 0.0
        rise = float((ee[esc] - e0[esc]).max()) if esc.any() else math.nan
        ids = lt["traj_id"].to_numpy()
        order = np.argsort(ids)[:n_ref]

        # the reference stops at the default r_far: an escaped orbit never returns, so the
        # outcome and the escape time (last outward r_esc crossing) do not depend on r_far
        ref = reference_orbits(region_ics(sc, 0, n_ref), gamma=g, t_max=t_max, r_esc=sc.r_esc)
        code = {"escaped": ESCAPED, "settled": SETTLED, "censored": CENSORED}
        o_eng = np.array([code[o] for o in oc[order]])
        t_eng = lt["t_end"].to_numpy()[order]
        same = o_eng == ref["outcome"]
        short = same & (ref["t_end"] <= 20) & (ref["outcome"] != CENSORED)
        t_ok = np.abs(t_eng[short] - ref["t_end"][short]) <= 1e-6 * ref["t_end"][short]
        row = {
            "gamma": g,
            "r_far": rf if rf is not None else "default",
            "n": n,
            "escaped": int(esc.sum()),
            "settled": int(settled.sum()),
            "censored": int((oc == "censored").sum()),
            "nonfinite_values": sum(nonfinite.values()),
            "settled_energy_err": s_err,
            "max_energy_rise_escaped": rise,
            "ref_outcome_agree": int(same.sum()),
            "ref_n": n_ref,
            "ref_short_t_agree": int(t_ok.sum()),
            "ref_short": int(short.sum()),
            "wall_s": wall,
            "error": "",
        }
        rows.append(row)
        ok &= (
            row["nonfinite_values"] == 0
            and s_err < 1e-12
            and not rise > 1e-12
            and bool(t_ok.all())
            and row["ref_outcome_agree"] >= n_ref - 1
        )
    finding = "; ".join(
        (
            f"γ={r['gamma']:g}, r_far={r['r_far']}: "
            + (
                r["error"]
                or f"{r['escaped']} esc / {r['settled']} settled / {r['censored']} cens, non-finite {r['nonfinite_values']}, "
                f"ref outcomes {r['ref_outcome_agree']}/{r['ref_n']}"
            )
        )
        for r in rows
    )
    return CaseResult("dissipation_extremes", rows, finding, ok)


# -- statistical stability -----------------------------------------------------


def case_statistics(n=20000, tols=(1e-12, 1e-15), seed=7, cons_window=(5.0, 30.0), n_diss=5000, diss_gamma=0.01):
    """case_statistics(...) -> CaseResult: P(t) at two tolerances on the same ICs.

    Conservative E = 0.27: two-sample KS test of the escape times, κ by
    maximum likelihood (:func:`hhscatter.analysis.survival.escape_rate.escape_rate_mle`)
    on ``cons_window``, and the fraction of orbits whose t_end differ by more
    than 1e-6 relative. Dissipative E0 = 0.3, γ = 0.01: KS of t_end and the
    fraction of outcomes that differ. Acceptance: KS p > 0.01 and
    |Δκ| < κ_err (the statistical error of one run).
    """
    from scipy.stats import ks_2samp  # deferred: scipy loads on first use

    from hhscatter.analysis.survival.escape_rate import escape_rate_mle  # deferred: scipy loads on first use

    rows, ok = [], True
    for kind, E, g, nn in (("conservative", 0.27, 0.0, n), ("dissipative", 0.3, diss_gamma, n_diss)):
        ics = _disk_ics(E, nn, seed, g)
        lts = [_run(ics, tol=t, energy=E, gamma=g, batch_size=4).lifetimes for t in tols]
        a, b = lts
        ks = ks_2samp(a["t_end"], b["t_end"], method="asymp")
        rel = np.abs(a["t_end"] - b["t_end"]) / b["t_end"]
        row = {
            "scene": kind,
            "n": nn,
            "tol_a": tols[0],
            "tol_b": tols[1],
            "ks_stat": float(ks.statistic),
            "ks_p": float(ks.pvalue),
            "outcome_differs": int((a["outcome"] != b["outcome"]).sum()),
            "frac_t_differs_1e-6": float(np.mean(rel > 1e-6)),
        }
        if g == 0:
            ka, kb = (escape_rate_mle(x["t_end"], x["outcome"] == ESCAPED, *cons_window) for x in lts)
            row.update(
                {"kappa_a": ka.kappa, "kappa_b": kb.kappa, "kappa_err": kb.kappa_err, "dkappa": ka.kappa - kb.kappa}
            )
            ok &= abs(row["dkappa"]) < kb.kappa_err
        ok &= row["ks_p"] > 0.01
        rows.append(row)
    c = rows[0]
    finding = (
        f"tol 1e-12 vs 1e-15, same ICs: conservative KS p = {c['ks_p']:.3f}, κ = {c['kappa_a']:.5f} vs "
        f"{c['kappa_b']:.5f} ± {c['kappa_err']:.5f}, {100 * c['frac_t_differs_1e-6']:.1f}% of t_end differ > 1e-6; "
        f"dissipative KS p = {rows[1]['ks_p']:.3f}"
    )
    return CaseResult("statistics", rows, finding, ok)


def case_cmeasure_distance(
    n=100000, tols=(1e-12, 1e-15), energy=0.35, gamma=0.01, t_star=17.0, seed=8, n_proj=64, n_splits=4
):
    """case_cmeasure_distance(...) -> CaseResult: Fig. 5a point sets at two tolerances (same ICs).

    The dissipative ensemble of study fig5 (E2 = 0.35, γ = 0.01): position of
    each survivor's first section crossing after t* ≈ 17 (paper). The sliced
    Wasserstein distance (:func:`hhscatter.analysis.geometry.distance.sliced_wasserstein`)
    between the sets at tol 1e-12 and 1e-15 is compared with the split-half
    noise of the 1e-15 set (mean over ``n_splits`` random halves). Acceptance:
    distance between tolerances < split-half noise.
    """
    from hhscatter.analysis.geometry.distance import sliced_wasserstein  # deferred: pandas, pyarrow load on first use

    ics = _disk_ics(energy, n, seed, gamma)
    sets, ids = [], []
    for tol in tols:
        res = _run(ics, tol=tol, energy=energy, gamma=gamma, sections=SectionWindow(t_from=t_star, first_only=True))
        sec = res.sections
        sets.append(np.column_stack([sec["x"], sec["y"]]))
        ids.append(sec["traj_id"])
    d = sliced_wasserstein(sets[0], sets[1], n_proj=n_proj)
    rng = np.random.default_rng(seed)
    P = sets[1]
    noise = []
    for _ in range(n_splits):
        perm = rng.permutation(len(P))
        noise.append(sliced_wasserstein(P[perm[: len(P) // 2]], P[perm[len(P) // 2 :]], n_proj=n_proj))
    same_ids = len(np.intersect1d(ids[0], ids[1]))
    row = {
        "n": n,
        "points_a": len(sets[0]),
        "points_b": len(sets[1]),
        "common_orbits": same_ids,
        "sw_between_tols": d,
        "sw_split_half_noise": float(np.mean(noise)),
        "t_star": t_star,
    }
    ok = len(P) >= 10 and d < row["sw_split_half_noise"]
    finding = (
        f"Fig. 5a sets (E2={energy}, γ={gamma}, t*={t_star:g}): {len(sets[0])} vs {len(sets[1])} points, "
        f"SW₁ between tol {tols[0]:g} and {tols[1]:g} = {d:.1e} vs split-half noise {np.mean(noise):.1e}"
    )
    return CaseResult("cmeasure_distance", [row], finding, ok)


# -- make stress ---------------------------------------------------------------

CASES = {
    "energy_drift": case_energy_drift,
    "energy_drift_long": case_energy_drift,
    "near_threshold": case_near_threshold,
    "saddle_starts": case_saddle_starts,
    "tangent_resc": case_tangent_resc,
    "section_skim": case_section_skim,
    "dissipation_extremes": case_dissipation_extremes,
    "statistics": case_statistics,
    "cmeasure_distance": case_cmeasure_distance,
}


def _kw(d):
    return {k: (tuple(v) if isinstance(v, list) else v) for k, v in d.items()}


def main(argv=None):
    """``python -m benchmarks.stress [--scale full|tiny] [--only CASE ...]``: writes CSVs, PNG, summary.md."""
    import pandas as pd  # deferred: pandas loads on first use

    ap = argparse.ArgumentParser(description="hhscatter numerical stress tests (make stress)")
    ap.add_argument("--scale", default="full")
    ap.add_argument("--root", default=None, help="folder of stress.toml and out/ (default: benchmarks/)")
    ap.add_argument("--only", nargs="*", default=None, help=f"subset of {list(CASES)}")
    a = ap.parse_args(argv)
    cfg = load_config("stress", a.scale, a.root)
    out = out_dir("stress", a.scale, a.root)
    note0 = machine_note()
    results = []
    t_all = time.perf_counter()
    for name, fn in CASES.items():
        if (a.only and name not in a.only) or name not in cfg:
            continue
        print(f"[{name}] …", flush=True)
        t0 = time.perf_counter()
        r = fn(**_kw(cfg[name]))
        r.extra["seconds"] = time.perf_counter() - t0
        r.name = name
        pd.DataFrame(r.rows).to_csv(out / f"{name}.csv", index=False)
        print(f"  {'ok' if r.ok else 'FAIL'} ({r.extra['seconds']:.0f} s): {r.finding}", flush=True)
        results.append(r)
    drift = [n for n in ("energy_drift", "energy_drift_long") if (out / f"{n}.csv").exists()]
    for n in drift:
        plot_energy_drift(out / f"{n}.csv", out / f"{n}.png")
    L = [
        "# Stress tests (`make stress`)",
        "",
        f"Scale `{a.scale}`, config `{cfg['_path']}`. Machine shared with other jobs ({note0} at start; "
        f"{machine_note()} at end); total {time.perf_counter() - t_all:.0f} s.",
        "",
        "| case | verdict | seconds | finding |",
        "|---|---|---|---|",
    ]
    for r in results:
        L.append(f"| {r.name} | {'ok' if r.ok else '**FAIL**'} | {r.extra['seconds']:.0f} | {r.finding} |")
    L += [
        "",
        "Per-case tables: `<case>.csv` beside this file; energy drift plots: "
        + ", ".join(f"`{n}.png`" for n in drift)
        + ".",
        "",
    ]
    for r in results:
        L += [
            f"## {r.name}",
            "",
            pd.DataFrame(r.rows).to_markdown(index=False)
            if _has_tabulate()
            else pd.DataFrame(r.rows).to_string(index=False),
            "",
        ]
    (out / "summary.md").write_text("\n".join(L))
    print("\n".join(L[: 8 + len(results)]))
    print(f"wrote {out}/summary.md")
    return 0 if all(r.ok for r in results) else 1


def _has_tabulate():
    try:
        import tabulate  # noqa: F401  # deferred: tabulate loads on first use
    except ImportError:
        return False
    return True


if __name__ == "__main__":
    raise SystemExit(main())
