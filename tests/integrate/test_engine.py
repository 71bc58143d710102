"""Accuracy of the batch engine against invariants and an independent
high-precision reference (heyoka's scalar integrator in real128/long double)."""

import heyoka as hy
import numpy as np
import pytest

from hhscatter.integrate.engine import CENSORED, ESCAPED, SETTLED, run_chunk, simulate_orbit, state_at
from hhscatter.model import HenonHeiles, equations
from hhscatter.scene.ics import region_ics, section_velocities
from hhscatter.scene.scene import Scene, SectionWindow

EPS = np.finfo(float).eps


def _run(scene, n=None, **kw):
    n = n or scene.n
    ics = region_ics(scene, 0, n)
    return ics, run_chunk(scene, ics, np.arange(n), **kw)


def test_energy_conserved_below_critical_energy():
    """E = 0.12 < E_c: every orbit is trapped; relative energy error after t = 5000 ≤ 1e-13."""
    m = HenonHeiles()
    rng = np.random.default_rng(1)
    r = 0.3 * np.sqrt(rng.random(8))
    phi = 2 * np.pi * rng.random(8)
    x, y = r * np.cos(phi), r * np.sin(phi)
    px, py = section_velocities(m, x, y, 0.12)
    ics = np.column_stack([x, y, px, py])
    sc = Scene(energy=0.2, n=8, t_max=5000.0)  # escape radius never reached below E_c
    res = run_chunk(sc, ics, np.arange(8))
    lt = res.lifetimes
    assert (lt["outcome"] == CENSORED).all() and (lt["t_end"] == 5000.0).all()
    rel = np.abs(lt["e_end"] - lt["e0"]) / lt["e0"]
    assert rel.max() <= 1e-13, rel.max()


def test_energy_conserved_on_kam_orbits_above_critical_energy():
    """E = 0.2 > E_c: orbits still inside at t = 5000 are KAM-trapped; |ΔE|/E ≤ 1e-13."""
    sc = Scene(energy=0.2, n=600, seed=4, t_max=5000.0, region="well")
    _, res = _run(sc)
    lt = res.lifetimes
    kam = lt["outcome"] == CENSORED
    assert kam.sum() >= 2, "expected some KAM-trapped orbits at E = 0.2"
    rel = np.abs(lt["e_end"][kam] - lt["e0"][kam]) / lt["e0"][kam]
    assert rel.max() <= 1e-13, rel.max()
    # escaped orbits conserve energy up to the escape event as well
    esc = lt["outcome"] == ESCAPED
    assert (np.abs(lt["e_end"][esc] - lt["e0"][esc]) / lt["e0"][esc]).max() <= 1e-13


def test_dissipative_energy_balance():
    """E(t) + γ∫|p|² dt − E0 = 0 along orbits (work integral carried as a 5th state), ≤ 1e-12."""
    m = HenonHeiles()
    gamma = 0.01
    sys = equations(m, hy, hy.par[0])
    x, y, px, py = (v for v, _ in sys)
    w = hy.make_vars("w")
    sys5 = sys + [(w, hy.par[0] * (px**2 + py**2))]
    sc = Scene(energy=0.3, gamma=gamma, n=6, seed=3)
    ics = region_ics(sc, 0, 6)
    for ic in ics:
        ta = hy.taylor_adaptive(sys5, list(ic) + [0.0], pars=[gamma], tol=1e-15)
        grid = np.linspace(0, 60, 61)
        out = ta.propagate_grid(grid)[-1]
        ok = np.isfinite(out).all(axis=1) & (np.hypot(out[:, 0], out[:, 1]) < 1.5)
        e = m.energy(out[ok, 0], out[ok, 1], out[ok, 2], out[ok, 3])
        balance = e + out[ok, 4] - m.energy(*ic)
        assert np.abs(balance).max() <= 1e-12


