"""Every mode of the one engine, built from the one event declaration (hhscatter.integrate.events):
against the scalar long-double reference driver (same events and rules, independent precision),
for invariance under chunking and lanes, and for what each scene option promises."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from hhscatter.analysis.survival.fits import observed_from_outcome
from hhscatter.integrate import events
from hhscatter.integrate.engine import CENSORED, ESCAPED, SETTLED, STOPPED, run_chunk, scheduler, simulate_orbit
from hhscatter.integrate.plan import plan_of
from hhscatter.model import HenonHeiles
from hhscatter.scene.ics import region_ics, section_velocities
from hhscatter.scene.scene import Follow, Scene, SceneError, SectionWindow

ROOT = Path(__file__).resolve().parents[2]
OLD_HASH = "4e97917dd6101d2cc772e8ceb545ee8f6dd47b4ed183576388f7feba3d9c93c5"  # computed by scene.py at 6a7a794


def _run(scene, n=None, ics=None, **kw):
    n = n or scene.n
    ics = region_ics(scene, 0, n) if ics is None else ics
    return ics, run_chunk(scene, ics, np.arange(len(ics)), **kw)


# -- the declaration ------------------------------------------------------------


def test_only_the_integrators_module_constructs_heyoka_events():
    pat = re.compile(r"\b(t_event|nt_event|t_event_batch|nt_event_batch)\(")
    users = sorted(str(p.relative_to(ROOT)) for p in (ROOT / "hhscatter").rglob("*.py") if pat.search(p.read_text()))
    assert users == ["hhscatter/integrate/integrators.py"]


@pytest.mark.parametrize(
    "kw, names",
    [
        ({}, ["escape", "clock"]),  # stream scenes censor with the clock (orbit time: test_determinism)
        ({"gamma": 0.01}, ["closure", "far", "resc", "clock"]),
        ({"gamma": 0.01, "snapshots": (1.0, 2.0)}, ["closure", "far", "resc"]),  # epochs censor at an epoch's end
        ({"sections": SectionWindow()}, ["escape", "section", "clock"]),
        ({"sections": SectionWindow(t_from=3.0, t_to=9.0)}, ["escape", "section", "clock"]),
        ({"follow": Follow((1.0, 2.0))}, ["far", "radius0", "radius1", "radius2", "clock"]),
    ],
)
def test_scene_events_compile_only_what_the_scene_needs(kw, names):
    # (a stream scene whose window opens late compiles the section event only into the
    # orbits' second phase: events.two_phase, tested bitwise and against the reference below)
    sc = plan_of(Scene(energy=0.3, n=1, r_esc=1.5, **kw))
    assert [e.name for e in sc.events] == names
    lay = sc.layout
    assert (lay.clock is not None) == ("clock" in names)
    assert (lay.gate is not None) == ("section" in names)


def test_scene_options_are_validated_before_any_work():
    with pytest.raises(SceneError, match="follow is for conservative"):
        Scene(energy=0.3, n=1, gamma=0.01, follow=Follow((1.0,)))
    with pytest.raises(SceneError, match="continue_settled needs"):
        Scene(energy=0.3, n=1, gamma=0.01, continue_settled=True)
    with pytest.raises(SceneError, match="sections.stop needs"):
        SectionWindow(t_from=1.0, stop=True)
    with pytest.raises(SceneError, match="first_only must be true or false"):
        SectionWindow(first_only="no")
    with pytest.raises(SceneError, match="strictly increasing"):
        Follow((2.0, 1.0))


def test_new_options_leave_existing_scene_hashes_unchanged():
    # a scene of the previous engine (no new options) hashes as before, so its runs resume
    sc = Scene(energy=0.3, gamma=0.01, n=100, seed=3, sections=SectionWindow(t_from=2.0), snapshots=(0.0, 1.0))
    d = sc.to_dict()
    assert "follow" not in d and "continue_settled" not in d and "stop" not in d["sections"]
    # the hash of this scene as the previous engine (commit 6a7a794) computed it
    assert sc.result_hash() == OLD_HASH
    assert sc.replace(continue_settled=False).result_hash() == sc.result_hash()


# -- against the scalar reference (long double) ------------------------------------


def _agree_short(scene, ics, res, t_short=12.0, rtol=1e-9, n_min=20):
    """Outcomes and t_end of short-lived orbits against the long-double scalar driver."""
    lt = res.lifetimes
    short = np.flatnonzero(lt["t_end"] < t_short)
    assert len(short) >= n_min, len(short)
    for k in short:
        ref = simulate_orbit(scene, ics[k], fp_type=np.longdouble)
        assert ref.outcome == lt["outcome"][k], k
        assert abs(float(ref.t_end) - lt["t_end"][k]) <= rtol * max(1.0, lt["t_end"][k]), k
    return short


def test_conservative_mode_against_reference():
    sc = Scene(energy=0.3, n=200, seed=31, r_esc=1.03)
    ics, res = _run(sc)
    _agree_short(sc, ics, res, n_min=100)


def test_dissipative_mode_against_reference():
    sc = Scene(energy=0.3, gamma=0.05, n=200, seed=32, r_esc=1.03)
    ics, res = _run(sc)
    lt = res.lifetimes
    assert {ESCAPED, SETTLED} <= set(lt["outcome"].tolist())
    short = _agree_short(sc, ics, res, t_short=20.0, n_min=100)
    assert (lt["outcome"][short] == SETTLED).any()


def test_sections_with_every_window_kind_against_reference():
    win = SectionWindow(t_from=2.0, t_to=14.0, e_min=0.29, e_max=0.31)
    sc = Scene(energy=0.3, gamma=0.005, n=120, seed=33, r_esc=1.03, sections=win)
    ics, res = _run(sc)
    sec = res.sections
    assert len(sec["t"]) > 50
    assert (sec["t"] >= 2.0).all() and (sec["t"] <= 14.0).all()
    assert ((sec["energy"] >= 0.29) & (sec["energy"] <= 0.31)).all()
    assert (sec["x"] * sec["py"] - sec["y"] * sec["px"] > 0).all()
    for k in range(25):
        ref = simulate_orbit(sc, ics[k], fp_type=np.longdouble)
        mine = sec["t"][sec["traj_id"] == k]
        theirs = np.array([float(r[0]) for r in ref.sections])
        assert len(mine) == len(theirs), k
        np.testing.assert_allclose(mine, theirs, rtol=1e-9)
    # first_only: at most one row per orbit, and the first of the full window's rows
    first = run_chunk(
        sc.replace(sections=SectionWindow(t_from=2.0, t_to=14.0, e_min=0.29, e_max=0.31, first_only=True)),
        ics,
        np.arange(len(ics)),
    ).sections
    assert not np.any(np.diff(first["traj_id"]) == 0)
    for k, t in zip(first["traj_id"][:30], first["t"][:30]):
        assert abs(t - sec["t"][sec["traj_id"] == k][0]) <= 1e-9 * t


def test_snapshots_epoch_scheduler_against_reference():
    snaps = tuple(np.arange(0.0, 30.01, 0.5))
    sc = Scene(energy=0.3, gamma=0.02, n=160, seed=34, r_esc=1.03, snapshots=snaps)
    assert scheduler(sc) == "epochs"
    ics, res = _run(sc)
    lt, sn = res.lifetimes, res.snapshots
    short = _agree_short(sc, ics, res, t_short=15.0, n_min=60)
    for k in short[:20]:
        ref = simulate_orbit(sc, ics[k], fp_type=np.longdouble)
        rows = sn["traj_id"] == k
        assert list(sn["t"][rows]) == [t for t in snaps if t <= lt["t_end"][k]]
        e_ref = [HenonHeiles().energy(*np.asarray(s, dtype=float)) for _, s in ref.snapshots]
        np.testing.assert_allclose(sn["energy"][rows], e_ref, rtol=1e-11)


def test_continue_settled_against_reference():
    # quickly settling orbits (E0 just above E_c, strong drag) keep chaos short, so the engine's
    # continued energies can be held to the long-double reference at 1e-10
    m = HenonHeiles()
    rng = np.random.default_rng(35)
    r = 0.4 * np.sqrt(rng.random(60))
    phi = 2 * np.pi * rng.random(60)
    x, y = r * np.cos(phi), r * np.sin(phi)
    px, py = section_velocities(m, x, y, m.critical_energy + 0.01)
    ics = np.column_stack([x, y, px, py])
    snaps = tuple(np.arange(0.0, 60.01, 2.0))
    sc = Scene(energy=0.3, gamma=0.1, n=60, snapshots=snaps, continue_settled=True)
    _, res = _run(sc, ics=ics)
    lt, sn = res.lifetimes, res.snapshots
    settled = np.flatnonzero(lt["outcome"] == SETTLED)
    assert len(settled) >= 30
    n_after = 0
    for k in settled[:20]:
        rows = sn["traj_id"] == k
        assert list(sn["t"][rows]) == list(snaps)  # every grid time, before and after settling
        assert (sn["energy"][rows][np.asarray(snaps) > lt["t_end"][k]] < m.critical_energy).all()
        ref = simulate_orbit(sc, ics[k], fp_type=np.longdouble)
        assert ref.outcome == SETTLED and abs(float(ref.t_end) - lt["t_end"][k]) <= 1e-10
        e_ref = np.array([m.energy(*np.asarray(s, dtype=float)) for _, s in ref.snapshots])
        np.testing.assert_allclose(sn["energy"][rows], e_ref, rtol=0, atol=1e-10)
        n_after += int((np.asarray(snaps) > lt["t_end"][k]).sum())
    assert n_after > 100


def test_stopped_orbits_are_censoring():
    sc = Scene(energy=0.35, n=300, seed=36, r_esc=1.03, sections=SectionWindow(t_from=4.0, first_only=True, stop=True))
    ics, res = _run(sc)
    lt, sec = res.lifetimes, res.sections
    stopped = lt["outcome"] == STOPPED
    assert stopped.sum() >= 20
    # a stopped orbit ends at its one recorded crossing, and nothing else is integrated
    np.testing.assert_array_equal(np.sort(sec["traj_id"]), np.flatnonzero(stopped))
    np.testing.assert_array_equal(sec["t"], lt["t_end"][stopped])
    assert (lt["t_end"][~stopped] < sec["t"].max()).any()
    labels = np.array(events.OUTCOMES, dtype=object)[lt["outcome"]]
    assert not observed_from_outcome(labels)[stopped].any()
    # the crossings themselves are those of the same scene without stop
    full = run_chunk(sc.replace(sections=SectionWindow(t_from=4.0, first_only=True)), ics, np.arange(sc.n))
    np.testing.assert_array_equal(full.sections["traj_id"], sec["traj_id"])
    np.testing.assert_allclose(full.sections["t"], sec["t"], rtol=1e-12)


def test_section_window_stop_at_t_to():
    sc = Scene(
        energy=0.3, gamma=0.01, n=200, seed=37, r_esc=1.03, sections=SectionWindow(t_from=3.0, t_to=9.0, stop=True)
    )
    _, res = _run(sc)
    lt = res.lifetimes
    st = lt["outcome"] == STOPPED
    assert st.sum() > 10
    # stopped when the window closes (t_to, plus the clock's margin of 1e-9 so no crossing is lost)
    assert ((lt["t_end"][st] >= 9.0) & (lt["t_end"][st] <= 9.0 + 2e-9)).all()
    assert (lt["t_end"][~st] < 9.0 + 1e-9).all()


# -- invariance -----------------------------------------------------------------------


@pytest.mark.parametrize(
    "kw",
    [
        {"gamma": 0.005, "energy": 0.32},
        {
            "gamma": 0.01,
            "energy": 0.3,
            "snapshots": tuple(np.arange(0.0, 40.01, 0.5)),
            "sections": SectionWindow(t_from=5.0, first_only=True),
        },
        {"gamma": 0.0, "energy": 0.3, "follow": Follow((1.0, 2.0))},
        {"gamma": 0.01, "energy": 0.35, "sections": SectionWindow(t_from=6.0, t_to=30.0)},
    ],
    ids=["dissipative", "epochs+sections", "follow", "two-phase sections"],
)
def test_tables_do_not_depend_on_chunking_or_lanes(kw):
    """Bitwise, for γ > 0 too: event roots end heyoka's step, so times come from the orbit's own clock."""
    sc = Scene(n=240, seed=38, r_esc=1.03, **kw)
    ics = region_ics(sc, 0, sc.n)
    ids = np.arange(sc.n)
    base = run_chunk(sc, ics, ids, batch_size=4).tables()
    split = [run_chunk(sc, ics[a : a + 70], ids[a : a + 70], batch_size=8).tables() for a in range(0, sc.n, 70)]
    for name, cols in base.items():
        for col, v in cols.items():
            other = np.concatenate([s[name][col] for s in split])
            assert np.array_equal(v, other), (name, col)


def test_follow_and_conservative_lifetimes_agree_on_outcomes():
    sc = Scene(energy=0.3, n=200, seed=39, r_esc=1.03)
    ics, plain = _run(sc)
    _, fol = _run(sc.replace(follow=Follow((1.0, 2.0))), ics=ics)
    short = plain.lifetimes["t_end"] < 12
    np.testing.assert_array_equal(fol.lifetimes["outcome"][short], plain.lifetimes["outcome"][short])
    cr = fol.crossings
    # the escape is the first outward crossing of r_esc in the crossings table
    for k in np.flatnonzero(fol.lifetimes["outcome"] == ESCAPED)[:50]:
        m = (cr["traj_id"] == k) & (cr["radius"] == 1.03) & (cr["direction"] == 1)
        assert cr["t"][m][0] == fol.lifetimes["t_end"][k]
    assert (fol.lifetimes["outcome"] != CENSORED).any()


# -- progress from inside a chunk ------------------------------------------------------


@pytest.mark.parametrize("kw", [{}, {"gamma": 0.01, "snapshots": (0.0, 5.0, 10.0)}], ids=["stream", "epochs"])
def test_progress_is_reported_from_inside_a_chunk(kw):
    from hhscatter.integrate.engine import PROGRESS_EVERY

    sc = Scene(energy=0.3, n=5000, seed=40, r_esc=1.03, **kw)
    ics = region_ics(sc, 0, sc.n)
    seen = []
    res = run_chunk(sc, ics, np.arange(sc.n), progress=seen.append)
    assert seen == [PROGRESS_EVERY] * (sc.n // PROGRESS_EVERY)  # (no reruns at t_max = 5000 here)
    plain = run_chunk(sc, ics, np.arange(sc.n))
    assert np.array_equal(res.lifetimes["t_end"], plain.lifetimes["t_end"])  # progress changes nothing


@pytest.mark.parametrize("workers", [1, 2])
def test_runner_progress_moves_within_chunks_and_totals_exactly(tmp_path, monkeypatch, workers):
    import hhscatter.run.runner as runner

    updates = []

    class Bar:
        def update(self, k):
            updates.append(k)

        def close(self):
            pass

    monkeypatch.setattr(runner, "progress_bar", lambda *a, **k: Bar())
    sc = Scene(energy=0.3, n=6000, seed=41, r_esc=1.03, chunk_size=3000)
    runner.simulate(sc, tmp_path / "run", workers=workers, progress=True)
    assert sum(updates) == sc.n
    assert len(updates) > 2  # more than one update per chunk


# -- the authors' square initial conditions ----------------------------------------------


def test_square_region_is_uniform_in_the_allowed_square_and_on_the_energy_shell():
    from scipy import stats

    E = 0.3
    m = HenonHeiles()
    sc = Scene(energy=E, n=20000, seed=42, region="square", r_esc=1.03)
    ics = region_ics(sc, 0, sc.n)
    x, y, px, py = ics.T
    assert (np.abs(x) <= 1).all() and (np.abs(y) <= 1).all()
    np.testing.assert_allclose(m.energy(x, y, px, py), E, rtol=0, atol=4e-16)
    assert np.abs(x * px + y * py).max() < 1e-15 and (x * py - y * px > 0).all()  # ṙ = 0, φ̇ > 0
    # the x marginal against the allowed area {V < E} ∩ [−1, 1]², from an independent fine grid
    g = np.linspace(-1, 1, 4001)
    X, Y = np.meshgrid(g, g, indexing="ij")
    allowed = (m.potential(X, Y) < E).sum(axis=1).astype(float)
    cdf_x = np.concatenate([[0.0], np.cumsum(0.5 * (allowed[1:] + allowed[:-1]))])
    cdf_x /= cdf_x[-1]
    assert stats.kstest(x, lambda v: np.interp(v, g, cdf_x)).pvalue > 0.01
    # and points beyond the saddle triangle are there (the disk and the well have none)
    assert (~m.inside_triangle(x, y)).mean() > 0.01


@pytest.mark.parametrize("gamma", [0.0, 0.01])
def test_orbits_starting_beyond_r_esc_are_escaped_at_t0(gamma):
    sc = Scene(
        energy=0.3,
        gamma=gamma,
        n=3000,
        seed=43,
        region="square",
        r_esc=1.03,
        snapshots=(0.0, 1.0, 2.0) if gamma else None,
    )
    ics = region_ics(sc, 0, sc.n)
    out = ics[:, 0] ** 2 + ics[:, 1] ** 2 >= 1.03**2
    assert out.sum() > 20
    res = run_chunk(sc, ics, np.arange(sc.n) + 100)
    lt = res.lifetimes
    np.testing.assert_array_equal(lt["traj_id"], np.arange(sc.n) + 100)
    assert (lt["outcome"][out] == ESCAPED).all() and (lt["t_end"][out] == 0.0).all()
    assert (lt["t_end"][~out] > 0).all()
    np.testing.assert_array_equal(lt["exit_channel"][out], HenonHeiles().exit_channel(ics[out, 0], ics[out, 1]))
    # the others exactly as in a run without them
    alone = run_chunk(sc, ics[~out], np.flatnonzero(~out) + 100).lifetimes
    np.testing.assert_array_equal(lt["t_end"][~out], alone["t_end"])
    if gamma:  # their one snapshot, at t = 0 ≤ t_end
        sn = res.snapshots
        rows = np.isin(sn["traj_id"], np.flatnonzero(out) + 100)
        assert (sn["t"][rows] == 0.0).all() and rows.sum() == out.sum()
    k = int(np.flatnonzero(out)[0])
    assert simulate_orbit(sc, ics[k]).outcome == ESCAPED and simulate_orbit(sc, ics[k]).t_end == 0.0
