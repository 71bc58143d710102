"""The no-return rule of dissipative scenes: an escaped orbit stops at the system's no-return radius
R(E) instead of r_far = max(10 r_s, 2 r_esc), with every table bitwise what the scene's own r_far gives
(the rule's proof: hhscatter.model.henon_heiles.HenonHeiles.no_return_radius; the engine's use of it:
hhscatter.integrate.rerun._no_return). The references are the same scenes with an explicit r_far (10, the
default's value, and 100: a ten times longer follow-up), which keep the old far event."""

from __future__ import annotations

import numpy as np
import pytest

from hhscatter.integrate import chunk, engine
from hhscatter.integrate.engine import CENSORED, ESCAPED, SETTLED, run_chunk
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene, SectionWindow


def _tables(scene, ics):
    res = run_chunk(scene, ics, np.arange(len(ics)), count_steps=True)
    return res, res.tables()


def _assert_same(a, b):
    for name, cols in a.items():
        for col, v in cols.items():
            assert np.array_equal(v, b[name][col], equal_nan=True), (name, col)


def test_no_return_radius_stops_escaped_orbits_earlier_with_the_same_tables():
    sc = Scene(energy=0.3, gamma=0.01, n=600, seed=71, r_esc=1.03)
    ics = region_ics(sc, 0, sc.n)
    fast, t_fast = _tables(sc, ics)
    own, t_own = _tables(sc.replace(r_far=10.0), ics)
    far, t_far = _tables(sc.replace(r_far=100.0), ics)
    out = t_fast["lifetimes"]["outcome"]
    assert {ESCAPED, SETTLED} <= set(out.tolist())
    _assert_same(t_fast, t_own)
    _assert_same(t_fast, t_far)  # held orbits followed 10× further: no return, same times and states
    # the rule is in use (most escaped orbits end at E = E_c before r_far: the longer follow-up costs few steps)
    assert fast.n_steps < 0.9 * own.n_steps and own.n_steps <= far.n_steps


def test_orbits_late_at_the_no_return_radius_are_rerun_to_r_far(monkeypatch):
    """Snapshots (epoch scheduler) and a short t_max: escapes close to t_max might not reach r_far by then,
    where the scene's rule censors them; those orbits run again with the scene's far event."""
    calls = []
    merge = chunk._merge_rerun
    monkeypatch.setattr(chunk, "_merge_rerun", lambda *a: calls.append(a[1].sum()) or merge(*a))
    sc = Scene(
        energy=0.32,
        gamma=0.01,
        n=400,
        seed=72,
        r_esc=1.03,
        t_max=30.0,
        snapshots=tuple(np.arange(0.0, 30.01, 1.0)),
        sections=SectionWindow(t_from=3.0),
    )
    ics = region_ics(sc, 0, sc.n)
    _, t_fast = _tables(sc, ics)
    assert calls and calls[0] > 0
    _, t_own = _tables(sc.replace(r_far=10.0), ics)
    _assert_same(t_fast, t_own)
    _, t_far = _tables(sc.replace(r_far=100.0), ics)  # censors more (r_far later): the same where both decide
    a, b = t_fast["lifetimes"], t_far["lifetimes"]
    both = (a["outcome"] != CENSORED) & (b["outcome"] != CENSORED)
    assert both.sum() > 0.5 * sc.n and (a["outcome"] == CENSORED).any()
    for col in ("outcome", "t_end", "exit_channel", "e_end"):
        assert np.array_equal(a[col][both], b[col][both]), col


@pytest.mark.parametrize("sections", [None, SectionWindow(t_from=4.0)], ids=["stream", "two-phase"])
def test_stream_chunks_with_censored_orbits_keep_the_scene_rule(sections):
    """Censored orbits never reached the no-return radius: the same steps, hence bitwise the tables of the
    scene's own rule (the clock censors in orbit time: the lane's history does not enter)."""
    sc = Scene(energy=0.3, gamma=0.01, n=300, seed=73, r_esc=1.03, t_max=40.0, sections=sections)
    ics = region_ics(sc, 0, sc.n)
    _, t_fast = _tables(sc, ics)
    assert (t_fast["lifetimes"]["outcome"] == CENSORED).any()
    _, t_own = _tables(sc.replace(r_far=10.0), ics)
    _assert_same(t_fast, t_own)


def test_a_chunk_with_censored_orbits_reports_its_orbits_once():
    sc = Scene(energy=0.3, gamma=0.01, n=1500, seed=74, r_esc=1.03, t_max=40.0)
    ticks = []
    res = run_chunk(sc, region_ics(sc, 0, sc.n), np.arange(sc.n), progress=ticks.append)
    assert (res.lifetimes["outcome"] == CENSORED).any()
    assert sum(ticks) == engine.PROGRESS_EVERY  # one report per 1024 orbits started