def test_settling_energy_matches_work_integral():
    """At the engine's settling time E0 − γ∫|p|² = E_c (independent integration), ≤ 1e-12."""
    m = HenonHeiles()
    sc = Scene(energy=0.3, gamma=0.02, n=200, seed=21)
    ics, res = _run(sc)
    lt = res.lifetimes
    settled = np.flatnonzero(lt["outcome"] == SETTLED)
    assert len(settled) >= 2
    sys = equations(m, hy, hy.par[0])
    px, py = sys[2][0], sys[3][0]
    w = hy.make_vars("w")
    for k in settled[:4]:
        ta = hy.taylor_adaptive(sys + [(w, hy.par[0] * (px**2 + py**2))], list(ics[k]) + [0.0], pars=[0.02], tol=1e-15)
        ta.propagate_until(lt["t_end"][k])
        assert abs(m.energy(*ics[k]) - ta.state[4] - m.critical_energy) <= 1e-12
        assert abs(lt["e_end"][k] - m.critical_energy) <= 1e-13
        assert np.hypot(*ta.state[:2]) < 1.0  # settled means inside Ω


@pytest.mark.parametrize("fp_type", [np.longdouble, hy.real128], ids=["longdouble", "real128"])
def test_escape_times_against_high_precision_reference(cons_scene, fp_type):
    ics, res = _run(cons_scene, n=40)
    t = res.lifetimes["t_end"]
    short = np.flatnonzero(t < 12)[: 8 if fp_type is np.longdouble else 3]
    assert len(short) >= 3
    for k in short:
        ref = simulate_orbit(cons_scene, ics[k], fp_type=fp_type)
        assert ref.outcome == ESCAPED
        assert abs(float(ref.t_end) - t[k]) / t[k] <= 1e-10


def test_section_points_against_high_precision_reference():
    sc = Scene(energy=0.27, n=12, seed=2, sections=SectionWindow())
    ics, res = _run(sc)
    sec = res.sections
    x, y, px, py = sec["x"], sec["y"], sec["px"], sec["py"]
    assert len(x) > 10
    assert np.abs(x * px + y * py).max() <= 1e-13  # the event's residual
    assert (x * py - y * px > 0).all()
    for k in range(3):
        mine = sec["t"][sec["traj_id"] == k]
        ref = simulate_orbit(sc, ics[k], fp_type=np.longdouble)  # same rules: φ̇ > 0, t > 1e-10
        ref_t = [r[0] for r in ref.sections]
        assert len(mine) == len(ref_t)
        for tm, tr in zip(mine, ref_t):
            assert abs(tm - float(tr)) <= 1e-10 * max(1.0, float(tr))
            # the state against an independent event-free long-double run to that time
            s_ref = state_at(sc, ics[k], tr, fp_type=np.longdouble).astype(float)
            row = (sec["traj_id"] == k) & (sec["t"] == tm)
            mine_s = np.array([x[row][0], y[row][0], px[row][0], py[row][0]])
            assert np.abs(mine_s - s_ref).max() <= 1e-10


def test_batch_equals_one_orbit_at_a_time(cons_scene):
    """Same escape times as the scalar driver to a few hundred eps for short orbits."""
    ics, res = _run(cons_scene, n=60)
    t = res.lifetimes["t_end"]
    for k in range(60):
        ref = simulate_orbit(cons_scene, ics[k])
        assert ref.outcome == res.lifetimes["outcome"][k]
        if t[k] < 10:  # chaos amplifies roundoff as e^{λt}; short orbits stay at eps level
            assert abs(float(ref.t_end) - t[k]) <= 256 * EPS * t[k], (k, t[k])


def test_results_do_not_depend_on_lanes_or_chunking(cons_scene):
    """Bitwise: batch sizes 2, 4, 8 and any split of the orbits give the same rows.

    (Batch size 1 runs heyoka's scalar code and 16 two AVX-512 registers:
    those differ in the last bits, amplified by chaos on long orbits.)
    """
    ics = region_ics(cons_scene, 0, 120)
    ids = np.arange(120)
    base = run_chunk(cons_scene, ics, ids, batch_size=4).lifetimes
    for b in (2, 8):
        other = run_chunk(cons_scene, ics, ids, batch_size=b).lifetimes
        for col in ("t_end", "e_end", "outcome", "exit_channel"):
            assert np.array_equal(base[col], other[col]), (b, col)
    split = [run_chunk(cons_scene, ics[a : a + 37], ids[a : a + 37]).lifetimes for a in range(0, 120, 37)]
    assert np.array_equal(base["t_end"], np.concatenate([s["t_end"] for s in split]))


