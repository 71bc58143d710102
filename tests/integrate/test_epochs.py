"""The epoch scheduler's per-epoch tables (built once per process and scene, not per chunk) and its lean orbit
loader (the tables of the rule methods it stands for)."""

import numpy as np
import pytest

from hhscatter.integrate import epochs, events
from hhscatter.integrate.chunk import run_chunk
from hhscatter.integrate.plan import plan_of
from hhscatter.integrate.schedulers import SCHEDULERS, register
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene, SectionWindow


def test_the_epoch_tables_are_built_once_for_all_chunks_of_a_scene():
    """A dissipative scene's chunks each integrate a plan of their own (the no-return rule moves its far radius
    per chunk), and the grid and snapshot-time tables (625 epochs at t_max = 5000: ~13 ms to build) are the
    same for all: the first chunk builds them, the next reuse them, and its tables are those of a fresh start."""
    scene = Scene(energy=0.3, n=40, seed=9, gamma=0.01, snapshots=(0.0, 2.5, 10.0, 100.0))
    plan = plan_of(scene)
    ics = region_ics(scene, 0, scene.n)
    epochs.epoch_tables.cache_clear()
    first = run_chunk(plan, ics[:20], np.arange(20)).tables()
    second = run_chunk(plan, ics[20:], np.arange(20, 40)).tables()
    info = epochs.epoch_tables.cache_info()
    assert (info.misses, info.hits) == (1, 1)
    assert len(first["snapshots"]["t"]) > 0
    epochs.epoch_tables.cache_clear()
    fresh = run_chunk(plan_of(scene), ics[20:], np.arange(20, 40)).tables()
    for name in second:
        for col in second[name]:
            assert np.array_equal(np.asarray(second[name][col]), np.asarray(fresh[name][col])), (name, col)


def test_the_shared_epoch_tables_are_read_only():
    grid, snap_times, has = epochs.epoch_tables(8.0, 3, (0.0, 1.0, 20.0))
    assert not (grid.flags.writeable or snap_times.flags.writeable or has.flags.writeable)


class _ByMethods(epochs._Epochs):
    """The epoch scheduler with its orbits loaded by the rule methods (``load_next``, ``load_orbit``,
    ``start_orbit``): a subclass that loads its own way gets no lean loader."""

    name = "epochs-by-methods"

    @classmethod
    def applies(cls, plan) -> bool:
        return False

    def load_orbit(self, lane, k):
        super().load_orbit(lane, k)


@pytest.mark.parametrize("window", ["opens at t = 17", "open to t = 25", "open to t = 25, starts opened late"])
def test_the_lean_loader_gives_the_tables_of_the_rule_methods(window, monkeypatch):
    """The epochs' orbit loader (one closure: initial condition, rule state, gate, clock) against the methods it
    stands for: orbits censored at t_max, progress reports, and a section window that opens late (the clock opens
    the gate), one open from the start, or one whose orbits start on the section and have it opened at T_INITIAL
    by the clock (every such start counted as near an inflection): byte-identical tables."""
    snaps = tuple(float(t) for t in np.arange(0.0, 30.0 + 1e-9, 0.5))
    if window == "opens at t = 17":
        sections = SectionWindow(t_from=17.0, first_only=True)
    else:
        sections = SectionWindow(t_to=25.0)
    if window.endswith("opened late"):
        monkeypatch.setattr(events, "OPEN_LATE_SLOPE", 1e300)
    scene = Scene(energy=0.3, gamma=0.01, n=1500, seed=5, r_esc=1.03, t_max=40.0, snapshots=snaps, sections=sections)
    ics = region_ics(scene, 0, scene.n)
    late = events.opens_late(plan_of(scene), ics)
    assert (late is not None and late.sum() > 100) == window.endswith("opened late")
    register(_ByMethods)
    try:
        ticks = {True: [], False: []}
        out = {}
        for lean in (True, False):
            plan = plan_of(scene) if lean else plan_of(scene, scheduler=_ByMethods.name)
            out[lean] = run_chunk(plan, ics, np.arange(scene.n), progress=ticks[lean].append).tables()
    finally:
        SCHEDULERS.pop(_ByMethods.name, None)
    assert ticks[True] == ticks[False] == [1024]
    assert (out[True]["lifetimes"]["outcome"] == epochs.CENSORED).any() and len(out[True]["sections"]["t"]) > 10
    for name, cols in out[False].items():
        for col, v in cols.items():
            assert np.asarray(out[True][name][col]).tobytes() == np.asarray(v).tobytes(), (name, col)
