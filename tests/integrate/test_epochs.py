"""The epoch scheduler's per-epoch tables: built once per process and scene, not per chunk."""

import numpy as np

from hhscatter.integrate import epochs
from hhscatter.integrate.chunk import run_chunk
from hhscatter.integrate.plan import plan_of
from hhscatter.scene.ics import region_ics
from hhscatter.scene.scene import Scene


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