def test_dissipative_outcomes(diss_scene):
    ics, res = _run(diss_scene)
    lt = res.lifetimes
    out = lt["outcome"]
    assert set(np.unique(out)) <= {ESCAPED, SETTLED}
    assert (out == SETTLED).sum() >= 1 and (out == ESCAPED).sum() >= 100
    assert np.isfinite(lt["t_end"]).all() and np.isfinite(lt["e_end"]).all()
    m = diss_scene.model
    assert np.allclose(lt["e_end"][out == SETTLED], m.critical_energy, rtol=1e-13)
    assert (lt["e_end"][out == ESCAPED] > m.critical_energy).all()  # escape happens before closure
    for k in np.flatnonzero(out == SETTLED)[:2].tolist() + np.flatnonzero(out == ESCAPED)[:3].tolist():
        ref = simulate_orbit(diss_scene, ics[k])
        assert ref.outcome == out[k]
        if out[k] == ESCAPED and lt["t_end"][k] < 15:
            assert abs(float(ref.t_end) - lt["t_end"][k]) <= 1e-10 * lt["t_end"][k]
        if out[k] == ESCAPED:
            # reference stops at closure or r_far, after the escape
            assert np.hypot(*ref.state_end[:2]) > 1.0


def test_dissipative_sections_and_snapshots_windows(diss_scene):
    ics, res = _run(diss_scene)
    sec, snap, lt = res.sections, res.snapshots, res.lifetimes
    assert len(sec["t"]) > 0 and (sec["t"] >= 5.0).all() and (sec["t"] <= 40.0).all()
    tend = dict(zip(lt["traj_id"], lt["t_end"]))
    assert all(t <= tend[k] for k, t in zip(sec["traj_id"], sec["t"]))
    # snapshots: exactly the grid times before each orbit's end, energies decreasing in time
    for k in range(diss_scene.n):
        rows = snap["traj_id"] == k
        expect = [t for t in diss_scene.snapshots if t <= tend[k]]
        assert list(snap["t"][rows]) == expect
        assert (np.diff(snap["energy"][rows]) < 0).all()
    for k in range(5):  # energies at t = 10 against an independent long-double run
        rows = (snap["traj_id"] == k) & (snap["t"] == 10.0)
        if rows.any():
            s = state_at(diss_scene, ics[k], 10.0, fp_type=np.longdouble).astype(float)
            assert abs(diss_scene.model.energy(*s) - snap["energy"][rows][0]) <= 1e-13


@pytest.mark.parametrize("gamma", [1e-5, 1.0])
def test_dissipation_extremes_write_finite_rows(gamma):
    sc = Scene(energy=0.35, gamma=gamma, n=40, seed=7, t_max=400.0)
    _, res = _run(sc)
    for col, v in res.lifetimes.items():
        assert np.isfinite(np.asarray(v, dtype=float)).all(), col


def _fresh_chunk(scene, ics, ids):
    """run_chunk on newly built integrators (the per-process cache emptied first)."""
    from hhscatter.integrate import batch  # deferred: only this helper empties the cache

    batch._FREE.clear()
    return run_chunk(scene, ics, ids)


@pytest.mark.parametrize("kind", ["dissipative_recording", "two_phase_sections"])
def test_reused_integrator_gives_the_rows_of_a_new_one(kind):
    """Bitwise: a chunk on an integrator that a chunk of another scene with the same compiled system
    (another γ, other orbits, orbits ended mid-flight) left behind gives the rows of a new integrator:
    the reset restores time, state, parameters and cooldowns."""
    from hhscatter.integrate import batch

    if kind == "dissipative_recording":
        a = Scene(
            energy=0.3,
            gamma=0.01,
            n=40,
            seed=3,
            snapshots=[0.0, 0.5, 3.0, 7.5],
            sections=SectionWindow(t_from=0.0),
            t_max=40.0,
        )
        b = a.replace(gamma=0.05, t_max=13.0)  # other γ and bound, same compiled system
    else:
        a = Scene(energy=0.27, n=40, seed=3, sections=SectionWindow(t_from=4.0, first_only=True))
        b = a.replace(seed=9)
    ids = np.arange(40)
    runs = [(a, region_ics(a, 0, 40)), (b, region_ics(b, 0, 40)[::-1])]
    want = [_fresh_chunk(sc, ics, ids).tables() for sc, ics in runs]
    assert batch._FREE, "the chunk returned no integrator to the cache"
    for (sc, ics), w in zip(runs + runs, want + want):  # each on the integrators the other left
        got = run_chunk(sc, ics, ids).tables()
        for table, cols in w.items():
            for col, v in cols.items():
                assert np.array_equal(v, got[table][col]), (table, col)
